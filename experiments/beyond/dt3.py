"""3D Delaunay against every 3D peer (issue 52): lfqt's insertion
(``lfqt.insert`` in Kd order, and ``lfqt.Delaunay``, the scipy drop-in)
against CGAL's Delaunay_triangulation_3 (range insertion, and its parallel
TBB build on 1 and 2 threads), gmsh's ``tetrahedralize`` with HXT (1 and 2
threads) and with its default algorithm, TetGen through meshpy and Qhull
through scipy, on the same points in the same run.

    python -m experiments.dt3 [--scale smoke|default|paper] [--rounds R]
                              [--regime loop,kept] [--threads T]

Two parts, one grid:

* time: uniform points in the unit cube (paper 2's cube) at 100k, 300k and
  1M (Qhull and gmsh's default path to 300k at the default scale: 10 s and
  more a run, and no target depends on them), in the loop and the kept
  regimes (drivers.isolate.REGIMES), every peer that takes threads on 1 and
  2 threads (and on --threads T), lfqt's 3D peers among them;
* exactness: every peer on the hard 3D sets (tagged "hard" in
  generators.REGISTRY: the 20^3 grid, exactly cospherical lattice points
  with their centre, a rounded sphere, duplicates, subnormal and 1e300
  magnitudes) at 8,000 points, in the loop regime.

Each peer runs in its fastest documented way (drivers/: one module per
family says how), in a child process per cell; a peer's compiled driver
(CGAL) times itself inside its process, the others are timed around the
call in theirs.  The last mesh of every hard-set cell, and of every timed
cell up to 100k points (CHECK_MAX_N), is judged by lfqt.verify
(drivers.exactness): a wrong mesh is a result (flat tetrahedra,
non-Delaunay faces, repeated faces, reflex hull edges), as is a refusal, a
crash or a hang.  Printed: per regime, each cell's median and minimum, its
runs, and the ratio of the peer's time to lfqt-insert-kdtree's (> 1: lfqt is
faster) on the same thread count, with the verdict of its mesh; then the
exactness table.  Figures: results/figures/dt3.png (loop), dt3-kept.png;
REPORT.md: the claims of issue 52 under "Beyond the papers" and both
tables."""
import sys

import numpy as np

import drivers
import generators
from drivers.isolate import REGIME_TEXT

from ..core import results
from ..core.claims import AtLeast, AtMost, Claim, Share
from ..core.experiment import Experiment, figure_paths, per_regime
from ..core.runner import Cell
from .field import verdict

REFERENCE = "lfqt-insert-kdtree"
OURS = [REFERENCE, "lfqt-delaunay"]
PEERS = OURS + ["cgal-dt3", "cgal-dt3-parallel", "gmsh-hxt", "gmsh-default", "tetgen",
                "qhull-3d"]
TIME_SET = "cube"
HARD_SETS = generators.names(3, tag="hard")
SIZES = {"smoke": [3_000], "default": [100_000, 300_000, 1_000_000],
         "paper": [100_000, 300_000, 1_000_000, 3_000_000]}
HARD_N = {"smoke": 500, "default": 8_000, "paper": 8_000}
# the largest set a slow peer is timed on, by scale: Qhull takes 10 s a run
# at 300k (issue 52), gmsh's default path 1 s at 100k and a wrong mesh
MAX_N = {"qhull-3d": {"smoke": 3_000, "default": 300_000, "paper": 1_000_000},
         "gmsh-default": {"smoke": 3_000, "default": 300_000, "paper": 1_000_000}}
