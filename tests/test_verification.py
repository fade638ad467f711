"""verify must accept correct meshes from anyone and reject every kind of
broken one."""
import copy
import itertools

import numpy as np
import pytest
import scipy.spatial
from hypothesis import assume, given, strategies as st

import lfqt
import lfqt.verification
from conftest import triangulate_verified, without_cell


@pytest.fixture
def good(rng):
    pts = rng.random((300, 2))
    return pts, triangulate_verified(pts)


def broken(tri, **changes):
    out = copy.copy(tri)
    for k, v in changes.items():
        setattr(out, k, v)
    return out


def test_accepts_scipy_triangulation(rng):
    pts = rng.random((500, 2))
    d = scipy.spatial.Delaunay(pts)
    # scipy's hull edges are unordered and undirected: chain them, then orient
    adj = {}
    for a, b in d.convex_hull:
        adj.setdefault(a, []).append(b)
        adj.setdefault(b, []).append(a)
    loop = [d.convex_hull[0, 0], d.convex_hull[0, 1]]
    while True:
        a, b = adj[loop[-1]]
        nxt = a if a != loop[-2] else b
        if nxt == loop[0]:
            break
        loop.append(nxt)
    ring = np.array(loop)
    area = np.sum(pts[ring, 0] * np.roll(pts[ring, 1], -1) - np.roll(pts[ring, 0], -1) * pts[ring, 1])
    if area < 0:
        ring = ring[::-1]

    class Mesh:
        simplices = d.simplices
        neighbors = d.neighbors
        hull = ring
    assert lfqt.verify(pts, Mesh()).ok


def test_rejects_clockwise_triangle(good):
    pts, tri = good
    s = tri.simplices.copy()
    s[5] = s[5, ::-1]
    rep = lfqt.verify(pts, broken(tri, simplices=s))
    assert not rep.ok and not rep.checks["orientation"]


def test_rejects_missing_triangle(good):
    pts, tri = good
    rep = lfqt.verify(pts, without_cell(tri, np.flatnonzero((tri.neighbors >= 0).all(axis=1))[0]))
    assert not rep.ok and not rep.checks["convex_boundary"]


def test_rejects_flipped_edge(good):
    pts, tri = good
    s, nb = tri.simplices.copy(), tri.neighbors.copy()
    t = np.flatnonzero((nb >= 0).all(axis=1))[0]
    i = 0
    u = nb[t, i]
    a, b, c = s[t, 0], s[t, 1], s[t, 2]  # edge b-c opposite a
    j = [k for k in range(3) if nb[u, k] == t][0]
    d = s[u, j]
    # flip edge b-c to a-d; stays a valid triangulation only if convex, so check orientation too
    s[t] = [a, b, d]
    s[u] = [d, c, a]
    rep = lfqt.verify(pts, broken(tri, simplices=s))
    assert not rep.ok


def test_rejects_non_delaunay_but_valid_triangulation():
    # Square split along the wrong diagonal of a non-cocircular quad.
    pts = np.array([[0.0, 0.0], [2.0, 0.0], [2.1, 1.0], [0.0, 1.0]])
    tri = lfqt.triangulate(pts)
    s = tri.simplices
    assert lfqt.verify(pts, tri).ok
    # the other diagonal
    diag = set(s[0]) & set(s[1])
    other = [v for v in range(4) if v not in diag]
    p, q = sorted(diag)
    t1 = [other[0], p, other[1]]
    t2 = [other[1], q, other[0]]
    fix = []
    for t in (t1, t2):
        a, b, c = pts[t]
        area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
        fix.append(t if area > 0 else t[::-1])
    s2 = np.array(fix)
    nb = np.full((2, 3), -1)
    for k, t in enumerate(s2):
        for i in range(3):
            if set(t) - {t[i]} == set(other):
                nb[k, i] = 1 - k
    rep = lfqt.verify(pts, broken(tri, simplices=s2, neighbors=nb))
    assert not rep.ok and rep.checks["orientation"] and not rep.checks["delaunay"]


def test_rejects_unused_point(good):
    pts, tri = good
    extra = np.r_[pts, [[0.5, 0.5 + 1e-9]]]
    rep = lfqt.verify(extra, broken(tri, duplicate_of=np.arange(len(extra))))
    assert not rep.ok and not rep.checks["all_points_used"]


