#!/usr/bin/env python3
"""Independent reader of ROS bags, used to check fuzzyvox's bag input (scripts/check-bags).

It reads bags with the `rosbags` library from PyPI (pure Python, written apart from fuzzyvox's
Rust reader) and numpy, and nothing else, so that the two readers can be compared.

BAG is a ROS 1 `.bag` file, a ROS 2 bag folder (metadata.yaml + storage files), or a single
ROS 2 storage file (`.mcap`, also `.db3`): rosbags 0.11.9 reads a bare `.mcap` without its
metadata.yaml (checked on robot-logs/hololens-000-mcap/hololens-000-mcap.mcap).

  rosbag_reference.py info BAG
      One JSON object: {"format": "ros1"|"ros2", "topics": [{"name", "type", "count"}, ...],
      "message_count", "start_ns", "end_ns"}. One entry per (topic, type), sorted by name then
      type (a ROS 1 topic can carry two types: jsk-watercan.bag's /tf has tf2_msgs/TFMessage and
      tf/tfMessage). Types as rosbags reports them: ROS 1 types normalised to pkg/msg/Name.
      Counts and times come from reading every message; start_ns and end_ns are the first and
      the last message's log time (inclusive; rosbags' own end_time is one past the last).

  rosbag_reference.py scan-list BAG TOPIC OUTDIR [--frame map]
      For every sensor_msgs/PointCloud2 on TOPIC (in log-time order): the transform from the
      cloud's header.frame_id to FRAME at the cloud's header stamp, from the bag's /tf and
      /tf_static (tf2_msgs/TFMessage or tf/tfMessage; leading '/' stripped from frame ids;
      chained through intermediate frames; per edge, linear interpolation of the translation and
      slerp of the rotation between the two samples around the stamp, an exact stamp uses that
      sample, /tf_static edges hold at all times; a stamp outside a dynamic edge's samples is an
      error, as is a frame not connected to FRAME; a cloud already in FRAME uses the identity).
      x, y, z are decoded by field name (any point_step, offsets, height x width with row_step,
      float32/float64 or integer types, either byte order), non-finite points are dropped, the
      rest transformed to FRAME and written as OUTDIR/cloud-NNNN.xyz (`x y z`, %.9g) with
      OUTDIR/scans.list lines `cloud-NNNN.xyz ox oy oz` (the sensor frame's origin in FRAME).
      All transforms are looked up before anything is written. Prints one JSON object:
      {"scans", "points", "dropped_nonfinite", "list"}. Exit status 1 with a message on error.
"""
import argparse
import json
import os
import sys
from bisect import bisect_left
from collections import defaultdict, deque
from pathlib import Path

import numpy as np
from rosbags.highlevel import AnyReader, AnyReaderError

TF_TOPICS = ("/tf", "/tf_static")
# sensor_msgs/PointField datatypes
FIELD_TYPES = {1: "i1", 2: "u1", 3: "i2", 4: "u2", 5: "i4", 6: "u4", 7: "f4", 8: "f8"}


class Fail(Exception):
    pass


def open_bag(path):
    p = Path(path)
    if not p.exists():
        raise Fail(f"no such bag: {path}")
    return AnyReader([p])


def stamp_ns(stamp):
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def fmt_ns(ns):
    return f"{ns // 1_000_000_000}.{ns % 1_000_000_000:09d} s"


def strip(frame):
    return frame[1:] if frame.startswith("/") else frame


# ---------------------------------------------------------------------------------------- info

def cmd_info(bag):
    counts = defaultdict(int)
    start = end = None
    total = 0
    with open_bag(bag) as r:
        for conn, t, _raw in r.messages():
            counts[(conn.topic, conn.msgtype)] += 1
            total += 1
            start = t if start is None else min(start, t)
            end = t if end is None else max(end, t)
        indexed = defaultdict(int)
        for c in r.connections:
            indexed[(c.topic, c.msgtype)] += c.msgcount
        if dict(indexed) != dict(counts):
            print(f"warning: the bag's index counts {dict(indexed)} differ from the messages read",
                  file=sys.stderr)
        fmt = "ros2" if r.is2 else "ros1"
    topics = [{"name": n, "type": ty, "count": counts[(n, ty)]} for n, ty in sorted(counts)]
    print(json.dumps({"format": fmt, "topics": topics, "message_count": total,
                      "start_ns": start, "end_ns": end}))


# ------------------------------------------------------------------------------------------ TF

def quat_normalise(q):
    n = np.linalg.norm(q)
    if not np.isfinite(n) or n == 0:
        raise Fail(f"invalid quaternion {q.tolist()}")
    return q / n


