"""What an experiment is: a name, the published figures and tables it
regenerates, a grid of cells, a plot drawn from stored results only, and
the published claims it judges (experiments.core.claims).
``Experiment.main`` is the command line every experiment shares."""
import argparse
import math
import os
import sys
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Callable

from drivers.isolate import REGIME_TEXT, REGIMES

from . import results, runner

SCALES = ("smoke", "default", "paper")
# Per-cell limit (child process: warm-up and repeats; its preparation, JIT
# compilation included, has its own: drivers.isolate.PREPARE_SECONDS).  A
# peer that is pathological on a set (Qhull on nearly cocircular points) is
# recorded as a timeout, as paper 1 recorded Triangle failing at 100M points.
TIMEOUTS = {"smoke": 60.0, "default": 120.0, "paper": 1800.0}
# What the default main job (python -m experiments.all) may take on 2 quiet
# cores, setup.sh's budget; --list prints it beside the experiments' minutes.
MAIN_JOB_MINUTES = 12


@dataclass(frozen=True)
class Experiment:
    name: str
    title: str
    grid: Callable    # (scale, threads, **grid_options) -> [runner.Cell]
    plot: Callable    # (results DataFrame, out dir) -> [figure paths]; prints its table
    reproduces: tuple = ()  # published items, (paper, item) as its section's PUBLISHED has them
    repeats: int = 3
    rounds: int = 1
    options: tuple = ()  # extra (flag, argparse keywords)
    grid_options: tuple = ()  # names of extra options the grid takes as keywords
    setup: Callable = None  # (args, out_dir) before the grid is measured
    main_job: bool = False  # part of ``python -m experiments.all``
    # {scale: minutes it took, measured on 2 cores shared with other work}:
    # --list shows the default's and adds up the main job's beside its budget
    minutes: dict = None
    # (scale, cell) -> why the cell is known to fail within the scale's cell
    # timeout, or None: such a cell is recorded as skipped with that reason
    # instead of being waited for again
    known_failure: Callable = None
    # (args, out_dir, command) -> None: measures and writes results.csv itself instead
    # of the runner, for cells that are not one peer in one child process
    # (experiments.distributed runs a whole Dask cluster per cell)
    measure: Callable = None
    # args -> more entries of the metadata sidecar, measured before the grid
    # (fig6: this machine's own thread scaling, experiments.core.probe)
    metadata: Callable = None
    # the regimes (drivers.isolate.REGIMES) the plot tells apart; --regime
    # takes any of them, and the grid is measured once per regime asked for
    regimes: tuple = ("loop",)
    default_regimes: tuple = ("loop",)  # what --regime is when not given
    # cell -> True for a cell whose outcome does not depend on the regime (the
    # field's exactness sets): measured in the loop regime alone
    loop_only: Callable = None
    # judge every mesh exactly (drivers.exactness) after its timed runs; or
    # cell -> whether to judge its mesh (dt3: verify of a 1M-point
    # tetrahedralisation takes longer than the cell's runs)
    check: object = False
    timeouts: dict = None  # per-cell limits by scale, where not TIMEOUTS
    # the published claims it judges (claims.Claim), in the report's order
    claims: tuple = ()
    # (results DataFrame or None) -> Markdown lines the report adds after the
    # claims: tables rather than verdicts (experiments.beyond.field)
    tables: Callable = None

    @property
    def command(self):
        return f"python -m experiments.{self.name}"

    def cells(self, args):
        """The grid at ``args.scale``, narrowed by --peers, --sizes, --dists;
        with --input, on the user's file instead of the grid's sets."""
        cells = self.grid(args.scale, args.threads,
                          **{k: getattr(args, k) for k in self.grid_options})
        flags = (("peers", "peer"), ("sizes", "n"), ("dists", "distribution"))
        if getattr(args, "input", None):
            cells, flags = self.input_cells(cells, args), flags[:1]
        for flag, field in flags:
            wanted = getattr(args, flag)
            if wanted:
                known = {getattr(c, field) for c in cells}
                unknown = [w for w in wanted if w not in known]
                if unknown:
                    raise SystemExit(f"{self.command}: --{flag} {','.join(map(str, unknown))} is "
                                     f"not in this experiment's {args.scale} grid (it has "
                                     f"{', '.join(map(str, sorted(known)))})")
                cells = [c for c in cells if getattr(c, field) in wanted]
        unknown = [r for r in args.regime if r not in self.regimes]
        if unknown:
            raise SystemExit(f"{self.command}: --regime {','.join(unknown)} is not measured by "
                             f"this experiment (it has {', '.join(self.regimes)})")
        cells = [replace(c, regime=r) for r in args.regime for c in cells
                 if r == "loop" or not (self.loop_only and self.loop_only(c))]
        for c in cells:
            try:
                runner.check(c)
            except ValueError as e:
                raise SystemExit(f"{self.command}: {e}") from None
        return cells

    def input_cells(self, cells, args):
        """The grid's cells on the user's file (--input): each cell's set
        replaced by the file's points of the same dimension, all of them, or
        its first N for each N of --sizes; duplicate cells dropped."""
        import generators
        if args.dists:
            raise SystemExit(f"{self.command}: --dists and --input exclude each other")
        try:
            names, size = generators.register(args.input)
        except (OSError, ValueError) as e:
            raise SystemExit(f"{self.command}: --input: {e}") from None
        sizes = args.sizes or [size]
        if max(sizes) > size:
            raise SystemExit(f"{self.command}: --sizes {max(sizes):,} is more than the "
                             f"{size:,} points of {args.input}")
        out = {}
        for c in cells:
            dim = generators.get(c.distribution).dim
            if dim not in names:
                raise SystemExit(f"{self.command}: {args.input} has no z column, and this "
                                 "experiment triangulates in 3D")
            for n in sizes:
                new = replace(c, distribution=names[dim], n=n)
                out.setdefault(new.key, new)
        return list(out.values())

    def main(self, argv=None):
        """Parse the common options, run the grid through the runner (unless
        --plot-only), then draw the figure from the stored results."""
        ap = argparse.ArgumentParser(prog=self.command, description=sys.modules[
            self.plot.__module__].__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
        ap.add_argument("--scale", choices=SCALES, default="default")
        ap.add_argument("--threads", type=int, default=1,
                        help="threads for the peers that take them (an error for the others)")
        ap.add_argument("--peers", type=lambda s: s.split(","),
                        help="registry keys, comma separated")
        ap.add_argument("--repeats", type=int, default=self.repeats,
                        help="timed runs per cell and round")
        ap.add_argument("--rounds", type=int, default=self.rounds,
                        help="measure the whole grid this many times, interleaving the peers "
                             "in time")
        ap.add_argument("--sizes", type=lambda s: [int(float(v)) for v in s.split(",")],
                        help="keep only these sizes of the scale's grid, e.g. 1e5,1e6")
        ap.add_argument("--dists", type=lambda s: s.split(","),
                        help="keep only these distributions, comma separated")
        ap.add_argument("--regime", type=lambda s: s.split(","),
                        default=list(self.default_regimes),
                        help="comma separated: loop (a warm process, each result dropped), kept "
                             "(every result kept alive), fresh (a new process's first call)")
        ap.add_argument("--force", action="store_true", help="measure finished cells again")
        ap.add_argument("--out", default="results")
        ap.add_argument("--plot-only", action="store_true", help="redraw from stored results")
        ap.add_argument("--quiet", action="store_true", help="no progress bar")
        ap.add_argument("--timeout", type=float, help="seconds per cell (default by scale)")
        ap.add_argument("--input", metavar="PATH",
                        help="run on this point cloud (.npy, .csv, Parquet, .las/.laz) instead "
                             "of the grid's sets: all its points, or its first N for each N of "
                             "--sizes")
        for flag, kwargs in self.options:
            ap.add_argument(flag, **kwargs)
        args = ap.parse_args(argv)
        root = results_root(args.out, args.scale)
        if args.input:  # a user's file: apart from the report's results
            root = root / "input"
        out_dir = root / self.name
        if args.input and self.measure:
            raise SystemExit(f"{self.command}: --input is not supported here: this experiment "
                             "draws its own sets (it does not measure through the runner)")
        if not args.plot_only:
            cells = [] if self.measure else self.cells(args)
            if self.setup:
                self.setup(args, out_dir)
            known = (lambda c: self.known_failure(args.scale, c)) if self.known_failure else None
            command = " ".join([self.command] + list(argv if argv is not None
                                                     else sys.argv[1:]))
            if self.measure:
                self.measure(args, out_dir, command)
            else:
                runner.run(self.name, cells, repeats=args.repeats, rounds=args.rounds, out=root,
                           known_failure=known, check=self.check,
                           force=args.force,
                           timeout=args.timeout or (self.timeouts or TIMEOUTS)[args.scale],
                           progress=not args.quiet, command=command,
                           extra_metadata={"scale": args.scale,
                                           **(self.metadata(args) if self.metadata else {})})
        import matplotlib
        matplotlib.use("Agg")
        if not (out_dir / "results.csv").exists():
            raise SystemExit(f"{self.command}: no results at {out_dir}: run it without "
                             "--plot-only first")
        try:
            paths = self.plot(results.load(out_dir), root)
        except Exception as e:  # noqa: BLE001 - a figure drawn for the grid's own sets
            if not args.input:
                raise
            print(f"{self.command}: its figure does not draw a user's file ({type(e).__name__}: "
                  f"{e}); the results are in {out_dir}", file=sys.stderr)
            paths = []
        for p in paths:
            print(p)
        return 0


def many_threads(threads):
    """The thread count of an experiment's "all threads" cells: --threads
    when it asks for more than one, else every core (at least 2, so that the
    parallel path runs even on one core)."""
    return threads if threads > 1 else max(os.cpu_count() or 1, 2)


def results_root(out, scale):
    """Where a scale's results and figures go: ``out`` for the default scale,
    ``out/<scale>`` for the others, so that scales never overwrite each other."""
    return Path(out) if scale == "default" else Path(out) / scale


def per_regime(df, draw):
    """draw(rows, regime) for each regime of drivers.isolate.REGIMES that
    ``df`` holds, each under a printed line naming it; the figure paths of
    all."""
    paths = []
    for regime in [r for r in REGIMES if r in set(df["regime"])]:
        print(f"\n== regime: {regime} ({REGIME_TEXT[regime]}) ==")
        paths += draw(df[df["regime"] == regime], regime)
    return paths


def figure_paths(fig, out, name):
    """Save ``fig`` as results/figures/<name>.png and .svg; returns the paths."""
    d = Path(out) / "figures"
    d.mkdir(parents=True, exist_ok=True)
    paths = [d / f"{name}.png", d / f"{name}.svg"]
    for p in paths:
        fig.savefig(p, dpi=120, bbox_inches="tight")
    import matplotlib.pyplot as plt
    plt.close(fig)
    return paths


def label_ends(ax, ends, gap=0.07):
    """Label each line at its right end, ``ends`` being (x, y, text, color)
    on log-log axes: the labels go right of the last x, in a column that
    keeps them at least ``gap`` of the axis height (in log y) apart, each tied
    to its point by a thin line."""
    if not ends:
        return
    lo, hi = (math.log10(v) for v in ax.get_ylim())
    step = gap * (hi - lo)
    ends = sorted(ends, key=lambda e: e[1])  # bottom up
    placed = []
    for _, y, _, _ in ends:
        want = math.log10(y)
        placed.append(max(want, placed[-1] + step) if placed else want)
    shift = max(0.0, placed[-1] - hi + step / 2)  # the column slides down to fit
    right = max(x for x, _, _, _ in ends)
    for (x, y, text, color), at in zip(ends, placed):
        ax.annotate(text, (x, y), xytext=(right * 1.6, 10 ** (at - shift)), textcoords="data",
                    fontsize=7, color=color, va="center",
                    arrowprops=dict(arrowstyle="-", color=color, lw=0.5, alpha=0.6))
    ax.set_xlim(right=right * 9)
