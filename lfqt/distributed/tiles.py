"""The work of one tile in Tile & Merge (Caraffa, Memari, Yirci and Brédif
2019; proof of consistency: Brédif et al., ISPRS Annals 2020): triangulate
the tile's own points with those it has received, and send to every other
tile j the vertices of each face whose closed circumdisk meets j's box.

A tile's state is what it holds beyond its own points: the foreign points
(global id, coordinates, home tile) and, per tile, the ids already sent
there.  Both only grow, so the rounds end.

Why the stars are right when no tile sends anything new (v local to tile i,
F a face of i's Delaunay subdivision around v, p a point of tile j in F's
closed disk but unknown to i): F's disk meets j's box, so j holds F's
vertices and p.  F is then no face of j's subdivision, so some face F'
around v there has a vertex q in F's closed disk (the star of v depends
only on v's neighbours).  F' has v on its circle, so its disk meets i's box
and j sent q to i: q would make F no face of i's subdivision either.  The
rule is applied to faces with a vertex of the sender or of the receiver,
which is all the argument uses; the hull's infinite faces count, as
closed outer half-planes.
"""
import numpy as np

from ..dc import triangulate
from . import geometry, partition, shuffle
from .engine import _peak_rss

EMPTY_IDS = np.empty(0, dtype=np.int64)


def new_state(tiles):
    """Nothing received or sent; ``keep`` (after the first round): the local
    points later rounds triangulate, ``frontier`` those of them whose star
    may still change."""
    return dict(ids=EMPTY_IDS, P=np.empty((0, 2)), home=EMPTY_IDS,
                sent=[EMPTY_IDS] * tiles, rounds=0, keep=None, frontier=None)


def _own(local, state):
    """(P, ids) of the tile's own points that the round triangulates: all
    of them, read from the partition's files, until the tile is sealed;
    then those it kept (few, held in its state)."""
    if state["keep"] is None:
        mine = partition.load(local)
        return mine["P"], mine["ids"]
    return state["kP"], state["kid"]


def _mesh(lp, lid, state):
    """The triangulation of the tile's own points ``lp`` (ids ``lid``) and
    its foreign points: (P, gid, home, Triangulation), vertices local
    first, each part sorted by global id."""
    P = np.concatenate((lp, state["P"]))
    gid = np.concatenate((lid, state["ids"]))
    home = np.concatenate((np.full(len(lid), -1, dtype=np.int64), state["home"]))
    return P, gid, home, triangulate(P, threads=1, counters=False)


def _receive(state, inbox):
    """state with the inbox's new foreign points added."""
    if not inbox:
        return state
    ids = np.concatenate([m[0] for m in inbox] + [state["ids"]])
    P = np.concatenate([m[1] for m in inbox] + [state["P"]])
    home = np.concatenate([m[2] for m in inbox] + [state["home"]])
    ids, first = np.unique(ids, return_index=True)
    return dict(state, ids=ids, P=P[first], home=home[first])


def _face_groups(tri, P):
    """(face of each triangle, triangle order grouped by face, group starts)."""
    face = geometry.faces(P, tri.simplices, tri.neighbors)
    order = np.argsort(face, kind="stable")
    starts = np.flatnonzero(np.r_[True, face[order][1:] != face[order][:-1], True])
    return face, order, starts


def _outgoing(P, home, tri, groups, cell, boxes, me, frontier, hull=True):
    """(vertex, tile) pairs to send, before removing what was sent already,
    and per face whether its disk is strictly inside the cell:
    faces with a vertex of the sender or the receiver, and a vertex on the
    frontier (the others are final or, once the sealed interior is left
    out, not faces of the tile's triangulation at all)."""
    tiles = len(boxes)
    if tri.degenerate:  # collinear or tiny: all of it is one face reaching everywhere
        others = [j for j in range(tiles) if j != me and not np.isnan(boxes[j, 0])]
        v = np.repeat(np.arange(len(P)), len(others))
        return v, np.tile(np.array(others, dtype=np.int64), len(P)), None
    S = tri.simplices
    face, order, starts = groups
    roots = face[order[starts[:-1]]]
    f, j, inside = geometry.reach(P, S, roots, cell, boxes, me)
    # every vertex of every face that reaches j: triangles of the face x 3
    size = np.diff(starts)[f]
    tri_idx = order[np.repeat(starts[:-1][f], size) + _ramp(size)]
    v = S[tri_idx].ravel()
    j = np.repeat(np.repeat(j, size), 3)
    hv, hj, hface = (_hull_pairs(P, np.asarray(tri.hull, dtype=np.int64), boxes, me) if hull
                     else (EMPTY_IDS, EMPTY_IDS, EMPTY_IDS))
    v, j = np.concatenate((v, hv)), np.concatenate((j, hj))
    # keep the faces with a vertex of the sender or of the receiver
    owner = np.where(home[v] < 0, me, home[v])
    face_id = np.concatenate((np.repeat(np.repeat(np.arange(len(f)), size), 3), len(f) + hface))
    pair = face_id * len(boxes) + j
    ok = ((owner == me) | (owner == j))
    good_pairs = np.intersect1d(pair[ok], pair[frontier[v]])
    keep = np.isin(pair, good_pairs)
    return v[keep], j[keep], inside


