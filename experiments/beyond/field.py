"""The field today: lfqt against every 2D peer a user would pick in 2026,
timed on the same input in the same run, and every mesh checked exactly.

    python -m experiments.field [--scale smoke|default|paper] [--input cloud.laz]
                                [--regime loop,kept,fresh]

Two parts, one grid:

* time: every peer on paper 1's five sets (tagged "paper1" in
  generators.REGISTRY) and the LiDAR model's xy, at 100k (default scale:
  plus 1M on uniform and the LiDAR set; paper scale: 100k, 1M and 10M on
  every set, where a peer finishes within the cell's time limit);
* exactness: every peer on the hard sets (tagged "hard": grid, circle,
  exactly cocircular lattice points, collinear sets, duplicates, signed
  zeros, 1e-300, subnormal and 1e300 magnitudes, GIS offsets, the LiDAR
  model) at a few thousand points.

Each cell runs in a child process (a crash or a hang is a recorded
outcome, never the end of the sweep) and its last mesh is judged by
lfqt.verify: exact, wrong (bad edges, missing triangles), refused (the
peer raised an error), crashed, or hung (no result within the cell's time
limit).  Each peer runs in its fastest documented way (drivers/: one
module per family says how).  The timed part runs in each regime asked
for (drivers.isolate.REGIMES; the loop by default); the exactness sets do
not depend on it and run in the loop regime alone.  Figures: results/figures/field.png (time
with each bar coloured by its exactness) and field_exactness.png (peer x
hard set); REPORT.md's section "The field today" has both tables."""
import re
import sys

import numpy as np

import drivers
import generators
from drivers import qhull
from drivers.exactness import describe
from drivers.isolate import REGIME_TEXT, REGIMES

from ..core import results
from ..core.experiment import Experiment, figure_paths
from ..core.runner import Cell

REFERENCE = "lfqt-dc"
PEERS = [REFERENCE, "cgal-dt2", "cgal-dt2-indexed", "triangle-native", "triangle",
         "meshpy-triangle", "delaunator", "cdt", "startinpy", "gmsh", "cgal-python",
         "cgal-python-points", "qhull-2d"]
TIME_SETS = generators.names(2, tag="paper1") + ["lidar-xy"]
HARD_SETS = generators.names(2, tag="hard")
SIZES = {"smoke": [20_000], "default": [100_000, 1_000_000],
         "paper": [100_000, 1_000_000, 10_000_000]}
# the default scale keeps to a few minutes on 2 cores: 1M on these sets only
DEFAULT_1M_SETS = ("uniform", "lidar-xy")
HARD_N = {"smoke": 500, "default": 2_000, "paper": 10_000}
# how a failed cell reads in the exactness table
FAILED = {"error": "refused", "crash": "crashed", "timeout": "hung", "memory": "out of memory",
          "unavailable": "unavailable", "skipped": "skipped"}
COLORS = {"exact": "#3aa655", "wrong": "#d1495b", "failed": "#9e9e9e"}
# per-cell limits: a peer that needs more is recorded as hung on that cell
# (the default scale keeps to a few minutes; a hang there costs its limit)
TIMEOUTS = {"smoke": 30.0, "default": 120.0, "paper": 600.0}
# published figures to read beside ours (issue 53 cites them)
PUBLISHED = ["Delaunator's README: 1M points in 1.35 s (a 2017 laptop)",
             "delaunator-rs: 1M in 0.90 s, 10M in 11.9 s",
             "PBBS incrementalDelaunay: 10M 2D points in 37.6 s on 1 thread, 0.75 s on 128"]


def _timed(scale, dist, n, peer):
    if peer == "qhull-2d" and not qhull.measured_at(scale, n):
        return False
    return not (scale == "default" and n > 100_000 and dist not in DEFAULT_1M_SETS)


def grid(scale, threads):
    timing = [Cell(p, d, n, threads=threads if p == REFERENCE else 1)
              for n in SIZES[scale] for d in TIME_SETS for p in PEERS if _timed(scale, d, n, p)]
    hard = [Cell(p, d, HARD_N[scale], threads=threads if p == REFERENCE else 1)
            for d in HARD_SETS for p in PEERS]
    return timing + hard


def known_failure(scale, cell):
    """A peer's known hang (its driver module's known_failure) is not waited
    for below the paper scale.  Qhull's on nearly cocircular points is not
    waited for at the paper scale either: there it would cost the cell's
    limit at 100k and at 1M."""
    reason = drivers.known_failure(cell.peer, cell.distribution, cell.n)
    if reason is None or cell.peer == "qhull-2d":
        return reason
    return None if scale == "paper" else reason + " (--scale paper waits for it)"


def verdict(rows):
    """(kind, text) of one cell's rows: kind "exact", "wrong" or "failed";
    text as the exactness table shows it."""
    first = rows.iloc[0]
    if first["status"] != "ok":
        reason = first["detail"].strip().splitlines()[0] if first["detail"].strip() else ""
        text = FAILED.get(first["status"], first["status"])
        if first["status"] == "skipped" and reason.startswith("known hang"):
            text = "hung"
        elif first["status"] == "error" and re.search(r"failed \(-\d+\)", reason):
            text = "crashed"  # a compiled driver killed by a signal
        elif first["status"] == "error":
            text += f" ({reason.split(':', 1)[0][:40]})" if reason else ""
        return "failed", text
    check = first["check"]
    if not check:
        return "failed", "not checked"
    return check["verdict"], describe(check)


