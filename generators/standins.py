"""Stand-ins for paper 2's practical models (Tables 16 and 17).

The originals cannot be redistributed (the Happy Buddha scan) or were never
published (the meshes of the constrained cube and the gear box), so these
are synthetic sets with the same sizes and the same kind of non-uniformity.
They are stand-ins: results on them say nothing about the originals.
"""
import numpy as np


def statue(rng, n):
    """Scanned-statue-like surface sample: a closed surface of revolution
    around the z axis, radius rho(z, a) = (0.35 + 0.15 sin(3 pi z) +
    0.05 cos(7 pi z)) (1 + 0.08 sin(5 a) sin(4 pi z)) for z in [0, 1], sampled
    uniformly in (z, a) and disturbed by N(0, 1e-4^2) per coordinate (scanner
    noise).  Dense where the surface narrows, like a scan of a figure."""
    z = rng.random(n)
    a = rng.random(n) * 2 * np.pi
    rho = (0.35 + 0.15 * np.sin(3 * np.pi * z) + 0.05 * np.cos(7 * np.pi * z)) \
        * (1 + 0.08 * np.sin(5 * a) * np.sin(4 * np.pi * z))
    pts = np.column_stack((rho * np.cos(a), rho * np.sin(a), z))
    return pts + rng.normal(0.0, 1e-4, (n, 3))


def constrained_cube(rng, n):
    """Mesh nodes of a unit cube graded toward three edges that meet at the
    origin (along x, y and z): a third of the points (i mod 3 = 0) ~
    U[0, 1)^3; each other point picks an edge k ~ U{0, 1, 2}, keeps its
    coordinate along the edge ~ U[0, 1) and sets the two others to 0.4 u^3,
    u ~ U[0, 1), so the density grows toward the edge."""
    pts = rng.random((n, 3))
    graded = np.flatnonzero(np.arange(n) % 3 != 0)
    edge = rng.integers(0, 3, graded.size)
    for j in range(3):
        rows = graded[edge != j]
        pts[rows, j] = 0.4 * rng.random(rows.size) ** 3
    return pts


def refined_cube(rng, n):
    """The constrained cube refined by nodes on element edges: 79.75% of the
    points are a constrained_cube set; each remaining point is the midpoint
    of two consecutive points of that set in Morton-like order (sorted by a
    coarse 3D cell index), i.e. a node on a short mesh edge.  Midpoints make
    near-coplanar and near-cospherical configurations, as refinement does."""
    base_n = int(round(n * 4_386_533 / 5_500_000))
    base = constrained_cube(rng, base_n)
    cells = np.floor(base * 64).astype(np.int64)
    order = np.lexsort((cells[:, 0], cells[:, 1], cells[:, 2]))
    pairs = rng.choice(max(base_n - 1, 1), size=n - base_n, replace=base_n - 1 < n - base_n)
    mids = 0.5 * (base[order[pairs]] + base[order[np.minimum(pairs + 1, base_n - 1)]])
    return np.vstack((base, mids))[:n]


def gearbox(rng, n):
    """Gear-box-like mesh nodes: a box [0, 2] x [0, 1] x [0, 1] with a
    cylindrical bore of radius 0.25 along x removed; 40% of the points
    uniform in it, 40% refined around the cross sections x = 0.6 and
    x = 1.4 (offset N(0, 0.01^2)), 20% refined around the segment from
    (0.2, 0.1, 0.1) to (1.8, 0.1, 0.1) (offset N(0, 0.01^2) per axis)."""
    out = np.empty((0, 3))
    while len(out) < n:
        m = 2 * (n - len(out)) + 16
        u = rng.random((m, 3)) * [2.0, 1.0, 1.0]
        kind = rng.random(m)
        sections = (kind >= 0.4) & (kind < 0.8)
        u[sections, 0] = np.where(rng.random(np.count_nonzero(sections)) < 0.5, 0.6, 1.4) \
            + rng.normal(0.0, 0.01, np.count_nonzero(sections))
        seg = kind >= 0.8
        u[seg] = np.column_stack((0.2 + 1.6 * rng.random(np.count_nonzero(seg)),
                                  np.full(np.count_nonzero(seg), 0.1),
                                  np.full(np.count_nonzero(seg), 0.1))) \
            + rng.normal(0.0, 0.01, (np.count_nonzero(seg), 3))
        bore = (u[:, 1] - 0.5) ** 2 + (u[:, 2] - 0.5) ** 2 < 0.25 ** 2
        out = np.vstack((out, u[~bore]))
    return out[:n]
