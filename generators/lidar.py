"""A seeded model of an airborne LiDAR tile, the data GIS users triangulate
first.

What it stands for: one flight strip of a small-footprint airborne laser
scanner over a town, as delivered in a LAS file.  The scanner sweeps across
the flight direction, so the pulses lie on parallel scan lines (across x,
advancing in y) with a fixed footprint spacing along a line and between
lines, disturbed by a small jitter (the mirror and the aircraft's motion).
The ground is a smooth surface of a few metres of relief; buildings are
raised rectangular blocks (flat roofs, vertical walls); trees are discs
where a pulse returns 2 to 4 times at the same xy (canopy, branches,
ground).  Coordinates are stored as LAS stores them: integers at a scale of
0.01 m plus a large offset (UTM-like eastings and northings, 5e5 and
4e6), so x and y are multiples of a centimetre that float64 cannot hold
exactly, many points repeat an xy (the returns of one pulse), the scan
lines are nearly collinear runs and the quantisation makes cocircular
quads.  It is a model, not a survey: results on it say nothing about a
particular real cloud (``python -m experiments.field --input cloud.laz``
runs on one)."""
import numpy as np

SCALE = 0.01  # metres per stored integer unit (LAS's scale factor)
OFFSET = (500_000.0, 4_000_000.0, 0.0)  # easting, northing, height offsets
DENSITY = 8.0  # pulses per square metre (a common survey density)
JITTER = 0.05  # standard deviation of the footprint jitter, as a fraction of the spacing


def _ground(x, y):
    """Smooth terrain, in metres above the offset: a slope and two swells."""
    return 120.0 + 0.02 * x + 2.5 * np.sin(x / 37.0) * np.cos(y / 53.0) + 1.5 * np.sin(y / 19.0)


def _buildings(rng, x0, width, height):
    """(k, 5) blocks: x0, y0, x1, y1, height of each flat-roofed building."""
    k = max(1, int(width * height / 2500))
    cx, cy = x0 + rng.random(k) * width, rng.random(k) * height
    w, d = 8 + rng.random(k) * 25, 8 + rng.random(k) * 25
    return np.column_stack((cx - w / 2, cy - d / 2, cx + w / 2, cy + d / 2, 4 + rng.random(k) * 16))


def _returns_per_pulse(rng, x, y, x0, width, height):
    """How many returns each pulse gives: 2 to 4 inside the tree discs, else 1."""
    k = max(1, int(width * height / 400))
    tx, ty, r = x0 + rng.random(k) * width, rng.random(k) * height, 2 + rng.random(k) * 4
    counts = np.ones(len(x), dtype=np.int64)
    for cx, cy, rr in zip(tx, ty, r):
        inside = (x - cx) ** 2 + (y - cy) ** 2 < rr * rr
        counts[inside] = rng.integers(2, 5, int(inside.sum()))
    return counts


def cloud(rng, n):
    """(n, 3) points: x, y, z in metres, quantised to SCALE with OFFSET."""
    return quantise(_strip(rng, n))


def _strip(rng, n, x0=0.0):
    """(n, 3) points of the model before quantisation, in metres from the
    tile's corner; ``x0``: where this strip starts across the flight line."""
    if n == 0:
        return np.empty((0, 3))
    pulses = max(1, int(n / 1.3))  # about 1.3 returns per pulse on average
    spacing = 1.0 / np.sqrt(DENSITY)
    per_line = max(1, int(np.sqrt(pulses)))
    lines = -(-pulses // per_line)
    width, height = per_line * spacing, lines * spacing
    i = np.arange(pulses)
    x = x0 + (i % per_line) * spacing + rng.normal(0.0, JITTER * spacing, pulses)
    y = (i // per_line) * spacing + rng.normal(0.0, JITTER * spacing, pulses)
    z = _ground(x, y)
    for bx0, by0, bx1, by1, h in _buildings(rng, x0, width, height):
        z[(x >= bx0) & (x < bx1) & (y >= by0) & (y < by1)] += h
    counts = _returns_per_pulse(rng, x, y, x0, width, height)
    pulse = np.repeat(np.arange(pulses), counts)[:n]
    first = np.r_[True, pulse[1:] != pulse[:-1]]
    # later returns of a pulse: lower, between the canopy top and the ground
    drop = np.where(first, 0.0, rng.random(len(pulse)) * 15.0)
    pts = np.column_stack((x[pulse], y[pulse], np.maximum(z[pulse] - drop, _ground(
        x[pulse], y[pulse]))))
    if len(pts) < n:  # fewer returns than asked: another strip beside this one
        pts = np.concatenate((pts, _strip(rng, n - len(pts), x0 + width + spacing)))
    return pts


def quantise(pts):
    """Coordinates as a LAS file holds them: round(v / SCALE) * SCALE + offset."""
    return np.round(pts / SCALE) * SCALE + np.asarray(OFFSET)


def cloud_xy(rng, n):
    """The LiDAR model's x and y alone (its 2D set): repeated xy where a pulse
    returned several times."""
    return cloud(rng, n)[:, :2]
