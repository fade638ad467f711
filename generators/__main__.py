"""python -m generators NAME N [--seed S] [--dtype float32|float64] --out FILE.npy
python -m generators --list"""
import argparse
import sys

import numpy as np

from . import DTYPES, REGISTRY, listing, make


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m generators", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("name", nargs="?", choices=list(REGISTRY), metavar="NAME")
    ap.add_argument("n", nargs="?", type=int)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--dtype", choices=list(DTYPES), default="float64")
    ap.add_argument("--out", help="output .npy file")
    ap.add_argument("--list", action="store_true", help="list the distributions and their formulas")
    args = ap.parse_args(argv)
    if args.list:
        print(listing())
        return 0
    if args.name is None or args.n is None or args.out is None:
        ap.error("NAME, N and --out are required (or --list)")
    pts = make(args.name, args.n, seed=args.seed, dtype=args.dtype)
    np.save(args.out, np.asarray(pts))
    print(f"wrote {args.out}: {pts.shape[0]} x {pts.shape[1]} {pts.dtype}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
