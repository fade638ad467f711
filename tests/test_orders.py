import numpy as np
import pytest

from lfqt import orders


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("name", orders.ORDERS)
def test_orders_are_permutations_with_inserted_hints(name, d, rng):
    pts = rng.random((777, d))
    perm, hint = orders.order(pts, name)
    assert sorted(perm.tolist()) == list(range(777))
    position = np.empty(777, dtype=int)
    position[perm] = np.arange(777)
    for k in range(777):
        assert hint[k] == -1 or position[hint[k]] < k


def test_kdtree_matches_the_papers_15_point_example():
    # A 1D-ordered line of 15 points: the BFS labels of the median tree are
    # the paper's p8, p4, p12, p2, p6, p10, p14, p1, ... (Fig. 5c).
    pts = np.c_[np.arange(1, 16, dtype=float), np.zeros(15)]
    perm, hint = orders.order(pts, "kdtree")
    assert (perm + 1).tolist() == [8, 4, 12, 2, 6, 10, 14, 1, 3, 5, 7, 9, 11, 13, 15]
    assert (hint[1:3] + 1).tolist() == [8, 8] and (hint[3:7] + 1).tolist() == [4, 4, 12, 12]


def test_kdtree_layout_is_the_trees_in_order():
    # the 15-point line: in-order of the median tree is the line itself
    pts = np.c_[np.arange(1, 16, dtype=float), np.zeros(15)][::-1]
    perm, hint, store, stored = orders.layout(pts, "kdtree")
    assert np.array_equal(pts[store, 0], np.arange(1, 16))
    assert np.array_equal(stored, pts[store])
    assert np.array_equal((perm, hint), orders.order(pts, "kdtree"))


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("kind", ["uniform", "ties", "sorted", "two values", "organ pipe"])
def test_kdtree_splits_every_range_at_its_median_on_its_longest_edge(kind, d, rng):
    n = 3000  # ranges above and below the branch-free partition's block size
    pipe = np.minimum(np.arange(n), n - np.arange(n)).astype(float)  # unbalances median of 3
    pts = {"uniform": rng.random((n, d)), "ties": rng.integers(0, 5, (n, d)).astype(float),
           "sorted": np.sort(rng.random((n, d)), axis=0),
           "two values": rng.integers(0, 2, (n, d)).astype(float),
           "organ pipe": np.c_[pipe, rng.random((n, d - 1)) * 1e-3]}[kind]
    perm, hint, store, stored = orders.layout(pts, "kdtree")
    assert np.array_equal(stored, pts[store])  # the selections' rows, left in order
    labels = []
    queue = [(0, n, -1)]
    for lo, hi, parent in queue:  # breadth first over the implicit ranges
        m = lo + (hi - lo) // 2
        sub = pts[store[lo:hi]]
        axis = int(np.argmax(sub.max(axis=0) - sub.min(axis=0)))
        key = [(pts[i, axis], i) for i in store[lo:hi]]
        assert all(k < key[m - lo] for k in key[:m - lo])
        assert all(k > key[m - lo] for k in key[m - lo + 1:])
        labels.append((store[m], parent))
        queue += [(a, b, store[m]) for a, b in ((lo, m), (m + 1, hi)) if b > a]
    assert [v for v, _ in labels] == perm.tolist()
    assert [p for _, p in labels] == hint.tolist()


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("alternate", [False, True])
@pytest.mark.parametrize("kind", ["uniform", "ties", "near ties", "signed zeros", "one point",
                                  "line"])
def test_presorted_subtrees_build_the_tree_that_selection_builds(kind, alternate, d, rng):
    # the same tree by selection alone (0), from sorted lists alone (n), or
    # both (the lists below 2, 3 or 64 points): ties by id, -0.0 equal to 0.0,
    # and values apart only below the bits that the lists' radix sort keeps
    n = 3000
    pts = {"uniform": rng.random((n, d)), "ties": rng.integers(0, 4, (n, d)).astype(float),
           "near ties": rng.integers(0, 50, (n, d)) + rng.integers(0, 3, (n, d)) * 2.0 ** -40,
           "signed zeros": rng.choice([-0.0, 0.0, 1.0, -1.0], (n, d)),
           "one point": np.full((n, d), 0.5),
           "line": np.c_[rng.random(n), np.zeros((n, d - 1))]}[kind]
    trees = [orders.kdtree_order(pts, alternate, False, presorted=k) for k in (0, 2, 3, 64, n)]
    # on threads: the top levels first, the subtrees below them apart
    trees += [orders.kdtree_order(pts, alternate, False, presorted=k, threads=t)
              for k, t in ((2, 2), (64, 3), (3, 7))]
    for perm, hint, ids, X in trees[1:]:
        assert np.array_equal(perm, trees[0][0]) and np.array_equal(hint, trees[0][1])
        assert np.array_equal(ids, trees[0][2]) and np.array_equal(X, pts[ids])