def test_rejects_wrong_hull(good):
    pts, tri = good
    rep = lfqt.verify(pts, broken(tri, hull=tri.hull[::-1]))
    assert not rep.ok and not rep.checks["hull"]


def test_rejects_bogus_duplicate_map(good):
    pts, tri = good
    dup = tri.duplicate_of.copy()
    dup[3] = 4
    rep = lfqt.verify(pts, broken(tri, duplicate_of=dup))
    assert not rep.ok and not rep.checks["duplicates"]


def test_rejects_unflagged_empty_mesh():
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    tri = lfqt.triangulate(pts)
    empty = broken(tri, simplices=np.empty((0, 3), int), neighbors=np.empty((0, 3), int),
                   degenerate=True, hull=tri.hull[:2])
    rep = lfqt.verify(pts, empty)
    assert not rep.ok and not rep.checks["collinear"]


def test_report_raises_with_reasons(good):
    pts, tri = good
    s = tri.simplices.copy()
    s[0] = s[0, ::-1]
    with pytest.raises(AssertionError, match="counter-clockwise"):
        lfqt.verify(pts, broken(tri, simplices=s)).raise_if_invalid()


@pytest.mark.parametrize("break_it", ["short_neighbors", "long_neighbors", "hull_out_of_range",
                                      "simplices_wrong_width", "neighbors_out_of_range",
                                      "float_simplices", "duplicate_of_short", "no_simplices"])
def test_malformed_arrays_are_reported_never_raised(break_it, rng):
    pts = rng.random((300, 2))
    tri = copy.copy(lfqt.triangulate(pts))
    if break_it == "short_neighbors":
        tri.neighbors = tri.neighbors[:-5]  # a truncated view must not pass as ok
    elif break_it == "long_neighbors":
        tri.neighbors = np.r_[tri.neighbors, tri.neighbors[:3]]
    elif break_it == "hull_out_of_range":
        tri.hull = np.r_[tri.hull, 10 ** 6]
    elif break_it == "simplices_wrong_width":
        tri.simplices = tri.simplices[:, :2]
    elif break_it == "neighbors_out_of_range":
        tri.neighbors = tri.neighbors.copy()
        tri.neighbors[0, 0] = len(tri.simplices) + 7
    elif break_it == "float_simplices":
        tri.simplices = tri.simplices + 0.5
    elif break_it == "duplicate_of_short":
        tri.duplicate_of = tri.duplicate_of[:10]
    else:
        tri.simplices = None
    report = lfqt.verify(pts, tri)
    assert not report.ok and report.problems and not report.checks["indices"]


def test_mesh_from_simplices_lets_verify_check_bare_simplices(rng):
    from lfqt.verification import mesh_from_simplices
    for d in (2, 3):
        pts = rng.random((500, d))
        s = lfqt.insert(pts).simplices
        assert lfqt.verify(pts, mesh_from_simplices(s, len(pts))).ok
        assert not lfqt.verify(pts, mesh_from_simplices(s[1:], len(pts))).ok


# -- every form verify reads: lfqt's, scipy's, bare simplices ---------------

KIND = {2: "triangles", 3: "tetrahedra"}
N_GENERIC = {2: 2000, 3: 1000}


def orientation_signs(p, s):
    """Float orientation signs; exact enough on generic random points."""
    q = p[np.asarray(s)]
    return np.sign(np.linalg.det(q[:, 1:] - q[:, :1]))


def positive(p, s):
    """``s`` with two vertices swapped in each negatively oriented simplex."""
    s = np.array(s, dtype=np.int64)
    neg = orientation_signs(p, s) < 0
    s[neg, :2] = s[neg, 1::-1]
    return s


def shuffled_tuples(s, rng):
    """A hand-built mesh: a list of tuples, each in a random vertex order
    (so about half of them reversed)."""
    return [tuple(int(v) for v in rng.permutation(t)) for t in np.asarray(s)]


def simplex_set(s):
    return {frozenset(map(int, t)) for t in np.asarray(s)}


def ours(p):
    return lfqt.triangulate(p) if p.shape[1] == 2 else lfqt.insert(p)


