"""What every experiment module shares: its command line, the figure
output, and the published values."""
import argparse
import csv
import sys
from pathlib import Path


from . import runner

PUBLISHED = Path(__file__).resolve().parent.parent / "results" / "published"
SCALES = ("smoke", "default", "paper")
# Per-cell limit (child process: warm-up and repeats).  A peer that is
# pathological on a set (Qhull on nearly cocircular points) is recorded as a
# timeout, as paper 1 recorded Triangle failing at 100M points.
TIMEOUTS = {"smoke": 60.0, "default": 120.0, "paper": 1800.0}


def published(name):
    """Rows of results/published/<name>.csv."""
    return list(csv.DictReader(open(PUBLISHED / f"{name}.csv")))


def figure_paths(fig, out, name):
    d = Path(out) / "figures"
    d.mkdir(parents=True, exist_ok=True)
    paths = [d / f"{name}.png", d / f"{name}.svg"]
    for p in paths:
        fig.savefig(p, dpi=120, bbox_inches="tight")
    return paths


def main(name, description, grid, plot, argv=None, repeats=3, rounds=1, options=(), setup=None):
    """Parse the common options, run the grid through the runner (unless
    --plot-only), then draw the figure from the stored results.

    ``options``: extra (flag, argparse keywords) of this experiment;
    ``setup(args, out_dir)``: runs before the grid (not with --plot-only).
    """
    ap = argparse.ArgumentParser(prog=f"python -m experiments.{name}", description=description,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scale", choices=SCALES, default="default")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--peers", type=lambda s: s.split(","), help="registry keys, comma separated")
    ap.add_argument("--repeats", type=int, default=repeats, help="timed runs per cell and round")
    ap.add_argument("--rounds", type=int, default=rounds,
                    help="measure the whole grid this many times, interleaving the peers in time")
    ap.add_argument("--sizes", type=lambda s: [int(float(v)) for v in s.split(",")],
                    help="keep only these sizes of the scale's grid, e.g. 1e5,1e6")
    ap.add_argument("--dists", type=lambda s: s.split(","),
                    help="keep only these distributions, comma separated")
    ap.add_argument("--force", action="store_true", help="measure finished cells again")
    ap.add_argument("--out", default="results")
    ap.add_argument("--plot-only", action="store_true", help="redraw from stored results")
    ap.add_argument("--quiet", action="store_true", help="no progress bar")
    ap.add_argument("--timeout", type=float, help="seconds per cell (default by scale)")
    for flag, kwargs in options:
        ap.add_argument(flag, **kwargs)
    args = ap.parse_args(argv)
    cells = grid(args.scale, args.threads)
    if args.peers:
        cells = [c for c in cells if c.peer in args.peers]
    if args.sizes:
        cells = [c for c in cells if c.n in args.sizes]
    if args.dists:
        cells = [c for c in cells if c.distribution in args.dists]
    if not args.plot_only:
        if setup:
            setup(args, Path(args.out) / name)
        runner.run(name, cells, repeats=args.repeats, rounds=args.rounds, out=args.out,
                   force=args.force,
                   timeout=args.timeout or TIMEOUTS[args.scale],
                   progress=not args.quiet, command=" ".join(["python -m experiments." + name]
                                                              + (argv or sys.argv[1:])))
    rows = runner.load(Path(args.out) / name)
    import matplotlib
    matplotlib.use("Agg")
    paths = plot(rows, args.out, args.scale)
    for p in paths:
        print(p)
    return 0


def ratio(a, b):
    return a / b if a and b else float("nan")


def fmt_ratio(x):
    return "-" if x != x else f"{x:.2f}x"
