"""The Python package's overhead: integrating OctoMap's scan.dat through `fuzzyvox` from a numpy
array versus the same integration in Rust (`fuzzyvox insert`, which times its integration
loop), measured in one run on the same data.

    python python/benchmarks/overhead.py                     # from the repository root
    python python/benchmarks/overhead.py --res 0.05 --repeats 7 --fuzzyvox target/release/fuzzyvox

The Python time is one `FuzzyMap.integrate_cloud(points)` call, arguments in and statistics out
(the array read into the Rust cloud, the GIL released, the map built); the Rust time is the
command's `insert_seconds` (after the file is parsed, before anything is written). Both take the
median of `--repeats` runs, interleaved, and the maps must be identical: the command's map file
and the package's `to_bytes` are compared byte for byte first.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import fuzzyvox

ROOT = Path(__file__).resolve().parents[2]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    data = Path(os.environ.get("FUZZYVOX_DATA", ROOT.parent / "shared" / "data"))
    parser.add_argument("--cloud", type=Path, default=data / "octomap-samples" / "scan.dat")
    parser.add_argument("--res", type=float, default=0.1)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--fuzzyvox", type=Path, default=ROOT / "target" / "release" / "fuzzyvox")
    args = parser.parse_args()

    points, _ = fuzzyvox.read_cloud(args.cloud)

    def rust(out=None):
        cmd = [str(args.fuzzyvox), "insert", "--cloud", str(args.cloud), "--res", str(args.res), "--json"]
        if out:
            cmd += ["--out", str(out)]
        report = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
        return report["insert_seconds"]

    def python():
        m = fuzzyvox.FuzzyMap(args.res)
        started = time.perf_counter()
        m.integrate_cloud(points)
        return time.perf_counter() - started, m

    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "scan.fvx"
        rust(out)
        _, m = python()
        if out.read_bytes() != m.to_bytes():
            print("the package's map differs from the command's", file=sys.stderr)
            return 1
    py_times, rust_times = [], []
    for _ in range(args.repeats):
        py_times.append(python()[0])
        rust_times.append(rust())
    py_s, rust_s = statistics.median(py_times), statistics.median(rust_times)
    print(f"{len(points)} points of {args.cloud.name} at {args.res} m, median of {args.repeats} runs (same map, byte for byte):")
    print(f"  Python  FuzzyMap.integrate_cloud: {py_s:.3f} s  (runs: {', '.join(f'{t:.3f}' for t in py_times)})")
    print(f"  Rust    fuzzyvox insert:          {rust_s:.3f} s  (runs: {', '.join(f'{t:.3f}' for t in rust_times)})")
    print(f"  ratio Python / Rust: {py_s / rust_s:.3f} (medians), {min(py_times) / min(rust_times):.3f} (fastest runs)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
