# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The yardstick of the CPU comparison: the rclpy node a lab would write by hand.

Usage: python bench/minimal_publisher.py RATE_HZ [single|events]

Publishes one sensor_msgs/JointState (three named joints, positions and velocities, stamped
with the node's clock) on /bench/joint_states per timer tick at RATE_HZ, on rclpy's default
SingleThreadedExecutor (``single``, the default) or on rclpy.experimental.EventsExecutor
(``events``), until SIGINT or SIGTERM.

On the default executor it spins as ``rclpy.spin(node)`` does. rclpy 7.1.6's EventsExecutor
``spin()`` never runs the timer here (it busy-waits at a full core and ignores SIGINT), so on
that executor the node spins with ``spin_once``, the way linkage_node does.
"""

from __future__ import annotations

import math
import sys

import rclpy
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from sensor_msgs.msg import JointState

EXECUTORS = {'single': SingleThreadedExecutor, 'events': EventsExecutor}


class MinimalPublisher(Node):
    def __init__(self, rate_hz: float) -> None:
        super().__init__('bench_minimal_publisher')
        self._publisher = self.create_publisher(JointState, '/bench/joint_states', 10)
        self._ticks = 0
        self._period = 1.0 / rate_hz
        self.create_timer(self._period, self._tick)

    def _tick(self) -> None:
        angle = self._ticks * self._period
        self._ticks += 1
        message = JointState()
        message.header.stamp = self.get_clock().now().to_msg()
        message.name = ['crank_joint', 'coupler_joint', 'rocker_joint']
        message.position = [angle, math.sin(angle), math.cos(angle)]
        message.velocity = [1.0, math.cos(angle), -math.sin(angle)]
        self._publisher.publish(message)


def main(argv: list[str]) -> int:
    rate_hz = float(argv[0])
    executor_name = argv[1] if len(argv) > 1 else 'single'
    rclpy.init()
    node = MinimalPublisher(rate_hz)
    executor = EXECUTORS[executor_name]()
    executor.add_node(node)
    try:
        if executor_name == 'single':
            executor.spin()
        else:
            while rclpy.ok():
                executor.spin_once(timeout_sec=0.1)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
