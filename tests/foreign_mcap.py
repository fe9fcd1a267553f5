#!/usr/bin/env python3
"""Re-writes one robot of an MCAP file of ours as another ROS 2 system would have recorded it,
with Foxglove's own Python writer (mcap-ros2-support, the writer rosbag2-style tools use).

Usage: foreign_mcap.py IN.mcap OUT.mcap --robot r1 [--compression zstd|lz4|none]
                       [--increment-scale K]

OUT holds `/scan` (sensor_msgs/LaserScan), `/odom` (nav_msgs/Odometry) and `/truth`
(geometry_msgs/PoseStamped) of that robot, decoded with mcap-ros2-support and encoded again
from the schema text in IN; every stamp and log time moved to a wall-clock epoch
(2023-11-14); no attachments and no scenario. The writer's default chunk compression is zstd,
as rosbag2's MCAP storage writes it. `--increment-scale K` multiplies every scan's
angle_increment by K (a laser the scenario does not describe).

Needs: pip install mcap==1.6.0 mcap-ros2-support==0.6.0 (tests/run.sh installs them).
Prints "wrote N messages" on success.
"""

import argparse

from mcap.reader import make_reader
from mcap.writer import CompressionType
from mcap_ros2.reader import read_ros2_messages
from mcap_ros2.writer import Writer

EPOCH_NS = 1_700_000_000_000_000_000


def shift(stamp):
    """Moves a builtin_interfaces/Time by EPOCH_NS."""
    ns = stamp.sec * 1_000_000_000 + stamp.nanosec + EPOCH_NS
    stamp.sec, stamp.nanosec = divmod(ns, 1_000_000_000)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("input")
    p.add_argument("output")
    p.add_argument("--robot", required=True)
    p.add_argument("--compression", choices=["zstd", "lz4", "none"], default="zstd")
    p.add_argument("--increment-scale", type=float, default=1.0)
    a = p.parse_args()
    renames = {
        f"/{a.robot}/scan": "/scan",
        f"/{a.robot}/odom": "/odom",
        f"/{a.robot}/ground_truth": "/truth",
    }
    with open(a.input, "rb") as f:
        summary = make_reader(f).get_summary()
    schemas = {}
    for ch in summary.channels.values():
        if ch.topic in renames:
            s = summary.schemas[ch.schema_id]
            schemas[ch.topic] = (s.name, s.data.decode())
    missing = sorted(set(renames) - set(schemas))
    assert not missing, f"{a.input}: no topics {missing}"
    compression = {
        "zstd": CompressionType.ZSTD,
        "lz4": CompressionType.LZ4,
        "none": CompressionType.NONE,
    }[a.compression]
    n = 0
    with open(a.output, "wb") as out:
        w = Writer(out, compression=compression)
        registered = {t: w.register_msgdef(*schemas[t]) for t in renames}
        for m in read_ros2_messages(a.input, topics=list(renames)):
            msg = m.ros_msg
            shift(msg.header.stamp)
            if m.channel.topic.endswith("/scan"):
                msg.angle_increment *= a.increment_scale
            t = m.log_time_ns + EPOCH_NS
            w.write_message(
                renames[m.channel.topic],
                registered[m.channel.topic],
                msg,
                log_time=t,
                publish_time=t,
                sequence=n,
            )
            n += 1
        w.finish()
    print(f"wrote {n} messages")


if __name__ == "__main__":
    main()
