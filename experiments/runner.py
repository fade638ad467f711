"""The one runner every experiment uses.

A *cell* is (peer, distribution, n, dtype, threads, seed, order, count).  For
each cell the runner generates the points (seeded, cached), measures the peer
in a child process with a time and a memory limit (a crash, timeout or
out-of-memory is recorded with its reason and the sweep goes on), after an
untimed warm-up that triggers JIT compilation, and records every repeat.

Results are tidy: one row per repeat in ``results/<experiment>/results.csv``
(seconds, raw cycles where the peer has them, seconds at 3 GHz as paper 1
normalised, MP/s, counts, peak memory, status), with a metadata sidecar
(``metadata.json``: CPU, caches, cores, versions, commit, date, command).
Each finished cell is appended to ``cells.jsonl`` and fsynced before the
next starts, so a killed sweep resumes where it stopped and loses nothing
finished; the CSV is rewritten atomically from that log.
"""
import csv
import io
import json
import os
import platform
import subprocess
import sys
import time
from dataclasses import asdict, dataclass, replace
from pathlib import Path

import numpy as np

import drivers
import generators

NOMINAL_HZ = 3.0e9  # paper 1 normalises cycle counts to 3 GHz
FIELDS = ["experiment", "peer", "distribution", "n", "dtype", "threads", "seed", "order", "count",
          "round", "repeat", "status", "detail", "seconds", "cycles", "seconds_at_3ghz", "mpts_per_s",
          "peak_bytes", "bytes_per_point", "version", "counts"]


@dataclass(frozen=True)
class Cell:
    peer: str
    distribution: str
    n: int
    dtype: str = "float64"
    threads: int = 1
    seed: int = 0
    order: str = ""
    count: bool = False
    round: int = 0  # the grid is measured `rounds` times, round after round

    @property
    def key(self):
        d = asdict(self)
        if not d["round"]:
            del d["round"]  # keys of single-round sweeps predate rounds: they still resume
        return json.dumps(d, sort_keys=True)

    def label(self):
        extra = f" {self.order}" if self.order else ""
        return (f"{self.peer} {self.distribution} n={self.n:,}{extra}"
                f"{' (counts)' if self.count else ''}{f' round {self.round + 1}' if self.round else ''}")


def machine_info():
    """CPU model, caches, cores, library versions, commit."""
    info = {"python": platform.python_version(), "platform": platform.platform(),
            "cores": os.cpu_count()}
    try:
        info["cpu"] = next(line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo")
                           if line.startswith("model name"))
    except (OSError, StopIteration):
        info["cpu"] = platform.processor()
    info["caches"] = cache_sizes()
    try:
        info["memory_bytes"] = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError):
        pass
    versions = {}
    for pkg in ("numpy", "numba", "scipy", "triangle", "lfqt"):
        try:
            from importlib import metadata
            versions[pkg] = metadata.version(pkg)
        except Exception:  # noqa: BLE001 - a missing package is just not listed
            pass
    info["versions"] = versions
    try:
        info["commit"] = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True,
                                        cwd=Path(__file__).parent).stdout.strip()
    except OSError:
        pass
    return info


def cache_sizes():
    """{"L1d": bytes, "L2": bytes, "L3": bytes} from sysfs (cpu0)."""
    out = {}
    base = Path("/sys/devices/system/cpu/cpu0/cache")
    for idx in sorted(base.glob("index*")):
        try:
            level = (idx / "level").read_text().strip()
            kind = (idx / "type").read_text().strip()
            size = (idx / "size").read_text().strip()
        except OSError:
            continue
        mult = {"K": 1024, "M": 1024 ** 2}.get(size[-1], 1)
        name = f"L{level}" + ("d" if kind == "Data" else "i" if kind == "Instruction" else "")
        out[name] = int(size.rstrip("KM")) * mult
    return out


def available_memory():
    try:
        for line in open("/proc/meminfo"):
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) * 1024
    except OSError:
        pass
    return None


def _atomic_write(path, text):
    tmp = path.with_suffix(path.suffix + ".tmp")
    with open(tmp, "w") as f:
        f.write(text)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


def _rows_for(cell, experiment, outcome):
    base = dict(experiment=experiment, **asdict(cell))
    if outcome.get("status") != "ok":
        return [dict(base, repeat=0, status=outcome["status"], detail=outcome.get("detail", ""))]
    rows = []
    for k, (sec, cyc) in enumerate(zip(outcome["seconds"], outcome["cycles"])):
        rows.append(dict(base, repeat=k, status="ok", detail="", seconds=sec, cycles=cyc,
                         seconds_at_3ghz=cyc / NOMINAL_HZ if cyc else "",
                         mpts_per_s=cell.n / sec / 1e6 if sec else "",
                         peak_bytes=outcome["peak_bytes"],
                         bytes_per_point=outcome["peak_bytes"] / max(cell.n, 1),
                         version=outcome["version"], counts=json.dumps(outcome["counts"])))
    return rows