@pytest.fixture(scope="module", params=[2, 3], ids=["2d", "3d"])
def generic(request):
    """Generic random points (their Delaunay triangulation is unique) and
    scipy's mesh of them."""
    dim = request.param
    p = np.random.default_rng(56).random((N_GENERIC[dim], dim))
    return p, scipy.spatial.Delaunay(p)


def test_verifies_scipys_own_output(generic):
    """The README's claim, on scipy's 2D and 3D output as scipy returns it:
    about half of its 3D tetrahedra are left-handed, which is named, not
    held against it."""
    p, d = generic
    dim = p.shape[1]
    report = lfqt.verify(p, d)
    assert report.ok, report.problems
    assert report.counts[KIND[dim]] == d.nsimplex and report.checks["hull"]
    reversed_ = report.counts["reversed"]
    assert report.summary.startswith(f"valid Delaunay triangulation ({d.nsimplex} {KIND[dim]})")
    if dim == 3:
        assert d.nsimplex / 4 < reversed_ < 3 * d.nsimplex / 4
        assert report.notes == [f"{reversed_} tetrahedra negatively oriented"]
        assert f"{reversed_} tetrahedra negatively oriented" in report.summary
        strict = lfqt.verify(p, d, orientation="strict")
        assert not strict.ok and not strict.checks["orientation"]
        assert strict.counts["reversed"] == reversed_
    assert reversed_ == np.count_nonzero(orientation_signs(p, d.simplices) < 0)


def test_same_verdict_in_every_form(generic):
    p, d = generic
    dim = p.shape[1]
    rng = np.random.default_rng(1)
    forms = {"scipy": d, "lfqt.Delaunay": lfqt.Delaunay(p), "lfqt": ours(p),
             "lfqt.insert": lfqt.insert(p), "tuples": shuffled_tuples(d.simplices, rng),
             "tuples of lfqt's": tuple(shuffled_tuples(ours(p).simplices, rng)),
             "array": np.asarray(d.simplices)}
    reports = {name: lfqt.verify(p, tri) for name, tri in forms.items()}
    assert {name: r.ok for name, r in reports.items()} == dict.fromkeys(forms, True)
    assert {r.counts[KIND[dim]] for r in reports.values()} == {d.nsimplex}
    assert {r.counts["duplicates"] for r in reports.values()} == {0}
    # the same triangulation in each form, so the verdicts are about one mesh
    for name in ("lfqt.Delaunay", "lfqt", "lfqt.insert"):
        assert simplex_set(forms[name].simplices) == simplex_set(d.simplices), name
    assert reports["tuples"].counts["reversed"] > d.nsimplex / 4  # shuffling reversed many


def flipped_2d(p, s):
    """A valid triangulation that is not Delaunay: one interior edge of a
    convex quadrilateral flipped."""
    s = positive(p, s)
    nb = lfqt.verification.mesh_from_simplices(s, len(p)).neighbors
    for t, i in zip(*np.nonzero(nb >= 0)):
        u = nb[t, i]
        a, b, c = s[t, i], s[t, (i + 1) % 3], s[t, (i + 2) % 3]  # edge b-c, opposite a
        e = next(v for v in s[u] if v not in (b, c))
        new = np.array([[a, b, e], [a, e, c]])
        if (orientation_signs(p, new) > 0).all():  # a, b, e, c convex: the flip is valid
            out = s.copy()
            out[t], out[u] = new
            return out
    raise AssertionError("no flippable edge")


def flipped_3d(p, s):
    """A valid triangulation that is not Delaunay: a 2-3 flip of two cells
    a b c d and a b c e whose union is convex (d-e crosses a b c)."""
    s = positive(p, s)
    nb = lfqt.verification.mesh_from_simplices(s, len(p)).neighbors
    for t, i in zip(*np.nonzero(nb >= 0)):
        u = nb[t, i]
        d = s[t, i]
        a, b, c = [v for v in s[t] if v != d]
        e = next(v for v in s[u] if v not in (a, b, c))
        new = np.array([[d, e, a, b], [d, e, b, c], [d, e, c, a]])
        if abs(orientation_signs(p, new).sum()) == 3:
            keep = np.ones(len(s), bool)
            keep[[t, u]] = False
            return np.concatenate([s[keep], positive(p, new)])
    raise AssertionError("no 2-3 flip")


