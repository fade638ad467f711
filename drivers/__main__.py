"""python -m drivers build   build the compiled peers (the CGAL driver)
python -m drivers list    list the peers and whether each can run here"""
import sys

from . import REGISTRY, available, build, make


def cpu():
    """The CPU's model name, from /proc/cpuinfo."""
    try:
        return next(line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo")
                    if line.startswith("model name"))
    except (OSError, StopIteration):
        return "unknown CPU"


def main(argv):
    cmd = argv[0] if argv else "list"
    if cmd == "build":
        return build()
    if cmd == "list":
        print(f"# {cpu()}")
        for name in REGISTRY:
            ok, why = available(name)
            peer = make(name)
            dims = "/".join(f"{d}D" for d in peer.dims)
            info = peer.build_info()
            built = f"  [{info['version']}; {info['compiler']} {info['flags']}]" if info else ""
            print(f"{name:30s} {dims:6s} {peer.family:15s} "
                  f"{'ok' if ok else 'unavailable: ' + why}{built}")
        return 0
    print(__doc__, file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
