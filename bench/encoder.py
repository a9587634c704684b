# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A lab's encoder for the measured benchmarks: one JointState per millisecond.

Usage: python bench/encoder.py OUTPUT.json RATE_HZ SECONDS [JOINTS.json]

Publishes on /encoder/joint_states the crank of the Grashof crank-rocker turning at 2 rad/s
(position wrapped at ±π, as an encoder's, and its velocity) next to an unrelated joint, each
stamped with the system clock just before it is published, at RATE_HZ on absolute deadlines
for SECONDS; then writes the stamps it published as JSON. JOINTS.json, a map from joint name to
[low, high] (rad or m), adds those joints to every message, each swinging sinusoidally over its
range (with its velocity, each in its own phase, the k-th of n a k/n of a period on): a robot's
measured joints. ``sample`` gives a message's values, for the benchmarks that time the same
motion in-process.
"""

from __future__ import annotations

from collections.abc import Sequence
import json
import math
import sys
import time

import rclpy
from rclpy.qos import QoSProfile
from sensor_msgs.msg import JointState

OMEGA = 2.0  # rad/s
SWING_HZ = 0.5  # of the added joints: slow, as a leg or a boom moves


def swings(ranges: dict[str, Sequence[float]]) -> list[tuple[float, float, float]]:
    """Return each added joint's centre, amplitude and phase: its swing stays inside its range."""
    return [((low + high) / 2.0, (high - low) / 2.0, 2.0 * math.pi * index / len(ranges))
            for index, (low, high) in enumerate(ranges.values())]


def joint_names(ranges: dict[str, Sequence[float]]) -> list[str]:
    """Return the names of every message: the crank, the unrelated joint, the added joints."""
    return ['crank_joint', 'gripper_finger', *ranges]


def sample(added: Sequence[tuple[float, float, float]], elapsed: float
           ) -> tuple[list[float], list[float]]:
    """Return the positions and velocities of ``joint_names`` at ``elapsed`` s from the start."""
    turn = 2.0 * math.pi * SWING_HZ
    positions = [math.remainder(OMEGA * elapsed, 2.0 * math.pi), 0.0]
    velocities = [OMEGA, 0.0]
    for centre, amplitude, phase in added:
        positions.append(centre + amplitude * math.sin(turn * elapsed + phase))
        velocities.append(amplitude * turn * math.cos(turn * elapsed + phase))
    return positions, velocities


def main(argv: list[str]) -> int:
    output, rate, seconds = argv[0], float(argv[1]), float(argv[2])
    ranges: dict[str, list[float]] = {}
    if len(argv) > 3:
        with open(argv[3], encoding='utf-8') as file:
            ranges = json.load(file)
    rclpy.init()
    node = rclpy.create_node('bench_encoder')
    publisher = node.create_publisher(JointState, '/encoder/joint_states', QoSProfile(depth=10))
    message = JointState(name=joint_names(ranges))
    added = swings(ranges)
    period = 1.0 / rate
    count = round(rate * seconds)
    stamps = []
    start = time.monotonic() + 0.5
    for index in range(count):
        delay = start + index * period - time.monotonic()
        if delay > 0.0:
            time.sleep(delay)
        message.position, message.velocity = sample(added, index * period)
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
