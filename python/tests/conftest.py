"""Shared fixtures: small synthetic scenes, and the real data under FUZZYVOX_DATA."""

import os
from pathlib import Path

import numpy as np
import pytest


def data_file(relative: str) -> Path:
    """A file of the shared data set: skip when FUZZYVOX_DATA is unset, fail when it is set
    but the file is missing (so that CI, which sets it, never skips silently)."""
    root = os.environ.get("FUZZYVOX_DATA")
    if not root:
        pytest.skip(f"FUZZYVOX_DATA is not set; {relative} is needed for this test")
    path = Path(root) / relative
    if not path.is_file():
        pytest.fail(f"FUZZYVOX_DATA={root} is set but {path} is missing")
    return path


@pytest.fixture
def scan_dat() -> Path:
    return data_file("octomap-samples/scan.dat")


@pytest.fixture
def rgbd_dir() -> Path:
    return data_file("rgbd-7scenes-redkitchen/camera-intrinsics.txt").parent


def wall_points(n: int = 50, x: float = 3.0) -> np.ndarray:
    """A line of points on the plane x = `x`, seen from the origin."""
    ys = -1.0 + 0.04 * np.arange(n)
    return np.column_stack([np.full(n, x), ys, np.full(n, 0.5)])


def room_cloud(seed: int = 0, n: int = 4000) -> np.ndarray:
    """Points on the walls, floor and ceiling of a 6 x 6 x 3 m box around the origin."""
    rng = np.random.default_rng(seed)
    pts = rng.uniform([-3, -3, -1], [3, 3, 2], size=(n, 3))
    face = rng.integers(0, 6, size=n)
    pts[face == 0, 0] = -3
    pts[face == 1, 0] = 3
    pts[face == 2, 1] = -3
    pts[face == 3, 1] = 3
    pts[face == 4, 2] = -1
    pts[face == 5, 2] = 2
    return pts


@pytest.fixture
def hololens_bag() -> Path:
    return data_file("robot-logs/hololens-000.bag")
