"""Integration, queries, bad input, files, pickling and merging."""

import copy
import pickle

import numpy as np
import pytest

import fuzzyvox
from conftest import room_cloud, wall_points

MAPS = [
    lambda: fuzzyvox.FuzzyMap(0.1),
    lambda: fuzzyvox.LogOddsMap(0.1),
    lambda: fuzzyvox.AlphaCutMap(0.1),
]


def filled(make):
    m = make()
    pts = wall_points()
    stats = m.integrate_cloud(pts, origin=(0, 0, 0), confidence=np.full(len(pts), 0.8))
    assert stats["integrated"] == len(pts)
    assert stats["skipped"] == 0
    assert stats["voxels_updated"] > len(pts)
    return m


@pytest.mark.parametrize("make", MAPS)
def test_wall_is_occupied_and_the_way_to_it_free(make):
    m = filled(make)
    q = np.array([[3.0, 0.02, 0.5], [1.5, 0.02, 0.25], [-5.0, 5.0, 5.0]])
    codes = m.classes(q)
    assert codes.dtype == np.int8
    assert list(codes) == [fuzzyvox.OCCUPIED, fuzzyvox.FREE, fuzzyvox.UNKNOWN]
    assert m.classes(q, names=True) == ["occupied", "free", "unknown"]
    mu = m.memberships(q)
    assert mu.shape == (3, 2) and mu.dtype == np.float32
    assert mu[0, 0] > mu[0, 1]  # occupied more than free at the wall
    assert mu[1, 1] > mu[1, 0]  # free more than occupied on the way
    assert np.all(mu[2] == 0)  # never observed
    safety = m.safety(q)
    assert safety.shape == (3,)
    assert safety[1] > safety[0] and safety[2] == 0
    assert m.ambiguity(q).shape == (3,)
    assert m.indeterminacy(q)[2] == pytest.approx(1.0)


@pytest.mark.parametrize("make", MAPS)
def test_centres_counts_and_boxes(make):
    m = filled(make)
    occ = m.occupied_centres()
    free = m.free_centres()
    counts = m.counts()
    assert occ.shape == (counts["occupied"], 3)
    assert free.shape == (counts["free"], 3)
    # Every occupied centre is on the wall (x = 3 m, voxel centre 3.05) and classifies so.
    assert np.allclose(occ[:, 0], 3.05)
    assert np.all(m.classes(occ) == fuzzyvox.OCCUPIED)
    centres, mu = m.voxels()
    assert len(centres) == len(mu) == counts["occupied"] + counts["free"] + counts["ambiguous"]
    assert np.array_equal(m.memberships(centres), mu)
    # Boxes: the wall's box holds occupied voxels, a box in front of it none.
    assert m.any_in_box((2.9, -1, 0.4), (3.1, 1, 0.6), "occupied")
    assert not m.any_in_box((1.0, -0.5, 0.4), (2.0, 0.5, 0.6), fuzzyvox.OCCUPIED)
    in_box = m.counts_in_box((2.9, -1, 0.4), (3.1, 1, 0.6))
    assert in_box["occupied"] == counts["occupied"]
    assert sum(in_box.values()) == 3 * 21 * 3  # every voxel of the box counted once
    part = m.centres("occupied", lo=(2.9, -1, 0.4), hi=(3.1, 0, 0.6))
    assert 0 < len(part) < len(occ)
    assert np.all(part[:, 1] <= 0.05)


def test_integration_reads_any_float_layout():
    pts = room_cloud(1, 2000)
    a = fuzzyvox.FuzzyMap(0.2)
    a.integrate_cloud(pts)
    b = fuzzyvox.FuzzyMap(0.2)
    fortran = np.asfortranarray(pts)
    assert not fortran.flags.c_contiguous
    b.integrate_cloud(fortran)
    c = fuzzyvox.FuzzyMap(0.2)
    c.integrate_cloud(pts.tolist())
    assert a.to_bytes() == b.to_bytes() == c.to_bytes()
    strided = np.zeros((2000, 6))
    strided[:, ::2] = pts
    d = fuzzyvox.FuzzyMap(0.2)
    d.integrate_cloud(strided[:, ::2])
    assert d.to_bytes() == a.to_bytes()


