"""The hard 3D sets on which the 3D peers' exactness is measured
(experiments.dt3): each is a case where floating-point predicates decide
wrongly, or where a code must handle degeneracy (a lattice, exactly
cospherical points, repeated points, magnitudes at the ends of float64).
Tagged "hard" in generators.REGISTRY, beside the 2D ones of
generators.hard."""
import numpy as np

# 105 = 3 * 5 * 7: 1,350 integer points on the sphere of that radius (and on
# each of its multiples' spheres at least as many)
SPHERE_RADIUS = 105


def _lattice_sphere(r):
    """The integer points on the sphere x^2 + y^2 + z^2 = r^2, exactly."""
    x = np.arange(-r, r + 1)
    X, Y = (a.ravel() for a in np.meshgrid(x, x))
    z2 = r * r - X * X - Y * Y
    ok = z2 >= 0
    X, Y, z2 = X[ok], Y[ok], z2[ok]
    z = np.round(np.sqrt(z2)).astype(np.int64)
    on = z * z == z2
    X, Y, z = X[on], Y[on], z[on]
    pts = np.concatenate((np.column_stack((X, Y, z)), np.column_stack((X, Y, -z))))
    return np.unique(pts, axis=0)


def grid(rng, n):
    """The integer lattice {0, ..., k-1}^3 with k = ceil(n^(1/3)), in random
    order, its first n points: at n = 8,000 the whole 20^3 grid, on which
    every cube's 8 corners are cospherical (issue 52: gmsh's default path
    returns 9,085 flat tetrahedra there)."""
    k = max(2, int(np.ceil(round(n ** (1 / 3), 9))))
    g = np.stack(np.meshgrid(*[np.arange(k)] * 3, indexing="ij"), -1).reshape(-1, 3)
    return g[rng.permutation(len(g))[:n]].astype(np.float64)


def grid_sorted(rng, n):
    """The lattice of ``grid`` in lexicographic order (x slowest, z
    fastest), as a regular grid's array usually comes, its first n points,
    shifted by a random integer vector in [0, 100)^3 (the seed's): gmsh's
    default path returns flat tetrahedra on it, where it finds no result on
    the same points in random order."""
    k = max(2, int(np.ceil(round(n ** (1 / 3), 9))))
    g = np.stack(np.meshgrid(*[np.arange(k)] * 3, indexing="ij"), -1).reshape(-1, 3)
    return (g[:n] + rng.integers(0, 100, 3)).astype(np.float64)


def cospherical(rng, n):
    """The centre (0, 0, 0), then integer lattice points on concentric spheres
    of radius 105 k, k = 1, 2, ... (exactly cospherical, at least 1,350
    points on each), a random n - 1 of them: every in-sphere test among five
    points of one sphere is exactly 0, and the centre's cavity holds all the
    tetrahedra inside the first sphere."""
    pts, k, have = [], 1, 0
    while have < n - 1:
        s = _lattice_sphere(SPHERE_RADIUS * k)
        pts.append(s)
        have += len(s)
        k += 1
    pts = np.concatenate(pts) if pts else np.empty((0, 3))
    shell = pts[rng.permutation(len(pts))[:max(n - 1, 0)]]
    return np.concatenate((np.zeros((1, 3)), shell))[:n].astype(np.float64)


def sphere_rounded(rng, n):
    """Points on the sphere of radius 0.45 about the origin, rounded to
    doubles: cospherical up to rounding, so that nearly every in-sphere
    test fails a floating-point filter."""
    v = rng.normal(size=(n, 3))
    return 0.45 * v / np.linalg.norm(v, axis=1)[:, None]


def duplicates(rng, n):
    """Uniform points in the unit cube each given twice, in random order:
    n / 2 distinct points."""
    half = rng.random((-(-n // 2), 3))
    return np.concatenate((half, half))[rng.permutation(2 * len(half))[:n]]


def subnormal(rng, n):
    """Uniform points in the unit cube scaled by 1e-310: subnormal
    coordinates (below 2.2e-308), with fewer significant bits."""
    return rng.random((n, 3)) * 1e-310


def huge(rng, n):
    """Uniform points in the unit cube scaled by 1e300: the predicates'
    products overflow."""
    return rng.random((n, 3)) * 1e300
