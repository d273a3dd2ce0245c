"""Build one fuzzy map on a Dask cluster: partial maps per part of a scan on the workers, merged
in a tree, checked against serial integration of the same parts.

    python dask_mapping.py                        # $FUZZYVOX_DATA/octomap-samples/scan.dat
    python dask_mapping.py --cloud scan.dat --parts 8 --res 0.1
    python dask_mapping.py --rgbd $FUZZYVOX_DATA/rgbd-7scenes-redkitchen --res 0.05
    python dask_mapping.py --scheduler tcp://host:8786   # a real cluster instead of a local one

With `--rgbd DIR` the parts are the frames of an RGB-D folder (Kinect depth as intervals), each
task integrating a run of frames that it reads itself (the workers need the folder's path).
Otherwise the cloud is split into `--parts` parts; each part is integrated as one scan (from the same
sensor origin). Each task builds a partial map from a run of consecutive parts; the partial
maps travel between processes by pickle (the native file bytes) and are merged pairwise, a
tree of merges of depth log2(tasks). The serial reference integrates the same parts, in order,
into one map. The fuzzy map's t-conorms are commutative and associative, and the map
accumulates them exactly (fixed-point levels of the generator), so both maps are the same bit
for bit: the check compares their native file bytes (`to_bytes`) and also reports the largest
membership difference and whether every voxel has the same class.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

import fuzzyvox


def partial_map(parts: list[np.ndarray], origin, res: float, op: str) -> fuzzyvox.FuzzyMap:
    """One worker's map: its parts integrated in order, one scan each."""
    m = fuzzyvox.FuzzyMap(res, op=op)
    for points in parts:
        m.integrate_cloud(points, origin=origin)
    return m


def merged(a: fuzzyvox.FuzzyMap, b: fuzzyvox.FuzzyMap) -> fuzzyvox.FuzzyMap:
    """The merge of two maps (a new map: Dask may hold the inputs for other tasks)."""
    m = a.copy()
    m.merge(b)
    return m


def tree_reduce(client, futures: list):
    """Merges futures of maps pairwise until one is left."""
    while len(futures) > 1:
        pairs = [client.submit(merged, futures[i], futures[i + 1]) for i in range(0, len(futures) - 1, 2)]
        if len(futures) % 2:
            pairs.append(futures[-1])
        futures = pairs
    return futures[0]


def partial_rgbd_map(folder: str, indices: list[int], res: float, op: str) -> fuzzyvox.FuzzyMap:
    """One worker's map of RGB-D frames: the frames `indices` of `folder`, in order."""
    frames = fuzzyvox.RgbdFolder(folder)
    m = fuzzyvox.FuzzyMap(res, op=op)
    for i in indices:
        m.integrate_depth(**frames.frame(i))
    return m


def compare(a: fuzzyvox.FuzzyMap, b: fuzzyvox.FuzzyMap) -> dict:
    """How two maps differ: byte equality of their native files, the largest membership
    difference over every voxel either observed, and whether every such voxel has one class."""
    ca, _ = a.voxels()
    cb, _ = b.voxels()
    centres = np.unique(np.vstack([ca, cb]), axis=0)
    diff = np.abs(a.memberships(centres) - b.memberships(centres))
    return {
        "bytes_equal": a.to_bytes() == b.to_bytes(),
        "voxels": (len(ca), len(cb)),
        "max_abs_membership_difference": float(diff.max()) if len(diff) else 0.0,
        "classes_equal": bool(np.array_equal(a.classes(centres), b.classes(centres))),
    }


def run(client, points: np.ndarray, parts: int = 8, tasks: int = 4, origin=(0.0, 0.0, 0.0), res: float = 0.1, op: str = "product", timeout: float | None = None) -> dict:
    """Integrates `points` split into `parts` scans on the cluster (`tasks` partial maps merged
    in a tree) and serially; returns both maps, the timings and `compare`'s result. `timeout`
    (seconds) bounds the wait for the cluster's result."""
    chunks = np.array_split(points, parts)
    groups = [list(g) for g in np.array_split(np.arange(parts), tasks) if len(g)]
    jobs = [(partial_map, [chunks[i] for i in g], origin, res, op) for g in groups]
    return against_serial(client, jobs, lambda: partial_map(chunks, origin, res, op), timeout)


