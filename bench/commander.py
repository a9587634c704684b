# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A planner's forward commands for the relay benchmark: one Float64MultiArray per millisecond.

Usage: python bench/commander.py OUTPUT.json RATE_HZ SECONDS JOINTS.json

JOINTS.json maps each joint of the commands, in order, to [low, high] (rad or m). Publishes on
/planner/commands every joint swinging sinusoidally over its range (each in its own phase) but
the first, which carries the message's number times 1e-6 rad (a joint both relays pass through
unchanged, so that the listener knows each answer's command), at RATE_HZ on absolute deadlines
for SECONDS; then writes the system-clock time each number was published at, as JSON.
"""

from __future__ import annotations

import json
import math
import sys
import time

import rclpy
from rclpy.qos import QoSProfile
from std_msgs.msg import Float64MultiArray

SWING_HZ = 0.5  # as a leg moves
NUMBER = 1e-6  # rad per message number, in the first joint


def main(argv: list[str]) -> int:
    output, rate, seconds, joints_file = argv[0], float(argv[1]), float(argv[2]), argv[3]
    with open(joints_file, encoding='utf-8') as file:
        ranges = list(json.load(file).values())
    rclpy.init()
    node = rclpy.create_node('bench_commander')
    publisher = node.create_publisher(Float64MultiArray, '/planner/commands',
                                      QoSProfile(depth=10))
    message = Float64MultiArray(data=[0.0] * len(ranges))
    swings = [((low + high) / 2.0, (high - low) / 2.0, 2.0 * math.pi * index / len(ranges))
              for index, (low, high) in enumerate(ranges)]
    turn = 2.0 * math.pi * SWING_HZ
    period = 1.0 / rate
    sent = []
    start = time.monotonic() + 0.5
    for index in range(round(rate * seconds)):
        delay = start + index * period - time.monotonic()
        if delay > 0.0:
            time.sleep(delay)
        elapsed = index * period
        values = [centre + amplitude * math.sin(turn * elapsed + phase)
                  for centre, amplitude, phase in swings]
        values[0] = index * NUMBER
        message.data = values
        sent.append(time.time_ns())
        publisher.publish(message)
    with open(output, 'w', encoding='utf-8') as file:
        json.dump(sent, file)
    node.destroy_node()
    rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
