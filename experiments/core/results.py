"""Results: tidy rows (one per measurement) written as CSV with a metadata
sidecar, loaded back as a typed pandas DataFrame, and the derived numbers
(summaries, ratios, rates) defined once, for the figures, the report and
the notebooks alike."""
import json
import os
from pathlib import Path

import numpy as np
import pandas as pd

NOMINAL_HZ = 3.0e9  # paper 1 normalises cycle counts to 3 GHz
PUBLISHED = Path(__file__).resolve().parents[2] / "results" / "published"
FIELDS = ["experiment", "peer", "distribution", "n", "dtype", "threads", "seed", "count",
          "round", "regime", "repeat", "status", "detail", "seconds", "cycles", "seconds_at_3ghz",
          "mpts_per_s", "peak_bytes", "bytes_per_point", "version", "counts", "check"]
INTS = ("n", "threads", "seed", "round", "repeat")
FLOATS = ("seconds", "cycles", "seconds_at_3ghz", "mpts_per_s", "peak_bytes", "bytes_per_point")
CELL = ["peer", "distribution", "n", "count"]  # what a summary groups by
# The variants of each 2D peer family; a headline ratio is against the
# fastest variant measured in the same run, and names it.
VARIANTS_2D = {"CGAL": ("cgal-dt2", "cgal-dt2-indexed"),
               "Triangle": ("triangle-native", "triangle")}


def atomic_write(path, text):
    """Write ``text`` to ``path`` through a synced temporary file."""
    path = Path(path)
    tmp = path.with_suffix(path.suffix + ".tmp")
    with open(tmp, "w") as f:
        f.write(text)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


def read_log(path, key):
    """{key(record): record} of a sweep's JSON-lines log (cells.jsonl); a
    line cut by a crash is left out, so its cell is measured again."""
    done = {}
    if Path(path).exists():
        for line in Path(path).read_text().splitlines():
            try:
                rec = json.loads(line)
                done[key(rec)] = rec
            except (json.JSONDecodeError, KeyError, TypeError):
                continue
    return done


def append_log(f, record):
    """Append one record to a log open with mode "a+" and sync it: a
    finished cell survives a crash of what follows.  After a line cut by a
    crash, the record starts a line of its own."""
    f.flush()
    size = os.fstat(f.fileno()).st_size
    if size and os.pread(f.fileno(), 1, size - 1) != b"\n":
        f.write("\n")
    f.write(json.dumps(record, default=float) + "\n")
    f.flush()
    os.fsync(f.fileno())


def rows_for(cell, experiment, outcome):
    """The tidy rows of one measured cell: one per timed repeat, or one row
    with the failure's status and reason."""
    base = dict(experiment=experiment, **cell.fields())
    if outcome.get("status") != "ok":
        return [dict(base, repeat=0, status=outcome["status"], detail=outcome.get("detail", ""))]
    rows = []
    for k, (sec, cyc) in enumerate(zip(outcome["seconds"], outcome["cycles"])):
        rows.append(dict(base, repeat=k, status="ok", detail="", seconds=sec, cycles=cyc,
                         seconds_at_3ghz=cyc / NOMINAL_HZ if cyc else None,
                         mpts_per_s=rate(cell.n, sec), peak_bytes=outcome["peak_bytes"],
                         bytes_per_point=outcome["peak_bytes"] / max(cell.n, 1),
                         version=outcome["version"], counts=json.dumps(outcome["counts"]),
                         check=json.dumps(outcome["check"]) if outcome.get("check") else ""))
    return rows


def write(out_dir, rows):
    """results.csv of ``rows``, atomically."""
    frame = pd.DataFrame(rows, columns=FIELDS)
    atomic_write(Path(out_dir) / "results.csv", frame.to_csv(index=False))


def load(out_dir):
    """The tidy results of an experiment as a DataFrame: typed columns, and
    ``counts`` parsed into dicts."""
    df = pd.read_csv(Path(out_dir) / "results.csv", keep_default_na=False,
                     na_values={c: [""] for c in FLOATS})
    if "round" not in df:  # results from before rounds existed
        df["round"] = 0
    if "regime" not in df:  # results from before regimes existed
        df["regime"] = "loop"
    for c in INTS:
        df[c] = pd.to_numeric(df[c], errors="coerce").fillna(0).astype(np.int64)
    for c in FLOATS:
        df[c] = pd.to_numeric(df[c], errors="coerce")
    df["count"] = df["count"].astype(str) == "True"
    df["counts"] = [json.loads(c) if c else {} for c in df["counts"].astype(str)]
    df["detail"] = df["detail"].astype(str)
    # the exact judgement of the mesh (drivers.exactness), where the sweep asked
    df["check"] = [json.loads(c) if c else {} for c in
                   (df["check"].astype(str) if "check" in df else [""] * len(df))]
    return df


