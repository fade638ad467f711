"""The main job: every experiment of the registry's main job at one scale,
then the report (experiments.report) from their results.

    python -m experiments.all [--scale smoke|default|paper] [--force] [--out DIR]

It judges every claim of those experiments, each experiment's default
scale sized for it (``python -m experiments --list`` gives their minutes
beside the budget, experiments.core.experiment.MAIN_JOB_MINUTES on 2 quiet
cores).  A killed
run resumes where it stopped; at the end it prints the seconds each
experiment took and where the figures are."""
import argparse
import sys
import time

from .core import report
from .core.experiment import SCALES, results_root
from .core.registry import main_job


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m experiments.all", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scale", choices=SCALES, default="default")
    ap.add_argument("--force", action="store_true")
    ap.add_argument("--out", default="results")
    ap.add_argument("--quiet", action="store_true")
    args = ap.parse_args(argv)
    t0 = time.time()
    extra = ["--scale", args.scale, "--out", args.out] + (["--force"] if args.force else []) \
        + (["--quiet"] if args.quiet else [])
    jobs = main_job()
    took = {}
    for exp in jobs:
        print(f"== {exp.name} ({args.scale}) ==", flush=True)
        t1 = time.time()
        exp.main(extra)
        took[exp.name] = time.time() - t1
    root = results_root(args.out, args.scale)
    print("== report ==", flush=True)
    report.main(["--scale", args.scale, "--out", args.out])
    print("\nseconds per experiment (a resumed run counts only what it measured): "
          + ", ".join(f"{name} {s:.0f}" for name, s in took.items()))
    print(f"\nDone in {time.time() - t0:.0f} s. Figures: {root}/figures/ "
          f"({', '.join(e.name for e in jobs)}; .png and .svg); tidy results and metadata: "
          f"{root}/<experiment>/; the claims judged: {root}/REPORT.md")
    return 0


if __name__ == "__main__":
    sys.exit(main())