def measure_cell(cell, repeats, timeout, memory_fraction=0.8):
    """Run one cell in a child process; a dict describing the outcome."""
    ok, why = drivers.available(cell.peer)
    if not ok:
        return {"status": "unavailable", "detail": why}
    need = estimated_bytes(cell)
    avail = available_memory()
    if avail is not None and need > memory_fraction * avail:
        return {"status": "skipped", "detail": f"needs about {need / 2**30:.1f} GiB, "
                f"{avail / 2**30:.1f} GiB available"}
    pts = np.asarray(generators.make(cell.distribution, cell.n, seed=cell.seed, dtype=cell.dtype))
    peer = drivers.make(cell.peer)
    if hasattr(peer, "threads"):
        peer.threads = cell.threads
    if cell.order and hasattr(peer, "order"):
        peer.order = cell.order
    limit = int(memory_fraction * avail) if avail else None
    m = drivers.measure_isolated(peer, pts, repeats=repeats, count=cell.count, timeout=timeout,
                                 memory_bytes=limit)
    if not m.ok:
        return {"status": m.reason, "detail": m.detail[:500]}
    return {"status": "ok", "seconds": m.seconds, "cycles": m.cycles,
            "peak_bytes": m.extra_peak_bytes, "version": m.version, "counts": m.counts}


def estimated_bytes(cell):
    """A generous estimate of a cell's peak memory, to skip what cannot fit."""
    per_point = {"qhull": 2500, "triangle": 400, "cgal": 400}.get(cell.peer.split("-")[0], 300)
    if "insert" in cell.peer or "dt3" in cell.peer:
        per_point = 1200
    return cell.n * per_point


def run(experiment, cells, *, repeats=3, rounds=1, out="results", force=False, timeout=1800.0,
        progress=True, command=None):
    """Measure every cell not already done; return the results directory.

    With ``rounds`` > 1 the whole grid is measured that many times, round
    after round, each cell in a fresh child with ``repeats`` runs.  On a
    shared machine whose speed drifts over minutes, this spreads every peer's
    runs over the same stretch of time, so the pooled medians of peers are
    compared under the same conditions rather than under whatever held while
    each peer's single cell ran.
    """
    cells = [replace(c, round=r) for r in range(max(rounds, 1)) for c in cells
             if r == 0 or not c.count]  # counts are deterministic: one round
    out_dir = Path(out) / experiment
    out_dir.mkdir(parents=True, exist_ok=True)
    log = out_dir / "cells.jsonl"
    if force and log.exists():
        log.unlink()
    done = {}
    if log.exists():
        for line in log.read_text().splitlines():
            try:
                rec = json.loads(line)
                done[rec["key"]] = rec
            except (json.JSONDecodeError, KeyError):
                continue  # a line cut by a crash: that cell is measured again
    todo = [c for c in cells if c.key not in done]
    meta = dict(experiment=experiment, command=command or " ".join(sys.argv),
                date=time.strftime("%Y-%m-%d %H:%M:%S %z"), repeats=repeats, rounds=rounds,
                cells=len(cells), resumed_cells=len(cells) - len(todo), **machine_info())
    _atomic_write(out_dir / "metadata.json", json.dumps(meta, indent=2, default=str))
    bar = None
    if progress and todo:
        try:
            from tqdm import tqdm
            bar = tqdm(total=len(todo), desc=experiment, unit="cell", file=sys.stderr)
        except ImportError:
            bar = None
    with open(log, "a") as f:
        for cell in todo:
            if bar:
                bar.set_postfix_str(cell.label())
            outcome = measure_cell(cell, 1 if cell.count else repeats, timeout)
            rec = {"key": cell.key, "cell": asdict(cell), "outcome": outcome}
            f.write(json.dumps(rec, default=float) + "\n")
            f.flush()
            os.fsync(f.fileno())
            done[cell.key] = rec
            if bar:
                bar.update(1)
            elif progress:
                print(f"[{experiment}] {cell.label()}: {outcome['status']}", file=sys.stderr)
    if bar:
        bar.close()
    rows = []
    for c in cells:
        rows += _rows_for(c, experiment, done[c.key]["outcome"])
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=FIELDS)
    w.writeheader()
    w.writerows(rows)
    _atomic_write(out_dir / "results.csv", buf.getvalue())
    return out_dir


def load(out_dir):
    """The tidy results as a list of dicts with numeric fields converted."""
    rows = list(csv.DictReader(open(Path(out_dir) / "results.csv")))
    for r in rows:
        r.setdefault("round", "0")
        for k in ("n", "threads", "seed", "round", "repeat"):
            r[k] = int(r[k]) if r[k] != "" else None
        for k in ("seconds", "cycles", "seconds_at_3ghz", "mpts_per_s", "peak_bytes",
                  "bytes_per_point"):
            r[k] = float(r[k]) if r.get(k) not in ("", None) else None
        r["counts"] = json.loads(r["counts"]) if r.get("counts") else {}
        r["count"] = r["count"] == "True"
    return rows


def summarize(rows, by=("peer", "distribution", "n", "order", "count")):
    """{key: {"min", "median", "status", "counts"}} over the repeats of each
    cell, pooled over rounds."""
    groups = {}
    for r in rows:
        groups.setdefault(tuple(r[k] for k in by), []).append(r)
    out = {}
    for key, rs in groups.items():
        secs = [r["seconds"] for r in rs if r["status"] == "ok" and r["seconds"] is not None]
        out[key] = {"status": rs[0]["status"], "detail": rs[0]["detail"],
                    "min": min(secs) if secs else None,
                    "median": float(np.median(secs)) if secs else None,
                    "counts": rs[0]["counts"], "bytes_per_point": rs[0]["bytes_per_point"]}
    return out
