"""3D sets of paper 2 (Liu et al. 2013, Fig. 6).

The paper says only that points are "disturbed a little away from their
geometry model".  Our disturbance is Gaussian with standard deviation
``NOISE`` = 1e-3 (the models have unit size) along the directions that leave
the model; the cube needs none.
"""
import numpy as np

NOISE = 1e-3


def cube(rng, n):
    """Uniform in the unit cube: x, y, z ~ U[0, 1)."""
    return rng.random((n, 3))


def plane(rng, n):
    """Around three planes: point i lies on the plane x_k = 0.5 with
    k = i mod 3 through the centre of the unit cube, the other two
    coordinates ~ U[0, 1), and x_k disturbed by N(0, NOISE^2)."""
    pts = rng.random((n, 3))
    k = np.arange(n) % 3
    pts[np.arange(n), k] = 0.5 + rng.normal(0.0, NOISE, n)
    return pts


def paraboloid(rng, n):
    """Around the paraboloid z = x^2 + y^2 over (x, y) ~ U[-1, 1)^2, with z
    disturbed by N(0, NOISE^2)."""
    xy = rng.random((n, 2)) * 2 - 1
    z = (xy ** 2).sum(axis=1) + rng.normal(0.0, NOISE, n)
    return np.column_stack((xy, z))


def spiral3d(rng, n):
    """Around a helix of radius 1 and 10 turns over height 1: t ~ U[0, 20 pi),
    (cos t, sin t, t / (20 pi)) plus N(0, (10 NOISE)^2) per coordinate (a thin
    tube around the curve)."""
    t = rng.random(n) * 20 * np.pi
    pts = np.column_stack((np.cos(t), np.sin(t), t / (20 * np.pi)))
    return pts + rng.normal(0.0, 10 * NOISE, (n, 3))


def disc(rng, n):
    """Around the unit disc in the plane z = 0: r = sqrt(u), u ~ U[0, 1),
    angle ~ U[0, 2pi) (uniform over the disc), z ~ N(0, NOISE^2)."""
    r = np.sqrt(rng.random(n))
    t = rng.random(n) * 2 * np.pi
    return np.column_stack((r * np.cos(t), r * np.sin(t), rng.normal(0.0, NOISE, n)))


def cylinder(rng, n):
    """On the unit cylinder x^2 + y^2 = 1, z ~ U[0, 1): angle ~ U[0, 2pi),
    radius 1 + N(0, NOISE^2)."""
    t = rng.random(n) * 2 * np.pi
    r = 1.0 + rng.normal(0.0, NOISE, n)
    return np.column_stack((r * np.cos(t), r * np.sin(t), rng.random(n)))


def axes(rng, n):
    """Along the three coordinate axes: point i lies on axis k = i mod 3 at
    t ~ U[-1, 1), its other two coordinates ~ N(0, NOISE^2)."""
    pts = rng.normal(0.0, NOISE, (n, 3))
    k = np.arange(n) % 3
    pts[np.arange(n), k] = rng.random(n) * 2 - 1
    return pts
