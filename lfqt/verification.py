"""Exact validation of triangulations, whoever built them.

``verify`` proves a mesh is *the* Delaunay triangulation of its points with
exact predicates only.  In 2D:

* every triangle is strictly counter-clockwise;
* every directed edge occurs once, neighbours are symmetric, and an edge
  without neighbour has no reverse: the boundary of the triangle chain is the
  set of hull edges;
* the hull edges form one loop that only turns left (or goes straight on) and
  winds exactly once, i.e. a convex polygon.  Then, by a degree argument, the
  positively oriented triangles cover every point inside it exactly once;
* every interior edge is locally Delaunay (exact in-circle <= 0), which on a
  triangulation of the convex hull means globally Delaunay;
* every distinct input point is a vertex, and no duplicate is.

In 3D the same with right-handed tetrahedra, oriented faces that cancel in
pairs, a hull surface that is one closed convex sphere, and exact in-sphere
tests.

The mesh may come from lfqt or from anyone else: a Triangulation, a
Delaunay (lfqt's or scipy's), or bare simplices.  Orientation is a finding
of its own.  Other libraries orient as they please (about half of scipy's
tetrahedra are left-handed), and the Delaunay property does not depend on
it, so a foreign mesh's reversed simplices are turned around before the
checks, counted and noted: ``ok`` keeps one meaning, "the simplices form
the Delaunay triangulation".  lfqt's own output is held to its contract,
positive orientation, because a reversed simplex there is a bug of lfqt.
"""
from __future__ import annotations

from collections import namedtuple
from dataclasses import dataclass, field
from typing import Literal, Protocol

import numpy as np
from numba import njit
from numpy.typing import ArrayLike

from ._input import exact_coordinates2d, exact_points3
from .triangulation import Triangulation
from .predicates.counters import N_PREDICATE, incircle, orient2d
from .predicates.planar import CCW_A, ICC_A
from .predicates.spatial import ISP_A, O3D_A, insphere_staged, orient3d_staged

ORIENTATIONS = ("auto", "strict", "either")
Orientation = Literal["auto", "strict", "either"]
# per dimension: the counts key of the simplices, their noun (one, many),
# what a reversed one is called, and what a flat one lacks
_KIND = {2: ("triangles", ("triangle", "triangles"), "clockwise", "area"),
         3: ("tetrahedra", ("tetrahedron", "tetrahedra"), "negatively oriented", "volume")}


class MeshLike(Protocol):
    """An object verify reads through its ``simplices``: a
    scipy.spatial.Delaunay, an lfqt.Delaunay, another library's mesh."""
    @property
    def simplices(self) -> ArrayLike: ...


@dataclass
class VerifyReport:
    """What :func:`verify` found.

    Attributes
    ----------
    ok : bool
        True exactly when the simplices form the Delaunay triangulation of
        the points: every check in ``checks`` passed.  ``notes`` never
        change it.
    checks : dict of str to bool
        Each check that ran, by name, and whether it passed: ``indices``
        (shapes and index ranges), ``duplicates``, ``orientation``,
        ``manifold``, ``convex_boundary``, ``coverage``, ``delaunay``,
        ``all_points_used`` and, when the mesh states its hull, ``hull``.
        A mesh without simplices is checked by ``flag`` (it is flagged
        degenerate), ``collinear`` (2D) or ``coplanar`` (3D) instead.
    problems : list of str
        One sentence per failed check.
    counts : dict of str to int
        What the checks counted: the simplices (``triangles`` or
        ``tetrahedra``), ``points``, ``duplicates`` (rows that repeat
        another row's coordinates), ``reversed`` (simplices given clockwise
        in 2D or left-handed in 3D), ``flat`` (zero area or volume), the
        faults per check (``non_delaunay_edges``, ``bad_neighbors``, ...)
        and the first bad simplex (``first_bad_triangle`` or
        ``first_bad_cell``, -1 when none).
    notes : list of str
        Sentences on findings that do not make the mesh invalid: reversed
        simplices that were accepted, duplicates inferred from the
        coordinates.
    summary : str
        One sentence: the verdict, then the problems or the notes.

    Examples
    --------
    >>> import numpy as np, lfqt
    >>> p = np.random.default_rng(0).random((100, 2))
    >>> clockwise = lfqt.triangulate(p).simplices[:, ::-1]
    >>> report = lfqt.verify(p, clockwise)
    >>> report.ok, report.counts["reversed"] == len(clockwise)
    (True, True)
    >>> report.summary
    'valid Delaunay triangulation (185 triangles); 185 triangles clockwise'
    """
    ok: bool
    checks: dict[str, bool]
    problems: list[str]
    counts: dict[str, int | None]
    notes: list[str] = field(default_factory=list)

    @property
    def summary(self) -> str:
        kind = next((k for k in ("triangles", "tetrahedra") if k in self.counts), None)
        if self.ok:
            size = f" ({_count(self.counts[kind], _KIND[2 if kind == 'triangles' else 3][1])})" \
                if kind else ""
            return "; ".join([f"valid Delaunay triangulation{size}"] + self.notes)
        text = "not the Delaunay triangulation: " + "; ".join(self.problems)
        return text + (f" (notes: {'; '.join(self.notes)})" if self.notes else "")

    def raise_if_invalid(self) -> None:
        """AssertionError listing the problems, unless ``ok``."""
        if not self.ok:
            raise AssertionError("invalid triangulation: " + "; ".join(self.problems))

    def __bool__(self) -> bool:
        return self.ok