def test_non_finite_points_are_skipped_and_counted():
    pts = wall_points()
    pts[3] = [np.nan, 0, 0]
    pts[7] = [np.inf, 1, 1]
    m = fuzzyvox.FuzzyMap(0.1)
    stats = m.integrate_cloud(pts)
    assert stats["skipped"] == 2
    assert stats["integrated"] == len(pts) - 2


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda m: m.integrate_cloud(np.zeros((4, 2))), r"\(N, 3\)"),
        (lambda m: m.integrate_cloud(np.zeros(3)), r"\(N, 3\)"),
        (lambda m: m.integrate_cloud(wall_points(), origin=(np.nan, 0, 0)), "finite"),
        (lambda m: m.integrate_cloud(wall_points(), origin=(0, 0)), "3 numbers"),
        (lambda m: m.integrate_cloud(wall_points(), confidence=np.ones(3)), r"\(50,\)"),
        (lambda m: m.integrate_cloud(wall_points(), confidence=np.full(50, 1.5)), "confidence"),
        (lambda m: m.integrate_cloud(wall_points(), confidence=np.full(50, np.nan)), "confidence"),
        (lambda m: m.integrate_cloud(wall_points(), max_range=-1.0), "max_range"),
        (lambda m: m.integrate_cloud([["a", "b", "c"]]), "float64"),
        (lambda m: m.memberships(np.array([[np.nan, 0, 0]])), "NaN"),
        (lambda m: m.safety(np.zeros((2, 4))), r"\(N, 3\)"),
        (lambda m: m.classes(np.array([[1e12, 0, 0]])), "key range"),
        (lambda m: m.any_in_box((0, 0, 0), (1, 1, 1), "solid"), "unknown class"),
        (lambda m: m.any_in_box((0, 0, 0), (1, 1, 1), 7), "class code"),
        (lambda m: m.centres("occupied", lo=(0, 0, 0)), "both box corners"),
    ],
)
def test_bad_input_raises_value_error(call, message):
    m = fuzzyvox.FuzzyMap(0.1)
    before = m.to_bytes()
    with pytest.raises(ValueError, match=message) as info:
        call(m)
    assert isinstance(info.value, fuzzyvox.InvalidInputError)
    assert isinstance(info.value, fuzzyvox.FuzzyvoxError)
    assert m.to_bytes() == before  # on error the map is unchanged


@pytest.mark.parametrize(
    "make, message",
    [
        (lambda: fuzzyvox.FuzzyMap(0.0), "resolution"),
        (lambda: fuzzyvox.FuzzyMap(float("nan")), "resolution|finite"),
        (lambda: fuzzyvox.FuzzyMap(0.1, op="nope"), "nope"),
        (lambda: fuzzyvox.FuzzyMap(0.1, op="dombi:-1"), "dombi"),
        (lambda: fuzzyvox.LogOddsMap(-1.0), "resolution"),
        (lambda: fuzzyvox.AlphaCutMap(0.1, cuts=0), "cuts"),
    ],
)
def test_bad_construction_raises(make, message):
    with pytest.raises(fuzzyvox.InvalidInputError, match=message):
        make()


def test_alpha_map_reads_confidence():
    # Without a confidence every point counts fully; a low confidence counts less.
    full = fuzzyvox.AlphaCutMap(0.1)
    full.integrate_cloud(wall_points())
    low = fuzzyvox.AlphaCutMap(0.1)
    low.integrate_cloud(wall_points(), confidence=np.full(50, 0.3))
    q = np.array([[3.0, 0.02, 0.5]])
    assert full.memberships(q)[0, 0] > low.memberships(q)[0, 0] > 0


def depth_planes(h=24, w=32, depth=2.0):
    value = np.full((h, w), depth, dtype=np.float32)
    return value - 0.05, value, value + 0.05, np.full((h, w), 0.9, dtype=np.float32)


