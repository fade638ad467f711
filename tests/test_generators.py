import hashlib

import numpy as np
import pytest

import generators
from generators import cache as gcache

ALL = list(generators.REGISTRY)


@pytest.fixture(autouse=True)
def private_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("LFQT_CACHE_DIR", str(tmp_path / "cache"))


def digest(a):
    return hashlib.sha256(np.ascontiguousarray(a).tobytes()).hexdigest()


@pytest.mark.parametrize("name,dtype", [(n, t) for n in ALL for t in ("float32", "float64")
                                        if t in generators.get(n).dtypes])
def test_shape_dtype_determinism_and_finiteness(name, dtype):
    a = generators.make(name, 2000, seed=3, dtype=dtype)
    b = generators.make(name, 2000, seed=3, dtype=dtype)
    c = generators.make(name, 2000, seed=4, dtype=dtype)
    dim = generators.get(name).dim
    assert a.shape == (2000, dim) and a.dtype == np.dtype(dtype)
    assert digest(a) == digest(b) and digest(a) != digest(c)
    assert np.isfinite(a).all()


@pytest.mark.parametrize("name", [n for n in ALL if generators.get(n).duplicates == "none"])
def test_no_duplicates_unless_the_set_means_them(name):
    a = generators.make(name, 20000, seed=1, dtype=generators.get(name).dtypes[0])
    assert len(np.unique(a, axis=0)) == len(a)


def test_redraw_removes_rounding_duplicates():
    # float32 in [0, 2**-20) has few values: duplicates are certain before redraw
    dist = generators.Distribution("tiny", 2, lambda rng, n: rng.random((n, 2)) * 2.0 ** -136, "test")
    out = generators._redraw_duplicates(dist, np.random.default_rng(0), dist.draw(np.random.default_rng(0), 3000),
                                        np.float32)
    assert len(np.unique(out, axis=0)) == 3000


def test_first_quadrant_and_centred_sets():
    for name in ("uniform", "grid", "cluster"):
        assert (generators.make(name, 5000) >= 0).all(), name
    circle = generators.make("circle", 20000)
    assert np.abs(circle.mean(axis=0)).max() < 0.01
    spiral = generators.make("spiral", 20000)
    assert np.hypot(*spiral.T).min() < 0.01  # it starts at the origin
    assert (spiral.min(axis=0) < -0.8).all() and (spiral.max(axis=0) > 0.8).all()


def test_grid_is_square_integer():
    pts = generators.make("grid", 10000)
    assert np.array_equal(pts, np.round(pts))
    assert pts.max(axis=0).tolist() == [99, 99] and len(np.unique(pts, axis=0)) == 10000


def test_circle_radius_and_unit_sets():
    r = np.hypot(*generators.make("circle", 1000).T)
    assert np.allclose(r, 0.45, rtol=1e-12)
    cube = generators.make("cube", 1000)
    assert cube.min() >= 0 and cube.max() < 1
    axes = generators.make("axes", 3000)
    assert (np.sort(np.abs(axes), axis=1)[:, 1] < 0.01).all()  # two coordinates near 0


def test_standins_have_published_default_sizes():
    assert generators.get("statue-standin").default_n == 543_652
    assert generators.get("constrained-cube-standin").default_n == 4_386_533
    assert generators.get("refined-cube-standin").default_n == 5_500_000
    assert generators.get("gearbox-standin").default_n == 3_204_652
    assert all("stand-in" in generators.get(n).source for n in ALL if n.endswith("standin"))


def test_unknown_name_and_bad_dtype():
    with pytest.raises(ValueError, match="unknown distribution"):
        generators.make("torus", 10)
    with pytest.raises(ValueError, match="dtype"):
        generators.make("uniform", 10, dtype="float16")


def test_cache_hit_miss_and_corruption(tmp_path):
    calls = []

    def build():
        calls.append(1)
        return np.arange(12.0).reshape(6, 2)

    a = np.array(gcache.cached("k", build))
    b = gcache.cached("k", build)
    assert len(calls) == 1 and np.array_equal(a, b)
    assert isinstance(b, np.memmap) and not b.flags.writeable
    path = gcache.cache_dir() / "k.npy"
    path.write_bytes(b"garbage")
    c = gcache.cached("k", build)
    assert len(calls) == 2 and np.array_equal(c, a)
    assert not list(gcache.cache_dir().glob("*.tmp"))


def test_make_caches_large_sets(monkeypatch):
    monkeypatch.setattr(generators, "CACHE_MIN_POINTS", 1000)
    a = generators.make("uniform", 1500, seed=9)
    files = list(gcache.cache_dir().glob("uniform-n1500-s9-float64-*.npy"))
    assert len(files) == 1 and isinstance(a, np.memmap)
    assert np.array_equal(a, generators.generate("uniform", 1500, seed=9))


def test_cli_writes_file(tmp_path):
    from generators.__main__ import main
    out = tmp_path / "p.npy"
    assert main(["spiral", "500", "--seed", "2", "--dtype", "float32", "--out", str(out)]) == 0
    assert np.array_equal(np.load(out), generators.make("spiral", 500, seed=2, dtype="float32"))


