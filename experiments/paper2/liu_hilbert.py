"""Paper 2's "Hilbert" and "BRIO": which order did it insert in?  Counts
per point (orientation tests while locating, conflicting cells) on the
seven models, for our Hilbert and BRIO orders (lfqt.orders) in lfqt and in
CGAL, and for CGAL's own hilbert_sort and spatial_sort (BRIO rounds of
hilbert_sort) with the previous vertex as hint (cgal-dt3-hilbert-sort,
cgal-dt3-spatial-sort), against the paper's Hilbert and BRIO rows.  The
order whose counts lie nearest the paper's (mean relative distance over the
models, flagged rows left out) is the likeliest reading."""
import sys

import numpy as np

from . import liu
from ..core import results
from ..core.claims import MISSING, PARTLY, Claim
from ..core.experiment import Experiment, figure_paths
from .liu_counts import per_point
from ..core.runner import Cell

CANDIDATES = {"lfqt-insert-hilbert": "our Hilbert, lfqt", "cgal-dt3-hilbert": "our Hilbert, CGAL",
              "cgal-dt3-hilbert-sort": "CGAL hilbert_sort",
              "lfqt-insert-brio": "our BRIO, lfqt", "cgal-dt3-brio": "our BRIO, CGAL",
              "cgal-dt3-spatial-sort": "CGAL spatial_sort (BRIO)"}
METRICS = ("orientation_per_point", "conflicts_per_point")
# two of the seven models at the smoke scale (part of the smoke main job, which CI runs)
SMOKE_MODELS = ("cube", "cylinder")


def grid(scale, threads):
    models = SMOKE_MODELS if scale == "smoke" else liu.MODELS
    return [Cell(peer, model, liu.sizes(model, scale)[0], count=True)
            for model in models for peer in CANDIDATES]


def distances(df):
    """{(candidate, paper order, metric): mean |ours - paper| / paper over
    the models}, the paper's value taken at the nearest size."""
    s = results.summarize(df)
    out = {}
    for peer in CANDIDATES:
        for order in ("hilbert", "brio"):
            for k, metric in enumerate(METRICS):
                d = []
                for model, (_, table) in liu.MODELS.items():
                    for n in df.loc[df["distribution"] == model, "n"].unique():
                        ours = per_point(results.cell(s, peer, model, n, True).get("counts", {}),
                                         n)[k]
                        v = liu.paper_value(table, metric, model, order, n)
                        if v and ours == ours:
                            d.append(abs(ours - v) / v)
                out[(peer, order, metric)] = float(np.mean(d)) if d else float("nan")
    return out


def best_matches(df):
    """{paper order: (candidate, its mean distance over both metrics)}."""
    d = distances(df)
    out = {}
    for order in ("hilbert", "brio"):
        scores = {p: np.mean([d[(p, order, m)] for m in METRICS]) for p in CANDIDATES}
        scores = {p: v for p, v in scores.items() if v == v}
        if scores:
            best = min(scores, key=scores.get)
            out[order] = (best, scores[best])
    return out


def plot(df, out):
    import matplotlib.pyplot as plt
    s = results.summarize(df)
    models = [m for m in liu.MODELS if m in set(df["distribution"])]
    fig, axes = plt.subplots(1, 2, figsize=(13, 4.4))
    width = 0.8 / (len(CANDIDATES) + 2)
    colors = ["#66a182", "#9cc9a8", "#2e6b45", "#d1495b", "#eb9aa5", "#8a1c2b"]
    names = [CANDIDATES[p][:19] for p in CANDIDATES] + ["paper Hilbert", "paper BRIO"]
    print(f"\n{'model':10} {'n':>8} " + " ".join(f"{name:>19}" for name in names)
          + "   (orientation / conflicts per point; paper: nearest size, flagged rows blank)")
    for ax, (k, metric) in zip(axes, enumerate(METRICS)):
        for j, peer in enumerate(CANDIDATES):
            vals = []
            for m in models:
                n = int(df.loc[df["distribution"] == m, "n"].max())
                vals.append(per_point(results.cell(s, peer, m, n, True).get("counts", {}), n)[k])
            ax.bar(np.arange(len(models)) + j * width, vals, width, color=colors[j],
                   label=CANDIDATES[peer])
        for j, order in enumerate(("hilbert", "brio")):
            pv = [liu.paper_value(liu.MODELS[m][1], metric, m, order,
                                  int(df.loc[df["distribution"] == m, "n"].max())) or np.nan
                  for m in models]
            ax.bar(np.arange(len(models)) + (len(CANDIDATES) + j) * width, pv, width,
                   color="#555555" if order == "hilbert" else "#aaaaaa",
                   label=f"paper {order}", hatch="//" if order == "brio" else None)
        ax.set_xticks(np.arange(len(models)) + 0.4, models, fontsize=8)
        ax.set_ylabel(metric.replace("_", " "))
        ax.grid(axis="y", alpha=0.3)
    for m in models:
        n = int(df.loc[df["distribution"] == m, "n"].max())
        cells = [per_point(results.cell(s, p, m, n, True).get("counts", {}), n) for p in CANDIDATES]
        cells += [tuple(liu.paper_value(liu.MODELS[m][1], metric, m, order, n) or np.nan
                        for metric in METRICS) for order in ("hilbert", "brio")]
        print(f"{m:10} {n:>8,} " + " ".join(f"{o:8.2f} / {c:8.2f}" for o, c in cells))
    d = distances(df)
    print("\nmean relative distance to the paper's rows (orientation, conflicts):")
    for order in ("hilbert", "brio"):
        for p in CANDIDATES:
            print(f"  paper {order:8} vs {CANDIDATES[p]:26} "
                  + ", ".join(f"{d[(p, order, m)]:.1%}" for m in METRICS))
    for order, (p, v) in best_matches(df).items():
        print(f"nearest to the paper's {order}: {CANDIDATES[p]} ({v:.1%} mean distance)")
    axes[0].legend(fontsize=7, ncol=2)
    fig.suptitle("Paper 2: which order was its Hilbert and its BRIO? Counts per point against "
                 "the paper's (flagged rows left out)", fontsize=10)
    fig.tight_layout()
    return figure_paths(fig, out, "liu_hilbert")


def _which_order(claim, res):
    best = best_matches(res.frame("liu_hilbert"))
    text = "; ".join(f"nearest to the paper's {o}: {CANDIDATES[p]} ({v:.0%} mean distance)"
                     for o, (p, v) in best.items())
    return claim.row(text, PARTLY if best else MISSING,
                     "counts per point against the paper's rows at the nearest size; a match is "
                     "a reading, not a proof")


CLAIMS = (
    # a question rather than a claim: at best a reading (partly), never proven
    Claim("which order was the paper's Hilbert", "'Hilbert' and 'BRIO' orders in CGAL 4.0 "
          "(Tables 8-14)", _which_order),
)


EXPERIMENT = Experiment("liu_hilbert", "the Hilbert question: our Hilbert and BRIO orders and "
                        "CGAL's hilbert_sort and spatial_sort against paper 2's counts",
                        grid, plot, repeats=1, main_job=True, minutes={"default": 0.4},
                        claims=CLAIMS)
main = EXPERIMENT.main

if __name__ == "__main__":
    sys.exit(main())
