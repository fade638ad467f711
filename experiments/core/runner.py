"""The one runner every experiment uses.

A *cell* is (peer, distribution, n, dtype, threads, seed, count, round).  For
each cell the runner generates the points (seeded, cached), measures the peer
in a child process with a time and a memory limit (a crash, timeout or
out-of-memory is recorded with its reason and the sweep goes on), after an
untimed warm-up that triggers JIT compilation, and records every repeat as a
tidy row (experiments.core.results).

Each finished cell is appended to ``cells.jsonl`` and fsynced before the
next starts, so a killed sweep resumes where it stopped and loses nothing
finished; ``results.csv`` is rewritten atomically from that log, with the
metadata sidecar (experiments.core.machine).
"""
import json
import sys
import time
from dataclasses import asdict, dataclass, fields, replace
from pathlib import Path

import numpy as np

import drivers
import generators

from . import results
from .machine import available_memory, machine_info


@dataclass(frozen=True)
class Cell:
    peer: str
    distribution: str
    n: int
    dtype: str = "float64"
    threads: int = 1
    seed: int = 0
    count: bool = False
    round: int = 0  # the grid is measured `rounds` times, round after round
    regime: str = "loop"  # drivers.isolate.REGIMES: loop, kept or fresh

    @classmethod
    def from_record(cls, record):
        """The cell of a logged record, whatever fields that version logged."""
        names = {f.name for f in fields(cls)}
        return cls(**{k: v for k, v in record.items() if k in names})

    def fields(self):
        return asdict(self)

    @property
    def key(self):
        d = asdict(self)
        if not d["round"]:
            del d["round"]  # keys of single-round sweeps predate rounds: they still resume
        if d["regime"] == "loop":
            del d["regime"]  # as do keys of the loop regime, which predate regimes
        return json.dumps(d, sort_keys=True)

    def label(self):
        return (f"{self.peer} {self.distribution} n={self.n:,}"
                f"{' (counts)' if self.count else ''}{f' round {self.round + 1}' if self.round else ''}"
                f"{'' if self.regime == 'loop' else f' ({self.regime})'}")


def check(cell):
    """ValueError when a cell asks a peer for an option it does not have."""
    drivers.make(cell.peer, threads=cell.threads)