@pytest.mark.parametrize("make", MAPS)
def test_depth_image_integration(make):
    m = make()
    near, value, far, conf = depth_planes()
    stats = m.integrate_depth(near, value, far, conf, fx=30, fy=30, cx=16, cy=12, pose=np.eye(4))
    assert stats["integrated"] == 24 * 32
    # The camera looks along +z: the plane at z = 2 m is occupied, the way to it free.
    q = np.array([[0.0, 0.0, 2.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]])
    assert list(m.classes(q)) == [fuzzyvox.OCCUPIED, fuzzyvox.FREE, fuzzyvox.UNKNOWN]
    # A pose 1 m along x moves the plane with it.
    pose = np.eye(4)
    pose[0, 3] = 10.0
    m.integrate_depth(near, value, far, conf, 30, 30, 16, 12, pose)
    assert m.classes(np.array([[10.0, 0.0, 2.0]]))[0] == fuzzyvox.OCCUPIED


def test_bad_depth_input_raises():
    m = fuzzyvox.FuzzyMap(0.1)
    near, value, far, conf = depth_planes()
    with pytest.raises(ValueError, match="shape"):
        m.integrate_depth(near, value[:, :5], far, conf, 30, 30, 16, 12, np.eye(4))
    with pytest.raises(ValueError, match="4x4"):
        m.integrate_depth(near, value, far, conf, 30, 30, 16, 12, np.eye(3))
    bad = np.eye(4)
    bad[0, 0] = 2.0
    with pytest.raises(ValueError, match="pose"):
        m.integrate_depth(near, value, far, conf, 30, 30, 16, 12, bad)
    with pytest.raises(ValueError, match="order"):
        m.integrate_depth(far, value, near, conf, 30, 30, 16, 12, np.eye(4))
    assert m.counts()["occupied"] == 0


@pytest.mark.parametrize("make", MAPS)
def test_pickle_and_copy_round_trip(make):
    m = filled(make)
    for other in (pickle.loads(pickle.dumps(m)), copy.deepcopy(m), m.copy()):
        assert type(other) is type(m)
        assert other.to_bytes() == m.to_bytes()
        assert other.resolution == m.resolution
    # A copy is independent of the original.
    c = m.copy()
    c.integrate_cloud(wall_points(x=4.0), confidence=np.full(50, 0.8))
    assert c.to_bytes() != m.to_bytes()


def test_fuzzy_map_keeps_its_operator_through_bytes():
    m = fuzzyvox.FuzzyMap(0.1, op="dombi:2")
    m.integrate_cloud(wall_points())
    again = pickle.loads(pickle.dumps(m))
    assert again.operator == "dombi:2"
    assert again.to_bytes() == m.to_bytes()


@pytest.mark.parametrize("make", MAPS)
def test_save_load_and_exports(make, tmp_path):
    m = filled(make)
    path = tmp_path / "map.fvx"
    m.save(path)
    assert path.read_bytes() == m.to_bytes()
    assert type(m).load(path).to_bytes() == m.to_bytes()
    any_kind = fuzzyvox.load(str(path))
    assert type(any_kind) is type(m)
    assert fuzzyvox.from_bytes(m.to_bytes()).to_bytes() == m.to_bytes()
    occupied, free = m.export_bt(tmp_path / "map.bt")
    assert (occupied, free) == (m.counts()["occupied"], m.counts()["free"])
    assert (tmp_path / "map.bt").read_bytes().startswith(b"# Octomap OcTree binary file")
    n = m.export_ply(tmp_path / "map.ply", classes=["occupied", "free"], ascii=True)
    assert n == occupied + free
    text = (tmp_path / "map.ply").read_text()
    assert f"element vertex {n}" in text
    assert m.export_ply(tmp_path / "occ.ply") == occupied


