"""Paper 2, Tables 8 to 14: orientation tests while locating, and conflicting
cells, per point, for the Kd-tree, BRIO and Hilbert orders on all seven 3D
models; through CGAL with counting traits and find_conflicts/insert_in_hole
(the paper's method) and through lfqt.insert.  CGAL's Hilbert is counted with
our Hilbert order, since CGAL's range insertion calls its conflict search
internally.  Sizes per model as experiments.paper2.liu.sizes (the paper's six at
the paper scale).  The flat-count check prints each count's spread across
the sizes, ours and the paper's (Kd's counts are flat in the paper, BRIO's
and Hilbert's grow); flagged published rows are drawn apart."""
import sys

import numpy as np

from . import liu
from ..core import results
from ..core.claims import AtMost, Claim
from ..core.experiment import Experiment, figure_paths
from ..core.runner import Cell

# CGAL's Hilbert here is our Hilbert order through find_conflicts (see above)
ORDERS = liu.ORDERS
TABLES = {m: f"Table {t}" for m, (_, t) in liu.MODELS.items()}
METRICS = ("orientation_per_point", "conflicts_per_point")
COLORS = liu.COLORS


def grid(scale, threads):
    return [Cell(peer, model, n, threads=threads, count=True)
            for model in TABLES for n in liu.sizes(model, scale)
            for _, ours, cgal in ORDERS for peer in (ours, cgal)]


def per_point(counts, n):
    """(orientation, conflicts) per point from a peer's counts."""
    o = counts.get("orientation_tests")
    c = counts.get("conflicts")
    return (o / n if o is not None else np.nan, c / n if c is not None else np.nan)


def published_counts():
    """{(model, order, n, metric): (value, flag)} of Tables 8 to 14, at the
    sizes the rows line up with."""
    out = {}
    for model, (_, table) in liu.MODELS.items():
        for metric in METRICS:
            for (m, order, n), (v, _, flag) in liu.values(table, metric).items():
                if v is not None:
                    out[(m, order, n, metric)] = (v, flag)
    return out


def spread(values):
    """(max - min) / mean of a metric across sizes: the flat-count check."""
    v = np.array([x for x in values if x == x])
    return float((v.max() - v.min()) / v.mean()) if len(v) > 1 else float("nan")


def flat_counts(df):
    """{(system, model, order, metric): spread across the measured sizes}
    for system "lfqt" and "CGAL", and "paper" across its six sizes."""
    s = results.summarize(df)
    pub = published_counts()
    out = {}
    for model in TABLES:
        ns = sorted(df.loc[df["distribution"] == model, "n"].unique())
        for label, ours, cgal in ORDERS:
            for k, metric in enumerate(METRICS):
                for system, peer in (("lfqt", ours), ("CGAL", cgal)):
                    vals = [per_point(results.cell(s, peer, model, n, True).get("counts", {}),
                                      n)[k] for n in ns]
                    out[(system, model, label, metric)] = spread(vals)
                out[("paper", model, label, metric)] = spread(
                    [v for (m, o, n, me), (v, flag) in pub.items()
                     if (m, o, me) == (model, label, metric) and not flag])
    return out


def _pct(x):
    return "-" if x != x else f"{x:.1%}"


