"""Benchmark: lfqt.insert against CGAL (and in 3D the other 3D peers) on
the same input in the same run, single thread.

    python -m experiments.bench_insert [--scale smoke|default|paper] [--rounds R]
                                       [--regime loop,kept,fresh]

2D: lfqt's Kd-order insertion against CGAL's Delaunay_triangulation_2 range
insertion (which spatially sorts) of plain points (cgal-dt2, CGAL at its
fastest) and of (point, index) pairs (cgal-dt2-indexed).  3D: the same with
Delaunay_triangulation_3, CGAL inserting our Kd order one point at a
time with the parent as hint (paper 2's setup), gmsh's HXT (gmsh-hxt) and
TetGen (tetgen) on one thread; experiments.dt3 has every 3D peer, on 1 and
2 threads, and their exactness.  Times include order
building.  lfqt's time is the whole ``lfqt.insert`` call: validation, the
order, the insertion, and the simplices and neighbours arrays (all but the
order and the insertion take about 0.25 s of 3.8 s in 3D at 1M).  CGAL's is
``dt.insert`` alone (its spatial sort included) on points already in a
``std::vector``, the triangulation left in CGAL's own structure (the driver
maps it to indices after the timed region): the comparison leans towards
CGAL.  The figure shows the medians; each CGAL bar
is labelled with lfqt's time divided by CGAL's (> 1: CGAL is faster).
Targets (issue 18): at most 1.2 in 2D and 1.0 in 3D, against CGAL's range
insertion and against CGAL inserting our order with our hints.  In each
regime asked for (drivers.isolate.REGIMES: a table and a figure each,
bench_insert.png for the loop, bench_insert-<regime>.png for the others)."""
import sys

from drivers.isolate import REGIME_TEXT, REGIMES

from ..core import results
from ..core.experiment import Experiment, figure_paths, per_regime
from ..core.runner import Cell

SIZES = {"smoke": [5_000], "default": [100_000, 1_000_000], "paper": [1_000_000, 3_000_000]}
# (dimension, distribution, ours, CGAL peers)
SETUPS = [(2, "uniform", "lfqt-insert-kdtree", ["cgal-dt2", "cgal-dt2-indexed", "cgal-dt2-kdtree"]),
          (3, "cube", "lfqt-insert-kdtree", ["cgal-dt3", "cgal-dt3-indexed", "cgal-dt3-kdtree",
                                             "gmsh-hxt", "tetgen"])]
TARGETS = {2: 1.2, 3: 1.0}  # lfqt time / CGAL time, by dimension


def grid(scale, threads):
    return [Cell(peer, dist, n, threads=threads) for n in SIZES[scale]
            for _, dist, ours, cgal in SETUPS
            for peer in [ours] + cgal]


def plot(df, out):
    return per_regime(df, lambda rows, regime: _plot(rows, out, regime))


def _plot(df, out, regime):
    import matplotlib.pyplot as plt
    s = results.summarize(df)
    ns = sorted(df["n"].unique())
    fig, axes = plt.subplots(1, len(SETUPS), figsize=(6 * len(SETUPS), 4.5), squeeze=False)
    print(f"\n{'dim':>3} {'n':>10} {'peer':18} {'median s':>9} {'min s':>8} {'lfqt/peer':>10}"
          f" {'by round':>9}   (lfqt time / peer time, lfqt's including its output arrays; "
          "medians pooled over rounds, and the median of the rounds' own ratios; targets: <= "
          + ", ".join(f"{t} in {d}D" for d, t in TARGETS.items()) + ")")
    for ax, (dim, dist, ours, cgal) in zip(axes[0], SETUPS):
        peers = [ours] + cgal
        width = 0.8 / len(peers)
        for k, peer in enumerate(peers):
            med = [results.cell(s, peer, dist, n, False).get("median") for n in ns]
            xs = [i + k * width for i in range(len(ns))]
            # time per point: both sizes on one readable scale
            us = [(m or 0) / n * 1e6 for m, n in zip(med, ns)]
            ax.bar(xs, us, width, label=peer)
            for x, m, n, h in zip(xs, med, ns, us):
                base = results.cell(s, ours, dist, n, False).get("median")
                r = results.ratio(base, m)
                lo = results.cell(s, peer, dist, n, False).get("min")
                if m:
                    ax.text(x, h, f"{m:.2f}s" + ("" if peer == ours else f"\n{r:.2f}x"),
                            ha="center", va="bottom", fontsize=7)
                    by_round = results.round_ratio(df, ours, peer, dist, n, False)[0]
                    print(f"{dim:>3} {n:>10,} {peer:18} {m:9.3f} {lo:8.3f} "
                          f"{results.fmt_ratio(r) if peer != ours else '':>10} "
                          f"{results.fmt_ratio(by_round) if peer != ours else '':>9}")
        ax.set_xticks([i + 0.4 - width / 2 for i in range(len(ns))], [f"{n:,}" for n in ns])
        ax.set_ylabel("microseconds per point (median)")
        ax.set_ylim(top=ax.get_ylim()[1] * 1.15)  # room for the labels
        ax.set_title(f"{dim}D, {dist}: insertion in Kd order vs CGAL"
                     + (" and the 3D peers " if dim == 3 else " ")
                     + f"(target lfqt/CGAL <= {TARGETS[dim]})", fontsize=10)
        ax.legend(fontsize=8)
        ax.grid(axis="y", alpha=0.3)
    fig.suptitle("lfqt.insert against CGAL, same input, same run; bar labels: median seconds "
                 f"and lfqt time / peer time\n{regime} regime: {REGIME_TEXT[regime]}",
                 fontsize=10)
    fig.tight_layout()
    return figure_paths(fig, out, "bench_insert" if regime == "loop" else f"bench_insert-{regime}")


# 3 interleaved rounds of 2 runs, not 1 round of 5: the 3D target's margin
# is a few percent, and on a shared machine whole minutes run slow; the
# median of the rounds' own ratios (results.round_ratio) then stands apart.
EXPERIMENT = Experiment("bench_insert", "lfqt.insert in Kd order against CGAL DT2/DT3 (and "
                        "HXT and TetGen in 3D), same input, same run, interleaved rounds", grid,
                        plot, repeats=2, rounds=3, regimes=REGIMES)
main = EXPERIMENT.main


if __name__ == "__main__":
    sys.exit(main())