def _count(k, nouns):
    """'1 triangle', '3 triangles'."""
    return f"{k} {nouns[0] if k == 1 else nouns[1]}"


@dataclass
class _Run:
    """One verify call's findings as they accumulate."""
    checks: dict = field(default_factory=dict)
    problems: list = field(default_factory=list)
    counts: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)

    def check(self, name, bad, sentence):
        self.checks[name] = not bad
        if bad:
            self.problems.append(sentence)

    def report(self):
        return VerifyReport(not self.problems, self.checks, self.problems, self.counts,
                            self.notes)


@dataclass
class _Mesh:
    """What verify reads from its input.  Arrays stay as given until
    ``_start`` checks their shapes and ranges, so that a malformed array is
    reported, not raised."""
    simplices: object
    neighbors: object = None     # None: matched from the simplices' shared faces
    hull: object = None          # lfqt's: 2D the counter-clockwise loop, 3D outward facets
    facets: object = None        # scipy's convex_hull: hull facets in any order and orientation
    duplicate_of: object = None  # None: inferred from equal coordinates
    degenerate: bool = True
    own: bool = False            # lfqt's output: held to positive orientation, must state its hull


@njit(cache=True)
def _lower_half(dx_sign, dy_sign):
    """Direction angle in [pi, 2pi): strictly below, or pointing left."""
    return dy_sign < 0 or (dy_sign == 0 and dx_sign < 0)


@njit(cache=True)
def _cmp(a, b):
    return 1 if a > b else (-1 if a < b else 0)


@njit(cache=True, inline="always")
def _pt3(P, v):
    """Point v of a 3D P as the (x, y, z) the spatial predicates take."""
    return P[v, 0], P[v, 1], P[v, 2]


# What _check_mesh finds in a 2D mesh: counts of each fault, the first
# triangle at fault, and the boundary (its edge count, a start vertex, and
# each vertex's outgoing boundary edge).
MeshFaults = namedtuple("MeshFaults", "bad_neighbors duplicate_directed boundary_with_reverse "
                        "boundary_not_single_loop reflex_turns winding not_delaunay "
                        "first_bad_triangle n_boundary loop_start out_next")


@njit(cache=True)
def _check_mesh(xs, ys, simplices, neighbors, n):
    """The structure and the in-circle tests of triangles whose orientation
    ``_orientations`` has checked: their MeshFaults."""
    m = simplices.shape[0]
    cnt = np.zeros(N_PREDICATE, dtype=np.int64)
    first_bad = -1
    bad_nb = 0
    keys = np.empty(3 * m, dtype=np.int64)
    for t in range(m):
        for i in range(3):
            a = simplices[t, (i + 1) % 3]
            b = simplices[t, (i + 2) % 3]
            keys[3 * t + i] = a * n + b
            u = neighbors[t, i]
            if u >= 0:
                ok = False
                if u < m:
                    for j in range(3):
                        if (simplices[u, (j + 1) % 3] == b and simplices[u, (j + 2) % 3] == a
                                and neighbors[u, j] == t):
                            ok = True
                if not ok:
                    bad_nb += 1
                    if first_bad < 0:
                        first_bad = t
    skeys = np.sort(keys)
    dup_directed = 0
    for k in range(1, 3 * m):
        if skeys[k] == skeys[k - 1]:
            dup_directed += 1
    # Boundary: edges without neighbour; their reverse must not exist.
    out_next = np.full(n, -1, dtype=np.int64)
    boundary_rev = 0
    n_boundary = 0
    loop_fail = 0
    start = -1
    for t in range(m):
        for i in range(3):
            if neighbors[t, i] < 0:
                a = simplices[t, (i + 1) % 3]
                b = simplices[t, (i + 2) % 3]
                rk = b * n + a
                pos = np.searchsorted(skeys, rk)
                if pos < 3 * m and skeys[pos] == rk:
                    boundary_rev += 1
                if out_next[a] >= 0:
                    loop_fail += 1
                out_next[a] = b
                n_boundary += 1
                start = a
    reflex = 0
    winding = 0
    if n_boundary > 0 and loop_fail == 0:
        steps = 0
        a = start
        while True:
            b = out_next[a]
            if b < 0:
                loop_fail += 1
                break
            c = out_next[b]
            if c < 0:
                loop_fail += 1
                break
            o = orient2d(xs[a], ys[a], xs[b], ys[b], xs[c], ys[c], CCW_A, cnt)
            if o < 0.0:
                reflex += 1
            elif o == 0.0:
                if (_cmp(xs[b], xs[a]) != _cmp(xs[c], xs[b])
                        or _cmp(ys[b], ys[a]) != _cmp(ys[c], ys[b])):
                    reflex += 1
            if (_lower_half(_cmp(xs[b], xs[a]), _cmp(ys[b], ys[a]))
                    and not _lower_half(_cmp(xs[c], xs[b]), _cmp(ys[c], ys[b]))):
                winding += 1
            steps += 1
            a = b
            if a == start or steps > n_boundary:
                break
        if steps != n_boundary or a != start:
            loop_fail += 1
    # Locally Delaunay interior edges, each checked once.
    not_delaunay = 0
    for t in range(m):
        for i in range(3):
            u = neighbors[t, i]
            if u > t and u < m:
                a = simplices[t, (i + 1) % 3]
                b = simplices[t, (i + 2) % 3]
                d = -1
                for j in range(3):
                    v = simplices[u, j]
                    if v != a and v != b:
                        d = v
                c = simplices[t, i]
                if d >= 0 and incircle(xs[a], ys[a], xs[b], ys[b], xs[c], ys[c], xs[d], ys[d],
                                       ICC_A, cnt) > 0.0:
                    not_delaunay += 1
                    if first_bad < 0:
                        first_bad = t
    return MeshFaults(bad_nb, dup_directed, boundary_rev, loop_fail, reflex, winding,
                      not_delaunay, first_bad, n_boundary, start, out_next)