def cells_of(df, regime="loop"):
    """{(peer, set, n): (median seconds or None, kind, text)} of a sweep's
    cells in ``regime``."""
    df = df[df["regime"] == regime]
    s = results.summarize(df)
    out = {}
    for (peer, d, n), rows in df.groupby(["peer", "distribution", "n"], sort=False):
        kind, text = verdict(rows)
        out[(peer, d, int(n))] = (results.median(s, peer, d, n, False), kind, text)
    return out


def regimes_of(df):
    """The regimes a sweep measured, in REGIMES' order."""
    return [r for r in REGIMES if r in set(df["regime"])]


def exactness_table(df):
    """Markdown lines: peer x hard set, each cell exact / wrong (how) /
    refused / crashed / hung; empty when the sweep has no hard sets."""
    cells = cells_of(df)
    sets = [d for d in HARD_SETS if any(k[1] == d for k in cells)]
    sets += sorted({k[1] for k in cells if k[1].startswith("input:")})
    peers = [p for p in PEERS if any(k[0] == p for k in cells)]
    hard_n = {d: max(n for p, dd, n in cells if dd == d) if d.startswith("input:") else
              min(n for p, dd, n in cells if dd == d) for d in sets}
    if not sets:
        return []
    lines = ["| peer | " + " | ".join(f"{d} ({results.fmt_count(hard_n[d])})" if hard_n[d] >= 1000
                                     else f"{d} ({hard_n[d]})" for d in sets) + " |",
             "|---|" + "---|" * len(sets)]
    for p in peers:
        row = [cells.get((p, d, hard_n[d]), (None, "", "-"))[2] for d in sets]
        lines.append(f"| {p} | " + " | ".join(f"**{t}**" if t.startswith("wrong") else t
                                              for t in row) + " |")
    return lines


def timing_table(df, regime="loop"):
    """Markdown lines: peer x (set, size) of the timed part in ``regime``:
    median seconds, its ratio to lfqt's, and the verdict of that mesh."""
    cells = cells_of(df, regime)
    keys = sorted({(d, n) for _, d, n in cells if d.startswith("input:")
                   or (d in TIME_SETS and n >= 10_000)},
                  key=lambda k: (k[1], TIME_SETS.index(k[0]) if k[0] in TIME_SETS else -1))
    if not keys:
        return []
    lines = ["| peer | " + " | ".join(f"{d} {results.fmt_count(n)}" for d, n in keys) + " |",
             "|---|" + "---|" * len(keys)]
    for p in [p for p in PEERS if any(k[0] == p for k in cells)]:
        row = []
        for d, n in keys:
            t, kind, text = cells.get((p, d, n), (None, "", "-"))
            ref = cells.get((REFERENCE, d, n), (None,))[0]
            if t is None:
                row.append(text if text != "-" else "-")
                continue
            ratio = "" if p == REFERENCE else f" ({results.fmt_ratio(results.ratio(t, ref))})"
            mark = "" if kind == "exact" else f", **{text}**"
            row.append(f"{t:.3g} s{ratio}{mark}")
        lines.append(f"| {p} | " + " | ".join(row) + " |")
    return lines


def timing_tables(df):
    """timing_table of each regime measured, each under a line naming it."""
    lines = []
    for regime in regimes_of(df):
        table = timing_table(df, regime)
        if table:
            lines += [f"Regime **{regime}**: {REGIME_TEXT[regime]}.", ""] + table + [""]
    return lines


def report_lines(df):
    """REPORT.md's section "The field today" from a stored sweep."""
    if df is None:
        return ["## The field today", "", "Not measured yet: run `python -m experiments.field`.",
                ""]
    return (["## The field today", "",
             "Every 2D peer a user would pick in 2026, in its fastest documented way, one child "
             "process per cell, on the same points (`python -m experiments.field`). Time: the "
             "median of the timed runs, in brackets the ratio to lfqt-dc's (> 1: lfqt faster); "
             "a mesh that is not the Delaunay triangulation (lfqt.verify, exact) is marked.", ""]
            + timing_tables(df)
            + ["Exactness on the hard sets: *exact*, *wrong* (edges whose in-circle test fails, "
               "triangles missing against the Delaunay count), *refused* (the peer raised an "
               "error), *crashed*, *hung* (no result within the cell's limit).", ""]
            + exactness_table(df)
            + ["", "Published, to read beside these (other machines): " + "; ".join(PUBLISHED)
               + ".", ""])


