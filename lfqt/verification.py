"""Exact validation of triangulations, whoever built them.

``verify`` proves a 2D mesh is *the* Delaunay triangulation of its points with
exact predicates only:

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
"""
from dataclasses import dataclass

import numpy as np
from numba import njit

from ._input import exact_coordinates2d, exact_points3
from .triangulation import Triangulation
from .predicates.counters import N_PREDICATE, incircle, orient2d
from .predicates.planar import CCW_A, ICC_A
from .predicates.spatial import ISP_A, O3D_A, insphere_staged, orient3d_staged


@dataclass
class VerifyReport:
    """Outcome of :func:`verify`; ``ok`` is the conjunction of the checks.
    Each failing check puts a sentence in ``problems``."""
    ok: bool
    checks: dict
    problems: list
    counts: dict

    def raise_if_invalid(self):
        if not self.ok:
            raise AssertionError("invalid triangulation: " + "; ".join(self.problems))

    def __bool__(self):
        return self.ok


@njit(cache=True)
def _lower_half(dx_sign, dy_sign):
    """Direction angle in [pi, 2pi): strictly below, or pointing left."""
    return dy_sign < 0 or (dy_sign == 0 and dx_sign < 0)


@njit(cache=True)
def _cmp(a, b):
    return 1 if a > b else (-1 if a < b else 0)