@njit(cache=True)
def _all_collinear(xs, ys, ids, a, b):
    cnt = np.zeros(N_PREDICATE, dtype=np.int64)
    for k in range(ids.shape[0]):
        i = ids[k]
        if orient2d(xs[a], ys[a], xs[b], ys[b], xs[i], ys[i], CCW_A, cnt) != 0.0:
            return False
    return True


@njit(cache=True)
def _check_cells3(P, simplices, neighbors):
    """3D, on cells whose orientation ``_orientations`` has checked:
    (asymmetric neighbours, non-Delaunay faces, first bad cell)."""
    m = simplices.shape[0]
    bad_nb = 0
    not_delaunay = 0
    first = -1
    for t in range(m):
        a, b, c, d = simplices[t, 0], simplices[t, 1], simplices[t, 2], simplices[t, 3]
        for i in range(4):
            u = neighbors[t, i]
            if u < 0:
                continue
            if u >= m:
                bad_nb += 1
                continue
            apex = -1
            back = False
            for j in range(4):
                v = simplices[u, j]
                inside = False
                for k in range(4):
                    if k != i and simplices[t, k] == v:
                        inside = True
                if not inside:
                    apex = v
                    back = neighbors[u, j] == t
            if not back:
                bad_nb += 1
                if first < 0:
                    first = t
            elif u > t:
                e = apex
                s_, st = insphere_staged(_pt3(P, a), _pt3(P, b), _pt3(P, c), _pt3(P, d),
                                         _pt3(P, e), ISP_A)
                if s_ > 0.0:
                    not_delaunay += 1
                    if first < 0:
                        first = t
    return bad_nb, not_delaunay, first


@njit(cache=True)
def _reflex_hull_edges(P, faces, edge_face, edge_other):
    """Hull edges whose two outward faces bend outward (non-convex)."""
    bad = 0
    for k in range(edge_face.shape[0]):
        f = edge_face[k]
        g = edge_other[k]
        a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
        # the vertex of g not on the shared edge
        q = -1
        for j in range(3):
            v = faces[g, j]
            if v != a and v != b and v != c:
                q = v
        if q < 0:
            continue
        o, st = orient3d_staged(_pt3(P, a), _pt3(P, b), _pt3(P, c), _pt3(P, q), O3D_A)
        if o > 0.0:
            bad += 1
    return bad


def _oriented_faces(simplices):
    """Outward faces (m*4, 3) of right-handed tetrahedra, row 4t + i being the
    face of cell t opposite its vertex i."""
    m = len(simplices)
    faces = np.empty((m, 4, 3), dtype=np.int64)
    for i in range(4):
        rest = [(i + 1) % 4, (i + 2) % 4, (i + 3) % 4]
        if i % 2 == 1:  # the cyclic rest of an odd index faces inward: swap two
            rest[0], rest[1] = rest[1], rest[0]
        faces[:, i] = simplices[:, rest]
    return faces.reshape(-1, 3)


@njit(cache=True)
def _orientations2(P, simplices):
    """Exact orientation of each triangle: 1 counter-clockwise, -1
    clockwise, 0 flat."""
    cnt = np.zeros(N_PREDICATE, dtype=np.int64)
    out = np.empty(simplices.shape[0], dtype=np.int8)
    for t in range(simplices.shape[0]):
        a, b, c = simplices[t, 0], simplices[t, 1], simplices[t, 2]
        o = orient2d(P[a, 0], P[a, 1], P[b, 0], P[b, 1], P[c, 0], P[c, 1], CCW_A, cnt)
        out[t] = 1 if o > 0.0 else (-1 if o < 0.0 else 0)
    return out


@njit(cache=True)
def _orientations3(P, simplices):
    """Exact orientation of each tetrahedron: 1 right-handed, -1
    left-handed, 0 flat."""
    out = np.empty(simplices.shape[0], dtype=np.int8)
    for t in range(simplices.shape[0]):
        a, b, c, d = simplices[t, 0], simplices[t, 1], simplices[t, 2], simplices[t, 3]
        o, st = orient3d_staged(_pt3(P, a), _pt3(P, b), _pt3(P, c), _pt3(P, d), O3D_A)
        out[t] = 1 if o > 0.0 else (-1 if o < 0.0 else 0)
    return out


