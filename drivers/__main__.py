"""python -m drivers build   build the CGAL driver (cmake, Release)
python -m drivers list    list the peers and whether each can run here"""
import subprocess
import sys

from . import REGISTRY, available, make
from .peers import CGAL_DIR


def build():
    out = CGAL_DIR / "build"
    out.mkdir(exist_ok=True)
    try:
        subprocess.run(["cmake", "-S", str(CGAL_DIR), "-B", str(out), "-DCMAKE_BUILD_TYPE=Release"],
                       check=True, stdout=subprocess.DEVNULL)
        subprocess.run(["cmake", "--build", str(out), "-j", "2"], check=True)
    except (OSError, subprocess.CalledProcessError) as e:
        print(f"building the CGAL driver failed: {e}\nIt needs Debian's libcgal-dev, libgmp-dev, "
              "libmpfr-dev and cmake; as root: apt-get install -y libcgal-dev libgmp-dev "
              "libmpfr-dev cmake", file=sys.stderr)
        return 1
    print(out / "cgal_driver")
    return 0


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
