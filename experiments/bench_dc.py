"""Issue-2 benchmark: lfqt's divide and conquer against the 2D peers, same
input, same run.

    python -m experiments.bench_dc [--scale small|default|full] [--repeats R]
                                   [--peers a,b] [--dists a,b] [--sizes 1e5,1e6]

Every cell runs in a child process (time and memory limits) after an
untimed warm-up; we report the median and minimum of R runs, each peer's
median as a ratio to lfqt-dc's (> 1: lfqt is faster), lfqt's rate in
points/s, and lfqt's peak memory above its input in bytes per point.
Compile time is measured apart, in fresh processes with a cold and a warm
numba cache.  Writes results/bench_dc/bench_dc.csv and a metadata sidecar.
"""
import argparse
import csv
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import drivers
import generators

SCALES = {
    "small": dict(sizes=[100_000], dists=["uniform"], repeats=3,
                  peers=["lfqt-dc", "lfqt-dc-alternating", "triangle", "cgal-dt2", "qhull-2d"]),
    "default": dict(sizes=[100_000, 1_000_000], dists=["uniform", "grid", "cluster"], repeats=5,
                    peers=["lfqt-dc", "lfqt-dc-alternating", "triangle", "cgal-dt2", "qhull-2d"]),
    "full": dict(sizes=[100_000, 1_000_000, 3_000_000, 10_000_000],
                 dists=["uniform", "grid", "cluster"], repeats=5,
                 peers=["lfqt-dc", "lfqt-dc-alternating", "triangle", "cgal-dt2", "qhull-2d"]),
}
QHULL_MAX = 1_000_000  # Qhull needs ~13 s per run at 1M: larger sizes are skipped
REFERENCE = "lfqt-dc"


def compile_seconds():
    """(cold compile, cached load) of the first triangulate call, each in a
    fresh interpreter."""
    code = ("import time, numpy as np; t=time.perf_counter(); import lfqt; "
            "lfqt.triangulate(np.random.default_rng(0).random((1000, 2))); "
            "lfqt.triangulate(np.random.default_rng(0).random((1000, 2)).astype(np.float32), "
            "subdivision='alternating'); print(time.perf_counter()-t)")
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        out = [float(subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                                    text=True, check=True).stdout) for _ in range(2)]
    return out[0], out[1]


def run(scale, sizes=None, dists=None, peers=None, repeats=None, out_dir="results/bench_dc",
        timeout=900.0):
    cfg = dict(SCALES[scale])
    sizes = sizes or cfg["sizes"]
    dists = dists or cfg["dists"]
    peers = peers or cfg["peers"]
    repeats = repeats or cfg["repeats"]
    rows = []
    for dist in dists:
        for n in sizes:
            pts = np.asarray(generators.make(dist, n))
            ref = None
            for name in peers:
                ok, why = drivers.available(name)
                row = dict(distribution=dist, n=n, peer=name)
                if not ok:
                    rows.append(dict(row, status="unavailable", detail=why))
                    continue
                if name.startswith("qhull") and n > QHULL_MAX:
                    rows.append(dict(row, status="skipped", detail=f"Qhull above {QHULL_MAX} points"))
                    continue
                m = drivers.measure_isolated(drivers.make(name), pts, repeats=repeats,
                                             timeout=timeout)
                if not m.ok:
                    rows.append(dict(row, status=m.reason, detail=m.detail))
                    print(f"{dist:8s} {n:>10,d} {name:22s} FAILED: {m.reason} {m.detail[:80]}")
                    continue
                med, best = float(np.median(m.seconds)), float(min(m.seconds))
                if name == REFERENCE:
                    ref = med
                rows.append(dict(row, status="ok", median_s=med, min_s=best,
                                 ratio_to_lfqt=med / ref if ref else None,
                                 mpts_per_s=n / med / 1e6,
                                 bytes_per_point=m.extra_peak_bytes / n, version=m.version))
                r = rows[-1]
                print(f"{dist:8s} {n:>10,d} {name:22s} median {med:8.3f} s  min {best:8.3f} s  "
                      f"{'ratio %5.2fx' % r['ratio_to_lfqt'] if ref else '':12s} "
                      f"{r['mpts_per_s']:6.2f} Mpt/s  {r['bytes_per_point']:6.0f} B/pt", flush=True)
    return rows


def machine():
    info = dict(python=platform.python_version(), platform=platform.platform(), cores=os.cpu_count())
    try:
        info["cpu"] = next(l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo")
                           if l.startswith("model name"))
    except (OSError, StopIteration):
        pass
    try:
        info["commit"] = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True,
                                        text=True).stdout.strip()
    except OSError:
        pass
    return info


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m experiments.bench_dc", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scale", choices=list(SCALES), default="default")
    ap.add_argument("--repeats", type=int)
    ap.add_argument("--peers", type=lambda s: s.split(","))
    ap.add_argument("--dists", type=lambda s: s.split(","))
    ap.add_argument("--sizes", type=lambda s: [int(float(v)) for v in s.split(",")])
    ap.add_argument("--out", default="results/bench_dc")
    ap.add_argument("--no-compile-time", action="store_true")
    args = ap.parse_args(argv)
    t0 = time.time()
    meta = dict(command=" ".join(sys.argv), date=time.strftime("%Y-%m-%d %H:%M:%S"), **machine())
    if not args.no_compile_time:
        cold, warm = compile_seconds()
        meta.update(compile_cold_s=cold, compile_cached_s=warm)
        print(f"first call incl. JIT: cold cache {cold:.1f} s, warm cache {warm:.1f} s")
    rows = run(args.scale, args.sizes, args.dists, args.peers, args.repeats, args.out)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    keys = sorted({k for r in rows for k in r})
    with open(out / "bench_dc.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)
    lf = [r for r in rows if r["peer"] == REFERENCE and r["status"] == "ok"]
    for dist in sorted({r["distribution"] for r in lf}):
        rates = [r["mpts_per_s"] for r in lf if r["distribution"] == dist]
        if len(rates) > 1:
            print(f"lfqt-dc rate on {dist}: {min(rates):.2f} to {max(rates):.2f} Mpt/s "
                  f"(max/min {max(rates) / min(rates):.2f})")
    meta["seconds"] = time.time() - t0
    (out / "bench_dc.meta.json").write_text(json.dumps(meta, indent=2))
    print(f"wrote {out / 'bench_dc.csv'} ({meta['seconds']:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