def slerp(q0, q1, s):
    """Quaternions as (x, y, z, w); shortest path."""
    d = float(np.dot(q0, q1))
    if d < 0:
        q1, d = -q1, -d
    if d > 0.9995:
        q = q0 + s * (q1 - q0)
        return q / np.linalg.norm(q)
    theta = np.arccos(min(d, 1.0))
    return (np.sin((1 - s) * theta) * q0 + np.sin(s * theta) * q1) / np.sin(theta)


def quat_matrix(q):
    x, y, z, w = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


class Edge:
    """parent -> child: samples (stamp_ns, translation, quaternion) of the child's pose in parent."""

    def __init__(self, parent, child):
        self.parent, self.child = parent, child
        self.static = False
        self.samples = {}  # stamp -> (t, q); a repeated stamp keeps the last one read

    def finish(self):
        items = sorted(self.samples.items())
        self.stamps = [s for s, _ in items]
        self.values = [v for _, v in items]

    def at(self, ns):
        """(R, t) of the child frame in the parent frame at ns."""
        if self.static:
            t, q = self.values[-1]
            return quat_matrix(q), t
        i = bisect_left(self.stamps, ns)
        if i < len(self.stamps) and self.stamps[i] == ns:
            t, q = self.values[i]
            return quat_matrix(q), t
        if i == 0 or i == len(self.stamps):
            raise Fail(self.range_message(ns))
        s0, s1 = self.stamps[i - 1], self.stamps[i]
        (t0, q0), (t1, q1) = self.values[i - 1], self.values[i]
        s = (ns - s0) / (s1 - s0)
        return quat_matrix(slerp(q0, q1, s)), t0 + s * (t1 - t0)

    def range_message(self, ns):
        first, last = self.stamps[0], self.stamps[-1]
        if ns < first:
            where = f"{(first - ns) / 1e9:.9f} s before its first sample"
        else:
            where = f"{(ns - last) / 1e9:.9f} s after its last sample"
        return (f"edge {self.parent} -> {self.child} has {len(self.stamps)} samples from "
                f"{fmt_ns(first)} to {fmt_ns(last)}; the stamp is {where}")


class TfTree:
    def __init__(self, reader):
        self.edges = {}
        conns = [c for c in reader.connections if c.topic in TF_TOPICS]
        for c in conns:
            if not c.msgtype.endswith(("/TFMessage", "/tfMessage")):
                raise Fail(f"{c.topic} has type {c.msgtype}, not a TF message")
        if conns:
            for conn, _t, raw in reader.messages(connections=conns):
                msg = reader.deserialize(raw, conn.msgtype)
                for tr in msg.transforms:
                    parent, child = strip(tr.header.frame_id), strip(tr.child_frame_id)
                    e = self.edges.get((parent, child))
                    if e is None:
                        e = self.edges[(parent, child)] = Edge(parent, child)
                    if conn.topic == "/tf_static":
                        e.static = True
                    v, r = tr.transform.translation, tr.transform.rotation
                    e.samples[stamp_ns(tr.header.stamp)] = (
                        np.array([v.x, v.y, v.z], dtype=np.float64),
                        quat_normalise(np.array([r.x, r.y, r.z, r.w], dtype=np.float64)))
        self.neighbours = defaultdict(list)
        parents = defaultdict(set)
        for (p, c), e in self.edges.items():
            e.finish()
            self.neighbours[p].append((c, e, True))   # walking parent -> child
            self.neighbours[c].append((p, e, False))  # walking child -> parent
            parents[c].add(p)
        for c, ps in parents.items():
            if len(ps) > 1:
                print(f"warning: frame {c} has more than one parent: {sorted(ps)}", file=sys.stderr)

    def path(self, target, source):
        """Edges from target to source (breadth first), each with its walking direction."""
        prev = {target: None}
        todo = deque([target])
        while todo:
            f = todo.popleft()
            if f == source:
                break
            for g, e, down in self.neighbours.get(f, ()):
                if g not in prev:
                    prev[g] = (f, e, down)
                    todo.append(g)
        if source not in prev:
            known = sorted(self.neighbours)
            raise Fail(f"no TF path from {source!r} to {target!r} in /tf and /tf_static "
                       f"(frames: {', '.join(known) if known else 'none'})")
        steps = []
        f = source
        while prev[f] is not None:
            g, e, down = prev[f]
            steps.append((e, down))
            f = g
        return steps[::-1]

    def lookup(self, target, source, ns):
        """(R, t) mapping points in source to target at ns."""
        R, t = np.eye(3), np.zeros(3)
        if source == target:
            return R, t
        errors = []
        for e, down in self.path(target, source):
            try:
                Re, te = e.at(ns)
            except Fail as err:
                errors.append(str(err))
                continue
            if not down:  # walking child -> parent: the inverse of the parent -> child transform
                Re, te = Re.T, -Re.T @ te
            R, t = R @ Re, R @ te + t
        if errors:
            raise Fail("; ".join(errors))
        return R, t


# ---------------------------------------------------------------------------------- PointCloud2

