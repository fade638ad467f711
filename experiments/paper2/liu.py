"""What the experiments of paper 2 (Liu, Yan and Lo 2013) share: its seven
models and their tables, the orders it compares, the sizes it printed, and
its published values read from results/published/liu2013.csv (each with its
flag: the Table 13 row that repeats another, the two misprinted sizes)."""
from functools import lru_cache

from ..core import results

# model: (its time table, its count table); the paper's order of models
MODELS = {"cube": (1, 8), "plane": (2, 9), "paraboloid": (3, 10), "spiral3d": (4, 11),
          "disc": (5, 12), "cylinder": (6, 13), "axes": (7, 14)}
# (the paper's label, lfqt's peer, CGAL's peer): the orders of Tables 1-14,
# built by lfqt.orders inside the timed run in both systems
ORDERS = [("kdtree", "lfqt-insert-kdtree", "cgal-dt3-kdtree"),
          ("brio", "lfqt-insert-brio", "cgal-dt3-brio"),
          ("hilbert", "lfqt-insert-hilbert", "cgal-dt3-hilbert")]
COLORS = {"kdtree": "#1b6ca8", "brio": "#d1495b", "hilbert": "#66a182", "random": "#8d8d8d"}
SMOKE_N = 5_000


@lru_cache(maxsize=None)
def published():
    """Paper 2's rows as dicts, with ``n`` the size the row lines up with
    (the printed size where it is misprinted is kept as ``n_printed``)."""
    rows = []
    for r in results.published("liu2013").to_dict("records"):
        r = dict(r, n_printed=r["n"])
        r["n"] = int(float(r["n_aligned"] or r["n"])) if (r["n_aligned"] or r["n"]) else None
        r["value"] = float(r["value"]) if r["value"] else None
        rows.append(r)
    return rows


def table_sizes(table):
    """The sizes a table printed, aligned with the others."""
    return sorted({r["n"] for r in published() if r["table"] == f"Table {table}" and r["n"]})


def sizes(model, scale):
    """Per model: the paper's six sizes at ``paper``; a tenth of its first
    two at ``default`` (two sizes, so that trends in the size show, within
    the main job's ten minutes: the non-uniform models cost up to 4 us per
    point); one small size at ``smoke``."""
    paper = table_sizes(MODELS[model][0])
    return {"smoke": [SMOKE_N], "default": [n // 10 for n in paper[:2]], "paper": paper}[scale]


def values(table, metric):
    """{(model, order, n): (value or None, note, flag)} of one table."""
    return {(r["model"], r["order"], r["n"]): (r["value"], r["note"], r["flag"])
            for r in published() if r["table"] == f"Table {table}" and r["metric"] == metric}


def paper_value(table, metric, model, order, n):
    """The paper's value of (model, order) in a table at the printed size
    nearest n, or None where it is missing or flagged."""
    rows = {m: (v, flag) for (mm, o, m), (v, _, flag) in values(table, metric).items()
            if (mm, o) == (model, order)}
    v, flag = rows.get(nearest(sorted(rows), n), (None, "missing"))
    return None if flag else v


def nearest(ns, n):
    """The published size nearest n, or None."""
    return min(ns, key=lambda m: abs(m - n)) if ns else None
