"""The Dask example's code on a small cloud, over a LocalCluster of 2 worker processes."""

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest
from distributed import Client, LocalCluster

import fuzzyvox
from conftest import data_file, room_cloud

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "dask_mapping.py"


def load_example():
    spec = importlib.util.spec_from_file_location("dask_mapping", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def example():
    return load_example()


@pytest.fixture(scope="module")
def client():
    with LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None
    ) as cluster, Client(cluster) as client:
        assert len(client.scheduler_info()["workers"]) == 2
        # The workers import the example by name, as they would import a project's module.
        client.upload_file(str(EXAMPLE))
        yield client


@pytest.fixture(scope="module")
def result(example, client):
    points = np.vstack([room_cloud(seed, 3000) for seed in range(4)])
    return example.run(
        client, points, parts=8, tasks=4, origin=(0.0, 0.0, 0.5), res=0.2, timeout=120
    )


def test_tree_merge_on_workers_matches_serial_integration(result):
    assert result["tasks"] == 4
    distributed, serial = result["distributed"], result["serial"]
    assert isinstance(distributed, fuzzyvox.FuzzyMap)
    assert result["voxels"][0] == result["voxels"][1] > 1000
    assert result["classes_equal"]
    assert result["max_abs_membership_difference"] < 1e-5
    assert distributed.counts() == serial.counts()


def test_tree_merge_is_bit_exact(result):
    assert result["bytes_equal"], (
        f"largest membership difference {result['max_abs_membership_difference']:.3g}"
    )


def test_rgbd_frames_on_workers_match_serial_integration(example, client):
    folder = data_file("rgbd-7scenes-redkitchen/camera-intrinsics.txt").parent
    r = example.run_rgbd(client, str(folder), list(range(0, 48, 6)), tasks=4, res=0.1, timeout=120)
    assert r["tasks"] == 4
    assert r["voxels"][0] == r["voxels"][1] > 1000
    assert r["classes_equal"]
    assert r["max_abs_membership_difference"] < 1e-5
    assert r["bytes_equal"], "the merged map differs from serial integration"