def plot(df, out):
    """The tables, a time figure per regime (field.png for the loop regime,
    field-<regime>.png for the others) and the exactness figure."""
    print("\n" + "\n".join(timing_tables(df)))
    print("\nExactness on the hard sets:\n" + "\n".join(exactness_table(df)))
    by_regime = {regime: cells_of(df, regime) for regime in regimes_of(df)}
    paths = []
    for regime, cells in by_regime.items():
        paths += _time_figure(cells, out, regime)
    cells = by_regime.get("loop", {})
    hard = [d for d in HARD_SETS if any(k[1] == d for k in cells)]
    if hard:
        paths += _exactness_figure(cells, hard, out)
    return paths


def _time_figure(cells, out, regime):
    """The time panels of one regime's cells (the largest size of each set)."""
    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch
    from matplotlib.ticker import NullFormatter
    panels = sorted({(d, n) for _, d, n in cells if d not in HARD_SETS or n >= 10_000
                     or d.startswith("input:")}, key=lambda k: (k[0], k[1]))
    panels = [k for k in panels if k[1] == max(n for _, d, n in cells if d == k[0])]
    paths = []
    if panels:
        cols = min(3, len(panels))
        rows_n = -(-len(panels) // cols)
        fig, axes = plt.subplots(rows_n, cols, figsize=(5.2 * cols, 4.2 * rows_n), squeeze=False)
        for ax, (d, n) in zip(axes.ravel(), panels):
            peers = [p for p in PEERS if (p, d, n) in cells][::-1]
            for y, p in enumerate(peers):
                t, kind, text = cells[(p, d, n)]
                ax.barh(y, t or 0, color=COLORS[kind], hatch="" if kind == "exact" else "//",
                        edgecolor="white")
                if kind != "exact":  # a failed cell has no bar: its outcome at the axis
                    ax.annotate(text[:38], (t, y) if t else (0.01, y), xytext=(3, 0),
                                xycoords="data" if t else ("axes fraction", "data"),
                                textcoords="offset points", va="center", fontsize=6.5,
                                color=COLORS[kind])
            ax.set_yticks(range(len(peers)), peers, fontsize=7.5)
            ax.set_xscale("log")
            ax.xaxis.set_minor_formatter(NullFormatter())  # a narrow range crowds them
            ax.set_xlabel("seconds (median)")
            ax.set_title(f"{d}, {n:,} points", fontsize=10)
            ax.grid(axis="x", alpha=0.3, which="both")
        for ax in axes.ravel()[len(panels):]:
            ax.axis("off")
        fig.legend([Patch(color=COLORS[k]) for k in COLORS],
                   ["exact (lfqt.verify)", "wrong: not the Delaunay triangulation",
                    "refused, crashed, hung"], loc="lower center", ncol=3, fontsize=8,
                   frameon=False)
        fig.suptitle("The field today: time of each 2D peer, coloured by whether its mesh is "
                     "the Delaunay triangulation"
                     + ("" if regime == "loop" else f"\n{regime} regime: {REGIME_TEXT[regime]}"))
        fig.tight_layout(rect=(0, 0.04, 1, 1))
        paths += figure_paths(fig, out, "field" if regime == "loop" else f"field-{regime}")
    return paths


def _exactness_figure(cells, sets, out):
    import matplotlib.pyplot as plt
    peers = [p for p in PEERS if any(k[0] == p for k in cells)]
    n_of = {d: min(n for _, dd, n in cells if dd == d) for d in sets}
    code = {"exact": 0, "wrong": 1, "failed": 2}
    grid_ = np.array([[code[cells.get((p, d, n_of[d]), (None, "failed", ""))[1]] for d in sets]
                      for p in peers])
    from matplotlib.colors import ListedColormap
    fig, ax = plt.subplots(figsize=(1.05 * len(sets) + 2.5, 0.42 * len(peers) + 1.8))
    ax.imshow(grid_, cmap=ListedColormap([COLORS["exact"], COLORS["wrong"], COLORS["failed"]]),
              vmin=0, vmax=2, aspect="auto")
    for i, p in enumerate(peers):
        for j, d in enumerate(sets):
            text = cells.get((p, d, n_of[d]), (None, "", "-"))[2]
            ax.text(j, i, text.replace("wrong: ", "").replace(", ", "\n")[:40], ha="center",
                    va="center", fontsize=5.5, color="white")
    ax.set_xticks(range(len(sets)), [f"{d}\n({n_of[d]:,})" for d in sets], fontsize=7,
                  rotation=30, ha="right")
    ax.set_yticks(range(len(peers)), peers, fontsize=7.5)
    ax.set_title("Exactness on the hard sets (green: exact; red: wrong; grey: refused, crashed, "
                 "hung)", fontsize=9)
    fig.tight_layout()
    return figure_paths(fig, out, "field_exactness")


EXPERIMENT = Experiment("field", "the field today: lfqt against every 2D peer of 2026, timed and "
                        "checked exactly, on paper 1's sets, a LiDAR model and the hard sets",
                        grid, plot, repeats=3, known_failure=known_failure, check=True,
                        timeouts=TIMEOUTS, tables=report_lines, regimes=REGIMES,
                        loop_only=lambda cell: cell.distribution in HARD_SETS)
main = EXPERIMENT.main


if __name__ == "__main__":
    sys.exit(main())