def run_rgbd(client, folder: str, frames: list[int], tasks: int = 4, res: float = 0.05, op: str = "product", timeout: float | None = None) -> dict:
    """`run` for the frames `frames` of an RGB-D folder: `tasks` runs of frames integrated on
    the cluster and merged in a tree, and all of them serially."""
    groups = [list(map(int, g)) for g in np.array_split(np.array(frames), tasks) if len(g)]
    jobs = [(partial_rgbd_map, folder, g, res, op) for g in groups]
    return against_serial(client, jobs, lambda: partial_rgbd_map(folder, frames, res, op), timeout)


def against_serial(client, jobs: list, serial, timeout: float | None) -> dict:
    """Builds one partial map per job (`(function, *arguments)`) on the cluster, merges them in
    a tree, builds `serial()` here, and returns both maps, their timings and `compare`'s
    result."""
    started = time.perf_counter()
    futures = [client.submit(*job) for job in jobs]
    distributed_map = tree_reduce(client, futures).result(timeout=timeout)
    distributed_seconds = time.perf_counter() - started
    started = time.perf_counter()
    serial_map = serial()
    serial_seconds = time.perf_counter() - started
    result = compare(distributed_map, serial_map)
    result.update(
        distributed=distributed_map,
        serial=serial_map,
        distributed_seconds=distributed_seconds,
        serial_seconds=serial_seconds,
        tasks=len(jobs),
    )
    return result


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    default = Path(os.environ.get("FUZZYVOX_DATA", "../shared/data")) / "octomap-samples" / "scan.dat"
    parser.add_argument("--cloud", type=Path, default=default, help="text cloud (x y z per line)")
    parser.add_argument("--rgbd", type=Path, help="an RGB-D folder (7-Scenes layout) instead of a cloud")
    parser.add_argument("--parts", type=int, default=8, help="parts of the cloud")
    parser.add_argument("--tasks", type=int, default=4)
    parser.add_argument("--res", type=float, default=0.1)
    parser.add_argument("--op", default="product")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--scheduler", help="address of a running scheduler (default: a LocalCluster)")
    args = parser.parse_args()

    from distributed import Client, LocalCluster

    if args.rgbd:
        frames = list(range(len(fuzzyvox.RgbdFolder(args.rgbd))))
        what = f"{len(frames)} RGB-D frames of {args.rgbd.name}"
    else:
        points, _ = fuzzyvox.read_cloud(args.cloud)
        what = f"{len(points)} points in {args.parts} parts"
    if args.scheduler:
        client = Client(args.scheduler)
        cluster = None
    else:
        cluster = LocalCluster(
            n_workers=args.workers, threads_per_worker=1, processes=True,
            host="127.0.0.1", dashboard_address=None,
        )
        client = Client(cluster)
    try:
        if args.rgbd:
            r = run_rgbd(client, str(args.rgbd.resolve()), frames, args.tasks, res=args.res, op=args.op)
        else:
            r = run(client, points, args.parts, args.tasks, res=args.res, op=args.op)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    print(f"{what}, {r['tasks']} partial maps merged in a tree")
    print(f"distributed: {r['distributed_seconds']:.2f} s; serial: {r['serial_seconds']:.2f} s")
    print(f"observed voxels: {r['voxels'][0]} distributed, {r['voxels'][1]} serial")
    print(f"every voxel of the same class: {r['classes_equal']}")
    print(f"largest membership difference: {r['max_abs_membership_difference']:.3g}")
    print(f"native bytes equal: {r['bytes_equal']}")
    return 0 if r["bytes_equal"] else 1


if __name__ == "__main__":
    sys.exit(main())
