"""python -m generators.gallery: draw every distribution into one figure
(paper 2's Fig. 6 and our 2D counterpart) under results/figures/."""
import argparse
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from . import REGISTRY, generate  # noqa: E402


def draw(out_dir, n=4000, seed=0):
    # the exactness sets (generators.hard) are degenerate on purpose and look
    # like the others at this scale; the sets of the papers and the LiDAR model
    dists = [d for d in REGISTRY.values() if "hard" not in d.tags or "paper1" in d.tags]
    cols = 6
    rows = -(-len(dists) // cols)
    fig = plt.figure(figsize=(3.2 * cols, 3.2 * rows))
    for k, d in enumerate(dists):
        pts = generate(d.name, n, seed=seed)
        if d.dim == 2:
            ax = fig.add_subplot(rows, cols, k + 1)
            ax.scatter(pts[:, 0], pts[:, 1], s=0.8, c="tab:blue", linewidths=0)
            ax.set_aspect("equal")
        else:
            ax = fig.add_subplot(rows, cols, k + 1, projection="3d")
            ax.scatter(pts[:, 0], pts[:, 1], pts[:, 2], s=1.2, c=pts[:, 2], cmap="viridis",
                       linewidths=0, depthshade=False)
            ax.view_init(elev=22, azim=35)
            span = np.ptp(pts, axis=0)
            ax.set_box_aspect(np.maximum(span / span.max(), 0.15))
        ax.set_title(f"{d.name} ({d.dim}D)", fontsize=10)
        ax.tick_params(labelsize=6)
    fig.suptitle(f"lfqt point sets, {n} points each (seed {seed})", fontsize=13)
    fig.tight_layout()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    paths = [out_dir / "distributions.png", out_dir / "distributions.svg"]
    for p in paths:
        fig.savefig(p, dpi=110)
    plt.close(fig)
    return paths


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m generators.gallery", description=__doc__)
    ap.add_argument("--n", type=int, default=4000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default="results/figures")
    args = ap.parse_args(argv)
    for p in draw(args.out, args.n, args.seed):
        print(p)


if __name__ == "__main__":
    main()
