"""2D sets of paper 1 (Fuetterling et al. 2014, section 4).

Circle and Spiral are centred at the origin; every other set lies in the
first quadrant, as the paper states.  Each function draws float64 points;
rounding to the requested dtype happens in ``generators.generate``.
"""
import numpy as np


def uniform(rng, n):
    """Uniform in the unit square: x, y ~ U[0, 1)."""
    return rng.random((n, 2))


def grid(rng, n):
    """Square integer grid: the first n nodes, row by row, of the k x k grid
    {0..k-1}^2 with k = ceil(sqrt(n)), in random order.  Integer coordinates
    only; every 4 neighbouring nodes are cocircular."""
    k = int(np.ceil(np.sqrt(n))) if n else 0
    idx = rng.permutation(n)
    return np.stack((idx % k, idx // k), axis=1).astype(np.float64) if n else np.empty((0, 2))


def cluster(rng, n):
    """Bentley's clusnorm: 10 centres c_j ~ U[0, 1)^2; point i is c_(i mod 10)
    + N(0, 0.05^2) per coordinate, shifted by +1 in x and y so that the set
    stays in the first quadrant (20 standard deviations from the axes)."""
    centres = rng.random((10, 2))
    which = np.arange(n) % 10
    return 1.0 + centres[which] + rng.normal(0.0, 0.05, (n, 2))


def circle(rng, n):
    """gDel2D's circle: angle t ~ U[0, 2pi), point 0.45 (cos t, sin t), rounded
    to the dtype, so the set is cocircular up to rounding."""
    t = rng.random(n) * 2 * np.pi
    return 0.45 * np.stack((np.cos(t), np.sin(t)), axis=1)


def spiral(rng, n):
    """Archimedean spiral of 5 turns, r = t / (10 pi) for t in [0, 10 pi], with
    t = 10 pi sqrt(u), u ~ U[0, 1) (about uniform along the arc), plus
    N(0, 0.002^2) noise per coordinate."""
    t = 10 * np.pi * np.sqrt(rng.random(n))
    r = t / (10 * np.pi)
    pts = np.stack((r * np.cos(t), r * np.sin(t)), axis=1)
    return pts + rng.normal(0.0, 0.002, (n, 2))
