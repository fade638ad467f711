"""Paper 1, Figure 6: speedup of lfqt against its own single-thread time,
for a list of thread counts, on the five distributions; CGAL's parallel 3D
Delaunay (cgal-dt3-parallel, TBB) as the one parallel peer (2D CGAL and
Triangle have no parallel mode).

Speedup is the median one-thread time over the median t-thread time of the
same peer, distribution and size.  The figure marks where the thread count
passes the machine's physical cores (SMT beyond), read from the stored
metadata.  The paper's text: 13-14x on 16 cores, close to 17x on 16 cores
with 32 threads for Uniform, Circle and Spiral, +30% from Hyperthreading.
The right panel compares parallel efficiency (speedup / threads), the one
quantity that carries over between a 2-core and a 32-thread machine.

Before the grid, the sidecar records what this machine lets threads gain on
compute, random reads and dependent reads (experiments.core.probe); the left
panel draws those ceilings in grey beside lfqt's speedup."""
import os
import sys

import numpy as np

import generators

from ..core import results
from ..core.claims import UNTESTABLE, AtLeast, Claim, Needs
from ..core.experiment import Experiment, figure_paths
from ..core.runner import Cell

# paper 1's five sets, as generators.REGISTRY tags them
DISTS = generators.names(tag="paper1")
SIZES = {"smoke": 100_000, "default": 1_000_000, "paper": 10_000_000}
SIZES_3D = {"smoke": 30_000, "default": 300_000, "paper": 1_000_000}
PUBLISHED = [(16, 13.0, 14.0, "16 cores: 13-14x"), (32, 17.0, 17.0, "16c/32t: ~17x")]
COLORS = dict(uniform="#1b6ca8", grid="#3aa655", cluster="#d1495b", circle="#edae49",
              spiral="#7b3294")


def default_counts():
    """Powers of two up to the logical CPUs, plus the physical core count
    and the logical CPU count."""
    from ..core.machine import topology
    top = topology()
    logical = top["logical_cpus"] or os.cpu_count() or 1
    counts = {1, logical, top["physical_cores"] or logical}
    t = 2
    while t < logical:
        counts.add(t)
        t *= 2
    return sorted(counts)


def _counts(thread_counts):
    """The grid's thread counts: those asked for (default_counts when none),
    with 1, the base of every speedup."""
    return sorted(set(thread_counts or default_counts()) | {1})


def grid(scale, threads, thread_counts=None):
    counts = _counts(thread_counts)
    cells = [Cell("lfqt-dc", d, SIZES[scale], threads=t) for d in DISTS for t in counts]
    cells += [Cell("cgal-dt3-parallel", "cube", SIZES_3D[scale], threads=t) for t in counts]
    return cells


def speedups(df):
    """{(peer, distribution, n): [(threads, speedup, median seconds)]}."""
    summary = results.summarize(df, by=["peer", "distribution", "n", "threads"])
    out = {}
    for (peer, dist, n, t), row in summary.iterrows():
        if row["status"] == "ok" and row["median"]:
            out.setdefault((peer, dist, n), []).append((t, row["median"]))
    series = {}
    for key, pts in out.items():
        base = dict(pts).get(1)
        if base:
            series[key] = [(t, base / m, m) for t, m in sorted(pts)]
    return series


def machine_scaling(args):
    """Sidecar entry: this machine's own thread scaling (experiments.core.probe)
    at the grid's thread counts, up to its logical CPUs."""
    from ..core.machine import topology
    from ..core.probe import thread_scaling
    logical = topology()["logical_cpus"] or os.cpu_count() or 1
    counts = [t for t in _counts(args.thread_counts) if t <= logical]
    return {"thread_scaling": thread_scaling(counts)}


def ceilings(meta):
    """{probe: {threads: speedup}} from a fig6 sidecar ({} before the probe
    was recorded); JSON keeps the thread counts as strings."""
    return {name: {int(t): sp for t, sp in by_t.items()}
            for name, by_t in (meta.get("thread_scaling") or {}).items()}


