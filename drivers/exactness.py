"""Is a peer's mesh the Delaunay triangulation?  Judged by lfqt's exact
``verify`` (a proof, not an estimate), in the measuring child right after
the timed runs, so that a sweep learns time and correctness of the same
mesh.

2D: the triangle count is compared with lfqt's on the same points: the
Delaunay triangulation's count is fixed by the points (cocircular points
allow other triangulations, all of the same count), so a shortfall is
triangles the peer dropped.  3D: the tetrahedron count is not fixed where
five points are cospherical (a cube's corners take 5 or 6), so a wrong
mesh is described by what verify counts: flat tetrahedra, faces that are
not locally Delaunay, repeated faces, reflex hull edges (tetrahedra missing
along the hull), points left out; lfqt's count is recorded beside the
peer's only for a wrong mesh."""
import numpy as np

EXACT, WRONG = "exact", "wrong"
# verify's 3D counts a wrong mesh is described by, and how a table says them
COUNTS_3D = {"flat": "flat tetrahedra", "non_delaunay_faces": "non-Delaunay faces",
             "repeated_oriented_faces": "repeated faces", "reflex_hull_edges": "reflex hull edges"}


def judge(points, simplices):
    """2D: {"verdict": "exact" or "wrong", "non_delaunay_edges",
    "missing_triangles", "problems": the failed checks, "summary": verify's
    sentence}.  3D: the verdict, problems and summary, each of COUNTS_3D's
    counts, "tetrahedra", and for a wrong mesh "lfqt_tetrahedra"."""
    pts = np.asarray(points, dtype=np.float64)
    if pts.ndim == 2 and pts.shape[1] == 3:
        return _judge3(pts, simplices)
    import lfqt
    s = np.asarray(simplices if simplices is not None else np.empty((0, 3)), dtype=np.int64)
    report = lfqt.verify(pts, s.reshape(-1, 3))
    try:
        expected = len(lfqt.triangulate(pts, counters=False).simplices)
    except Exception:  # noqa: BLE001 - lfqt refusing the set is lfqt's own verdict elsewhere
        expected = None
    missing = max(expected - len(s), 0) if expected is not None else None
    return {"verdict": EXACT if report.ok else WRONG,
            "non_delaunay_edges": int(report.counts.get("non_delaunay_edges") or 0),
            "missing_triangles": missing,
            "problems": sorted(k for k, ok in report.checks.items() if not ok),
            "summary": report.summary[:300]}


def _judge3(pts, simplices):
    import lfqt
    s = np.asarray(simplices if simplices is not None else np.empty((0, 4)), dtype=np.int64)
    report = lfqt.verify(pts, s.reshape(-1, 4))
    out = {"verdict": EXACT if report.ok else WRONG,
           "problems": sorted(k for k, ok in report.checks.items() if not ok),
           "summary": report.summary[:300], "tetrahedra": int(len(s)),
           **{k: int(report.counts.get(k) or 0) for k in COUNTS_3D}}
    if not report.ok:
        try:
            out["lfqt_tetrahedra"] = int(len(lfqt.insert(pts, counters=False).simplices))
        except Exception:  # noqa: BLE001 - lfqt refusing the set is lfqt's own verdict elsewhere
            out["lfqt_tetrahedra"] = None
    return out


def describe(check):
    """A check as a table cell: "exact", or "wrong: 250 bad edges, 371
    missing triangles" (3D: "wrong: 9,085 flat tetrahedra, ..."; or the
    failed checks when nothing is counted)."""
    if not check:
        return ""
    if check["verdict"] == EXACT:
        return EXACT
    parts = []
    if check.get("non_delaunay_edges"):
        parts.append(f"{check['non_delaunay_edges']:,} bad edges")
    if check.get("missing_triangles"):
        parts.append(f"{check['missing_triangles']:,} missing triangles")
    parts += [f"{check[k]:,} {what}" for k, what in COUNTS_3D.items() if check.get(k)]
    if check.get("tetrahedra") == 0:
        parts.append("no tetrahedra")
    if not parts:
        parts = [", ".join(check.get("problems", [])) or "invalid"]
    return "wrong: " + ", ".join(parts)