def _ramp(size):
    """0..size[0]-1, 0..size[1]-1, ... concatenated."""
    if not len(size):
        return np.empty(0, dtype=np.int64)
    ends = np.cumsum(size)
    return np.arange(ends[-1]) - np.repeat(ends - size, size)


def _hull_pairs(P, hull, boxes, me):
    """(vertex, tile, run) for each run of collinear hull edges (an infinite
    face) and each tile its closed outer half-plane meets."""
    run = geometry.hull_runs(P, hull)
    vs, js, rs = [], [], []
    for r in np.unique(run):
        edges = np.flatnonzero(run == r)
        verts = np.unique(np.concatenate((hull[edges], hull[(edges + 1) % len(hull)])))
        for j in geometry.beyond(P, hull[r], hull[(r + 1) % len(hull)], boxes, me):
            vs.append(verts)
            js.append(np.full(len(verts), j))
            rs.append(np.full(len(verts), r))
    if not vs:
        return EMPTY_IDS, EMPTY_IDS, EMPTY_IDS
    return np.concatenate(vs), np.concatenate(js), np.concatenate(rs)


def step(me, local, state, inbox, cell, boxes, out=None, near=None):
    """One round of tile ``me``: (new state, outbox {tile: (ids, P, home)},
    summary).  With ``out``, the sealed interior's triangles wait there
    rather than in the worker's memory.  ``near`` (the driver's first
    phase): send only to these tiles, and leave the hull's infinite faces
    out; until its neighbours' points close it, a tile's border is a chain
    of slivers whose huge disks, like its hull's half-planes, reach half the
    tiles."""
    hull = near is None
    if near is not None:
        boxes = np.where(near[:, None], boxes, np.nan)
    state = _receive(state, inbox)
    P, gid, home, tri = _mesh(*_own(local, state), state)
    groups = None if tri.degenerate else _face_groups(tri, P)
    n_local = int(np.count_nonzero(home < 0))
    v, j, inside = _outgoing(P, home, tri, groups, cell, boxes, me, _frontier(state, len(P)),
                             hull)
    if state["frontier"] is None and not tri.degenerate:
        state = _seal(state, P, gid, home, tri, groups, inside, n_local)
        if out is not None:
            from pathlib import Path
            path = Path(out) / f"tile-{me:05d}.interior.npy"
            interior = state["interior"]
            if not len(interior) or interior.max() <= np.iinfo(np.int32).max:
                interior = interior.astype(np.int32)  # half the disk while it waits
            with shuffle.writing(path):
                np.save(path, interior)
            state["interior"] = str(path)
    send_home = np.where(home < 0, me, home)
    ok = send_home[v] != j  # a tile knows its own points
    v, j = v[ok], j[ok]
    sent = list(state["sent"])
    outbox = {}
    for t in np.unique(j):
        ids = np.unique(gid[v[j == t]])
        new = ids[~np.isin(ids, sent[t], assume_unique=True)]
        if len(new):
            sent[t] = np.union1d(sent[t], new)
            rows = _rows(gid, n_local, new)
            outbox[int(t)] = (new, P[rows], send_home[rows])
    state = dict(state, sent=sent, rounds=state["rounds"] + 1)
    summary = dict(tile=me, points=len(P), foreign=len(state["ids"]),
                   triangles=len(tri.simplices), sent={t: len(m[0]) for t, m in outbox.items()},
                   peak_rss=_peak_rss())
    return state, outbox, summary


def _frontier(state, n):
    """Per vertex of the tile's mesh (n of them, local first): may its star
    still change?  All of them until the tile is sealed; foreign points
    always."""
    if state["frontier"] is None:
        return np.ones(n, dtype=bool)
    return np.concatenate((state["frontier"], np.ones(n - len(state["frontier"]), dtype=bool)))