THREADS = (1, 2)  # issue 52's targets are on 1 and 2 threads
REGIMES = ("loop", "kept")
# a 1M cell's warm-up and three runs, on a loaded machine: 2.5x the quiet times
TIMEOUTS = {"smoke": 60.0, "default": 300.0, "paper": 900.0}
# the largest timed set whose meshes are judged: lfqt.verify of bare
# simplices (neighbours matched from the faces) takes more than ten times
# lfqt.insert's time at 1M (docs/performance.md), longer than the cell's
# runs; the hard sets are judged at every scale
CHECK_MAX_N = 100_000
COLORS = {"lfqt-insert-kdtree": "#1b6ca8", "lfqt-delaunay": "#5fa8d3", "cgal-dt3": "#d1495b",
          "cgal-dt3-parallel": "#edae49", "gmsh-hxt": "#3aa655", "gmsh-default": "#8cc084",
          "tetgen": "#7b3294", "qhull-3d": "#9e9e9e"}


def thread_counts(peer, threads=1):
    """The thread counts ``peer`` is measured on: THREADS (and --threads)
    when it takes threads, else 1."""
    if "threads" not in drivers.make(peer).options:
        return (1,)
    return tuple(sorted(set(THREADS) | {threads}))


def _timed(scale, peer, n):
    return n <= MAX_N.get(peer, {}).get(scale, n)


def grid(scale, threads):
    timing = [Cell(p, TIME_SET, n, threads=t) for n in SIZES[scale] for p in PEERS
              if _timed(scale, p, n) for t in thread_counts(p, threads)]
    hard = [Cell(p, d, HARD_N[scale], threads=t) for d in HARD_SETS for p in PEERS
            for t in thread_counts(p, threads)]
    return timing + hard


def judged(cell):
    """Whether the cell's mesh is judged exactly (CHECK_MAX_N)."""
    return cell.distribution in HARD_SETS or cell.n <= CHECK_MAX_N


def known_failure(scale, cell):
    """A peer's known hang on a set (its driver's known_failure) is not
    waited for below the paper scale."""
    reason = drivers.known_failure(cell.peer, cell.distribution, cell.n)
    return None if reason is None or scale == "paper" else reason + " (--scale paper waits for it)"


BY = ["peer", "distribution", "n", "threads"]


def cells_of(df, regime="loop"):
    """{(peer, set, n, threads): (median, min, runs, kind, text)} of one
    regime's cells (kind and text: field.verdict's; kind "unchecked" and no
    text for a timed cell whose mesh was not judged, CHECK_MAX_N)."""
    df = df[df["regime"] == regime]
    s = results.summarize(df, by=BY)
    out = {}
    for key, rows in df.groupby(BY, sort=False):
        unjudged = rows.iloc[0]["status"] == "ok" and not rows.iloc[0]["check"]
        kind, text = ("unchecked", "") if unjudged else verdict(rows)
        c = results.cell(s, *key)
        out[(key[0], key[1], int(key[2]), int(key[3]))] = (c.get("median"), c.get("min"),
                                                           c.get("runs"), kind, text)
    return out


def round_ratio(df, a, b, n, distribution=TIME_SET, regime="loop"):
    """The median over rounds of (a's median / b's median) in each round,
    ``a`` and ``b`` being (peer, threads) on ``n`` points; NaN when no round
    timed both."""
    sel = df[(df["status"] == "ok") & (df["regime"] == regime) & (df["n"] == n)
             & (df["distribution"] == distribution)]
    per = {}
    for who in (a, b):
        rows = sel[(sel["peer"] == who[0]) & (sel["threads"] == who[1])]
        per[who] = rows.groupby("round")["seconds"].median()
    ratios = (per[a] / per[b]).dropna().tolist()
    return float(np.median(ratios)) if ratios else float("nan")


