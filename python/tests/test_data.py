"""OctoMap's scan.dat through the package (needs FUZZYVOX_DATA)."""

import pickle

import numpy as np

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