def plot(df, out):
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D
    from matplotlib.ticker import FuncFormatter, MaxNLocator
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
                ax.plot(ns, [p[k] for p in po], "-o", color=COLORS[label])
                ax.plot(ns, [p[k] for p in pc], "--s", color=COLORS[label])
                pts = [(n, *pub[(model, label, n, metric)]) for n in pub_n
                       if (model, label, n, metric) in pub]
                ax.plot([n for n, _, f in pts if not f], [v for _, v, f in pts if not f], ":^",
                        color=COLORS[label], alpha=0.6)
                flagged = [(n, v) for n, v, f in pts if f]
                if flagged:
                    ax.scatter(*zip(*flagged), marker="x", s=40, color="black", zorder=4)
            for n, a, b in zip(ns, po, pc):
                near = min(pub_n, key=lambda m: abs(m - n)) if pub_n else None
                po_pub, fo = pub.get((model, label, near, METRICS[0]), (np.nan, ""))
                pc_pub, fc = pub.get((model, label, near, METRICS[1]), (np.nan, ""))
                print(f"{model:10} {n:>9,} {label:8} {a[0]:15.2f} {b[0]:7.2f} {po_pub:7.2f}"
                      f"{'*' if fo else ' '}  {a[1]:18.2f} {b[1]:7.2f} {pc_pub:7.2f}"
                      f"{'*' if fc else ''}")
        axes[0, col].set_title(f"{model} ({TABLES[model]})", fontsize=9)
        for k, ylabel in enumerate(("orientation tests / point", "conflicting cells / point")):
            ax = axes[k, col]
            ax.set_ylim(bottom=0)
            ax.xaxis.set_major_locator(MaxNLocator(3))
            ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: results.fmt_count(v)))
            ax.grid(alpha=0.3)
            if col == 0:
                ax.set_ylabel(ylabel)
            if k == 1:
                ax.set_xlabel("points")
    handles = [Line2D([], [], color=COLORS[o], lw=2, label=o) for o, _, _ in ORDERS]
    handles += [Line2D([], [], color="black", ls=ls, marker=m, label=lab) for ls, m, lab in
                (("-", "o", "lfqt"), ("--", "s", "CGAL 5.5 (this machine)"),
                 (":", "^", "paper (CGAL 4.0)"))]
    handles.append(Line2D([], [], color="black", marker="x", ls="", label="paper, flagged "
                          "(results/published)"))
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=8,
               frameon=False)
    fig.suptitle("Paper 2, Tables 8-14: orientation tests and conflicting cells per point, by "
                 "insertion order")
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    flat = flat_counts(df)
    print("\nflat-count check: (max - min) / mean of each count across the sizes "
          "(lfqt / CGAL / paper)")
    for model in models:
        for label, _, _ in ORDERS:
            print(f"{model:10} {label:8} " + "   ".join(
                f"{metric.split('_')[0]:12} " + " / ".join(
                    _pct(flat[(sy, model, label, metric)]) for sy in ("lfqt", "CGAL", "paper"))
                for metric in METRICS))
    return figure_paths(fig, out, "liu_counts")


def _flat(claim, res):
    flat = flat_counts(res.frame("liu_counts"))
    kd = {k: v for k, v in flat.items() if k[2] == "kdtree" and k[0] != "paper" and v == v}
    if not kd:
        return claim.missing("needs two sizes per model: the default scale")
    others = [v for k, v in flat.items() if k[2] != "kdtree" and k[0] == "CGAL" and v == v]
    worst = max(kd.values())
    paper = [v for k, v in flat.items() if k[0] == "paper" and k[2] == "kdtree" and v == v]
    return claim.row(f"Kd's largest spread across sizes {worst:.1%} (lfqt and CGAL); BRIO and "
                     f"Hilbert up to {max(others, default=float('nan')):.0%}; the paper's Kd up "
                     f"to {max(paper, default=float('nan')):.0%}", claim.rule(worst),
                     "(max - min) / mean of each count over the measured sizes")


CLAIMS = (
    Claim("Kd's counts are flat in the size", "Kd orientation and conflicts per point nearly "
          "constant over six sizes (Tables 8-14)", _flat,
          rule=AtMost(holds=0.1, partly=0.25)),  # Kd's largest (max - min) / mean of a count
)


EXPERIMENT = Experiment("liu_counts", "orientation tests and conflicts per point, seven 3D models, "
                        "three orders, in CGAL and in lfqt", grid, plot,
                        reproduces=tuple(("Paper 2", f"Table {k}") for k in range(8, 15)),
                        repeats=1, main_job=True, minutes={"default": 1.8}, claims=CLAIMS)
main = EXPERIMENT.main


if __name__ == "__main__":
    sys.exit(main())