@njit(cache=True)
def _check_mesh(xs, ys, simplices, neighbors, n):
    """Returns (bad_orientation, bad_neighbors, duplicate_directed, boundary_with_reverse,
    boundary_not_single_loop, reflex_turns, winding, not_delaunay, first_bad_triangle,
    n_boundary, loop_start)."""
    m = simplices.shape[0]
    cnt = np.zeros(N_PREDICATE, dtype=np.int64)
    bad_orient = 0
    first_bad = -1
    for t in range(m):
        a, b, c = simplices[t, 0], simplices[t, 1], simplices[t, 2]
        if orient2d(xs[a], ys[a], xs[b], ys[b], xs[c], ys[c], CCW_A, cnt) <= 0.0:
            bad_orient += 1
            if first_bad < 0:
                first_bad = t
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
    return (bad_orient, bad_nb, dup_directed, boundary_rev, loop_fail, reflex, winding,
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
    """3D: (non-positive cells, asymmetric neighbours, non-Delaunay faces,
    first bad cell)."""
    m = simplices.shape[0]
    bad_orient = 0
    bad_nb = 0
    not_delaunay = 0
    first = -1
    for t in range(m):
        a, b, c, d = simplices[t, 0], simplices[t, 1], simplices[t, 2], simplices[t, 3]
        o, st = orient3d_staged(P[a, 0], P[a, 1], P[a, 2], P[b, 0], P[b, 1], P[b, 2],
                                P[c, 0], P[c, 1], P[c, 2], P[d, 0], P[d, 1], P[d, 2], O3D_A)
        if o <= 0.0:
            bad_orient += 1
            if first < 0:
                first = t
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
                s_, st = insphere_staged(P[a, 0], P[a, 1], P[a, 2], P[b, 0], P[b, 1], P[b, 2],
                                         P[c, 0], P[c, 1], P[c, 2], P[d, 0], P[d, 1], P[d, 2],
                                         P[e, 0], P[e, 1], P[e, 2], ISP_A)
                if s_ > 0.0:
                    not_delaunay += 1
                    if first < 0:
                        first = t
    return bad_orient, bad_nb, not_delaunay, first


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
        o, st = orient3d_staged(P[a, 0], P[a, 1], P[a, 2], P[b, 0], P[b, 1], P[b, 2],
                                P[c, 0], P[c, 1], P[c, 2], P[q, 0], P[q, 1], P[q, 2], O3D_A)
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


def _verify3(P, simplices, neighbors, problems, checks, counts):
    n = len(P)
    bad_orient, bad_nb, not_delaunay, first = _check_cells3(P, simplices, neighbors)
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
    counts.update(bad_orientation=int(bad_orient), bad_neighbors=int(bad_nb),
                  repeated_oriented_faces=dup_oriented, hull_faces=int(len(boundary)),
                  non_delaunay_faces=int(not_delaunay), first_bad_cell=int(first))
    _problem(problems, checks, "orientation", bad_orient,
             f"{bad_orient} tetrahedra are not positively oriented")
    _problem(problems, checks, "manifold", bad_nb or dup_oriented or mismatch,
             f"facet structure broken: {bad_nb} asymmetric neighbours, {dup_oriented} repeated "
             "oriented faces" + (", hull faces do not match the unpaired faces" if mismatch else ""))
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
    counts.update(reflex_hull_edges=reflex, hull_euler=euler)
    _problem(problems, checks, "convex_boundary",
             not (closed and connected and euler == 2 and reflex == 0),
             f"hull surface is not one closed convex sphere (closed {closed}, connected "
             f"{connected}, Euler {euler}, {reflex} reflex edges)")
    checks["coverage"] = checks["orientation"] and checks["manifold"] and checks["convex_boundary"]
    _problem(problems, checks, "delaunay", not_delaunay,
             f"{not_delaunay} interior faces are not locally Delaunay")
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


def _shape_problems(P, tri):
    """Every array's shape and index range, checked before anything reads
    through them: (simplices, neighbors, dup, problems)."""
    n, width = len(P), P.shape[1] + 1
    problems = []
    simplices = _int_array(getattr(tri, "simplices", None), "simplices", problems)
    neighbors = _int_array(getattr(tri, "neighbors", None), "neighbors", problems)
    dup = getattr(tri, "duplicate_of", None)
    dup = np.arange(n) if dup is None else _int_array(dup, "duplicate_of", problems)
    hull = getattr(tri, "hull", None)  # None: not given (3D derives it; 2D then fails "hull")
    hull = None if hull is None else _int_array(hull, "hull", problems)
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
    if hull is not None and hull.size and (hull.min() < 0 or hull.max() >= n):
        problems.append(f"hull holds vertex indices outside [0, {n})")
    return simplices, neighbors, dup, problems


def _start(P, tri, kind):
    """Checks shared by 2D and 3D: shapes, indices in range and a consistent
    ``duplicate_of``.  Returns (simplices, neighbors, dup, distinct,
    problems, checks, counts), or a failed VerifyReport."""
    n = len(P)
    simplices, neighbors, dup, problems = _shape_problems(P, tri)
    checks = {"indices": not problems}
    counts = {kind: int(len(simplices)) if simplices is not None else 0, "points": int(n)}
    if problems:
        return VerifyReport(False, checks, problems, counts)
    rep_ok = bool(np.all(dup[dup] == dup)) and bool(np.all(P[dup] == P))
    _problem(problems, checks, "duplicates", not rep_ok,
             "duplicate_of maps a row to a different point or to a non-representative")
    distinct = np.flatnonzero(dup == np.arange(n))
    return simplices, neighbors, dup, distinct, problems, checks, counts


def _check_points_used(simplices, dup, distinct, problems, checks):
    used = np.zeros(len(dup), dtype=bool)
    used[simplices.ravel()] = True
    missing = int(np.count_nonzero(~used[distinct]))
    dup_used = int(np.count_nonzero(used & (dup != np.arange(len(dup)))))
    _problem(problems, checks, "all_points_used", missing or dup_used,
             f"{missing} distinct points are not vertices, {dup_used} duplicates are")


def _problem(problems, checks, name, bad, sentence):
    checks[name] = not bad
    if bad:
        problems.append(sentence)


def verify(points, tri):
    """Exactly check that ``tri`` is the Delaunay triangulation of ``points``.

    Works for any :class:`Triangulation` (or object with ``simplices``,
    ``neighbors``, ``hull`` and optionally ``duplicate_of``), whoever built
    it.  Returns a :class:`VerifyReport`.
    """
    if np.asarray(points).ndim == 2 and np.asarray(points).shape[1] == 3:
        return _verify_3d(exact_points3(points), tri)
    xs, ys = exact_coordinates2d(points)
    n = xs.shape[0]
    start = _start(np.column_stack((xs, ys)), tri, "triangles")
    if isinstance(start, VerifyReport):
        return start
    hull = np.asarray([] if tri.hull is None else tri.hull, dtype=np.int64)
    simplices, neighbors, dup, distinct, problems, checks, counts = start

    if len(simplices) == 0:
        degenerate = bool(getattr(tri, "degenerate", True))
        _problem(problems, checks, "flag", not degenerate, "no triangles but not flagged degenerate")
        if len(distinct):
            order = np.lexsort((ys[distinct], xs[distinct]))
            lo, hi = distinct[order[0]], distinct[order[-1]]
            collinear = len(distinct) < 3 or _all_collinear(xs, ys, distinct, lo, hi)
            _problem(problems, checks, "collinear", not collinear,
                     "no triangles although the distinct points are not collinear")
            expect = {int(lo), int(hi)}
            _problem(problems, checks, "hull", set(map(int, hull)) != expect or len(hull) != len(expect),
                     f"hull of a degenerate set must be its extreme points {sorted(expect)}")
        return VerifyReport(not problems, checks, problems, counts)

    (bad_orient, bad_nb, dup_directed, boundary_rev, loop_fail, reflex, winding, not_delaunay,
     first_bad, n_boundary, start, out_next) = _check_mesh(xs, ys, simplices, neighbors, n)
    counts.update(bad_orientation=int(bad_orient), bad_neighbors=int(bad_nb),
                  duplicate_directed_edges=int(dup_directed), boundary_edges=int(n_boundary),
                  reflex_hull_turns=int(reflex), hull_winding=int(winding),
                  non_delaunay_edges=int(not_delaunay), first_bad_triangle=int(first_bad))
    _problem(problems, checks, "orientation", bad_orient,
             f"{bad_orient} triangles are not strictly counter-clockwise")
    _problem(problems, checks, "manifold", bad_nb or dup_directed or boundary_rev,
             f"edge structure broken: {bad_nb} asymmetric neighbours, {dup_directed} repeated "
             f"directed edges, {boundary_rev} hull edges with a reverse")
    _problem(problems, checks, "convex_boundary", loop_fail or reflex or winding != 1,
             f"boundary is not one convex loop ({loop_fail} loop faults, {reflex} reflex turns, "
             f"winding {winding})")
    checks["coverage"] = checks["orientation"] and checks["manifold"] and checks["convex_boundary"]
    _problem(problems, checks, "delaunay", not_delaunay, f"{not_delaunay} interior edges are not locally Delaunay")
    _check_points_used(simplices, dup, distinct, problems, checks)
    hull_ok = len(hull) == n_boundary and n_boundary > 0
    if hull_ok:
        nxt = np.roll(hull, -1)
        hull_ok = bool(np.all(out_next[hull] == nxt))
    _problem(problems, checks, "hull", not hull_ok, "hull is not the counter-clockwise boundary loop")
    return VerifyReport(not problems, checks, problems, counts)


def _verify_3d(P, tri):
    start = _start(P, tri, "tetrahedra")
    if isinstance(start, VerifyReport):
        return start
    simplices, neighbors, dup, distinct, problems, checks, counts = start
    if len(simplices) == 0:
        _problem(problems, checks, "flag", not getattr(tri, "degenerate", True),
                 "no tetrahedra but not flagged degenerate")
        return VerifyReport(not problems, checks, problems, counts)
    boundary = _verify3(P, simplices, neighbors, problems, checks, counts)
    _check_points_used(simplices, dup, distinct, problems, checks)
    hull = getattr(tri, "hull", None)
    hull = boundary if hull is None else np.asarray(hull)
    if hull.ndim == 2 and hull.shape[1] == 3:
        same = {tuple(np.roll(f, -int(np.argmin(f)))) for f in boundary.tolist()} == \
            {tuple(np.roll(f, -int(np.argmin(f)))) for f in hull.tolist()}
        _problem(problems, checks, "hull", not same, "hull facets differ from the boundary faces")
    return VerifyReport(not problems, checks, problems, counts)


def mesh_from_simplices(simplices, n):
    """A Triangulation of ``n`` points from bare ``simplices`` (another
    library's output, such as CGAL's or Triangle's): neighbours by matching
    faces, and the hull (2D: the counter-clockwise loop of boundary edges;
    3D: the unmatched outward faces), so that :func:`verify` can check it.
    Faces that do not pair up are left for verify to reject."""
    s = np.asarray(simplices, dtype=np.int64)
    m, width = s.shape if s.ndim == 2 else (0, 3)
    if width == 3:
        # face i of triangle t is the directed edge v[i+1] -> v[i+2]; its twin runs back
        a, b = s[:, [1, 2, 0]].ravel(), s[:, [2, 0, 1]].ravel()
        own, twin = a * n + b, b * n + a
    else:
        faces = _oriented_faces(s)
        srt = np.sort(faces, axis=1)
        key = (srt[:, 0] * n + srt[:, 1]) * n + srt[:, 2]
        own = twin = key
    order = np.argsort(own, kind="stable")
    pos = np.searchsorted(own[order], twin)
    pos = np.minimum(pos, max(len(order) - 1, 0))
    hit = order[pos] if len(order) else pos
    found = (own[hit] == twin) if len(order) else np.zeros(0, bool)
    if width == 4:  # the same sorted face in another cell
        other = np.where(hit // 4 == np.arange(len(own)) // 4,
                         order[np.minimum(pos + 1, len(order) - 1)], hit)
        found = found & (own[other] == own) & (other // 4 != np.arange(len(own)) // 4)
        hit = other
    neighbors = np.where(found, hit // width, -1).reshape(m, width)
    if width == 4:
        hull = faces[~found]
    else:
        nxt = dict(zip(a[~found].tolist(), b[~found].tolist()))
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
                         duplicate_of=np.arange(n), degenerate=m == 0)
