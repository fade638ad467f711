"""Paper 1, Figure 5: lfqt's run time broken down into phases, in percent, on
the five distributions, on one thread and on all threads.

Phases as the paper's: sort (Morton keys and radix sort), subdivide and
merge in the bins (the lower LFQT), subdivide and merge in the top (the upper
LFQT, above the bins), and other (validation, allocation, output,
scheduling).  On several threads the bins run in parallel: their share is
their thread-seconds over the thread count, so that the shares add up to the
wall time.  The published figure has no numbers; its text says the top is
almost nothing on one thread and about 10% at 32 threads."""
import sys

import numpy as np

import generators

from ..core.claims import UNTESTABLE, AtMost, Claim, Needs
from ..core.experiment import Experiment, figure_paths, many_threads
from ..core.runner import Cell

# paper 1's five sets, as generators.REGISTRY tags them
DISTS = generators.names(tag="paper1")
SIZES = {"smoke": [100_000], "default": [1_000_000], "paper": [10_000_000]}
PHASES = [("sort", "sort"), ("subdivide_lower", "subdivide (bins)"),
          ("merge_lower", "merge (bins)"), ("subdivide_top", "subdivide (top)"),
          ("merge_top", "merge (top)")]
COLORS = ["#8d8d8d", "#9ecae1", "#1b6ca8", "#fdae6b", "#d1495b", "#e0e0e0"]


def grid(scale, threads):
    many = many_threads(threads)
    return [Cell("lfqt-dc", d, n, threads=t) for n in SIZES[scale] for d in DISTS
            for t in (1, many)]


def shares(counts, threads):
    """{phase label: percent of the wall time} of one run's counts."""
    wall = {k: counts.get(f"phase_{k}", 0.0) / (threads if k.endswith("_lower") else 1)
            for k, _ in PHASES}
    # the bins' thread-seconds over the threads exceed the wall time when the
    # machine has fewer free cores than threads (time descheduled counts):
    # then the phases share the whole wall time, in their own proportions
    total = max(counts.get("seconds_total", 0.0), sum(wall.values()))
    out = {label: 100 * wall[k] / total for k, label in PHASES}
    out["other"] = max(0.0, 100 - sum(out.values()))
    return out


def plot(df, out):
    import matplotlib.pyplot as plt
    ok = df[(df["status"] == "ok") & (df["peer"] == "lfqt-dc")]
    # the median run of each cell by time, with its own phases
    picks = (ok.sort_values("seconds").groupby(["distribution", "n", "threads"])
             .apply(lambda g: g.iloc[len(g) // 2], include_groups=False))
    threads = sorted(ok["threads"].unique())
    labels = [label for _, label in PHASES] + ["other"]
    fig, axes = plt.subplots(1, len(threads), figsize=(6.5 * len(threads), 4.2), squeeze=False,
                             sharey=True)
    print(f"\n{'distribution':12} {'n':>10} {'threads':>7} " + " ".join(f"{l:>16}" for l in labels)
          + "   (% of the wall time)")
    for ax, t in zip(axes[0], threads):
        rows = [(d, n) for d in DISTS for n in sorted(ok["n"].unique())
                if (d, n, t) in picks.index]
        left = np.zeros(len(rows))
        table = [shares(picks.loc[(d, n, t), "counts"], t) for d, n in rows]
        for k, label in enumerate(labels):
            vals = np.array([sh[label] for sh in table])
            ax.barh(np.arange(len(rows)), vals, left=left, color=COLORS[k], label=label)
            left += vals
        for (d, n), sh in zip(rows, table):
            print(f"{d:12} {n:>10,} {t:>7} " + " ".join(f"{sh[l]:16.1f}" for l in labels))
        ax.set_yticks(np.arange(len(rows)), [f"{d} ({n:,})" for d, n in rows])
        ax.set_xlim(0, 100)
        ax.set_xlabel("% of the run time")
        ax.set_title(f"{t} thread{'s' if t > 1 else ''}")
    axes[0][0].invert_yaxis()  # the axes share y: once for all
    handles, names = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, names, loc="lower center", ncol=len(labels), fontsize=8, frameon=False)
    fig.suptitle("Paper 1, Fig. 5: phases of lfqt in percent (the published figure has no "
                 "numbers; its text: the top is ~10% at 32 threads)", fontsize=10)
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    return figure_paths(fig, out, "fig5")


def _top_share(claim, res):
    df = res.frame("fig5")
    ok = df[(df["status"] == "ok") & (df["peer"] == "lfqt-dc")]
    t = int(ok["threads"].max())
    sub = ok[ok["threads"] == t]
    tops = {d: np.median([sum(v for k, v in shares(c, t).items() if "(top)" in k)
                          for c in g["counts"]]) for d, g in sub.groupby("distribution")}
    text = ", ".join(f"{d} {v:.1f}%" for d, v in tops.items())
    enough = t >= claim.limits["threads"]
    return claim.row(f"{t} threads: {text}",
                     claim.rule(max(tops.values())) if enough else UNTESTABLE,
                     f"the top grows with the thread count; {t} threads here" if not enough
                     else "measured at 32+ threads")


CLAIMS = (
    Claim("the top part takes about 10% at 32 threads", "about 10% at 32 threads (Fig. 5)",
          _top_share,
          rule=AtMost(holds=15),  # the largest share of the top, in percent, over the sets
          limits={"threads": 32},  # judged from this many threads on
          needs=Needs("a machine with 32 hardware threads", "python -m experiments.fig5")),
)


EXPERIMENT = Experiment("fig5", "lfqt's phases in percent, one thread and all threads, five "
                        "distributions", grid, plot, reproduces=(("Paper 1", "Fig. 5"),),
                        main_job=True, minutes={"default": 0.4}, claims=CLAIMS)
main = EXPERIMENT.main

if __name__ == "__main__":
    sys.exit(main())
