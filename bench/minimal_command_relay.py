# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The yardstick of the relay benchmark: the command relay a lab would write by hand.

Usage: python bench/minimal_command_relay.py RATIOS.json

Subscribes to /planner/commands (std_msgs/Float64MultiArray) and publishes on /minimal/commands
each value times its constant ratio from RATIOS.json (one per joint, in order: 1 for a joint
passed through): the constant transmission labs write instead of solving the loops, on rclpy's
default executor with ``rclpy.spin``, until SIGINT or SIGTERM.
"""

from __future__ import annotations

import json
import sys

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import Float64MultiArray


class MinimalCommandRelay(Node):
    def __init__(self, ratios: list[float]) -> None:
        super().__init__('bench_minimal_command_relay')
        self._ratios = ratios
        self._publisher = self.create_publisher(Float64MultiArray, '/minimal/commands', 10)
        self.create_subscription(Float64MultiArray, '/planner/commands', self._relay, 10)

    def _relay(self, command: Float64MultiArray) -> None:
        if len(command.data) != len(self._ratios):
            return
        self._publisher.publish(Float64MultiArray(
            data=[value * ratio for value, ratio in zip(command.data, self._ratios)]))


def main(argv: list[str]) -> int:
    with open(argv[0], encoding='utf-8') as file:
        ratios = json.load(file)
    rclpy.init()
    node = MinimalCommandRelay(ratios)
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
