# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A lab's encoder for the measured benchmark: one JointState per millisecond.

Usage: python bench/encoder.py OUTPUT.json RATE_HZ SECONDS

Publishes on /encoder/joint_states the crank of the Grashof crank-rocker turning at 2 rad/s
(position wrapped at ±π, as an encoder's, and its velocity) next to an unrelated joint, each
stamped with the system clock just before it is published, at RATE_HZ on absolute deadlines
for SECONDS; then writes the stamps it published as JSON.
"""

from __future__ import annotations

import json
import math
import sys
import time

import rclpy
from rclpy.qos import QoSProfile
from sensor_msgs.msg import JointState

OMEGA = 2.0  # rad/s


def main(argv: list[str]) -> int:
    output, rate, seconds = argv[0], float(argv[1]), float(argv[2])
    rclpy.init()
    node = rclpy.create_node('bench_encoder')
    publisher = node.create_publisher(JointState, '/encoder/joint_states', QoSProfile(depth=10))
    message = JointState(name=['crank_joint', 'gripper_finger'], position=[0.0, 0.0],
                         velocity=[OMEGA, 0.0])
    period = 1.0 / rate
    count = round(rate * seconds)
    stamps = []
    start = time.monotonic() + 0.5
    for index in range(count):
        delay = start + index * period - time.monotonic()
        if delay > 0.0:
            time.sleep(delay)
        message.position[0] = math.remainder(OMEGA * index * period, 2.0 * math.pi)
        stamp = time.time_ns()
        message.header.stamp.sec, message.header.stamp.nanosec = divmod(stamp, 1_000_000_000)
        publisher.publish(message)
        stamps.append(stamp)
    with open(output, 'w', encoding='utf-8') as file:
        json.dump(stamps, file)
    node.destroy_node()
    rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
