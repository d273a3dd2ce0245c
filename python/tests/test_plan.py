"""Planning through the maps from Python."""

import pickle

import numpy as np
import pytest

import fuzzyvox


def corridor_map(cls=fuzzyvox.FuzzyMap):
    """A closed 10 x 4 x 3 m box seen from inside, from three positions along its axis."""
    rng = np.random.default_rng(3)
    m = cls(0.2)
    for x0 in (1.0, 5.0, 9.0):
        n = 20000
        pts = rng.uniform([0, -2, 0], [10, 2, 3], size=(n, 3))
        face = rng.integers(0, 6, size=n)
        pts[face == 0, 0] = 0
        pts[face == 1, 0] = 10
        pts[face == 2, 1] = -2
        pts[face == 3, 1] = 2
        pts[face == 4, 2] = 0
        pts[face == 5, 2] = 3
        conf = np.full(n, 0.9)
        m.integrate_cloud(pts, origin=(x0, 0, 1.5), confidence=conf)
    return m


@pytest.mark.parametrize("cls", [fuzzyvox.FuzzyMap, fuzzyvox.LogOddsMap, fuzzyvox.AlphaCutMap])
def test_plan_through_the_corridor(cls):
    m = corridor_map(cls)
    p = fuzzyvox.plan(m, (1.5, 0, 1.5), (8.5, 0.5, 1.5), radius=0.3)
    w = p.waypoints
    assert w.ndim == 2 and w.shape[1] == 3 and len(p) == len(w) >= 2
    assert np.linalg.norm(w[0] - [1.5, 0, 1.5]) < 0.2
    assert np.linalg.norm(w[-1] - [8.5, 0.5, 1.5]) < 0.2
    straight = np.linalg.norm(np.subtract((8.5, 0.5, 1.5), (1.5, 0, 1.5)))
    assert straight - 0.4 <= p.length <= straight * 1.5
    assert p.cost >= p.length * 0.99
    assert p.min_safety >= 0.2
    assert p.min_clearance >= 0.3
    assert p.expanded > 0
    # Every waypoint is in known-safe space.
    assert np.all(m.classes(w) == fuzzyvox.FREE)
    # Plans pickle (for example back from Dask workers).
    again = pickle.loads(pickle.dumps(p))
    assert np.array_equal(again.waypoints, w)
    assert (again.length, again.cost, again.min_safety, again.min_clearance, again.expanded) == (
        p.length, p.cost, p.min_safety, p.min_clearance, p.expanded)


def test_plan_failures_say_why():
    m = corridor_map()
    with pytest.raises(fuzzyvox.PlanError) as info:
        fuzzyvox.plan(m, (1.5, 0, 1.5), (15, 0, 1.5))
    assert info.value.failure == "goal_unsafe"
    assert isinstance(info.value, fuzzyvox.FuzzyvoxError)
    with pytest.raises(fuzzyvox.PlanError) as info:
        fuzzyvox.plan(m, (0.0, 0, 1.5), (8.5, 0, 1.5))
    assert info.value.failure == "start_unsafe"
    # Unknown space at a cost: a goal outside the box is reachable only through the wall,
    # which stays forbidden, so no path.
    with pytest.raises(fuzzyvox.PlanError):
        fuzzyvox.plan(m, (1.5, 0, 1.5), (15, 0, 1.5), unknown="cost")


def test_plan_bad_requests():
    m = corridor_map()
    with pytest.raises(ValueError, match="forbid"):
        fuzzyvox.plan(m, (1, 0, 1), (2, 0, 1), unknown="maybe")
    with pytest.raises(ValueError, match="unknown_cost"):
        fuzzyvox.plan(m, (1, 0, 1), (2, 0, 1), unknown_cost=2.0)
    with pytest.raises(ValueError, match="radius|vehicle"):
        fuzzyvox.plan(m, (1.5, 0, 1.5), (2, 0, 1.5), radius=-1)
    with pytest.raises(ValueError, match="finite"):
        fuzzyvox.plan(m, (np.nan, 0, 1), (2, 0, 1))
    with pytest.raises(TypeError):
        fuzzyvox.plan("not a map", (1, 0, 1), (2, 0, 1))