@njit(cache=True)
def _all_coplanar(P, ids):
    """Whether the distinct points P[ids] lie in one plane: a third point
    off the line of the first two (off it in some axis projection) spans a
    plane that every orient3d then finds them on.  The 3D window's
    coordinates lie inside the 2D window, so orient2d is exact on them."""
    cnt = np.zeros(N_PREDICATE, dtype=np.int64)
    if ids.shape[0] < 4:
        return True
    a, b = ids[0], ids[1]
    c = -1
    for k in range(2, ids.shape[0]):
        i = ids[k]
        for x, y in ((0, 1), (1, 2), (2, 0)):
            if orient2d(P[a, x], P[a, y], P[b, x], P[b, y], P[i, x], P[i, y], CCW_A, cnt) != 0.0:
                c = i
        if c >= 0:
            break
    if c < 0:
        return True  # collinear
    for k in range(ids.shape[0]):
        i = ids[k]
        o, st = orient3d_staged(_pt3(P, a), _pt3(P, b), _pt3(P, c), _pt3(P, i), O3D_A)
        if o != 0.0:
            return False
    return True


def _verify3(P, simplices, neighbors, run):
    """The 3D checks after _start's; returns the boundary's outward faces."""
    n = len(P)
    bad_nb, not_delaunay, first = _check_cells3(P, simplices, neighbors)
    faces = _oriented_faces(simplices)
    srt = np.sort(faces, axis=1)
    # parity of the sort: is the face an even permutation of its sorted form?
    rank = np.argsort(faces, axis=1)
    parity = ((rank[:, 0] > rank[:, 1]).astype(int) + (rank[:, 0] > rank[:, 2]) +
              (rank[:, 1] > rank[:, 2])) % 2
    order = np.lexsort((parity, srt[:, 2], srt[:, 1], srt[:, 0]))
    key = np.column_stack((srt, parity))[order]
    same = np.all(key[1:] == key[:-1], axis=1)
    dup_oriented = int(np.count_nonzero(same))
    nbr = neighbors.reshape(-1)
    boundary = faces[nbr < 0]
    # every undirected face: twice with opposite parity (interior) or once (hull)
    und = np.all(key[1:, :3] == key[:-1, :3], axis=1)
    interior_pairs = int(np.count_nonzero(und))
    mismatch = (len(faces) - 2 * interior_pairs) != len(boundary)
    if run.counts["first_bad_cell"] < 0:
        run.counts["first_bad_cell"] = int(first)
    run.counts.update(bad_neighbors=int(bad_nb), repeated_oriented_faces=dup_oriented,
                      hull_faces=int(len(boundary)), non_delaunay_faces=int(not_delaunay))
    run.check("manifold", bad_nb or dup_oriented or mismatch,
              f"facet structure broken: {bad_nb} asymmetric neighbours, {dup_oriented} repeated "
              "oriented faces" + (", hull faces do not match the unpaired faces" if mismatch
                                  else ""))
    # hull surface: closed, edge-manifold, connected, Euler characteristic 2, locally convex
    fb = len(boundary)
    directed = np.concatenate([boundary[:, [0, 1]], boundary[:, [1, 2]], boundary[:, [2, 0]]])
    owner = np.tile(np.arange(fb), 3)
    fwd = directed[:, 0] * n + directed[:, 1]
    rev = directed[:, 1] * n + directed[:, 0]
    o = np.argsort(fwd)
    sf = fwd[o]
    pos = np.searchsorted(sf, rev)
    found = (pos < len(sf)) & (sf[np.minimum(pos, len(sf) - 1)] == rev)
    closed = bool(found.all()) and len(np.unique(fwd)) == len(fwd)
    reflex = 0
    connected = False
    euler = None
    if closed and fb:
        other = owner[o[pos]]
        reflex = int(_reflex_hull_edges(P, boundary.astype(np.int64), owner, other))
        parent = np.arange(fb)

        def root(x):
            while parent[x] != x:
                parent[x] = parent[parent[x]]
                x = parent[x]
            return x
        for a, b in zip(owner, other):
            ra, rb = root(a), root(b)
            if ra != rb:
                parent[ra] = rb
        connected = len({root(x) for x in range(fb)}) == 1
        euler = len(np.unique(boundary)) - len(fwd) // 2 + fb
    run.counts.update(reflex_hull_edges=reflex, hull_euler=euler)
    run.check("convex_boundary", not (closed and connected and euler == 2 and reflex == 0),
              f"hull surface is not one closed convex sphere (closed {closed}, connected "
              f"{connected}, Euler {euler}, {reflex} reflex edges)")
    run.checks["coverage"] = (run.checks["orientation"] and run.checks["manifold"]
                              and run.checks["convex_boundary"])
    run.check("delaunay", not_delaunay, f"{not_delaunay} interior faces are not locally Delaunay")
    return boundary


def _int_array(value, name, problems):
    """``value`` as an int64 array, or None with a problem when it is not one."""
    try:
        arr = np.asarray(value)
        if arr.dtype.kind not in "iu" and arr.size:
            raise TypeError(f"dtype {arr.dtype}")
        return np.ascontiguousarray(arr, dtype=np.int64)
    except (TypeError, ValueError) as e:
        problems.append(f"{name} is not an integer array ({e})")
        return None


