"""The hard 2D sets on which exactness is measured (experiments.field):
each is a case where floating-point predicates decide wrongly, or where a
code must handle degeneracy (repeated, collinear or cocircular points,
signed zeros, magnitudes at the ends of float64).  Tagged "hard" in
generators.REGISTRY; the grid and the circle of paper 1 and the LiDAR
model's xy are hard sets too."""
import numpy as np

LATTICE_RADIUS = 5 * 13 * 17  # 1105 = a product of primes 1 mod 4: 32 lattice points per circle


def _lattice_circle(r):
    """The integer points on the circle x^2 + y^2 = r^2, exactly."""
    x = np.arange(-r, r + 1)
    y2 = r * r - x * x
    y = np.round(np.sqrt(y2)).astype(np.int64)
    on = y * y == y2
    x, y = x[on], y[on]
    return np.unique(np.concatenate((np.column_stack((x, y)), np.column_stack((x, -y)))), axis=0)


def cocircular(rng, n):
    """Integer lattice points on concentric circles of radius 1105 k, k = 1,
    2, ... (exactly cocircular, 32 or more points on each circle), a random n
    of them: every in-circle test among points of one circle is exactly 0."""
    pts, k, have = [], 1, 0
    while have < n:
        c = _lattice_circle(LATTICE_RADIUS * k)
        pts.append(c)
        have += len(c)
        k += 1
    pts = np.concatenate(pts) if pts else np.empty((0, 2))
    return pts[rng.permutation(len(pts))[:n]].astype(np.float64)


def collinear(rng, n):
    """All points on one line, exactly: (3 i, i) for distinct integers i in
    random order.  There is no triangle; the answer is an empty mesh (or a
    refusal that says the points are collinear)."""
    i = rng.permutation(n).astype(np.float64)
    return np.column_stack((3 * i, i))


def collinear_fan(rng, n):
    """n - 1 points on the line y = x / 3 (exactly), plus one apex off it:
    the triangulation is a fan of thin triangles."""
    pts = collinear(rng, max(n - 1, 0))
    return np.concatenate((pts, [[0.0, 10.0 * max(n, 1)]]))[:n]


def duplicates(rng, n):
    """Uniform points each given twice, in random order: n / 2 distinct points."""
    half = rng.random((-(-n // 2), 2))
    return np.concatenate((half, half))[rng.permutation(2 * len(half))[:n]]


def signed_zeros(rng, n):
    """A small integer grid about the origin in which every zero coordinate
    has a random sign, and each point on an axis is also given with the
    other sign of its zero: -0.0 and 0.0 are one coordinate, so those rows
    are duplicates that differ in their bits."""
    k = max(2, int(np.ceil(np.sqrt(n))))
    g = np.stack(np.meshgrid(np.arange(k) - k // 2, np.arange(k) - k // 2), -1).reshape(-1, 2)
    g = g.astype(np.float64)
    flip = (g == 0) & (rng.random(g.shape) < 0.5)
    g[flip] = -0.0
    axis = g[np.any(g == 0, axis=1)].copy()
    axis[axis == 0] = np.where(np.signbit(axis[axis == 0]), 0.0, -0.0)
    pts = np.concatenate((g, axis))
    return pts[rng.permutation(len(pts))[:n]]


def tiny(rng, n):
    """Uniform points scaled by 1e-300: the predicates' products underflow."""
    return rng.random((n, 2)) * 1e-300


def subnormal(rng, n):
    """Uniform points scaled by 1e-310: subnormal coordinates (below
    2.2e-308), with fewer significant bits."""
    return rng.random((n, 2)) * 1e-310


def huge(rng, n):
    """Uniform points scaled by 1e300: the predicates' products overflow."""
    return rng.random((n, 2)) * 1e300


def gis(rng, n):
    """GIS coordinates: 5e5 and 4e6 (easting, northing) plus millimetres, on a
    100 m square: every coordinate is a multiple of 1e-3 m that float64 holds
    only approximately, and the millimetre grid makes cocircular quads."""
    mm = rng.integers(0, 100_000, (n, 2))
    return np.array([500_000.0, 4_000_000.0]) + mm * 1e-3