def _duplicates(tri, gid, n_local):
    """(ids of the local points that duplicate another, the ids that
    represent them): lfqt keeps the smallest index, here the smallest id."""
    dup = np.flatnonzero(tri.duplicate_of[:n_local] != np.arange(n_local))
    return gid[dup], gid[tri.duplicate_of[dup]]


def _seal(state, P, gid, home, tri, groups, inside, n_local):
    """After the tile's first full triangulation: the local points whose
    star may still change (``frontier``), the points later rounds need
    (those and every vertex of their faces: no local edge ever appears
    later, so the faces around the frontier stay whole, and a cocircular
    one is cut alike by every round), the duplicates, and the owned
    triangles of the final faces, which no later round recomputes."""
    S = tri.simplices
    face, order, starts = groups
    roots = face[order[starts[:-1]]]
    number = np.empty(len(S), dtype=np.int64)
    number[roots] = np.arange(len(roots))
    live = geometry.unsealed(S, number[face], inside, np.asarray(tri.hull, dtype=np.int64),
                             n_local)
    keep = np.flatnonzero(geometry.with_face_neighbours(S, live, face))
    frontier = np.concatenate((live, np.ones(len(P) - n_local, dtype=bool)))
    interior = geometry.owned(_cut(tri, P, gid, groups), gid, home, frontier, True)
    dup, rep = _duplicates(tri, gid, n_local)
    return dict(state, keep=keep, kP=P[keep], kid=gid[keep], frontier=live[keep],
                interior=interior, dup=dup, rep=rep)


def _cut(tri, P, gid, groups):
    """The triangles with every cocircular face cut as a fan from its
    smallest global id (local vertex indices)."""
    face, order, starts = groups
    return geometry.canonical(tri.simplices, tri.neighbors, face, order, starts, gid)


def _rows(gid, n_local, ids):
    """Rows of ``ids`` in the tile's vertex list (local ids sorted, then the
    foreign ids sorted)."""
    local = gid[:n_local]
    foreign = gid[n_local:]
    pos = np.searchsorted(local, ids)
    pos_ok = pos < n_local
    is_local = np.zeros(len(ids), dtype=bool)
    is_local[pos_ok] = local[pos[pos_ok]] == ids[pos_ok]
    rows = np.where(is_local, pos, n_local + np.searchsorted(foreign, ids))
    return rows


def collect(me, *outboxes):
    """Tile ``me``'s inbox: its messages from every outbox that has one."""
    return [o[me] for o in outboxes if me in o]


def finish(me, local, state, out=None, fmt="npy"):
    """The tile's share of the result: every triangle whose smallest global
    id is one of the tile's points, cocircular faces cut canonically: the
    sealed interior from the first round, the rest from the points kept.
    Returns the (m, 3) global ids, or with ``out`` the path written."""
    P, gid, home, tri = _mesh(*_own(local, state), state)
    frontier = _frontier(state, len(P))
    if state["frontier"] is None:  # never sealed: degenerate all along
        dup, rep = _duplicates(tri, gid, int(np.count_nonzero(home < 0)))
        state = dict(state, interior=np.empty((0, 3), dtype=np.int64), dup=dup, rep=rep)
    rest = (np.empty((0, 3), dtype=np.int64) if tri.degenerate else
            geometry.owned(_cut(tri, P, gid, _face_groups(tri, P)), gid, home, frontier,
                           False))
    interior = state["interior"]
    if isinstance(interior, str):  # waiting in a file of ``out`` (step)
        interior = np.load(interior).astype(np.int64)
    G = np.concatenate((interior, rest))
    info = dict(tile=me, triangles=len(G), points=len(P), foreign=len(state["ids"]),
                local=local["n"], rounds=state["rounds"], peak_rss=_peak_rss(),
                duplicates=len(state["dup"]))
    if out is None:
        return G, (state["dup"], state["rep"]), info
    from pathlib import Path
    path = Path(out) / f"tile-{me:05d}.{fmt}"
    with shuffle.writing(path):
        if fmt == "npy":
            np.save(path, G)
        else:
            import pyarrow as pa
            import pyarrow.parquet as pq
            pq.write_table(pa.table({"a": G[:, 0], "b": G[:, 1], "c": G[:, 2]}), path)
    return str(path), (state["dup"], state["rep"]), info


def cleanup(state):
    """Remove the file where the sealed interior waited (after finish)."""
    if isinstance(state.get("interior"), str):
        from pathlib import Path
        Path(state["interior"]).unlink(missing_ok=True)