def timing_table(df, regime="loop"):
    """Markdown lines: one row per (peer, threads), one column per size:
    median seconds, the ratio to lfqt-insert-kdtree's on the same thread
    count (> 1: lfqt is faster; its 1-thread time where it has no such
    count), and the verdict of a wrong mesh."""
    cells = cells_of(df, regime)
    ns = sorted({n for p, d, n, t in cells if d == TIME_SET})
    rows = sorted({(p, t) for p, d, n, t in cells if d == TIME_SET},
                  key=lambda k: (PEERS.index(k[0]) if k[0] in PEERS else len(PEERS), k[1]))
    if not ns:
        return []
    lines = ["| peer | threads | " + " | ".join(results.fmt_count(n) for n in ns) + " |",
             "|---|---|" + "---|" * len(ns)]
    for p, t in rows:
        row = []
        for n in ns:
            med, lo, runs, kind, text = cells.get((p, TIME_SET, n, t), (None,) * 3 + ("", "-"))
            if med is None:
                row.append(text)
                continue
            ref = cells.get((REFERENCE, TIME_SET, n, t)) or cells.get((REFERENCE, TIME_SET, n, 1))
            ratio = results.ratio(med, ref and ref[0])
            r = "" if p == REFERENCE else f" ({results.fmt_ratio(ratio)})"
            row.append(f"{med:.3g} s{r}" + (f", **{text}**" if text and kind != "exact" else ""))
        lines.append(f"| {p} | {t} | " + " | ".join(row) + " |")
    return lines


def exactness_table(df):
    """Markdown lines: (peer, threads) x hard set, each cell exact / wrong
    (how) / refused / crashed / hung."""
    cells = cells_of(df)
    sets = [d for d in HARD_SETS if any(k[1] == d for k in cells)]
    if not sets:
        return []
    n_of = {d: min(n for _, dd, n, _ in cells if dd == d) for d in sets}
    rows = sorted({(p, t) for p, d, n, t in cells if d in sets},
                  key=lambda k: (PEERS.index(k[0]) if k[0] in PEERS else len(PEERS), k[1]))
    lines = ["| peer | threads | " + " | ".join(f"{d} ({n_of[d]:,})" for d in sets) + " |",
             "|---|---|" + "---|" * len(sets)]
    for p, t in rows:
        texts = [cells.get((p, d, n_of[d], t), (None,) * 4 + ("-",))[4] for d in sets]
        lines.append(f"| {p} | {t} | " + " | ".join(f"**{x}**" if x.startswith("wrong") else x
                                                    for x in texts) + " |")
    return lines


def report_lines(df):
    """REPORT.md's 3D tables, from the stored sweep."""
    head = ["## 3D: lfqt against every 3D peer", ""]
    if df is None:
        return head + ["Not measured yet: run `python -m experiments.dt3`.", ""]
    lines = head + ["Every 3D peer in its fastest documented way, one child process per cell, "
                    "on the same uniform points in the cube (`python -m experiments.dt3`). "
                    "Median seconds, in brackets the peer's time over lfqt-insert-kdtree's on "
                    "the same thread count (> 1: lfqt faster); a mesh that is not the Delaunay "
                    "tetrahedralisation (lfqt.verify, exact) is marked.", ""]
    for regime in [r for r in REGIMES if r in set(df["regime"])]:
        table = timing_table(df, regime)
        if table:
            lines += [f"Regime **{regime}**: {REGIME_TEXT[regime]}.", ""] + table + [""]
    exact = exactness_table(df)
    if exact:
        lines += ["Exactness on the hard 3D sets: *exact*, *wrong* (what lfqt.verify "
                  "counted), *refused* (the peer raised an error), *crashed*, *hung* (no "
                  "result within the cell's limit; a known hang is skipped below the paper "
                  "scale).", ""] + exact + [""]
    return lines


def plot(df, out):
    paths = per_regime(df, lambda rows, regime: _plot(rows, out, regime))
    print("\nExactness on the hard 3D sets:\n" + "\n".join(exactness_table(df)))
    return paths