@pytest.mark.parametrize("budget", [0, 1, 3, -1])
@pytest.mark.parametrize("kind", ["uniform", "ties", "organ pipe", "sorted", "periodic"])
@pytest.mark.parametrize("n, k", [(2500, 1234), (3 * orders._SAMPLED, 200),
                                  (3 * orders._SAMPLED, 3 * orders._SAMPLED // 2),
                                  (3 * orders._SAMPLED, 3 * orders._SAMPLED - 300)])
def test_selection_past_its_pivot_budget_is_still_nth_element(n, k, kind, budget, rng):
    # budget 0: pseudo-random pivots from the first round (the guard against
    # inputs that defeat median of three); -1: the default budget.  Ranges of
    # _SAMPLED rows or more take sampled pivots (k near either end, or the
    # median), "periodic" repeating with the sample's stride.
    pipe = np.minimum(np.arange(n), n - np.arange(n)).astype(float)
    X = {"uniform": rng.random((n, 2)), "ties": rng.integers(0, 4, (n, 2)).astype(float),
         "organ pipe": np.c_[pipe, rng.random(n)],
         "sorted": np.c_[np.arange(n, dtype=float), rng.random(n)],
         "periodic": np.c_[np.arange(n) % int(np.sqrt(n - 200)), rng.random(n)]}[kind]
    ids = np.arange(n)
    Xs, ids_s = X.copy(), ids.copy()
    lo, hi = 100, n - 100
    orders._select_axis(Xs, ids_s, lo, hi, k, 0, np.empty(2 * orders._BLOCK, dtype=np.int64),
                        budget)
    assert np.array_equal(Xs, X[ids_s])  # rows moved with their ids
    assert np.array_equal(ids_s[:lo], ids[:lo]) and np.array_equal(ids_s[hi:], ids[hi:])
    key = sorted((X[i, 0], i) for i in ids[lo:hi])
    assert (X[ids_s[k], 0], ids_s[k]) == key[k - lo]
    assert all((X[i, 0], i) < key[k - lo] for i in ids_s[lo:k])
    assert all((X[i, 0], i) > key[k - lo] for i in ids_s[k + 1:hi])


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("name", orders.ORDERS)
def test_layouts_are_permutations_along_space(name, d, rng):
    pts = rng.random((4096, d))
    perm, hint, store, stored = orders.layout(pts, name)
    assert np.array_equal((perm, hint), orders.order(pts, name))
    assert np.array_equal(stored, pts[store]) and stored.flags.c_contiguous
    assert sorted(store.tolist()) == list(range(4096))
    if name == "hilbert":
        assert np.array_equal(store, perm)
    # consecutive points are near: far closer than in input (random) order
    step = np.linalg.norm(np.diff(pts[store], axis=0), axis=1).mean()
    assert step < 0.25 * np.linalg.norm(np.diff(pts, axis=0), axis=1).mean()


def test_kdtree_cuts_the_longest_edge_and_alternate_does_not():
    pts = np.c_[np.linspace(0, 1, 9), np.linspace(0, 100, 9)[np.random.default_rng(0).permutation(9)]]
    perm, _ = orders.order(pts, "kdtree")
    alt, _ = orders.order(pts, "kdtree-alternate")
    # root = median of the long axis (y) vs of x
    assert pts[perm[0], 1] == np.median(pts[:, 1])
    assert pts[alt[0], 0] == np.median(pts[:, 0])


def test_sibling_hint_uses_the_left_sibling():
    pts = np.c_[np.arange(1, 8, dtype=float), np.zeros(7)]
    perm, hint = orders.order(pts, "kdtree", hint="sibling")
    # labels: 4 | 2 6 | 1 3 5 7: node 6's left sibling is 2, node 3's is 1
    assert (perm + 1).tolist() == [4, 2, 6, 1, 3, 5, 7]
    assert hint[2] == perm[1] and hint[4] == perm[3]


@pytest.mark.parametrize("name", ["hilbert", "hilbert-grid"])
@pytest.mark.parametrize("d,k", [(2, 16), (3, 8)])
def test_hilbert_orders_visit_neighbouring_cells_consecutively(name, d, k):
    g = np.stack(np.meshgrid(*[np.arange(k)] * d), -1).reshape(-1, d).astype(float)
    g = g[np.random.default_rng(0).permutation(len(g))]
    perm, _ = orders.order(g, name)
    steps = np.abs(np.diff(g[perm], axis=0)).sum(axis=1)
    assert np.all(steps == 1)  # a Hilbert curve moves to an adjacent cell each time


def test_brio_rounds_grow_geometrically(rng):
    pts = rng.random((10000, 3))
    perm, _ = orders.order(pts, "brio", seed=3)
    again, _ = orders.order(pts, "brio", seed=3)
    assert np.array_equal(perm, again)
    assert not np.array_equal(perm, orders.order(pts, "brio", seed=4)[0])


def test_bad_names():
    with pytest.raises(ValueError, match="unknown order"):
        orders.order(np.zeros((3, 2)), "morton")
    with pytest.raises(ValueError, match="hint"):
        orders.order(np.zeros((3, 2)), "kdtree", hint="grandparent")


@pytest.mark.parametrize("shape", [(5, 4), (5, 1), (5,)])
def test_orders_take_2d_and_3d_points_only(shape):
    with pytest.raises(ValueError, match=r"shape \(n, 2\) or \(n, 3\)"):
        orders.order(np.zeros(shape), "kdtree")


def test_longest_axis_takes_the_first_among_equal_edges():
    X = np.array([[0.0, 0.0, 0.0], [2.0, 2.0, 1.0]])
    assert orders._longest_axis(X, 0, 2) == 0
    X[1] = [1.0, 2.0, 2.0]
    assert orders._longest_axis(X, 0, 2) == 1
    X[1] = [1.0, 1.0, 2.0]
    assert orders._longest_axis(X, 0, 2) == 2
    assert orders._longest_axis(X[:, :2], 0, 2) == 0
