"""Is a peer's mesh the Delaunay triangulation?  Judged by lfqt's exact
``verify`` (a proof, not an estimate), in the measuring child right after
the timed runs, so that a sweep learns time and correctness of the same
mesh.  The triangle count is compared with lfqt's on the same points: the
Delaunay triangulation's count is fixed by the points (cocircular points
allow other triangulations, all of the same count), so a shortfall is
triangles the peer dropped."""
import numpy as np

EXACT, WRONG = "exact", "wrong"


def judge(points, simplices):
    """{"verdict": "exact" or "wrong", "non_delaunay_edges", "missing_triangles",
    "problems": the failed checks, "summary": verify's sentence}."""
    import lfqt
    pts = np.asarray(points, dtype=np.float64)
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


def describe(check):
    """A check as a table cell: "exact", or "wrong: 250 bad edges, 371
    missing triangles" (or the failed checks when neither is counted)."""
    if not check:
        return ""
    if check["verdict"] == EXACT:
        return EXACT
    parts = []
    if check.get("non_delaunay_edges"):
        parts.append(f"{check['non_delaunay_edges']:,} bad edges")
    if check.get("missing_triangles"):
        parts.append(f"{check['missing_triangles']:,} missing triangles")
    if not parts:
        parts = [", ".join(check.get("problems", [])) or "invalid"]
    return "wrong: " + ", ".join(parts)
