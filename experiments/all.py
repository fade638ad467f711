"""The main job: every reproduced figure and table at one scale.

    python -m experiments.all [--scale smoke|default|paper] [--force] [--out DIR]

Runs fig3, fig4, liu_table1 and liu_counts (a killed run resumes where it
stopped), then prints where the figures are."""
import argparse
import sys
import time

from . import fig3, fig4, liu_counts, liu_table1

EXPERIMENTS = [fig3, fig4, liu_table1, liu_counts]


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m experiments.all", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scale", choices=("smoke", "default", "paper"), default="default")
    ap.add_argument("--force", action="store_true")
    ap.add_argument("--out", default="results")
    ap.add_argument("--quiet", action="store_true")
    args = ap.parse_args(argv)
    t0 = time.time()
    extra = ["--scale", args.scale, "--out", args.out] + (["--force"] if args.force else []) \
        + (["--quiet"] if args.quiet else [])
    for exp in EXPERIMENTS:
        print(f"== {exp.__name__.split('.')[-1]} ({args.scale}) ==", flush=True)
        exp.main(extra)
    print(f"\nDone in {time.time() - t0:.0f} s. Figures: {args.out}/figures/ "
          f"(fig3, fig4, liu_table1, liu_counts; .png and .svg); tidy results and metadata: "
          f"{args.out}/<experiment>/")
    return 0


if __name__ == "__main__":
    sys.exit(main())
