# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
An encoder in its own process: publishes the JointState samples of a JSON file, as a lab's would.

``python test/encoder_process.py SAMPLES.json``. The file holds ``topic`` (where to publish),
``state_topic`` (the completer's ``linkage/state``) and ``samples``, each with ``stamp_ns``,
``name``, ``position``, ``velocity`` and ``answered`` (whether the completer will publish a state
for it), and optionally ``truncate``: only that many of the message's CDR bytes are sent.
After each answered sample the encoder waits for the state stamped like it before publishing
the next, so that no sample waits in a queue a busy machine could overflow; the samples the
completer drops in between are delivered in order before it (one reliable writer).
Exit status 0 when every answered sample was answered, 1 otherwise.
"""

from __future__ import annotations

import json
import sys
import time

import rclpy
from rclpy.node import Node
from rclpy.qos import QoSProfile
from rclpy.serialization import serialize_message
from sensor_msgs.msg import JointState
from trajectory_msgs.msg import JointTrajectory

TIMEOUT = 60.0  # s, as PROCESS_TIMEOUT in node_process.py


def main(path: str) -> int:
    """Publish every sample of the file at ``path``; return the exit status."""
    with open(path, encoding='utf-8') as file:
        plan = json.load(file)
    rclpy.init()
    node = Node('encoder')
    answered: set[int] = set()

    def heard(message: JointTrajectory) -> None:
        answered.add(message.header.stamp.sec * 1_000_000_000 + message.header.stamp.nanosec)

    publisher = node.create_publisher(JointState, plan['topic'], QoSProfile(depth=1000))
    node.create_subscription(JointTrajectory, plan['state_topic'], heard, QoSProfile(depth=1000))

    def spin_until(done) -> bool:
        deadline = time.monotonic() + TIMEOUT
        while not done() and time.monotonic() < deadline:
            rclpy.spin_once(node, timeout_sec=0.05)
        return done()

    try:
        if not spin_until(lambda: publisher.get_subscription_count() > 0
                          and node.count_publishers(plan['state_topic']) > 0):
            print('encoder: no completer found', file=sys.stderr)
            return 1
        for sample in plan['samples']:
            message = JointState(name=sample['name'], position=sample['position'],
                                 velocity=sample['velocity'])
            message.header.stamp.sec, message.header.stamp.nanosec = divmod(
                sample['stamp_ns'], 1_000_000_000)
            publisher.publish(message if 'truncate' not in sample
                              else serialize_message(message)[:sample['truncate']])
            if sample['answered'] and not spin_until(lambda: sample['stamp_ns'] in answered):
                print(f"encoder: no state stamped {sample['stamp_ns']}", file=sys.stderr)
                return 1
        return 0
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    sys.exit(main(sys.argv[1]))