def plot(df, out):
    import matplotlib.pyplot as plt
    series = speedups(df)
    meta = results.metadata(out, "fig6")
    physical, logical = meta.get("physical_cores"), meta.get("logical_cpus")
    fig, (ax, eff) = plt.subplots(1, 2, figsize=(12, 4.6), gridspec_kw=dict(width_ratios=(3, 2)))
    tmax = max([t for s in series.values() for t, _, _ in s] + [2])
    print(f"\n{'peer':18} {'distribution':12} {'n':>10} " + " ".join(
        f"{'t=' + str(t):>8}" for t in sorted({t for s in series.values() for t, _, _ in s}))
        + "   (speedup over 1 thread)")
    for (peer, dist, n), s in sorted(series.items()):
        t, sp, _ = map(np.array, zip(*s))
        lfqt = peer == "lfqt-dc"
        kw = dict(color=COLORS.get(dist, "black"), marker="o") if lfqt else \
            dict(color="black", ls=":", marker="s")
        label = f"{dist} ({n:,})" if lfqt else f"{peer}, 3D {dist} ({n:,})"
        ax.plot(t, sp, label=label, **kw)
        eff.plot(t, sp / t, **kw)
        print(f"{peer:18} {dist:12} {n:>10,} " + " ".join(f"{v:8.2f}" for v in sp))
    ax.plot([1, tmax], [1, tmax], color="#999999", lw=0.8, ls="--", label="linear")
    for (name, by_t), ls in zip(sorted(ceilings(meta).items()), ("-.", ":", (0, (5, 1)))):
        if len(by_t) > 1:
            t, sp = zip(*sorted(by_t.items()))
            ax.plot(t, sp, color="#777777", lw=1.2, ls=ls, label=f"this machine: {name}")
    for a in (ax, eff):
        top = a.get_ylim()[1] if a is ax else 1.08
        for lo, hi, text, shade in ((physical, logical, " SMT", "#eeeeee"),
                                    (logical, tmax, " more threads than CPUs", "#f7e1e1")):
            if lo and hi and lo < hi:
                a.axvspan(lo, hi, color=shade, zorder=0)
                a.text(lo, top, text, va="top", fontsize=8)
        a.set_xscale("log", base=2)
        a.set_xlabel("threads")
        a.set_xticks(sorted({t for s in series.values() for t, _, _ in s}))
        a.get_xaxis().set_major_formatter(plt.ScalarFormatter())
    ax.set_ylabel("speedup over one thread")
    where = f"{physical} physical cores, {logical} logical CPUs" if physical else "topology unknown"
    ax.set_title(f"this machine ({where})", fontsize=9)
    ax.legend(fontsize=7, loc="upper left")
    for t, lo, hi, text in PUBLISHED:
        eff.axhspan(lo / t, hi / t + 1e-3, color="#bdbdbd", alpha=0.6)
        eff.text(eff.get_xlim()[0] if eff.get_xlim()[0] > 0 else 1, hi / t, f"paper, {text}",
                 fontsize=7, va="bottom")
    eff.set_ylim(0, 1.1)
    eff.set_ylabel("parallel efficiency (speedup / threads)")
    eff.set_title("efficiency; grey: the paper's stated 16-core and 32-thread values", fontsize=9)
    fig.suptitle("Paper 1, Fig. 6: scaling with threads", fontsize=10)
    fig.tight_layout()
    return figure_paths(fig, out, "fig6")


def _scaling(claim, res):
    df = res.frame("fig6")
    series = speedups(df)
    meta = res.meta("fig6")
    physical = meta.get("physical_cores") or 1
    cores = claim.limits["cores"]
    ours = {d: dict((t, sp) for t, sp, _ in s) for (p, d, n), s in series.items()
            if p == "lfqt-dc"}
    at = min(cores, physical)
    text = ", ".join(f"{d} {v.get(at, float('nan')):.2f}x" for d, v in ours.items())
    probes = ", ".join(f"{name} {by_t[at]:.2f}x" for name, by_t in
                       ceilings(meta).items() if at in by_t)
    ceiling = f"; this machine's own ceiling at {at} threads: {probes}" if probes else ""
    if physical >= cores:
        worst = min(v.get(cores, 0) for v in ours.values())
        return claim.row(f"{cores} threads: {text}{ceiling}", claim.rule(worst),
                         "speedup over one thread, same machine")
    eff = np.median([v.get(at, np.nan) / at for v in ours.values()])
    cg = [dict((t, sp) for t, sp, _ in s).get(at) for (p, _, _), s in series.items()
          if p == "cgal-dt3-parallel"]
    return claim.row(f"{at} threads: {text}; median efficiency {eff:.0%} (paper 81-88% at 16)"
                     + (f"; cgal-dt3-parallel {cg[0]:.2f}x" if cg and cg[0] else "") + ceiling,
                     UNTESTABLE, f"{physical} physical cores here")


CLAIMS = (
    Claim("13 to 14x on 16 cores", "13-14x on 16 cores, ~17x on 16c/32t (Fig. 6)", _scaling,
          rule=AtLeast(holds=13, partly=8),  # the worst set's speedup at 16 threads
          limits={"cores": 16},  # judged on a machine with this many physical cores
          needs=Needs("a machine with 16+ physical cores",
                      "python -m experiments.fig6 --thread-counts 1,2,4,8,16,32")),
)


EXPERIMENT = Experiment(
    "fig6", "speedup over one thread on the five distributions, CGAL's parallel 3D beside",
    grid, plot, reproduces=(("Paper 1", "Fig. 6"),), main_job=True, minutes={"default": 1.4},
    options=(("--thread-counts", dict(type=lambda s: [int(v) for v in s.split(",")],
                                      help="comma-separated thread counts (default: powers of "
                                           "two up to the logical CPUs, the physical core "
                                           "count and the logical CPU count)")),),
    grid_options=("thread_counts",), metadata=machine_scaling, claims=CLAIMS)
main = EXPERIMENT.main

if __name__ == "__main__":
    sys.exit(main())
