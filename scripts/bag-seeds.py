#!/usr/bin/env python3
"""Writes the seed corpus of the recording fuzz targets (fuzz/corpus/{ros1_bag,mcap_bag,
ros_message}) with the rosbags library: tiny recordings with the topics the targets read.

Each recording holds /tf (map -> lidar at two stamps, map -> camera), /points (two
sensor_msgs/PointCloud2 of five points in `lidar`, x y z float32 and an intensity), /image (a
4x3 PNG as sensor_msgs/CompressedImage) and /camera_info. ros_message seeds are single messages behind the target's selector byte.

Usage: target/bag-venv/bin/python scripts/bag-seeds.py   (the venv scripts/check-bags makes)
"""
import os
import struct
import tempfile
import zlib

import numpy as np
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CORPUS = os.path.join(ROOT, "fuzz", "corpus")


def put(target, name, data):
    folder = os.path.join(CORPUS, target)
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, name), "wb") as f:
        f.write(bytes(data))


def png(width, height):
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    rows = b"".join(b"\0" + bytes((x * 40 + y * 60) % 256 for x in range(width)) for y in range(height))
    header = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b"")


def messages(ros1):
    ts = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
    if "tf2_msgs/msg/TFMessage" not in ts.types:
        ts.register(get_types_from_msg("geometry_msgs/TransformStamped[] transforms", "tf2_msgs/msg/TFMessage"))
    T = ts.types
    Time = T["builtin_interfaces/msg/Time"]

    def header(t, frame, seq=0):
        stamp = Time(sec=int(t), nanosec=int(round((t - int(t)) * 1e9)))
        H = T["std_msgs/msg/Header"]
        return H(seq=seq, stamp=stamp, frame_id=frame) if ros1 else H(stamp=stamp, frame_id=frame)

    def transform(t, parent, child, x):
        V, Q = T["geometry_msgs/msg/Vector3"], T["geometry_msgs/msg/Quaternion"]
        return T["geometry_msgs/msg/TransformStamped"](
            header=header(t, parent), child_frame_id=child,
            transform=T["geometry_msgs/msg/Transform"](translation=V(x=x, y=0.5, z=1.0),
                                                       rotation=Q(x=0.0, y=0.0, z=0.3826834, w=0.9238795)))

    def cloud(t):
        F = T["sensor_msgs/msg/PointField"]
        fields = [F(name=n, offset=4 * i, datatype=7, count=1) for i, n in enumerate(["x", "y", "z", "intensity"])]
        pts = np.array([[1, 0, 0, 9], [2, 1, 0, 9], [np.nan, 0, 0, 9], [0, 3, 1, 9], [4, 4, 4, 9]], dtype="<f4")
        return T["sensor_msgs/msg/PointCloud2"](
            header=header(t, "/lidar"), height=1, width=5, fields=fields, is_bigendian=False, point_step=16,
            row_step=80, data=np.frombuffer(pts.tobytes(), dtype=np.uint8), is_dense=False)

    def image(t):
        return T["sensor_msgs/msg/CompressedImage"](header=header(t, "camera"), format="png",
                                                      data=np.frombuffer(png(4, 3), dtype=np.uint8))

    def info(t):
        K = np.array([5.0, 0, 2, 0, 5, 1.5, 0, 0, 1]); R = np.eye(3).reshape(-1)
        P = np.array([5.0, 0, 2, 0, 0, 5, 1.5, 0, 0, 0, 1, 0])
        roi = T["sensor_msgs/msg/RegionOfInterest"](x_offset=0, y_offset=0, height=0, width=0, do_rectify=False)
        d = dict(D=np.zeros(5), K=K, R=R, P=P) if ros1 else dict(d=np.zeros(5), k=K, r=R, p=P)
        return T["sensor_msgs/msg/CameraInfo"](header=header(t, "camera"), height=3, width=4,
                                                distortion_model="plumb_bob", binning_x=0, binning_y=0, roi=roi, **d)

    TF = T["tf2_msgs/msg/TFMessage"]
    out = []
    for k, t in enumerate([1.0, 1.5]):
        out.append(("/tf", "tf2_msgs/msg/TFMessage",
                    TF(transforms=[transform(t, "map", "lidar", float(k)), transform(t, "map", "camera", 0.0)])))
        out.append(("/points", "sensor_msgs/msg/PointCloud2", cloud(t if k == 0 else 1.25)))
        out.append(("/image", "sensor_msgs/msg/CompressedImage", image(t)))
        out.append(("/camera_info", "sensor_msgs/msg/CameraInfo", info(t)))
    return ts, out


def write(ros1, path):
    ts, out = messages(ros1)
    if ros1:
        from rosbags.rosbag1 import Writer
        writer = Writer(path)
    else:
        from rosbags.rosbag2 import StoragePlugin, Writer
        writer = Writer(path, version=9, storage_plugin=StoragePlugin.MCAP)
    ser = ts.serialize_ros1 if ros1 else ts.serialize_cdr
    with writer:
        conns = {}
        for i, (topic, kind, msg) in enumerate(out):
            if topic not in conns:
                conns[topic] = writer.add_connection(topic, kind, typestore=ts)
            writer.write(conns[topic], int((1.0 + 0.1 * i) * 1e9), ser(msg, kind))
    return ts, out


def main():
    with tempfile.TemporaryDirectory() as tmp:
        bag = os.path.join(tmp, "small.bag")
        ts1, out1 = write(True, bag)
        put("ros1_bag", "small.bag", open(bag, "rb").read())
        folder = os.path.join(tmp, "small")
        ts2, out2 = write(False, folder)
        mcap = [f for f in os.listdir(folder) if f.endswith(".mcap")][0]
        put("mcap_bag", "small.mcap", open(os.path.join(folder, mcap), "rb").read())
    names = {"/points": ("cloud", 0), "/tf": ("tf", 2), "/camera_info": ("info", 4)}
    for topic, kind, msg in out1[:4]:
        if topic in names:
            name, sel = names[topic]
            put("ros_message", f"ros1-{name}", bytes([sel]) + bytes(ts1.serialize_ros1(msg, kind)))
    for topic, kind, msg in out2[:4]:
        if topic in names:
            name, sel = names[topic]
            put("ros_message", f"cdr-{name}", bytes([sel + 1]) + bytes(ts2.serialize_cdr(msg, kind)))
    print("wrote seeds into", CORPUS)


if __name__ == "__main__":
    main()
