"""python -m drivers build   build the compiled peers (the CGAL driver)
python -m drivers list    list the peers and whether each can run here"""
import sys

from . import REGISTRY, available, build, make


def main(argv):
    cmd = argv[0] if argv else "list"
    if cmd == "build":
        return build()
    if cmd == "list":
        for name in REGISTRY:
            ok, why = available(name)
            peer = make(name)
            dims = "/".join(f"{d}D" for d in peer.dims)
            print(f"{name:30s} {dims:6s} {peer.family:9s} {'ok' if ok else 'unavailable: ' + why}")
        return 0
    print(__doc__, file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
