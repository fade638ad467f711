"""Paper 1, Figure 1: the geometric structure of the floating-point
quad-tree, drawn from lfqt's own subdivision (lfqt.quadtree) of small
float32 sets.

Left: Uniform in the unit square.  Right: Spiral, centred at the origin, so
the first two levels are the sign bits of x and y (the four quadrants of
Fig. 1c).  Every split is drawn across its cell: black for a sign bit,
coloured by level for an exponent bit (each exponent split halves the
distance to an axis), thin blue for a mantissa bit (the regular grids inside
one exponent's area).  The grey line is the Morton order.  The published
figure is a drawing without numbers; nothing is measured here, the split
table is stored as results/<scale>/fig1/quadtree.csv."""
import sys

import numpy as np

import generators
import lfqt

from ..core.experiment import Experiment, figure_paths

SETS = ["uniform", "spiral"]
SIZES = {"smoke": 120, "default": 400, "paper": 1000}
SEED = 0


def grid(scale, threads):
    return []  # a drawing of the structure: no cell is timed


def tables(args, out_dir):
    """Write the split table of each set (one row per node)."""
    import pandas as pd
    frames = []
    for name in SETS:
        pts = generators.make(name, SIZES[args.scale], seed=SEED, dtype="float32")
        tree = lfqt.quadtree(pts)
        frame = pd.DataFrame(tree.nodes)
        frame.insert(0, "distribution", name)
        frame.insert(1, "n", len(pts))
        frames.append(frame)
    out_dir.mkdir(parents=True, exist_ok=True)
    pd.concat(frames).to_csv(out_dir / "quadtree.csv", index=False)


def _draw(ax, nodes, pts, order):
    import matplotlib.pyplot as plt
    lo, hi = pts.min(0), pts.max(0)
    pad = 0.04 * (hi - lo)
    win = np.array([lo - pad, hi + pad])
    exp_levels = sorted(nodes.loc[nodes["field"] == "exponent", "level"].unique())
    cmap = plt.get_cmap("plasma", max(len(exp_levels), 2) + 1)
    style = {"sign": dict(color="black", lw=1.6, zorder=4),
             "mantissa": dict(color="#6baed6", lw=0.6, zorder=2)}
    for r in nodes.itertuples():
        kw = style.get(r.field) or dict(color=cmap(exp_levels.index(r.level)), lw=1.1, zorder=3)
        if r.axis == 0:
            ax.plot([r.cut, r.cut], np.clip([r.y0, r.y1], *win[:, 1]), **kw)
        else:
            ax.plot(np.clip([r.x0, r.x1], *win[:, 0]), [r.cut, r.cut], **kw)
    path = pts[order]
    ax.plot(path[:, 0], path[:, 1], color="#bbbbbb", lw=0.5, zorder=1)
    ax.scatter(pts[:, 0], pts[:, 1], s=4, color="#222222", zorder=5)
    ax.set_xlim(*win[:, 0])
    ax.set_ylim(*win[:, 1])
    ax.set_aspect("equal")
    counts = nodes["field"].value_counts()
    return ", ".join(f"{counts.get(f, 0)} {f}" for f in ("sign", "exponent", "mantissa"))


def plot(df, out):
    import matplotlib.pyplot as plt
    import pandas as pd
    from matplotlib.lines import Line2D
    table = pd.read_csv(out / "fig1" / "quadtree.csv")
    fig, axes = plt.subplots(1, len(SETS), figsize=(6.2 * len(SETS), 6.4))
    print(f"\n{'distribution':12} {'n':>6} {'splits':>7} {'sign':>5} {'exponent':>9} "
          f"{'mantissa':>9} {'depth':>6}")
    for ax, name in zip(axes, SETS):
        nodes = table[table["distribution"] == name]
        n = int(nodes["n"].iloc[0])
        pts = generators.make(name, n, seed=SEED, dtype="float32").astype(np.float64)
        order = lfqt.quadtree(pts.astype(np.float32)).order
        summary = _draw(ax, nodes, pts, order)
        ax.set_title(f"{name}, {n} float32 points: {summary} splits", fontsize=9)
        c = nodes["field"].value_counts()
        print(f"{name:12} {n:>6} {len(nodes):>7} {c.get('sign', 0):>5} {c.get('exponent', 0):>9} "
              f"{c.get('mantissa', 0):>9} {nodes['depth'].max():>6}")
    legend = [Line2D([], [], color="black", lw=1.6, label="sign bit"),
              Line2D([], [], color=plt.get_cmap("plasma")(0.4), lw=1.1,
                     label="exponent bit (colour: level)"),
              Line2D([], [], color="#6baed6", lw=0.6, label="mantissa bit"),
              Line2D([], [], color="#bbbbbb", lw=0.8, label="Morton order")]
    fig.legend(handles=legend, loc="lower center", ncol=4, frameon=False, fontsize=9)
    fig.suptitle("Paper 1, Fig. 1: the floating-point quad-tree as lfqt subdivides it "
                 "(splits drawn across their cells)", fontsize=10)
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    return figure_paths(fig, out, "fig1")


EXPERIMENT = Experiment("fig1", "the LFQT of small float32 sets, splits by level and bit field",
                        grid, plot, reproduces=(("Paper 1", "Fig. 1"),), setup=tables,
                        main_job=True, minutes={"default": 0.1})
main = EXPERIMENT.main

if __name__ == "__main__":
    sys.exit(main())