def test_non_delaunay_mesh_is_rejected_in_every_form(generic):
    """The same non-Delaunay triangulation, valid in every other respect,
    fails the Delaunay check alone whatever form it is passed in."""
    p, d = generic
    dim = p.shape[1]
    rng = np.random.default_rng(2)
    bad = (flipped_2d if dim == 2 else flipped_3d)(p, d.simplices)
    assert len(simplex_set(bad)) == len(bad) and simplex_set(bad) != simplex_set(d.simplices)
    tri = lfqt.verification.mesh_from_simplices(bad, len(p))
    dl = lfqt.Delaunay(p)
    dl._tri = tri  # the Triangulation an lfqt.Delaunay wraps is what verify reads
    sp = scipy.spatial.Delaunay(p)
    mixed = bad.copy()
    if dim == 3:  # scipy's own habit: rows of either orientation (faces match either way)
        flip = rng.random(len(mixed)) < 0.5
        mixed[flip, :2] = mixed[flip, 1::-1]
    sp.simplices, sp.nsimplex = mixed.astype(np.intc), len(mixed)  # scipy's convex_hull reads both
    sp.neighbors = lfqt.verification.mesh_from_simplices(mixed, len(p)).neighbors.astype(np.intc)
    forms = {"tuples": shuffled_tuples(bad, rng), "array": bad.astype(np.int32),
             "Triangulation": tri, "lfqt.Delaunay": dl, "scipy": sp}
    for name, form in forms.items():
        report = lfqt.verify(p, form)
        assert not report.ok, name
        assert [k for k, v in report.checks.items() if not v] == ["delaunay"], (name, report)
        assert report.summary.startswith("not the Delaunay triangulation: "), name
        assert report.counts[KIND[dim]] == len(bad)


def two_triangulations(p, s):
    """The other triangulation of dim + 2 points in convex position (a
    circuit has exactly two): the other diagonal in 2D, the 2-3 or 3-2
    flip in 3D."""
    common = sorted(set.intersection(*[set(map(int, t)) for t in s]))
    rest = sorted(set(range(len(p))) - set(common))
    if len(common) == 2:  # a diagonal (2D) or an edge of three cells: it goes, the rest join
        return [rest + [v] for v in common]
    return [rest + list(pair) for pair in itertools.combinations(common, 2)]  # face a b c goes


@given(seed=st.integers(0, 2 ** 32 - 1), dim=st.sampled_from([2, 3]))
def test_exactly_one_triangulation_of_a_circuit_passes(seed, dim):
    """dim + 2 points in convex position have two triangulations, and for
    generic points exactly one is Delaunay: verify accepts it in every
    form and rejects the other in every form."""
    rng = np.random.default_rng(seed)
    p = rng.random((dim + 2, dim))
    d = scipy.spatial.Delaunay(p)
    # in convex position: every point a vertex, and no fan around an inner point
    assume(len(np.unique(d.simplices)) == dim + 2 and d.nsimplex in ((2,) if dim == 2 else (2, 3)))
    other = two_triangulations(p, d.simplices)
    assert len(other) == (2 if dim == 2 else 5 - d.nsimplex)
    assert simplex_set(ours(p).simplices) == simplex_set(d.simplices)
    sp = scipy.spatial.Delaunay(p)
    sp.simplices, sp.nsimplex = positive(p, other).astype(np.intc), len(other)
    sp.neighbors = lfqt.verification.mesh_from_simplices(sp.simplices, len(p)).neighbors.astype(
        np.intc)
    for s, scipy_form, expect in ((d.simplices, d, True), (other, sp, False)):
        for form in (scipy_form, shuffled_tuples(s, rng),
                     lfqt.verification.mesh_from_simplices(positive(p, s), len(p))):
            report = lfqt.verify(p, form)
            assert report.ok == expect, (form, report.problems)
            assert [k for k, v in report.checks.items() if not v] == ([] if expect else
                                                                       ["delaunay"])


@pytest.mark.parametrize("dtype", [np.int8, np.int16, np.int32, np.int64, np.uint8, np.uint16,
                                   np.uint32, np.uint64, np.intc, "list", "tuple", "lists"])