def test_gallery_draws_every_set(tmp_path):
    from generators.gallery import draw
    paths = draw(tmp_path, n=300)
    assert all(p.exists() and p.stat().st_size > 10000 for p in paths)


def test_the_cache_is_keyed_by_the_definition(tmp_path, monkeypatch):
    """A changed formula never serves a stale file: the key holds a hash of
    the set's definition, and another definition builds another file."""
    monkeypatch.setenv("LFQT_CACHE_DIR", str(tmp_path))
    a = generators.make("uniform", 1000, cache=True)
    files = list(tmp_path.glob("*.npy"))
    assert len(files) == 1 and generators.definition("uniform") in files[0].name
    monkeypatch.setattr(generators, "definition", lambda name: "dchanged")
    b = generators.make("uniform", 1000, cache=True)
    assert len(list(tmp_path.glob("*.npy"))) == 2 and np.array_equal(a, b)


def test_definitions_differ_between_sets_and_are_stable():
    assert generators.definition("uniform") != generators.definition("cube")
    assert generators.definition("uniform") == generators.definition("uniform")
    assert generators.definition("uniform") != generators.definition("grid")  # same module


def test_chunked_sets_are_reproducible_chunk_by_chunk(tmp_path):
    from generators import chunked
    pattern = chunked.write("cluster", 2500, tmp_path, rows=1000)
    import glob
    files = sorted(glob.glob(pattern))
    assert [len(np.load(f)) for f in files] == [1000, 1000, 500]
    again = chunked.chunk("cluster", 2500, 1, rows=1000)
    assert np.array_equal(np.load(files[1]), again)
    pts = np.concatenate([np.load(f) for f in files])
    # ten clusters of sd 0.05 around centres in [1, 2)^2, as generators.sets2d.cluster
    assert np.allclose(pts.mean(0), 1.0 + np.random.default_rng(0).random((10, 2)).mean(0),
                       atol=0.01)
    u = chunked.chunk("uniform", 10, 0)
    assert u.shape == (10, 2) and (u >= 0).all() and (u < 1).all()
    with pytest.raises(ValueError, match="chunk-wise"):
        chunked.chunk("spiral", 10, 0)


# --- the LiDAR model, the hard sets, tags, and a user's own cloud (issue 53) ---

def test_paper_1s_five_sets_are_tagged():
    assert generators.names(2, tag="paper1") == ["uniform", "grid", "cluster", "circle", "spiral"]
    assert "lidar" in generators.names(3, tag="2.5d") and "lidar-xy" in generators.names(2, "hard")


def test_lidar_is_quantised_at_an_offset_with_returns_sharing_xy():
    from generators import lidar
    pts = generators.make("lidar", 20000, seed=2)
    units = (pts - np.array(lidar.OFFSET)) / lidar.SCALE
    assert np.abs(units - np.round(units)).max() < 1e-3  # centimetres, as a LAS file stores them
    assert (pts[:, 0] > 4.9e5).all() and (pts[:, 1] > 3.9e6).all()
    distinct = len(np.unique(pts[:, :2], axis=0))
    assert 0.3 * len(pts) < distinct < len(pts)  # several returns of one pulse share xy
    ground = lidar._ground(pts[:, 0] - lidar.OFFSET[0], pts[:, 1] - lidar.OFFSET[1])
    above = pts[:, 2] - ground
    assert above.min() > -0.02 and (above > 3).mean() > 0.02  # roofs stand above the ground
    assert np.array_equal(lidar.cloud_xy(np.random.default_rng(7), 3000),
                          lidar.cloud(np.random.default_rng(7), 3000)[:, :2])


def test_lidar_scan_lines_are_parallel_rows_of_footprints():
    from generators import lidar
    pts = lidar._strip(np.random.default_rng(0), 5000)
    spacing = 1 / np.sqrt(lidar.DENSITY)
    rows = np.round(pts[:, 1] / spacing)
    assert np.abs(pts[:, 1] / spacing - rows).max() < 0.3  # jitter well inside a line gap
    assert len(np.unique(rows)) > 20


def test_cocircular_points_lie_exactly_on_their_circles():
    from generators.hard import LATTICE_RADIUS
    pts = generators.make("cocircular", 3000).astype(np.int64)
    r2 = pts[:, 0] ** 2 + pts[:, 1] ** 2
    k = np.round(np.sqrt(r2) / LATTICE_RADIUS).astype(np.int64)
    assert np.array_equal(r2, (k * LATTICE_RADIUS) ** 2)
    assert len(np.unique(pts, axis=0)) == len(pts)


def test_degenerate_sets_are_what_they_say():
    col = generators.make("collinear", 500)
    assert np.array_equal(col[:, 0], 3 * col[:, 1])
    fan = generators.make("collinear-fan", 500)
    assert (fan[:, 0] != 3 * fan[:, 1]).sum() == 1
    dup = generators.make("duplicates", 1000)
    assert len(np.unique(dup, axis=0)) == 500
    z = generators.make("signed-zeros", 400)
    zeros = z[z == 0]
    assert np.signbit(zeros).any() and (~np.signbit(zeros)).any()
    assert len(np.unique(z + 0.0, axis=0)) < len(z)  # -0.0 rows repeat 0.0 rows
    gis = generators.make("gis", 1000)
    assert (gis[:, 0] >= 5e5).all() and np.ptp(gis, axis=0).max() < 100
    assert 0 < np.abs(generators.make("subnormal", 100)).max() < 2.3e-308


