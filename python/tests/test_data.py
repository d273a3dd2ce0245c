"""Real data through the package: OctoMap's scan.dat, RGB-D frames and a robot recording (needs
FUZZYVOX_DATA)."""

import pickle

import numpy as np
import pytest

import fuzzyvox


def test_scan_dat(scan_dat):
    points, confidence = fuzzyvox.read_cloud(scan_dat)
    assert points.shape == (88206, 3)
    assert confidence is None
    m = fuzzyvox.FuzzyMap(0.2)
    stats = m.integrate_cloud(points, origin=(0, 0, 0))
    assert stats["integrated"] + stats["skipped"] == len(points)
    counts = m.counts()
    assert counts["occupied"] > 1000 and counts["free"] > 10 * counts["occupied"]
    # The sensor stands in free space; scan end points are mostly occupied.
    assert m.classes(np.zeros((1, 3)))[0] == fuzzyvox.FREE
    share = np.mean(m.classes(points[::50]) == fuzzyvox.OCCUPIED)
    assert share > 0.5
    assert pickle.loads(pickle.dumps(m)).to_bytes() == m.to_bytes()


def test_rgbd_frames(rgbd_dir):
    folder = fuzzyvox.RgbdFolder(rgbd_dir)
    assert len(folder) == 50
    assert folder.numbers == sorted(folder.numbers)
    frame = folder.frame(0)
    assert frame["value"].shape == (480, 640) and frame["value"].dtype == np.float32
    valid = frame["value"] > 0
    assert np.all(frame["near"][valid] < frame["value"][valid])
    assert np.all(frame["value"][valid] < frame["far"][valid])
    m = fuzzyvox.FuzzyMap(0.05)
    stats = m.integrate_depth(**frame)
    assert stats["integrated"] == int(valid.sum())
    # The surface seen at the centre pixel is occupied, the way to it free.
    z = float(frame["value"][240, 320])
    assert z > 0
    pose = frame["pose"]
    along = [pose[:3, :3] @ np.array([0.0, 0.0, d]) + pose[:3, 3] for d in (z, z / 2)]
    assert m.classes(np.array(along), names=True) == ["occupied", "free"]
    assert folder.frame(-1)["pose"].shape == (4, 4)
    try:
        folder.frame(50)
    except ValueError as e:
        assert "out of range" in str(e)
    else:
        raise AssertionError("frame 50 of 50 did not raise")


def test_rgbd_frames_merge_as_serial(rgbd_dir):
    folder = fuzzyvox.RgbdFolder(rgbd_dir)
    frames = [folder.frame(i) for i in range(0, 40, 10)]
    serial = fuzzyvox.FuzzyMap(0.05)
    halves = [fuzzyvox.FuzzyMap(0.05), fuzzyvox.FuzzyMap(0.05)]
    for i, f in enumerate(frames):
        serial.integrate_depth(**f)
        halves[i // 2].integrate_depth(**f)
    halves[0].merge(halves[1])
    centres, mu = serial.voxels()
    assert len(halves[0].voxels()[0]) == len(centres)
    assert np.abs(halves[0].memberships(centres) - mu).max() < 1e-5
    assert np.array_equal(halves[0].classes(centres), serial.classes(centres))


def test_robot_recording(hololens_bag, tmp_path):
    info = fuzzyvox.bag_info(hololens_bag)
    assert info["format"] == "ros1"
    assert [(t["name"], t["type"], t["count"]) for t in info["topics"]] == [
        ("/camera/depth/points", "sensor_msgs/PointCloud2", 80),
        ("/tf", "tf2_msgs/TFMessage", 80),
    ]
    assert info["tf"][0]["parent"] == "map"
    scans = fuzzyvox.read_bag(hololens_bag, "/camera/depth/points")
    assert len(scans) == 80
    assert sum(len(points) for points, _ in scans) == 1_138_584
    # The same map as `fuzzyvox insert --bag`: OctoMap's counts for these clouds and origins.
    m = fuzzyvox.LogOddsMap(0.05)
    for points, origin in scans:
        m.integrate_cloud(points, origin=origin)
    counts = m.counts()
    assert (counts["occupied"], counts["free"]) == (28_011, 351_202)
    with pytest.raises(fuzzyvox.InvalidInputError, match="point cloud topics: /camera/depth/points"):
        fuzzyvox.read_bag(hololens_bag, "/points")
    with pytest.raises(fuzzyvox.InvalidInputError, match="no transform from"):
        fuzzyvox.read_bag(hololens_bag, "/camera/depth/points", frame="world")
    cut = tmp_path / "cut.bag"
    cut.write_bytes(hololens_bag.read_bytes()[:100_000])
    with pytest.raises(fuzzyvox.MapFileError, match="damaged recording"):
        fuzzyvox.bag_info(cut)