def _interpret(tri, width):
    """The _Mesh that ``tri`` holds; TypeError or ValueError when it is
    none of the forms verify reads."""
    inner = getattr(tri, "triangulation", None)
    if isinstance(inner, Triangulation):  # lfqt.Delaunay: the Triangulation it wraps
        tri = inner
    if isinstance(tri, Triangulation):
        return _Mesh(tri.simplices, tri.neighbors, tri.hull, None, tri.duplicate_of,
                     bool(tri.degenerate), own=True)
    if hasattr(tri, "simplices"):  # scipy.spatial.Delaunay, or another library's object
        hull = getattr(tri, "hull", None)
        return _Mesh(tri.simplices, getattr(tri, "neighbors", None), hull,
                     getattr(tri, "convex_hull", None) if hull is None else None,
                     getattr(tri, "duplicate_of", None), bool(getattr(tri, "degenerate", True)))
    return _Mesh(_bare_simplices(tri, width))


def _bare_simplices(value, width):
    """Bare simplices as an (m, width) integer array; TypeError or
    ValueError, with what verify reads, when ``value`` is not one."""
    forms = ("verify reads an lfqt Triangulation, an lfqt or scipy Delaunay, an object with "
             "simplices, or bare simplices: an integer array or a sequence of "
             f"{'triples' if width == 3 else 'quadruples'} of point indices")
    if value is None or isinstance(value, (str, bytes, dict)):
        raise TypeError(f"{forms}; got {type(value).__name__}")
    try:
        arr = np.asarray(value)
    except ValueError as e:  # a ragged sequence
        raise ValueError(f"{forms}; got a {type(value).__name__} that is no array ({e})") from None
    if arr.shape in ((0,), (0, width)):  # no simplices: [] for collinear points
        return np.empty((0, width), dtype=np.int64)
    if arr.dtype.kind not in "iu":
        raise TypeError(f"{forms}; got a {type(value).__name__} of dtype {arr.dtype}")
    if arr.ndim != 2 or arr.shape[1] != width:
        raise ValueError(f"simplices of {width - 1}D points have shape (m, {width}); got a "
                         f"{type(value).__name__} of shape {arr.shape}")
    return arr


def _shape_problems(P, mesh, problems):
    """Every array's shape and index range, checked before anything reads
    through them: the validated Arrays (simplices, neighbors, duplicate_of, hull,
    facets), or None for the arrays that are not given or not integers."""
    n, width = len(P), P.shape[1] + 1
    simplices = _int_array(mesh.simplices, "simplices", problems)
    neighbors, dup, hull, facets = (
        None if v is None else _int_array(v, name, problems)
        for v, name in ((mesh.neighbors, "neighbors"), (mesh.duplicate_of, "duplicate_of"),
                        (mesh.hull, "hull"), (mesh.facets, "convex_hull")))
    if simplices is not None and simplices.size == 0:
        simplices = simplices.reshape(0, width)
    if simplices is not None and (simplices.ndim != 2 or simplices.shape[1] != width):
        problems.append(f"simplices must have shape (m, {width}), got {simplices.shape}")
        simplices = None
    if simplices is not None and neighbors is not None:
        if neighbors.size == 0 and len(simplices) == 0:
            neighbors = neighbors.reshape(0, width)
        if neighbors.shape != simplices.shape:
            problems.append(f"neighbors must have the shape of simplices {simplices.shape}, "
                            f"got {neighbors.shape}")
        elif neighbors.size and (neighbors.min() < -1 or neighbors.max() >= len(simplices)):
            problems.append(f"neighbors must be -1 or a simplex index below {len(simplices)}")
    if simplices is not None and simplices.size and (simplices.min() < 0 or simplices.max() >= n):
        problems.append(f"simplices hold vertex indices outside [0, {n})")
    if dup is not None and (dup.shape != (n,) or (n and (dup.min() < 0 or dup.max() >= n))):
        problems.append(f"duplicate_of must be {n} indices in [0, {n})")
    for arr, name in ((hull, "hull"), (facets, "convex_hull")):
        if arr is not None and arr.size and (arr.min() < 0 or arr.max() >= n):
            problems.append(f"{name} holds vertex indices outside [0, {n})")
    return Arrays(simplices, neighbors, dup, hull, facets)


def _inferred_duplicates(P, simplices):
    """duplicate_of from the coordinates, for a mesh that does not state
    it.  Rows with equal coordinates form a group, represented by its
    first row that is a vertex, or by its first row when none is: a
    foreign mesh keeps whichever twin it likes (Qhull's is often not the
    first), and a group with no vertex, or two, stays a fault for
    ``all_points_used`` to find."""
    n = len(P)
    used = np.zeros(n, dtype=bool)
    used[simplices.ravel()] = True
    # rows sorted by coordinates, a group's vertices first, then by row (lexsort is stable)
    order = np.lexsort((~used,) + tuple(P.T[::-1]))
    srt = P[order]
    head = np.ones(n, dtype=bool)
    head[1:] = np.any(srt[1:] != srt[:-1], axis=1)
    dup = np.empty(n, dtype=np.int64)
    dup[order] = order[head][np.cumsum(head) - 1]
    return dup


# A mesh's arrays as read and checked (_shape_problems).
Arrays = namedtuple("Arrays", "simplices neighbors dup hull facets")
# What _start hands the structural checks.
Start = namedtuple("Start", "run simplices neighbors dup distinct")