def decode_xyz(msg):
    """(N, 3) float64 array of x, y, z, all points in row order (non-finite ones included)."""
    by_name = {f.name: f for f in msg.fields}
    missing = [n for n in "xyz" if n not in by_name]
    if missing:
        raise Fail(f"cloud has no field {', '.join(missing)} (fields: {sorted(by_name)})")
    order = ">" if msg.is_bigendian else "<"
    formats, offsets = [], []
    for n in "xyz":
        f = by_name[n]
        if f.datatype not in FIELD_TYPES:
            raise Fail(f"field {n} has unknown datatype {f.datatype}")
        formats.append(order + FIELD_TYPES[f.datatype])
        offsets.append(f.offset)
    h, w, step, row = int(msg.height), int(msg.width), int(msg.point_step), int(msg.row_step)
    dt = np.dtype({"names": list("xyz"), "formats": formats, "offsets": offsets, "itemsize": step})
    for n, off, fm in zip("xyz", offsets, formats):
        if off + np.dtype(fm).itemsize > step:
            raise Fail(f"field {n} at offset {off} does not fit in point_step {step}")
    if h * w == 0:
        return np.zeros((0, 3))
    if row < w * step:
        raise Fail(f"row_step {row} is less than width {w} x point_step {step}")
    data = np.asarray(msg.data, dtype=np.uint8).tobytes()
    need = (h - 1) * row + w * step
    if len(data) < need:
        raise Fail(f"cloud data has {len(data)} bytes, height {h} x row_step {row} needs {need}")
    buf = np.frombuffer(data, dtype=np.uint8)
    if row == w * step:
        rows = buf[: h * row]
    else:
        rows = np.concatenate([buf[i * row: i * row + w * step] for i in range(h)])
    pts = rows.view(dt)
    return np.stack([pts["x"].astype(np.float64), pts["y"].astype(np.float64),
                     pts["z"].astype(np.float64)], axis=1)


def cmd_scan_list(bag, topic, outdir, frame):
    frame = strip(frame)
    with open_bag(bag) as r:
        conns = [c for c in r.connections if c.topic == topic]
        if not conns:
            raise Fail(f"no topic {topic} in {bag} (topics: {sorted({c.topic for c in r.connections})})")
        bad = sorted({c.msgtype for c in conns if c.msgtype != "sensor_msgs/msg/PointCloud2"})
        if bad:
            raise Fail(f"{topic} has type {', '.join(bad)}, not sensor_msgs/msg/PointCloud2")
        tf = TfTree(r)
        # first pass: every cloud's transform, so that nothing is written if one fails
        poses = []
        for k, (conn, _t, raw) in enumerate(r.messages(connections=conns)):
            msg = r.deserialize(raw, conn.msgtype)
            src, ns = strip(msg.header.frame_id), stamp_ns(msg.header.stamp)
            try:
                poses.append(tf.lookup(frame, src, ns))
            except Fail as err:
                raise Fail(f"cloud {k} on {topic} (frame {msg.header.frame_id!r}, stamp "
                           f"{fmt_ns(ns)}): no transform to {frame!r}: {err}") from None
        if not poses:
            raise Fail(f"no messages on {topic}")
        os.makedirs(outdir, exist_ok=True)
        lines, points, dropped = [], 0, 0
        for k, (conn, _t, raw) in enumerate(r.messages(connections=conns)):
            msg = r.deserialize(raw, conn.msgtype)
            xyz = decode_xyz(msg)
            keep = np.isfinite(xyz).all(axis=1)
            dropped += int((~keep).sum())
            R, t = poses[k]
            world = xyz[keep] @ R.T + t
            name = f"cloud-{k:04d}.xyz"
            np.savetxt(os.path.join(outdir, name), world, fmt="%.9g")
            lines.append(f"{name} {t[0]:.9g} {t[1]:.9g} {t[2]:.9g}")
            points += len(world)
    listing = os.path.join(outdir, "scans.list")
    with open(listing, "w") as f:
        f.write("\n".join(lines) + "\n")
    print(json.dumps({"scans": len(lines), "points": points, "dropped_nonfinite": dropped,
                      "list": listing}))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    p = sub.add_parser("info", help="topics, types, counts and time range as JSON")
    p.add_argument("bag")
    p = sub.add_parser("scan-list", help="PointCloud2 messages as a world-frame scan list")
    p.add_argument("bag"); p.add_argument("topic"); p.add_argument("outdir")
    p.add_argument("--frame", default="map", help="world frame (default map)")
    a = ap.parse_args()
    try:
        if a.cmd == "info":
            cmd_info(a.bag)
        else:
            cmd_scan_list(a.bag, a.topic, a.outdir, a.frame)
    except (Fail, AnyReaderError) as err:
        print(f"rosbag_reference.py: {err}", file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