def _plot(df, out, regime):
    import matplotlib.pyplot as plt
    cells = cells_of(df, regime)
    print(f"{'n':>10} {'peer':20} {'T':>2} {'median s':>9} {'min s':>8} {'runs':>4} "
          f"{'peer/lfqt':>9} {'by round':>8}  mesh   (peer time / lfqt-insert-kdtree's on the "
          "same thread count: > 1, lfqt is faster)")
    fig, ax = plt.subplots(figsize=(7.5, 5))
    timed = sorted({(p, t) for p, d, n, t in cells if d == TIME_SET},
                   key=lambda k: (PEERS.index(k[0]) if k[0] in PEERS else len(PEERS), k[1]))
    for p, t in timed:
        pts = sorted((n, c[0]) for (pp, d, n, tt), c in cells.items()
                     if (pp, d, tt) == (p, TIME_SET, t) and c[0])
        for n, _ in pts:
            med, lo, runs, kind, text = cells[(p, TIME_SET, n, t)]
            ref_t = t if (REFERENCE, TIME_SET, n, t) in cells else 1
            ref = cells.get((REFERENCE, TIME_SET, n, ref_t), (None,))[0]
            r = results.ratio(med, ref)
            rr = round_ratio(df, (p, t), (REFERENCE, ref_t), n, regime=regime)
            mine = p == REFERENCE and ref_t == t
            print(f"{n:>10,} {p:20} {t:>2} {med:9.3f} {lo:8.3f} {runs:>4} "
                  f"{'' if mine else results.fmt_ratio(r):>9} "
                  f"{'' if mine else results.fmt_ratio(rr):>8}  {text}")
        if pts:
            ax.plot([n for n, _ in pts], [m / n * 1e6 for n, m in pts],
                    "-o" if t == 1 else "--s", color=COLORS.get(p, "black"),
                    label=f"{p}, {t} thread{'s' if t > 1 else ''}", ms=4)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("points (uniform in the unit cube)")
    ax.set_ylabel("microseconds per point (median)")
    ax.grid(alpha=0.3, which="both")
    if timed:
        ax.legend(fontsize=7, ncol=2)
    ax.set_title("3D Delaunay: lfqt against every 3D peer, same input, same run\n"
                 f"{regime} regime: {REGIME_TEXT[regime]}", fontsize=10)
    fig.tight_layout()
    return figure_paths(fig, out, "dt3" if regime == "loop" else f"dt3-{regime}")


# -- issue 52's targets --------------------------------------------------------


def _largest(res):
    """(summary by BY in the loop regime, the largest size timed, or None)."""
    df = res.frame("dt3")
    s = res.summary("dt3", by=BY)
    ns = sorted(set(df.loc[df["distribution"] == TIME_SET, "n"]))
    return s, (int(ns[-1]) if ns else None)


def _sequential(claim, res):
    s, n = _largest(res)
    ours = results.median(s, REFERENCE, TIME_SET, n, 1) if n else None
    hxt = results.median(s, "gmsh-hxt", TIME_SET, n, 1) if n else None
    cgal = results.median(s, "cgal-dt3", TIME_SET, n, 1) if n else None
    if not ours:
        return claim.missing()
    r = results.ratio(hxt, ours)
    rows = [claim.row(
        f"{results.fmt_count(n)}: lfqt {ours:.2f} s, gmsh-hxt {hxt:.2f} s: {results.fmt_ratio(r)}",
        claim.rule(r), "HXT's time (gmsh's wheel, Mesh.Algorithm3D=10) over lfqt.insert's, loop "
        "regime, 1 thread (>= 1: lfqt as fast)") if hxt else claim.missing("gmsh-hxt has no time")]
    share = results.ratio(ours, cgal)
    rows.append(claim.missing("cgal-dt3 has no time") if not cgal else claim.row(
        f"{results.fmt_count(n)}: lfqt/CGAL DT3 {results.fmt_ratio(share)}",
        AtMost(claim.limits["cgal_share"])(share),
        f"HXT built from source took 1.97 s here, about {claim.limits['cgal_share']}x plain CGAL "
        "DT3's time in the same run; the harness has gmsh's wheel only, so CGAL stands in",
        text="1 thread, 1M uniform: lfqt at most the source-built HXT's time (as a share of "
             "CGAL DT3's)", published="HXT 1.97 s = 0.55x CGAL DT3"))
    return rows


