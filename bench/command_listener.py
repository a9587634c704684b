# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A subscriber in its own process for the relay benchmark.

Usage: python bench/command_listener.py OUTPUT.json SECONDS TOPIC...

Subscribes to each TOPIC (std_msgs/Float64MultiArray); once the first message of every TOPIC
has arrived (discovery is done), records for SECONDS each message's number (its first value ÷
1e-6, bench/commander.py) and receive time (system clock, the commander's); then writes them as
JSON.
"""

from __future__ import annotations

import json
import sys
import time

import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import QoSProfile
from std_msgs.msg import Float64MultiArray

NUMBER = 1e-6  # bench/commander.py's


def main(argv: list[str]) -> int:
    output, seconds, *topics = argv
    rclpy.init()
    node = rclpy.create_node('bench_command_listener')
    received: dict[str, list[tuple[int, int]]] = {topic: [] for topic in topics}
    matched: set[str] = set()
    recording = False

    def on_command(topic: str):
        answers = received[topic]

        def callback(message: Float64MultiArray) -> None:
            arrival = time.time_ns()
            matched.add(topic)
            if recording:
                answers.append((round(message.data[0] / NUMBER), arrival))
        return callback

    for topic in topics:
        node.create_subscription(Float64MultiArray, topic, on_command(topic),
                                 QoSProfile(depth=10))
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    print('listening', flush=True)
    give_up = time.monotonic() + 30.0
    while not set(topics) <= matched and time.monotonic() < give_up:
        executor.spin_once(timeout_sec=0.05)
    recording = True
    deadline = time.monotonic() + float(seconds)
    while time.monotonic() < deadline:
        executor.spin_once(timeout_sec=0.05)
    with open(output, 'w', encoding='utf-8') as file:
        json.dump({'received': received}, file)
    node.destroy_node()
    rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