def summarize(df, by=CELL):
    """One row per cell (grouped by ``by``), pooled over rounds and repeats:
    status and detail of its first row, median and min seconds of the ok
    repeats, its counts and bytes per point."""
    def one(g):
        ok = g.loc[g["status"] == "ok", "seconds"].dropna()
        return pd.Series({"status": g["status"].iloc[0], "detail": g["detail"].iloc[0],
                          "median": float(ok.median()) if len(ok) else None,
                          "min": float(ok.min()) if len(ok) else None,
                          "runs": int(len(ok)), "counts": g["counts"].iloc[0],
                          "bytes_per_point": g["bytes_per_point"].iloc[0]})
    if df.empty:
        return pd.DataFrame(columns=["status", "detail", "median", "min", "runs", "counts",
                                     "bytes_per_point"])
    return df.groupby(list(by), sort=False).apply(one, include_groups=False)


def cell(summary, *key):
    """The summary row of ``key`` (in the order of ``by``) as a dict; {} when
    the cell was not measured."""
    try:
        row = summary.loc[tuple(key)].to_dict()
    except (KeyError, pd.errors.IndexingError):  # not measured, or nothing at all (no levels)
        return {}
    return {k: None if isinstance(v, float) and v != v else v for k, v in row.items()}


def median(summary, *key):
    return cell(summary, *key).get("median")


def fastest(summary, peers, *key):
    """(peer, median) of the fastest of ``peers`` in the cell ``key`` (the
    summary's key without its peer), or (None, None) when none has a time:
    a headline ratio is always against a peer's fastest variant."""
    times = [(m, p) for p in peers if (m := median(summary, p, *key))]
    return (min(times)[1], min(times)[0]) if times else (None, None)


def ratio(a, b):
    """a / b, NaN when either is missing."""
    return a / b if a and b else float("nan")


def round_ratio(df, a, b, *key):
    """The ratio of peer ``a``'s time to peer ``b``'s in the cell ``key``
    (distribution, n, count), taken round by round: in each round both
    medians of that round's ok runs, then the median of the rounds'
    ratios.  Returns (that median, the rounds' ratios); (NaN, []) when no
    round timed both.

    The rounds are interleaved so that a drift of the machine's speed hits
    every peer alike; a pooled median (``summarize``) can still pair a slow
    round's runs of one peer with a fast round's of the other, which the
    ratio of same-round medians cannot.  With one round both agree."""
    sel = df[(df["status"] == "ok") & df["seconds"].notna()]
    for column, value in zip(CELL[1:], key):
        sel = sel[sel[column] == value]
    per = sel[sel["peer"].isin([a, b])].groupby(["round", "peer"])["seconds"].median().unstack()
    if a not in per or b not in per:
        return float("nan"), []
    ratios = (per[a] / per[b]).dropna().tolist()
    return (float(np.median(ratios)) if ratios else float("nan")), ratios


def fmt_ratio(x):
    return "-" if x != x else f"{x:.2f}x"


def fmt_count(n):
    """A point count as the papers write it: 100k, 1M, 2.5M."""
    return f"{n / 1e6:g}M" if n >= 1e6 else f"{n / 1e3:g}k"


def rate(n, seconds):
    """Million points per second."""
    return n / seconds / 1e6 if seconds else None


def published(name):
    """results/published/<name>.csv as a DataFrame (strings kept as given)."""
    return pd.read_csv(PUBLISHED / f"{name}.csv", dtype=str, keep_default_na=False)


def stored(root, name, scale="default"):
    """The results of experiment ``name`` under ``root`` as a DataFrame, or
    None after printing the command that makes them (for the notebooks)."""
    path = Path(root) / name / "results.csv"
    if not path.exists():
        flag = "" if scale == "default" else f" --scale {scale}"
        print(f"no {name} results under {root}: run `python -m experiments.{name}{flag}`")
        return None
    return load(path.parent)


def metadata(root, name):
    """The metadata sidecar of experiment ``name`` under ``root`` ({} if none)."""
    try:
        return json.loads((Path(root) / name / "metadata.json").read_text())
    except (OSError, ValueError):
        return {}