def test_the_hard_3d_sets_are_what_they_say():
    from generators.hard3d import SPHERE_RADIUS
    assert generators.names(3, tag="hard") == ["grid-3d", "grid-3d-sorted", "cospherical",
                                               "sphere-rounded", "duplicates-3d",
                                               "subnormal-3d", "huge-3d"]
    lattice = np.stack(np.meshgrid(*[np.arange(20)] * 3, indexing="ij"), -1).reshape(-1, 3)
    grid = generators.make("grid-3d", 8000)
    assert np.array_equal(np.unique(grid, axis=0), lattice)  # the whole 20^3 grid
    assert not np.array_equal(grid, lattice)  # in random order
    rows = generators.make("grid-3d-sorted", 8000)
    assert np.array_equal(rows - rows[0], lattice)  # in lexicographic order, shifted
    c = generators.make("cospherical", 3000).astype(np.int64)
    assert np.array_equal(c[0], [0, 0, 0]) and len(np.unique(c, axis=0)) == 3000
    r2 = (c[1:] ** 2).sum(axis=1)
    k = np.round(np.sqrt(r2) / SPHERE_RADIUS).astype(np.int64)
    assert np.array_equal(r2, (k * SPHERE_RADIUS) ** 2) and set(k) == {1, 2, 3}
    sphere = generators.make("sphere-rounded", 1000)
    assert np.allclose(np.linalg.norm(sphere, axis=1), 0.45, rtol=1e-15, atol=0)
    assert len(np.unique(generators.make("duplicates-3d", 1000), axis=0)) == 500
    assert 0 < np.abs(generators.make("subnormal-3d", 100)).max() < 2.3e-308
    assert np.abs(generators.make("huge-3d", 100)).max() > 1e299


def test_magnitude_sets_refuse_float32():
    with pytest.raises(ValueError, match="float64 set"):
        generators.make("huge", 10, dtype="float32")


def _laz(path, pts):
    laspy = pytest.importorskip("laspy")
    header = laspy.LasHeader(point_format=3, version="1.2")
    header.scales, header.offsets = [0.01] * 3, [500_000.0, 4_000_000.0, 0.0]
    las = laspy.LasData(header)
    las.x, las.y, las.z = pts[:, 0], pts[:, 1], pts[:, 2]
    las.write(path)
    return path


@pytest.mark.parametrize("suffix", [".las", ".laz"])
def test_load_reads_las_and_laz_exactly(tmp_path, suffix):
    pts = generators.make("lidar", 700)
    path = _laz(tmp_path / f"cloud{suffix}", pts)
    assert np.array_equal(generators.load(path), pts)
    assert np.array_equal(generators.load(path, dim=2), pts[:, :2])


def test_load_reads_npy_csv_and_parquet(tmp_path):
    pts = generators.make("uniform", 50, seed=5)
    np.save(tmp_path / "a.npy", pts)
    np.savetxt(tmp_path / "plain.csv", pts, delimiter=",", fmt="%.17g")
    (tmp_path / "named.csv").write_text("id,Y,X\n" + "\n".join(
        f"{i},{y!r},{x!r}" for i, (x, y) in enumerate(pts.tolist())))
    pq = pytest.importorskip("pyarrow.parquet")
    import pyarrow as pa
    pq.write_table(pa.table({"x": pts[:, 0], "y": pts[:, 1]}), tmp_path / "a.parquet")
    for name in ("a.npy", "plain.csv", "named.csv", "a.parquet"):
        assert np.array_equal(generators.load(tmp_path / name), pts), name


@pytest.mark.parametrize("name,content,message", [
    ("missing.laz", None, "no such point cloud"),
    ("cloud.ply", "x", "unknown format"),
    ("cols.csv", "a,b\n1,2\n", "no x/y columns"),
    ("one.npy", np.arange(5.0), "no x/y columns"),
    ("nan.csv", "x,y\n1,2\nnan,3\n", "NaN"),
    ("empty.csv", "x,y\n", "empty"),
    ("empty.npy", np.empty((0, 2)), "empty"),
])
def test_load_says_what_is_wrong(tmp_path, name, content, message):
    path = tmp_path / name
    if isinstance(content, str):
        path.write_text(content)
    elif content is not None:
        np.save(path, content)
    with pytest.raises((OSError, ValueError), match=message):
        generators.load(path)


def test_load_of_xy_alone_refuses_a_3d_experiment(tmp_path):
    np.save(tmp_path / "xy.npy", np.random.default_rng(0).random((10, 2)))
    with pytest.raises(generators.LoadError, match="no z column"):
        generators.load(tmp_path / "xy.npy", dim=3)
