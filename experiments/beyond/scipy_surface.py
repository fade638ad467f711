"""Beyond the papers: the whole scipy.spatial.Delaunay surface, and the
interpolators a scipy user reaches for next, lfqt against scipy on the same
points and queries (issue 51).

    python -m experiments.scipy_surface [--scale smoke|default|paper]
                                        [--regime loop,fresh] [--threads T]

Each cell is one library on one set; its run performs every operation of
drivers.surface.OPERATIONS in turn (construction, point location in random,
Hilbert-sorted and 1M-query random order, vertex_neighbor_vertices,
convex_hull, transform, equations, lift_points, plane_distance, add_points,
and the linear, cubic, nearest and natural-neighbour interpolators on the
built mesh) and times each apart.  Both regimes by default: ``loop`` (a warm
process) and ``fresh`` (a new process, so that every operation is the first
of its kind there).  2D uniform at 10k, 100k and 1M; 3D cube at 10k, 100k
and 300k.  scipy's BLAS runs on one thread (its fastest here: with more,
its per-simplex LAPACK calls stall when the machine is loaded).

Ratios are scipy's time over lfqt's (> 1: lfqt is faster).  scipy computes
``equations`` with its mesh, so that row compares construction plus
equations on both sides.  Figure: results/figures/scipy_surface.png.
"""
import sys

import numpy as np

from drivers.surface import NOT_SCIPY, OPERATIONS

from ..core import results
from ..core.claims import FAILS, HOLDS, Claim
from ..core.experiment import Experiment, figure_paths
from ..core.runner import Cell

SETS = {2: "uniform", 3: "cube"}
SIZES = {"smoke": {2: [2_000], 3: [2_000]},
         "default": {2: [10_000, 100_000, 1_000_000], 3: [10_000, 100_000, 300_000]},
         "paper": {2: [10_000, 100_000, 1_000_000], 3: [10_000, 100_000, 300_000]}}
LIBRARIES = ("lfqt", "scipy")
# issue 51's location targets, warm: (dimension, points) -> seconds for
# find_simplex_many (1M random queries), and the ratios against scipy
TARGET_SECONDS = {(2, 1_000_000): 0.3, (3, 300_000): 1.0}
TARGET_RATIOS = {"find_simplex_random": 10.0, "find_simplex_sorted": 2.0}
# equations: scipy's come with its construction
WITH_CONSTRUCT = {"equations"}


def grid(scale, threads):
    return [Cell(f"surface-{lib}", SETS[d], n, threads=threads if lib == "lfqt" else 1)
            for d in (2, 3) for n in SIZES[scale][d] for lib in LIBRARIES]


def operations(df):
    """One row per (library, dim, n, regime, op) with the median and min of
    that operation's seconds, pooled over rounds: the warm-up's value, which
    the peer timed too, is left out (each process's last ``repeats``)."""
    import pandas as pd
    rows = []
    ok = df[df["status"] == "ok"]
    for (peer, dist, n, regime, rnd), g in ok.groupby(
            ["peer", "distribution", "n", "regime", "round"], sort=False):
        counts, runs = g["counts"].iloc[0], len(g)
        for op in OPERATIONS:
            times = counts.get(f"seconds_{op}")
            if times:
                rows += [dict(library=peer.removeprefix("surface-"),
                              dim=2 if dist == SETS[2] else 3, n=int(n), regime=regime, op=op,
                              seconds=t) for t in times[-runs:]]
    frame = pd.DataFrame(rows, columns=["library", "dim", "n", "regime", "op", "seconds"])
    return (frame.groupby(["library", "dim", "n", "regime", "op"], sort=False)["seconds"]
            .agg(["median", "min", "count"]).reset_index())


def _lookup(ops):
    return {(r.library, r.dim, r.n, r.regime, r.op): r for r in ops.itertuples()}


def ratios(ops):
    """{(dim, n, regime, op): scipy seconds / lfqt seconds} where both ran."""
    at = _lookup(ops)
    out = {}
    for (lib, d, n, regime, op), r in at.items():
        s = at.get(("scipy", d, n, regime, op))
        if lib != "lfqt" or s is None:
            continue
        ours, theirs = r.median, s.median
        if op in WITH_CONSTRUCT:
            ours += at[("lfqt", d, n, regime, "construct")].median
            theirs += at[("scipy", d, n, regime, "construct")].median
        out[(d, n, regime, op)] = theirs / ours if ours > 0 else float("nan")
    return out