def _start(P, mesh, strict):
    """Checks shared by 2D and 3D, before the structure: shapes and index
    ranges, orientation, duplicate_of.  Unless ``strict``, reversed
    simplices are turned around here (two vertices swapped, and their
    neighbours with them), so that the structural checks see one
    orientation.  ``mesh.hull`` and ``mesh.facets`` become their
    validated arrays.  Returns a Start; its simplices are None when the
    arrays cannot be read through."""
    n, dim = P.shape
    kind, nouns, reversed_name, lacks = _KIND[dim]
    run = _Run()
    simplices, neighbors, dup, hull, facets = _shape_problems(P, mesh, run.problems)
    mesh.hull, mesh.facets = hull, facets
    run.checks["indices"] = not run.problems
    run.counts.update({kind: int(len(simplices)) if simplices is not None else 0,
                       "points": int(n)})
    if run.problems:
        return Start(run, None, None, None, None)
    signs = (_orientations2 if dim == 2 else _orientations3)(P, simplices)
    rev, flat = int(np.count_nonzero(signs < 0)), int(np.count_nonzero(signs == 0))
    bad = signs <= 0 if strict else signs == 0
    run.counts.update({"reversed": rev, "flat": flat,
                       f"first_bad_{'triangle' if dim == 2 else 'cell'}":
                       int(np.argmax(bad)) if bad.any() else -1})
    if strict:
        want = "strictly counter-clockwise" if dim == 2 else "positively oriented"
        run.check("orientation", rev + flat,
                  f"{kind} not {want}: {rev + flat} ({rev} {reversed_name}, {flat} flat)")
    else:
        run.check("orientation", flat, f"{_count(flat, nouns)} flat (zero {lacks})")
        if rev:
            run.notes.append(f"{_count(rev, nouns)} {reversed_name}")
            turn = np.flatnonzero(signs < 0)
            simplices = simplices.copy()  # never the caller's array
            simplices[turn, :2] = simplices[turn, 1::-1]
            if neighbors is not None:
                neighbors = neighbors.copy()
                neighbors[turn, :2] = neighbors[turn, 1::-1]
    if neighbors is None:
        neighbors = _matched_neighbors(simplices, n)[0]
    if dup is None:
        dup = _inferred_duplicates(P, simplices)
        inferred = int(np.count_nonzero(dup != np.arange(n)))
        if inferred:
            run.notes.append(f"{_count(inferred, ('duplicate point', 'duplicate points'))} "
                             "inferred from equal coordinates")
    rep_ok = bool(np.all(dup[dup] == dup)) and bool(np.all(P[dup] == P))
    run.check("duplicates", not rep_ok,
              "duplicate_of maps a row to a different point or to a non-representative")
    distinct = np.flatnonzero(dup == np.arange(n))
    run.counts["duplicates"] = int(n - len(distinct))
    return Start(run, simplices, neighbors, dup, distinct)


def _check_points_used(simplices, dup, distinct, run):
    used = np.zeros(len(dup), dtype=bool)
    used[simplices.ravel()] = True
    missing = int(np.count_nonzero(~used[distinct]))
    dup_used = int(np.count_nonzero(used & (dup != np.arange(len(dup)))))
    run.check("all_points_used", missing or dup_used,
              f"{missing} distinct points are not vertices, {dup_used} duplicates are")


def _same_facets(found, given):
    """Whether two (k, d) lists of hull facets are the same set, each facet
    in any vertex order."""
    if given.ndim != 2 or given.shape[1] != found.shape[1] or len(given) != len(found):
        return False
    a = np.unique(np.sort(found, axis=1), axis=0)
    return len(a) == len(found) and np.array_equal(a, np.unique(np.sort(given, axis=1), axis=0))


def _verify_2d(xs, ys, mesh, strict):
    P = np.column_stack((xs, ys))
    n = len(P)
    run, simplices, neighbors, dup, distinct = _start(P, mesh, strict)
    if simplices is None:
        return run.report()
    hull = np.zeros(0, np.int64) if mesh.hull is None else mesh.hull
    if len(simplices) == 0:
        run.check("flag", not mesh.degenerate, "no triangles but not flagged degenerate")
        if len(distinct):
            order = np.lexsort((ys[distinct], xs[distinct]))
            lo, hi = distinct[order[0]], distinct[order[-1]]
            collinear = len(distinct) < 3 or _all_collinear(xs, ys, distinct, lo, hi)
            run.check("collinear", not collinear,
                      "no triangles although the distinct points are not collinear")
            expect = {int(lo), int(hi)}
            if mesh.hull is not None or mesh.own:
                run.check("hull", set(map(int, hull)) != expect or len(hull) != len(expect),
                          f"hull of a degenerate set must be its extreme points {sorted(expect)}")
        return run.report()

    (bad_nb, dup_directed, boundary_rev, loop_fail, reflex, winding, not_delaunay, first_bad,
     n_boundary, start, out_next) = _check_mesh(xs, ys, simplices, neighbors, n)
    if run.counts["first_bad_triangle"] < 0:
        run.counts["first_bad_triangle"] = int(first_bad)
    run.counts.update(bad_neighbors=int(bad_nb), duplicate_directed_edges=int(dup_directed),
                      boundary_edges=int(n_boundary), reflex_hull_turns=int(reflex),
                      hull_winding=int(winding), non_delaunay_edges=int(not_delaunay))
    run.check("manifold", bad_nb or dup_directed or boundary_rev,
              f"edge structure broken: {bad_nb} asymmetric neighbours, {dup_directed} repeated "
              f"directed edges, {boundary_rev} hull edges with a reverse")
    run.check("convex_boundary", loop_fail or reflex or winding != 1,
              f"boundary is not one convex loop ({loop_fail} loop faults, {reflex} reflex "
              f"turns, winding {winding})")
    run.checks["coverage"] = (run.checks["orientation"] and run.checks["manifold"]
                              and run.checks["convex_boundary"])
    run.check("delaunay", not_delaunay, f"{not_delaunay} interior edges are not locally Delaunay")
    _check_points_used(simplices, dup, distinct, run)
    if mesh.facets is not None:
        t, i = np.nonzero(neighbors < 0)
        edges = np.column_stack((simplices[t, (i + 1) % 3], simplices[t, (i + 2) % 3]))
        run.check("hull", not _same_facets(edges, mesh.facets),
                  "convex_hull is not the set of boundary edges")
    elif mesh.hull is not None or mesh.own:
        hull_ok = len(hull) == n_boundary and n_boundary > 0
        if hull_ok:
            nxt = np.roll(hull, -1)
            hull_ok = bool(np.all(out_next[hull] == nxt))
        run.check("hull", not hull_ok, "hull is not the counter-clockwise boundary loop")
    return run.report()