@pytest.mark.parametrize("dim", [2, 3])
def test_bare_simplices_of_any_integer_type(dtype, dim):
    p = np.random.default_rng(7).random((40, dim))  # 40 points: int8 holds every index
    s = ours(p).simplices
    if dtype == "list":
        bare = [tuple(map(int, t)) for t in s]
    elif dtype == "tuple":
        bare = tuple(tuple(map(int, t)) for t in s)
    elif dtype == "lists":
        bare = s.tolist()
    else:
        bare = s.astype(dtype)
    report = lfqt.verify(p, bare)
    assert report.ok and report.counts[KIND[dim]] == len(s), report.problems
    assert "hull" not in report.checks  # bare simplices state no hull to compare


@given(seed=st.integers(0, 2 ** 32 - 1), n=st.integers(5, 60), extra=st.integers(1, 20),
       dim=st.sampled_from([2, 3]))
def test_meshes_of_points_with_duplicates(seed, n, extra, dim):
    """scipy leaves repeated rows out (in ``coplanar``) and keeps whichever
    twin it meets; verify infers the duplicates from the coordinates, in
    every form, and still catches a mesh that uses two twins or none."""
    rng = np.random.default_rng(seed)
    base = rng.random((n, dim))
    p = np.concatenate([base, base[rng.integers(0, n, extra)]])[rng.permutation(n + extra)]
    d = scipy.spatial.Delaunay(p)
    assume(len(np.unique(d.simplices)) == n)  # scipy kept every distinct point
    for form in (d, lfqt.Delaunay(p), ours(p), shuffled_tuples(d.simplices, rng),
                 ours(p).simplices.astype(np.uint32)):
        report = lfqt.verify(p, form)
        assert report.ok, report.problems
        assert report.counts["duplicates"] == extra
    # a vertex's twin swapped in for it in one of its simplices: two twins used
    s = d.simplices.copy()
    uses = np.bincount(s.ravel(), minlength=len(p))
    v, w = max(((v, w) for v in np.unique(s) for w in range(len(p))
                if w != v and (p[w] == p[v]).all()), key=lambda vw: uses[vw[0]])
    if uses[v] > 1:
        t = np.flatnonzero((s == v).any(axis=1))[0]
        s[t][s[t] == v] = w
        report = lfqt.verify(p, s)
        assert not report.ok and not report.checks["all_points_used"]
    # the twin swapped in everywhere: the same mesh
    s[s == v] = w
    assert lfqt.verify(p, s).ok


def test_reversed_simplices_in_our_own_output_stay_a_fault(good):
    """lfqt's Triangulation is held to counter-clockwise triangles (a
    clockwise one is a bug of lfqt); the same simplices, bare, are accepted
    with a note, and orientation= chooses either way."""
    pts, tri = good
    s, nb = tri.simplices.copy(), tri.neighbors.copy()
    s[[3, 7]], nb[[3, 7]] = s[[3, 7], ::-1], nb[[3, 7], ::-1]  # neighbour i stays opposite vertex i
    own = lfqt.verify(pts, broken(tri, simplices=s, neighbors=nb))
    assert not own.ok and not own.checks["orientation"] and own.counts["reversed"] == 2
    assert own.counts["first_bad_triangle"] == 3
    either = lfqt.verify(pts, broken(tri, simplices=s, neighbors=nb), orientation="either")
    bare = lfqt.verify(pts, s)
    for report in (either, bare):
        assert report.ok and report.counts["reversed"] == 2 and report.counts["flat"] == 0
        assert report.notes == ["2 triangles clockwise"]
        assert report.summary == (f"valid Delaunay triangulation ({len(s)} triangles); "
                                  "2 triangles clockwise")
    assert (s[3] == tri.simplices[3, ::-1]).all()  # the caller's array is left as it was
    strict = lfqt.verify(pts, s, orientation="strict")
    assert not strict.ok and not strict.checks["orientation"] and strict.counts["reversed"] == 2
    one = s.copy()
    one[7] = tri.simplices[7]
    assert lfqt.verify(pts, one).notes == ["1 triangle clockwise"]


