# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A subscriber in its own process for the node benchmark.

Usage: python bench/listener.py OUTPUT.json SECONDS [TOPIC ...]

Subscribes to /diagnostics and to each TOPIC (sensor_msgs/JointState); once the first message
of every TOPIC (without TOPICs: of /diagnostics) has arrived (discovery is done), records for
SECONDS every JointState's header stamp and receive time (system clock, the clock the node
stamps with) and the key-value pairs of every /diagnostics status; then writes them, and the
joint names of each TOPIC's first message, as JSON.
"""

from __future__ import annotations

import json
import sys
import time

from diagnostic_msgs.msg import DiagnosticArray
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import QoSProfile
from sensor_msgs.msg import JointState


def main(argv: list[str]) -> int:
    output, seconds, *topics = argv
    rclpy.init()
    node = rclpy.create_node('bench_listener')
    received: dict[str, list[tuple[int, int]]] = {topic: [] for topic in topics}
    # the joint names of each TOPIC's first message, to check what a node publishes
    names: dict[str, list[str]] = {}
    diagnostics: list[dict[str, str]] = []
    matched: set[str] = set()
    recording = False

    def on_state(topic: str):
        samples = received[topic]

        def callback(message: JointState) -> None:
            arrival = time.time_ns()
            matched.add(topic)
            names.setdefault(topic, list(message.name))
            if recording:
                stamp = message.header.stamp
                samples.append((stamp.sec * 1_000_000_000 + stamp.nanosec, arrival))
        return callback

    def on_diagnostics(message: DiagnosticArray) -> None:
        matched.add('/diagnostics')
        if recording:
            for status in message.status:
                diagnostics.append({value.key: value.value for value in status.values})

    # Depth matches the node's publishers; a slow listener then drops, it does not stall them.
    for topic in topics:
        node.create_subscription(JointState, topic, on_state(topic), QoSProfile(depth=10))
    node.create_subscription(DiagnosticArray, '/diagnostics', on_diagnostics, QoSProfile(depth=10))
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    print('listening', flush=True)
    give_up = time.monotonic() + 30.0
    awaited = set(topics) or {'/diagnostics'}
    while not awaited <= matched and time.monotonic() < give_up:
        executor.spin_once(timeout_sec=0.05)
    recording = True
    deadline = time.monotonic() + float(seconds)
    while time.monotonic() < deadline:
        executor.spin_once(timeout_sec=0.05)
    with open(output, 'w', encoding='utf-8') as file:
        json.dump({'received': received, 'diagnostics': diagnostics, 'names': names}, file)
    node.destroy_node()
    rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