def _verify_3d(P, mesh, strict):
    run, simplices, neighbors, dup, distinct = _start(P, mesh, strict)
    if simplices is None:
        return run.report()
    if len(simplices) == 0:
        run.check("flag", not mesh.degenerate, "no tetrahedra but not flagged degenerate")
        run.check("coplanar", not _all_coplanar(P, distinct),
                  "no tetrahedra although the distinct points are not coplanar")
        return run.report()
    boundary = _verify3(P, simplices, neighbors, run)
    _check_points_used(simplices, dup, distinct, run)
    if mesh.facets is not None:
        run.check("hull", not _same_facets(boundary, mesh.facets),
                  "convex_hull is not the set of boundary faces")
    elif mesh.hull is not None or mesh.own:
        hull = np.zeros((0, 3), np.int64) if mesh.hull is None else mesh.hull
        same = hull.ndim == 2 and hull.shape[1] == 3 and \
            {tuple(np.roll(f, -int(np.argmin(f)))) for f in boundary.tolist()} == \
            {tuple(np.roll(f, -int(np.argmin(f)))) for f in hull.tolist()}
        run.check("hull", not same, "hull facets differ from the outward boundary faces")
    return run.report()


def verify(points: ArrayLike, tri: Triangulation | MeshLike | ArrayLike, *,
           orientation: Orientation = "auto") -> VerifyReport:
    """Exactly check that ``tri`` is the Delaunay triangulation of ``points``.

    Every test is an exact predicate (orientation, in-circle, in-sphere),
    so ``ok`` is a proof, not an estimate.

    Parameters
    ----------
    points : array_like, shape (n, 2) or (n, 3)
        The points that were triangulated, as given to the triangulator
        (float or integer coordinates, read exactly).
    tri : Triangulation, Delaunay, scipy.spatial.Delaunay or array_like of int
        The mesh, in one of these forms:

        * an :class:`lfqt.Triangulation`, from ``lfqt.triangulate`` or
          ``lfqt.insert`` (or :func:`mesh_from_simplices`);
        * an :class:`lfqt.Delaunay`: the Triangulation it wraps is checked;
        * a ``scipy.spatial.Delaunay``, or any object with ``simplices``:
          its ``neighbors`` (matched from shared faces when absent),
          ``hull`` (lfqt's convention) or else ``convex_hull`` (facets in
          any order, checked as a set), ``duplicate_of`` and ``degenerate``
          are read when present;
        * bare simplices: an (m, 3) or (m, 4) array of any integer dtype,
          or a sequence (list, tuple) of index triples or quadruples.
          Neighbours are matched from shared faces; an empty sequence
          claims that the points are collinear (2D) or coplanar (3D).

        Where the mesh does not state ``duplicate_of``, rows with equal
        coordinates are taken as one point, represented by the row the
        mesh uses (as scipy leaves the others in ``coplanar``).
    orientation : {"auto", "strict", "either"}, optional
        ``"strict"``: a simplex that is not positively oriented
        (counter-clockwise in 2D, right-handed in 3D) fails the
        ``orientation`` check.  ``"either"``: a reversed simplex is turned
        around (two vertices swapped, with their neighbours) before the
        other checks, counted in ``counts["reversed"]`` and named in
        ``notes``; ``ok`` then says whether the set of simplices is the
        Delaunay triangulation.  ``"auto"`` (the default) is strict for
        lfqt's own Triangulation and Delaunay, whose contract is positive
        orientation (a reversed simplex there is a bug of lfqt), and either
        for every other form.  A flat simplex (zero area or volume) fails
        in every mode: it is not reversed, it is no simplex.

    Returns
    -------
    VerifyReport
        ``ok``, each check by name, a sentence per problem, the counts, and
        notes on what was accepted; ``summary`` says it in one sentence.

    Raises
    ------
    TypeError
        ``tri`` is none of the forms above (``None``, a string, an array
        of floats or of Python objects).
    ValueError
        ``points`` is not a finite (n, 2) or (n, 3) array; bare simplices
        are ragged or of the wrong width for the points; ``orientation``
        is not one of the three.

    See Also
    --------
    lfqt.distributed.verify : the same proof, tile by tile, on Dask.

    Notes
    -----
    In 2D the checks are: strictly counter-clockwise triangles; an edge
    structure whose boundary is one convex loop winding once (so the
    triangles tile the hull exactly once); every interior edge locally
    Delaunay; every distinct point a vertex, and no duplicate.  In 3D:
    right-handed tetrahedra; oriented faces that cancel in pairs; a hull
    surface that is closed, connected, of Euler characteristic 2 and
    locally convex; every interior face locally Delaunay; every distinct
    point a vertex.  A locally Delaunay triangulation of the convex hull
    is the Delaunay triangulation (unique unless 4 points are cocircular,
    or 5 cospherical, where any of the valid ones passes).

    Malformed arrays (wrong shapes, indices out of range, float
    simplices inside a Triangulation) are reported in ``problems`` with
    the ``indices`` check failed, never raised.

    Examples
    --------
    >>> import numpy as np, lfqt
    >>> p = np.random.default_rng(0).random((100, 2))
    >>> lfqt.verify(p, lfqt.triangulate(p)).ok
    True

    scipy's mesh, and bare simplices in either orientation:

    >>> import scipy.spatial
    >>> lfqt.verify(p, scipy.spatial.Delaunay(p)).ok
    True
    >>> triples = [(int(c), int(b), int(a)) for a, b, c in lfqt.triangulate(p).simplices]
    >>> lfqt.verify(p, triples).summary
    'valid Delaunay triangulation (185 triangles); 185 triangles clockwise'
    >>> lfqt.verify(p, triples[1:]).summary  # doctest: +ELLIPSIS
    'not the Delaunay triangulation: ...boundary is not one convex loop...'
    """
    if orientation not in ORIENTATIONS:
        raise ValueError(f"orientation must be one of {ORIENTATIONS}, got {orientation!r}")
    arr = np.asarray(points)
    dim = 3 if arr.ndim == 2 and arr.shape[1] == 3 else 2
    mesh = _interpret(tri, dim + 1)
    strict = orientation == "strict" or (orientation == "auto" and mesh.own)
    if dim == 3:
        return _verify_3d(exact_points3(points), mesh, strict)
    xs, ys = exact_coordinates2d(points)
    return _verify_2d(xs, ys, mesh, strict)