def measure_cell(cell, repeats, timeout, memory_fraction=0.8, check=False):
    """Run one cell in a child process; a dict describing the outcome
    (``check``: with the exact judgement of the peer's mesh)."""
    ok, why = drivers.available(cell.peer)
    if not ok:
        return {"status": "unavailable", "detail": why}
    peer = drivers.make(cell.peer, threads=cell.threads)
    need = peer.estimated_bytes(cell.n)
    avail = available_memory()
    if avail is not None and need > memory_fraction * avail:
        return {"status": "skipped", "detail": f"needs about {need / 2**30:.1f} GiB, "
                f"{avail / 2**30:.1f} GiB available"}
    pts = np.asarray(generators.make(cell.distribution, cell.n, seed=cell.seed, dtype=cell.dtype))
    limit = int(memory_fraction * avail) if avail else None
    # a fresh process per timed run in the fresh regime: each is a first call
    per_process = repeats if cell.regime != "fresh" else 1
    if cell.regime == "fresh":
        # one untimed process first, so that a cold numba cache (a new install,
        # an edit of lfqt) is compiled there: fresh times a first call, not a
        # compilation, which bench_dc's compile time reports apart
        drivers.measure_isolated(peer, pts, repeats=1, timeout=timeout, memory_bytes=limit,
                                 regime="fresh")
    runs = []
    for _ in range(repeats // per_process):
        m = drivers.measure_isolated(peer, pts, repeats=per_process, count=cell.count,
                                     timeout=timeout, memory_bytes=limit, regime=cell.regime,
                                     check=check and not runs)
        if not m.ok:
            return {"status": m.reason, "detail": m.detail[:500]}
        runs.append(m)
    return {"status": "ok", "seconds": [s for m in runs for s in m.seconds],
            "cycles": [c for m in runs for c in m.cycles],
            "peak_bytes": max(m.extra_peak_bytes for m in runs), "version": runs[0].version,
            "counts": _merged_counts([m.counts for m in runs]),
            **({"check": runs[0].check} if check else {})}


def _merged_counts(counts):
    """The counts of a cell measured in several processes (the fresh
    regime): a per-run list (drivers.surface's times) is concatenated in
    run order; any other count is the first process's (counts do not vary
    between runs of the same input)."""
    out = dict(counts[0])
    for key, value in out.items():
        if isinstance(value, list):
            out[key] = [x for c in counts for x in c.get(key, [])]
    return out


def peer_builds(names):
    """{peer: its version and, for a compiled peer, compiler, flags and library}."""
    out = {}
    for name in sorted(names):
        peer = drivers.make(name)
        out[name] = {"version": peer.version(), **peer.build_info()}
    return out


def _done(log, code):
    """({cell key: record}, stale count) of a log: the cells measured on
    ``code`` (machine.code_version); a line cut by a crash, and a cell
    measured on other code (a later commit, uncommitted changes), are
    measured again.  Without this a sweep resumed after an update would mix
    old times under new metadata."""
    done = results.read_log(log, lambda rec: Cell.from_record(rec["cell"]).key)
    fresh = {k: rec for k, rec in done.items() if rec.get("code") == code}
    return fresh, len(done) - len(fresh)


def _progress(experiment, total):
    try:
        from tqdm import tqdm
    except ImportError:
        return None
    return tqdm(total=total, desc=experiment, unit="cell", file=sys.stderr)


def run(experiment, cells, *, repeats=3, rounds=1, out="results", force=False, timeout=1800.0,
        progress=True, command=None, extra_metadata=None, known_failure=None, check=False):
    """Measure every cell not already done; return the results directory.

    With ``rounds`` > 1 the whole grid is measured that many times, round
    after round, each cell in a fresh child with ``repeats`` runs.  On a
    shared machine whose speed drifts over minutes, this spreads every peer's
    runs over the same stretch of time, so the pooled medians of peers are
    compared under the same conditions rather than under whatever held while
    each peer's single cell ran.  ``known_failure(cell)`` may give a reason
    the cell is known to fail; it is then recorded as skipped, not run.
    ``check``: judge every mesh exactly (drivers.exactness), in the child;
    or a function of the cell saying whether to judge its mesh.
    """
    cells = [replace(c, round=r) for r in range(max(rounds, 1)) for c in cells
             if r == 0 or not c.count]  # counts are deterministic: one round
    out_dir = Path(out) / experiment
    out_dir.mkdir(parents=True, exist_ok=True)
    log = out_dir / "cells.jsonl"
    if force and log.exists():
        log.unlink()
    machine = machine_info()
    code = machine["code"]
    done, stale = _done(log, code)
    if stale and progress:
        print(f"[{experiment}] {stale} finished cells were measured on other code than "
              f"{code or 'this checkout'}: measuring them again", file=sys.stderr)
    todo = [c for c in cells if c.key not in done]
    meta = dict(experiment=experiment, command=command or " ".join(sys.argv),
                date=time.strftime("%Y-%m-%d %H:%M:%S %z"), repeats=repeats, rounds=rounds,
                cells=len(cells), resumed_cells=len(cells) - len(todo), stale_cells=stale,
                **(extra_metadata or {}),
                peers=peer_builds({c.peer for c in cells}),
                distributions={d: generators.definition(d)
                               for d in sorted({c.distribution for c in cells})},
                **machine)
    results.atomic_write(out_dir / "metadata.json", json.dumps(meta, indent=2, default=str))
    bar = _progress(experiment, len(todo)) if progress and todo else None
    with open(log, "a+") as f:
        for cell in todo:
            if bar:
                bar.set_postfix_str(cell.label())
            reason = known_failure(cell) if known_failure else None
            outcome = ({"status": "skipped", "detail": reason} if reason else
                       measure_cell(cell, 1 if cell.count else repeats, timeout,
                                    check=check(cell) if callable(check) else check))
            rec = {"key": cell.key, "cell": cell.fields(), "outcome": outcome, "code": code}
            results.append_log(f, rec)
            done[cell.key] = rec
            if bar:
                bar.update(1)
            elif progress:
                print(f"[{experiment}] {cell.label()}: {outcome['status']}", file=sys.stderr)
    if bar:
        bar.close()
    rows = [row for c in cells for row in results.rows_for(c, experiment, done[c.key]["outcome"])]
    results.write(out_dir, rows)
    return out_dir
