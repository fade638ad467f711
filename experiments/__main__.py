"""python -m experiments --list   every published figure and table of both
papers, with the command that regenerates it, and the benchmarks."""
import argparse
import sys

from .core.registry import listing, papers


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m experiments", description=__doc__)
    ap.add_argument("--list", action="store_true", help="list the experiments (the default)")
    ap.parse_args(argv)
    for title in papers().values():
        print(f"# {title}")
    print(listing())
    return 0


if __name__ == "__main__":
    sys.exit(main())