def _parallel(claim, res):
    s, n = _largest(res)
    one = results.median(s, REFERENCE, TIME_SET, n, 1) if n else None
    two = results.median(s, REFERENCE, TIME_SET, n, 2) if n else None
    if not two:
        return claim.missing("no 2-thread cell of lfqt.insert")
    speedup = results.ratio(one, two)
    return claim.row(f"{results.fmt_count(n)}: 1 thread {one:.2f} s, 2 threads {two:.2f} s: "
                     f"{results.fmt_ratio(speedup)}", claim.rule(speedup),
                     "lfqt.insert's 1-thread time over its 2-thread time, loop regime")


def _parallel_vs_hxt(claim, res):
    s, n = _largest(res)
    two = results.median(s, REFERENCE, TIME_SET, n, 2) if n else None
    hxt = results.median(s, "gmsh-hxt", TIME_SET, n, 2) if n else None
    if not two or not hxt:
        return claim.missing("no 2-thread cell of " + ("lfqt.insert" if not two else "gmsh-hxt"))
    r = results.ratio(hxt, two)
    return claim.row(f"{results.fmt_count(n)}: lfqt {two:.2f} s, gmsh-hxt {hxt:.2f} s: "
                     f"{results.fmt_ratio(r)}", claim.rule(r),
                     "HXT's 2-thread time (gmsh's wheel) over lfqt.insert's, loop regime "
                     "(>= 1: lfqt as fast); HXT from source took 1.13-1.18 s here")


def _exact_everywhere(claim, res):
    cells = cells_of(res.frame("dt3"))
    ours = {k: v for k, v in cells.items() if k[0] in OURS}
    if not ours:
        return claim.missing()
    ours = {k: v for k, v in ours.items() if v[3] != "unchecked"}
    bad = sorted(f"{p} {d} {t}T: {v[4]}" for (p, d, n, t), v in ours.items() if v[3] != "exact")
    return claim.row(f"{len(ours) - len(bad)} of {len(ours)} cells exact",
                     claim.rule(len(ours) - len(bad), len(ours)),
                     "; ".join(bad) if bad else "lfqt.verify on every judged mesh of lfqt's 3D "
                     f"peers: the hard sets, and the timed sets up to {CHECK_MAX_N:,} points")


CLAIMS = (
    Claim("1 thread, 1M uniform: lfqt's 3D insertion at least as fast as HXT (issue 52, item 1)",
          "HXT/lfqt >= 1", _sequential, rule=AtLeast(1.0), limits={"cgal_share": 0.55}),
    Claim("2 threads, 1M uniform: at least 1.8x lfqt's own 1 thread (issue 52, item 2)",
          ">= 1.8x", _parallel, rule=AtLeast(1.8)),
    Claim("2 threads, 1M uniform: lfqt at most HXT's 2-thread time (issue 52, item 2)",
          "HXT/lfqt >= 1", _parallel_vs_hxt, rule=AtLeast(1.0)),
    Claim("every mesh of lfqt's 3D peers is the Delaunay tetrahedralisation, hard sets included",
          "exact on every input", _exact_everywhere, rule=Share(1.0)),
)


EXPERIMENT = Experiment("dt3", "3D Delaunay: lfqt's insertion and Delaunay against every 3D "
                        "peer (CGAL, CGAL parallel, gmsh HXT and default, TetGen, Qhull), "
                        "timed on 1 and 2 threads and checked exactly on the hard 3D sets",
                        grid, plot, repeats=3, known_failure=known_failure, check=judged,
                        timeouts=TIMEOUTS, tables=report_lines, regimes=REGIMES,
                        default_regimes=REGIMES, claims=CLAIMS, minutes={"default": 30},
                        loop_only=lambda cell: cell.distribution in HARD_SETS)
main = EXPERIMENT.main


if __name__ == "__main__":
    sys.exit(main())