@pytest.mark.parametrize("orientation", ["auto", "either", "strict"])
def test_flat_simplices_are_never_reversed(orientation):
    """A flat simplex is no simplex: a fault in every mode, and not counted
    as reversed."""
    line = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]])
    plane = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]])
    for p, flat in ((line, [(0, 1, 2)]), (plane, [(0, 1, 2, 3)])):
        report = lfqt.verify(p, flat, orientation=orientation)
        assert not report.ok and not report.checks["orientation"]
        assert report.counts["flat"] == 1 and report.counts["reversed"] == 0
        assert any("flat" in problem for problem in report.problems)
        # and no simplices at all is their Delaunay triangulation
        assert lfqt.verify(p, [], orientation=orientation).ok


def test_no_simplices_claims_a_degenerate_set(rng):
    for dim, check in ((2, "collinear"), (3, "coplanar")):
        report = lfqt.verify(rng.random((20, dim)), [])
        assert not report.ok and not report.checks[check]
        assert not lfqt.verify(rng.random((20, dim)), np.empty((0, dim + 1), np.uint8)).ok


@pytest.mark.parametrize("tri, error, words", [
    (None, TypeError, "got NoneType"),
    ("0 1 2", TypeError, "got str"),
    ({"simplices": [(0, 1, 2)]}, TypeError, "got dict"),
    (np.array([[0.0, 1.0, 2.0]]), TypeError, "dtype float64"),
    ([[True, False, True]], TypeError, "dtype bool"),
    ([[2 ** 70, 0, 1]], TypeError, "dtype object"),
    ((t for t in [(0, 1, 2)]), TypeError, "dtype object"),
    ([[0, 1, 2], [1, 2]], ValueError, "no array"),
    ([[0, 1], [1, 2]], ValueError, r"shape \(m, 3\)"),
    ([(0, 1, 2, 3)], ValueError, r"2D points have shape \(m, 3\)"),
    (7, ValueError, r"shape \(\)"),
])
def test_input_it_cannot_read_raises_a_sentence(tri, error, words, rng):
    with pytest.raises(error, match=words) as caught:
        lfqt.verify(rng.random((10, 2)), tri)
    assert "verify reads" in str(caught.value) or "simplices of" in str(caught.value)


def test_unknown_orientation_mode_raises(good):
    pts, tri = good
    with pytest.raises(ValueError, match="orientation must be one of"):
        lfqt.verify(pts, tri, orientation="clockwise")


def test_faces_match_beyond_two_million_points():
    """3D faces are matched by their sorted vertices, not by a key
    (a * n + b) * n + c that overflows int64 beyond 2**21 points."""
    from lfqt.verification import mesh_from_simplices
    p = np.random.default_rng(3).random((60, 3))
    s = lfqt.insert(p).simplices
    far = 3_000_000
    small, big = mesh_from_simplices(s, 60), mesh_from_simplices(s + far, far + 60)
    assert np.array_equal(small.neighbors, big.neighbors)
    assert np.array_equal(small.hull + far, big.hull)


def test_docstring_examples_run():
    """As tests/test_doctests.py runs them: empty globals, each example
    importing what it uses."""
    import doctest
    from lfqt import verification
    failed, attempted = doctest.testmod(verification, globs={}, report=False,
                                        optionflags=doctest.NORMALIZE_WHITESPACE)
    assert attempted >= 10 and failed == 0


def test_a_stated_hull_that_differs_is_reported(generic):
    """scipy's convex_hull is compared as a set of facets: one left out, or
    one too many, fails the hull check alone."""
    import types
    p, d = generic
    hull = d.convex_hull
    for wrong in (hull[1:], np.r_[hull, hull[:1]], np.r_[hull[1:], d.simplices[:1, :p.shape[1]]]):
        mesh = types.SimpleNamespace(simplices=d.simplices, neighbors=d.neighbors,
                                     convex_hull=wrong)
        report = lfqt.verify(p, mesh)
        assert [k for k, v in report.checks.items() if not v] == ["hull"]
    right = types.SimpleNamespace(simplices=d.simplices, convex_hull=hull[::-1, ::-1])
    assert lfqt.verify(p, right).ok  # any order, either orientation; neighbours matched
