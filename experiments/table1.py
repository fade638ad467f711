"""Paper 1, Table 1: orientation and in-circle tests that the stage-1 filter
leaves undecided, on the five distributions, for Triangle (its own source,
counted by triangle-native), fqDel-const (lfqt with Triangle's constant
bound: lfqt-dc-constant) and fqDel-level (lfqt with the LFQT's level
bounds: lfqt-dc); and the run-time effect of the level bound (the paper:
about 0.5% on Cluster).  The paper counts at 10M points, the paper scale."""
import sys

import numpy as np

from . import results
from .experiment import Experiment, figure_paths
from .runner import Cell

DISTS = ["uniform", "cluster", "circle", "spiral", "grid"]
SIZES = {"smoke": [20_000], "default": [1_000_000], "paper": [10_000_000]}
# (configuration as the paper names it, our peer)
CONFIGS = [("Triangle", "triangle-native"), ("fqDel-const", "lfqt-dc-constant"),
           ("fqDel-level", "lfqt-dc")]
METRICS = [("orientation_stage1_undecided", "orientation_within_error_bound", "orientation"),
           ("incircle_stage1_undecided", "incircle_within_error_bound", "in-circle")]
COLORS = ["#edae49", "#66a182", "#1b6ca8"]


def grid(scale, threads):
    counted = [Cell(peer, d, n, count=True) for n in SIZES[scale] for d in DISTS
               for _, peer in CONFIGS]
    timed = [Cell(peer, d, n) for n in SIZES[scale] for d in DISTS
             for peer in ("lfqt-dc-constant", "lfqt-dc")]
    return counted + timed


def published_counts():
    """{(configuration, distribution, metric): value} of Table 1 (10M points)."""
    pub = results.published("fuetterling2014")
    rows = pub[pub["source"] == "Table 1"]
    return {(r["peer"], r["distribution"], r["metric"]): float(r["value"])
            for r in rows.to_dict("records")}


def plot(df, out):
    import matplotlib.pyplot as plt
    s = results.summarize(df)
    pub = published_counts()
    ns = sorted(df["n"].unique())
    fig, axes = plt.subplots(1, 2, figsize=(13, 4.5))
    width = 0.8 / len(CONFIGS)
    print(f"\n{'distribution':12} {'n':>11} {'test':12} " + " ".join(
        f"{c + ' ours':>18} {'paper':>9}" for c, _ in CONFIGS) + "   (undecided by stage 1; "
        "paper at 10M)")
    for ax, (ours_key, pub_key, label) in zip(axes, METRICS):
        for k, (config, peer) in enumerate(CONFIGS):
            xs = np.arange(len(DISTS)) + k * width
            vals = [results.cell(s, peer, d, ns[-1], True).get("counts", {}).get(ours_key)
                    for d in DISTS]
            ax.bar(xs, [v if v is not None else 0 for v in vals], width, color=COLORS[k],
                   label=f"{config} (ours, {ns[-1]:,})")
            ax.scatter(xs, [pub.get((config, d, pub_key), np.nan) for d in DISTS], marker="_",
                       s=250, color="black", zorder=3,
                       label="paper (10M)" if k == 0 else None)
        ax.set_yscale("symlog", linthresh=1)
        ax.set_xticks(np.arange(len(DISTS)) + 0.4 - width / 2, DISTS)
        ax.set_ylabel(f"{label} tests left undecided by stage 1")
        ax.grid(axis="y", alpha=0.3)
    for d in DISTS:
        for n in ns:
            for ours_key, pub_key, label in METRICS:
                cells = []
                for config, peer in CONFIGS:
                    v = results.cell(s, peer, d, n, True).get("counts", {}).get(ours_key)
                    p = pub.get((config, d, pub_key))
                    cells.append(f"{'-' if v is None else v:>18} {'-' if p is None else int(p):>9}")
                print(f"{d:12} {n:>11,} {label:12} " + " ".join(cells))
    print("\nrun-time effect of the level bound (median time with Triangle's constant bound / "
          "with the level bound; the paper: about 1.005 on Cluster)")
    for d in DISTS:
        for n in ns:
            r = results.ratio(results.median(s, "lfqt-dc-constant", d, n, False),
                              results.median(s, "lfqt-dc", d, n, False))
            print(f"{d:12} {n:>11,} {results.fmt_ratio(r)}")
    axes[0].legend(fontsize=8)
    fig.suptitle("Paper 1, Table 1: predicates the stage-1 filter leaves undecided "
                 "(bars: ours; black: the paper at 10M)", fontsize=10)
    fig.tight_layout()
    return figure_paths(fig, out, "table1")


EXPERIMENT = Experiment("table1", "undecided orientation and in-circle tests: Triangle, "
                        "fqDel-const, fqDel-level, five distributions", grid, plot,
                        reproduces=(("Paper 1", "Table 1"),), repeats=3)
main = EXPERIMENT.main

if __name__ == "__main__":
    sys.exit(main())
