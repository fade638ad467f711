"""Paper 2, Tables 8 to 14: orientation tests while locating, and conflicting
cells, per point, for the Kd-tree, BRIO and Hilbert orders on all seven 3D
models; through CGAL with counting traits and find_conflicts/insert_in_hole
(the paper's method) and through lfqt.insert.  CGAL's Hilbert is counted with
our Hilbert order, since CGAL's range insertion calls its conflict search
internally.  The paper's sizes differ per model; ours are one grid for all,
and the figure draws the published values at their own sizes."""
import sys

import numpy as np

from . import results
from .experiment import Experiment, figure_paths
from .runner import Cell

SIZES = {"smoke": [5_000], "default": [100_000], "paper": [100_000, 1_000_000]}
# (label, ours, CGAL); CGAL's Hilbert here is our Hilbert order through
# find_conflicts (see above)
ORDERS = [("kdtree", "lfqt-insert-kdtree", "cgal-dt3-kdtree"),
          ("brio", "lfqt-insert-brio", "cgal-dt3-brio"),
          ("hilbert", "lfqt-insert-hilbert", "cgal-dt3-hilbert")]
TABLES = {"cube": "Table 8", "plane": "Table 9", "paraboloid": "Table 10",
          "spiral3d": "Table 11", "disc": "Table 12", "cylinder": "Table 13", "axes": "Table 14"}
METRICS = ("orientation_per_point", "conflicts_per_point")
COLORS = {"kdtree": "#1b6ca8", "brio": "#d1495b", "hilbert": "#66a182"}


def grid(scale, threads):
    return [Cell(peer, model, n, threads=threads, count=True)
            for model in TABLES for n in SIZES[scale]
            for _, ours, cgal in ORDERS for peer in (ours, cgal)]


def per_point(counts, n):
    """(orientation, conflicts) per point from a peer's counts."""
    o = counts.get("orientation_tests")
    c = counts.get("conflicts")
    return (o / n if o is not None else np.nan, c / n if c is not None else np.nan)


def published_counts():
    """{(model, order, n, metric): value} of Tables 8 to 14."""
    tables = {t: m for m, t in TABLES.items()}
    return {(tables[r["table"]], r["order"], int(r["n"]), r["metric"]): float(r["value"])
            for r in results.published("liu2013").to_dict("records")
            if r["table"] in tables and r["value"]}


def plot(df, out):
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FuncFormatter
    plain = FuncFormatter(lambda v, _: f"{v:g}")
    sparse = FuncFormatter(lambda v, _: f"{v:g}" if f"{v:g}"[0] in "125" else "")
    s = results.summarize(df)
    pub = published_counts()
    models = [m for m in TABLES if m in set(df["distribution"])]
    fig, axes = plt.subplots(2, len(models), figsize=(3.2 * len(models), 6.4), squeeze=False)
    print(f"\n{'model':10} {'n':>9} {'order':8} {'orient/pt lfqt':>15} {'CGAL':>7} {'paper':>7}   "
          f"{'conflicts/pt lfqt':>18} {'CGAL':>7} {'paper':>7}   (paper: nearest published n)")
    for col, model in enumerate(models):
        ns = sorted(df.loc[df["distribution"] == model, "n"].unique())
        for label, ours, cgal in ORDERS:
            po = [per_point(results.cell(s, ours, model, n, True).get("counts", {}), n) for n in ns]
            pc = [per_point(results.cell(s, cgal, model, n, True).get("counts", {}), n) for n in ns]
            pub_n = sorted({n for (m, o, n, _) in pub if m == model and o == label})
            for k, metric in enumerate(METRICS):
                ax = axes[k, col]
                ax.plot(ns, [p[k] for p in po], "-o", color=COLORS[label], label=f"{label}: lfqt")
                ax.plot(ns, [p[k] for p in pc], "--s", color=COLORS[label], label=f"{label}: CGAL")
                ax.plot(pub_n, [pub[(model, label, n, metric)] for n in pub_n], ":^",
                        color=COLORS[label], alpha=0.6, label=f"{label}: paper (CGAL 4.0)")
            for n, a, b in zip(ns, po, pc):
                near = min(pub_n, key=lambda m: abs(m - n)) if pub_n else None
                po_pub = pub.get((model, label, near, METRICS[0]), np.nan)
                pc_pub = pub.get((model, label, near, METRICS[1]), np.nan)
                print(f"{model:10} {n:>9,} {label:8} {a[0]:15.2f} {b[0]:7.2f} {po_pub:7.2f}   "
                      f"{a[1]:18.2f} {b[1]:7.2f} {pc_pub:7.2f}")
        axes[0, col].set_title(f"{model} ({TABLES[model]})")
        for k, ylabel in enumerate(("orientation tests / point", "conflicting cells / point")):
            ax = axes[k, col]
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.yaxis.set_major_formatter(plain)
            ax.yaxis.set_minor_formatter(sparse)
            ax.grid(alpha=0.3, which="both")
            if col == 0:
                ax.set_ylabel(ylabel)
            if k == 1:
                ax.set_xlabel("points")
    axes[1, -1].legend(fontsize=6, ncol=1, loc="best")
    fig.suptitle("Paper 2, Tables 8-14: per-point counts by insertion order (solid: lfqt, "
                 "dashed: CGAL 5.5, dotted: paper)")
    fig.tight_layout()
    return figure_paths(fig, out, "liu_counts")


EXPERIMENT = Experiment("liu_counts", "orientation tests and conflicts per point, seven 3D models, "
                        "three orders, in CGAL and in lfqt", grid, plot,
                        reproduces=tuple(("Paper 2", f"Table {k}") for k in range(8, 15)),
                        repeats=1, main_job=True)
main = EXPERIMENT.main


if __name__ == "__main__":
    sys.exit(main())