def _matched_neighbors(s, n):
    """Neighbours of bare (m, 3) or (m, 4) simplices from their shared
    faces: (neighbors, matched) with ``matched`` per face (row ``width *
    t + i``, the face opposite vertex i of simplex t).  In 2D a face's twin
    is its reverse directed edge; in 3D, the same vertex set in another
    cell, whatever its orientation.  Faces that do not pair up are left -1
    for verify to reject."""
    m, width = s.shape
    if width == 3:
        # face i of triangle t is the directed edge v[i+1] -> v[i+2]; its twin runs back
        a, b = s[:, [1, 2, 0]].ravel(), s[:, [2, 0, 1]].ravel()
        own, twin = a * n + b, b * n + a
        order = np.argsort(own, kind="stable")
        pos = np.minimum(np.searchsorted(own[order], twin), max(len(order) - 1, 0))
        hit = order[pos] if len(order) else pos
        matched = (own[hit] == twin) if len(order) else np.zeros(0, bool)
    else:
        # sorted faces in lexicographic order: a face's twin is its equal
        # neighbour in that order (a key like (a * n + b) * n + c would
        # overflow int64 beyond 2 million points)
        srt = np.sort(_oriented_faces(s), axis=1)
        order = np.lexsort(srt.T[::-1])
        same = np.all(srt[order[1:]] == srt[order[:-1]], axis=1)
        after = np.r_[same, False]   # the face at order[k] equals the one at order[k + 1]
        before = np.r_[False, same]
        k = np.arange(len(order))
        partner = np.where(after, np.minimum(k + 1, len(order) - 1), np.maximum(k - 1, 0))
        hit = np.empty_like(order)
        hit[order] = order[partner]
        matched = np.zeros(len(order), dtype=bool)
        matched[order] = after | before
        matched &= hit // 4 != np.arange(len(order)) // 4
    neighbors = np.where(matched, hit // width, -1).reshape(m, width)
    return neighbors, matched


def mesh_from_simplices(simplices, n):
    """A Triangulation of ``n`` points from bare, positively oriented
    ``simplices`` (another library's output, such as CGAL's or Triangle's):
    neighbours by matching faces, and the hull (2D: the counter-clockwise
    loop of boundary edges; 3D: the unmatched outward faces).  Faces that
    do not pair up are left for verify to reject.  (:func:`verify` also
    reads bare simplices directly, in either orientation.)"""
    s = np.asarray(simplices, dtype=np.int64)
    if s.ndim != 2:
        s = s.reshape(0, 3)
    neighbors, matched = _matched_neighbors(s, n)
    if s.shape[1] == 4:
        hull = _oriented_faces(s)[~matched]
    else:
        a, b = s[:, [1, 2, 0]].ravel(), s[:, [2, 0, 1]].ravel()
        nxt = dict(zip(a[~matched].tolist(), b[~matched].tolist()))
        hull = []
        if nxt:
            start = next(iter(nxt))
            v = start
            while len(hull) <= len(nxt):
                hull.append(v)
                v = nxt.get(v, start)
                if v == start:
                    break
        hull = np.array(hull, dtype=np.int64)
    return Triangulation(points=None, simplices=s, neighbors=neighbors, hull=hull,
                         duplicate_of=np.arange(n), degenerate=len(s) == 0)