def claims(df):
    """(claim, ours, held, why) rows of issue 51's targets, judged from
    stored results only (``held``: True or False; experiments.report words
    it)."""
    ops = operations(df)
    at, rs = _lookup(ops), ratios(ops)
    rows = []
    for regime in sorted(set(ops["regime"])):
        slower = [f"{op} {d}D {results.fmt_count(n)} ({results.fmt_ratio(r)})"
                  for (d, n, g, op), r in sorted(rs.items()) if g == regime and r < 1]
        rows.append((f"no operation slower than scipy's at any size ({regime})",
                     f"{sum(1 for k in rs if k[2] == regime)} (operation, size) pairs; slower: "
                     + (", ".join(slower) or "none"),
                     not slower,
                     "scipy time over lfqt's per operation, same points and queries"))
    for (d, n), limit in TARGET_SECONDS.items():
        r = at.get(("lfqt", d, n, "loop", "find_simplex_many"))
        if r is not None:
            rows.append((f"1M random queries on a {results.fmt_count(n)}-point {d}D mesh in at "
                         f"most {limit:g} s (warm)", f"{r.median:.3f} s",
                         bool(r.median <= limit),
                         "median of the loop regime"))
    for op, target in TARGET_RATIOS.items():
        got = [(k, v) for k, v in rs.items() if k[3] == op and k[2] == "loop"]
        if got:
            worst = min(v for _, v in got)
            rows.append((f"{op}: at least {target:g}x faster than scipy",
                         ", ".join(f"{d}D {results.fmt_count(n)} {results.fmt_ratio(v)}"
                                   for (d, n, _, _), v in sorted(got)),
                         bool(worst >= target),
                         "scipy over lfqt, loop regime"))
    return rows


def plot(df, out):
    import matplotlib.pyplot as plt
    ops = operations(df)
    at, rs = _lookup(ops), ratios(ops)
    regimes = [r for r in ("loop", "fresh") if r in set(ops["regime"])]
    print(f"\n{'regime':6} {'dim':>3} {'n':>9} {'operation':26} {'lfqt s':>9} {'scipy s':>9} "
          f"{'scipy/lfqt':>10}")
    for (lib, d, n, regime, op), r in sorted(at.items(), key=lambda kv: (
            kv[0][3], kv[0][1], kv[0][2], OPERATIONS.index(kv[0][4]))):
        if lib != "lfqt":
            continue
        s = at.get(("scipy", d, n, regime, op))
        theirs = f"{s.median:9.4f}" if s is not None else f"{'-':>9}"
        ratio = results.fmt_ratio(rs.get((d, n, regime, op), float("nan")))
        note = f"  ({NOT_SCIPY[op]})" if op in NOT_SCIPY else (
            "  (with construction)" if op in WITH_CONSTRUCT else "")
        print(f"{regime:6} {d:>3} {n:>9,} {op:26} {r.median:9.4f} {theirs} {ratio:>10}{note}")
    print()
    for claim, ours, held, why in claims(df):
        print(f"{'holds' if held else 'does not hold':>14}: {claim}: {ours}")
    dims = sorted(set(ops["dim"]))
    fig, axes = plt.subplots(len(regimes), len(dims), figsize=(7.5 * len(dims),
                                                                 4.2 * len(regimes)),
                             squeeze=False)
    for i, regime in enumerate(regimes):
        for j, d in enumerate(dims):
            ax = axes[i][j]
            names = [op for op in OPERATIONS if any(k[0] == d and k[2] == regime and k[3] == op
                                                    for k in rs)]
            sizes = sorted({k[1] for k in rs if k[0] == d and k[2] == regime})
            width = 0.8 / max(len(sizes), 1)
            for k, n in enumerate(sizes):
                vals = [rs.get((d, n, regime, op), np.nan) for op in names]
                ax.bar(np.arange(len(names)) + k * width, vals, width,
                       label=f"{results.fmt_count(n)} points",
                       color=["#c6dbef", "#6baed6", "#08519c"][k % 3])
            ax.axhline(1.0, color="black", lw=1)
            ax.set_yscale("log")
            ax.set_xticks(np.arange(len(names)) + 0.4 - width / 2,
                          [op.replace("_", " ") for op in names], rotation=35, ha="right",
                          fontsize=8)
            ax.set_ylabel("scipy time / lfqt time")
            ax.set_title(f"{d}D, {regime} regime (above 1: lfqt faster)", fontsize=10)
            ax.grid(axis="y", which="both", alpha=0.3)
            if sizes:
                ax.legend(fontsize=8)
    fig.suptitle("lfqt.Delaunay and lfqt.interpolate against scipy, operation by operation")
    fig.tight_layout()
    return figure_paths(fig, out, "scipy_surface")


def _targets(claim, res):
    return [claim.row(ours, HOLDS if held else FAILS, why, text=text,
                      published="scipy's time, same points and queries")
            for text, ours, held, why in claims(res.frame("scipy_surface"))]


# issue 51's targets (TARGET_SECONDS, TARGET_RATIOS), one row each, as ``claims`` judges them
CLAIMS = (
    Claim("lfqt.Delaunay and lfqt.interpolate at or below scipy's time on every operation",
          "scipy 1.17 (Qhull)", _targets),
)


EXPERIMENT = Experiment("scipy_surface", "lfqt.Delaunay and lfqt.interpolate against scipy, "
                        "every operation, warm and first call", grid, plot, repeats=2,
                        regimes=("loop", "fresh"), default_regimes=("loop", "fresh"),
                        claims=CLAIMS)
main = EXPERIMENT.main

if __name__ == "__main__":
    sys.exit(main())
