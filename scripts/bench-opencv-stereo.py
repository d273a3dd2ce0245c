#!/usr/bin/env python3
"""Times OpenCV's StereoBM and StereoSGBM on a Middlebury pair and prints their accuracy with
fuzzyvox's definitions (see `fuzzyvox stereo --gt`): errors over pixels with ground truth,
"matched" figures over pixels that got a disparity, "all" figures counting missing ones as errors.

With `--fuzzyvox BINARY` it also times `fuzzyvox stereo` on the same pair with the same number
of disparities, interleaved with OpenCV's matchers (`--rounds` rounds, best of each), and prints
each time as a multiple of StereoBM's.

Usage: pip install opencv-python-headless
       python3 scripts/bench-opencv-stereo.py [../shared/data/middlebury-motorcycle] [--ndisp 80]
           [--fuzzyvox target/release/fuzzyvox] [--rounds 5]
Not part of the tests.
"""
import argparse
import json
import os
import subprocess
import sys
import time

import cv2
import numpy as np


def read_pfm(path):
    with open(path, "rb") as f:
        if f.readline().strip() != b"Pf":
            sys.exit(f"{path}: not a one-channel PFM")
        width, height = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    return np.flipud(data.reshape(height, width))


def accuracy(disp, gt):
    has_gt = np.isfinite(gt)
    matched = has_gt & np.isfinite(disp)
    err = np.abs(disp - gt)
    total, n = has_gt.sum(), matched.sum()
    bad1 = (err[matched] > 1).sum()
    bad2 = (err[matched] > 2).sum()
    return {
        "density": 100.0 * n / total,
        "bad1_matched": 100.0 * bad1 / n,
        "bad2_matched": 100.0 * bad2 / n,
        "bad2_all": 100.0 * (bad2 + total - n) / total,
    }


def timed(fn, repeats):
    best = float("inf")
    for _ in range(repeats):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out


def main():
    p = argparse.ArgumentParser()
    p.add_argument("dir", nargs="?", default="../shared/data/middlebury-motorcycle")
    p.add_argument("--ndisp", type=int, default=80)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--repeats", type=int, default=20)
    p.add_argument("--rounds", type=int, default=1)
    p.add_argument("--fuzzyvox", help="a fuzzyvox binary to time in the same run")
    a = p.parse_args()
    cv2.setNumThreads(a.threads)
    left = cv2.imread(f"{a.dir}/im0.png", cv2.IMREAD_GRAYSCALE)
    right = cv2.imread(f"{a.dir}/im1.png", cv2.IMREAD_GRAYSCALE)
    gt = read_pfm(f"{a.dir}/disp0GT.pfm")
    print(f"OpenCV {cv2.__version__}, {a.threads} threads, {a.ndisp} disparities, "
          f"{left.shape[1]}x{left.shape[0]}, best of {a.repeats} x {a.rounds} rounds")
    bm = cv2.StereoBM_create(numDisparities=a.ndisp, blockSize=15)
    sgbm = cv2.StereoSGBM_create(minDisparity=0, numDisparities=a.ndisp, blockSize=5,
                                 P1=8 * 25, P2=32 * 25)
    env = dict(os.environ, RAYON_NUM_THREADS=str(a.threads))
    best, report = {}, {}
    for _ in range(a.rounds):
        for name, matcher in [("StereoBM block 15", bm), ("StereoSGBM block 5", sgbm)]:
            seconds, raw = timed(lambda: matcher.compute(left, right), a.repeats)
            disp = raw.astype(np.float32) / 16.0
            disp[raw < 0] = np.nan  # OpenCV marks invalid pixels with (minDisparity - 1) * 16
            best[name] = min(best.get(name, seconds), seconds)
            report[name] = accuracy(disp, gt)
        if a.fuzzyvox:
            out = subprocess.run(
                [a.fuzzyvox, "stereo", "--middlebury", a.dir, "--ndisp", str(a.ndisp),
                 "--repeat", str(a.repeats), "--json"],
                env=env, check=True, capture_output=True, text=True).stdout
            run = json.loads(out.strip().splitlines()[-1])
            name = "fuzzyvox stereo"
            best[name] = min(best.get(name, run["seconds"]), run["seconds"])
            report[name] = {k: run[k] for k in
                            ["density", "bad1_matched", "bad2_matched", "bad2_all",
                             "bad2_top50_confidence"]}
    for name, seconds in best.items():
        ratio = seconds / best["StereoBM block 15"]
        print(f"{name}: {seconds * 1e3:.1f} ms ({ratio:.2f}x StereoBM), " +
              ", ".join(f"{k} {v:.1f}%" for k, v in report[name].items()))

if __name__ == "__main__":
    main()