def test_file_errors_are_os_errors(tmp_path):
    with pytest.raises(OSError) as info:
        fuzzyvox.FuzzyMap.load(tmp_path / "missing.fvx")
    assert isinstance(info.value, fuzzyvox.MapFileError)
    with pytest.raises(OSError):
        fuzzyvox.FuzzyMap(0.1).save(tmp_path / "no" / "such" / "dir" / "m.fvx")
    logodds = tmp_path / "l.fvx"
    fuzzyvox.LogOddsMap(0.1).save(logodds)
    with pytest.raises(fuzzyvox.MapFileError, match="log-odds|logodds"):
        fuzzyvox.FuzzyMap.load(logodds)
    damaged = bytearray(filled(MAPS[0]).to_bytes())
    damaged[-10] ^= 0xFF
    (tmp_path / "d.fvx").write_bytes(bytes(damaged))
    with pytest.raises(fuzzyvox.MapFileError, match="checksum"):
        fuzzyvox.load(tmp_path / "d.fvx")
    with pytest.raises(fuzzyvox.InvalidInputError, match="checksum"):
        fuzzyvox.from_bytes(bytes(damaged))
    with pytest.raises(fuzzyvox.InvalidInputError, match="magic"):
        fuzzyvox.FuzzyMap.from_bytes(b"not a map at all, not at all")


def test_merge_equals_integrating_both_scans():
    a_pts, b_pts = room_cloud(1), room_cloud(2)
    serial = fuzzyvox.FuzzyMap(0.2)
    serial.integrate_cloud(a_pts)
    serial.integrate_cloud(b_pts)
    a = fuzzyvox.FuzzyMap(0.2)
    a.integrate_cloud(a_pts)
    b = fuzzyvox.FuzzyMap(0.2)
    b.integrate_cloud(b_pts)
    a.merge(b)
    centres, mu = serial.voxels()
    merged_centres, merged_mu = a.voxels()
    assert len(merged_centres) == len(centres)
    # Equal up to the rounding of f32 memberships (same classes everywhere).
    assert np.abs(a.memberships(centres) - mu).max() < 1e-5
    assert np.array_equal(a.classes(centres), serial.classes(centres))


def test_merge_refuses_other_maps():
    a = fuzzyvox.FuzzyMap(0.2)
    with pytest.raises(fuzzyvox.InvalidInputError, match="resolution"):
        a.merge(fuzzyvox.FuzzyMap(0.1))
    with pytest.raises(fuzzyvox.InvalidInputError, match="operator"):
        a.merge(fuzzyvox.FuzzyMap(0.2, op="max"))
    with pytest.raises(TypeError):
        a.merge(fuzzyvox.LogOddsMap(0.2))
    with pytest.raises(ValueError, match="itself"):
        a.merge(a)
    assert not hasattr(fuzzyvox.LogOddsMap(0.2), "merge")


def test_read_cloud(tmp_path):
    path = tmp_path / "c.xyz"
    path.write_text("1 2 3\n4 5 6\n")
    points, confidence = fuzzyvox.read_cloud(path)
    assert points.tolist() == [[1, 2, 3], [4, 5, 6]]
    assert confidence is None
    path.write_text("1 2 3 0.5\n4 5 6 1\n")
    points, confidence = fuzzyvox.read_cloud(path)
    assert confidence.tolist() == [0.5, 1.0]
    path.write_text("1 2 three\n")
    with pytest.raises(fuzzyvox.MapFileError, match=":1"):
        fuzzyvox.read_cloud(path)


def test_threads_integrate_into_their_own_maps():
    # Integration releases the GIL: threads integrating into separate maps give the maps a
    # serial run gives.
    from concurrent.futures import ThreadPoolExecutor

    clouds = [room_cloud(seed, 3000) for seed in range(4)]

    def build(pts):
        m = fuzzyvox.FuzzyMap(0.2)
        m.integrate_cloud(pts, origin=(0, 0, 0.5))
        return m.to_bytes()

    with ThreadPoolExecutor(4) as pool:
        threaded = list(pool.map(build, clouds))
    assert threaded == [build(c) for c in clouds]
    assert len(set(threaded)) == 4
