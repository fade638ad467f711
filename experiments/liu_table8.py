"""Paper 2, Table 8 (cube): orientation tests while locating and conflicting
cells, per point, for the Kd-tree, BRIO and Hilbert orders; through CGAL
with counting traits and find_conflicts/insert_in_hole (the paper's method)
and through lfqt.insert.  CGAL's Hilbert is counted with our Hilbert order,
since CGAL's range insertion calls its conflict search internally."""
import sys

import numpy as np

from . import common
from .liu_table1 import MODEL, SIZES
from .runner import Cell, summarize

# CGAL's Hilbert here is our Hilbert order through find_conflicts (see above)
ORDERS = [("kdtree", "lfqt-insert-kdtree", "cgal-dt3-kdtree"),
          ("brio", "lfqt-insert-brio", "cgal-dt3-brio"),
          ("hilbert", "lfqt-insert-hilbert", "cgal-dt3-hilbert")]
TABLE = "Table 8"


def grid(scale, threads):
    return [Cell(peer, MODEL, n, count=True) for n in SIZES[scale] for _, ours, cgal in ORDERS
            for peer in (ours, cgal)]


def per_point(counts, n):
    """(orientation, conflicts) per point from a peer's counts."""
    o = counts.get("orientation_tests", counts.get("orientation"))
    c = counts.get("conflicts")
    return (o / n if o is not None else np.nan, c / n if c is not None else np.nan)


def plot(rows, out, scale):
    import matplotlib.pyplot as plt
    s = summarize(rows)
    pub = {}
    for r in common.published("liu2013"):
        if r["table"] == TABLE:
            pub[(r["order"], int(r["n"]), r["metric"])] = float(r["value"])
    ns = sorted({r["n"] for r in rows})
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.8))
    colors = {"kdtree": "#1b6ca8", "brio": "#d1495b", "hilbert": "#66a182"}
    print(f"\n{'n':>9} {'order':8} {'orient/pt lfqt':>15} {'CGAL':>7} {'paper':>7}   "
          f"{'conflicts/pt lfqt':>18} {'CGAL':>7} {'paper':>7}")
    for label, ours, cgal in ORDERS:
        po = [per_point(s.get((ours, MODEL, n, "", True), {}).get("counts", {}), n) for n in ns]
        pc = [per_point(s.get((cgal, MODEL, n, "", True), {}).get("counts", {}), n) for n in ns]
        for k, metric in enumerate(("orientation_per_point", "conflicts_per_point")):
            ax = axes[k]
            ax.plot(ns, [p[k] for p in po], "-o", color=colors[label], label=f"{label}: lfqt")
            ax.plot(ns, [p[k] for p in pc], "--s", color=colors[label], label=f"{label}: CGAL")
            pn = sorted(n for (o, n, m) in pub if o == label and m == metric)
            ax.plot(pn, [pub[(label, n, metric)] for n in pn], ":^", color=colors[label], alpha=0.6,
                    label=f"{label}: paper (CGAL 4.0)")
        for n, a, b in zip(ns, po, pc):
            print(f"{n:>9,} {label:8} {a[0]:15.2f} {b[0]:7.2f} "
                  f"{pub.get((label, n, 'orientation_per_point'), np.nan):7.2f}   {a[1]:18.2f} "
                  f"{b[1]:7.2f} {pub.get((label, n, 'conflicts_per_point'), np.nan):7.2f}")
    for ax, title in zip(axes, ("orientation tests per point (locating)", "conflicting cells per point")):
        ax.set_xlabel("points")
        ax.set_title(title)
        ax.grid(alpha=0.3)
        ax.set_ylim(bottom=0)
    axes[1].legend(fontsize=7, ncol=3)
    fig.suptitle(f"Paper 2, {TABLE} ({MODEL})")
    return common.figure_paths(fig, out, "liu_table8")


def main(argv=None):
    return common.main("liu_table8", __doc__, grid, plot, argv, repeats=1)


if __name__ == "__main__":
    sys.exit(main())
