# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The yardstick of the measured benchmark: the relay a lab would write by hand.

Usage: python bench/minimal_relay.py

Subscribes to /encoder/joint_states and, for each message that carries crank_joint, publishes
on /relay/joint_states the two passive joints at the input's stamp: a linear mimic of the
crank (what labs write instead of solving the loop), on rclpy's default executor with
``rclpy.spin``, until SIGINT or SIGTERM.
"""

from __future__ import annotations

import sys

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from sensor_msgs.msg import JointState


class MinimalRelay(Node):
    def __init__(self) -> None:
        super().__init__('bench_minimal_relay')
        self._publisher = self.create_publisher(JointState, '/relay/joint_states', 10)
        self.create_subscription(JointState, '/encoder/joint_states', self._relay, 10)

    def _relay(self, measured: JointState) -> None:
        if 'crank_joint' in measured.name:
            self._publisher.publish(relayed(measured))


def relayed(measured: JointState) -> JointState:
    """Return the coupler and rocker joints a lab's hand-written relay makes of the crank's."""
    index = measured.name.index('crank_joint')
    angle = measured.position[index]
    rate = measured.velocity[index] if len(measured.velocity) > index else 0.0
    message = JointState()
    message.header.stamp = measured.header.stamp
    message.name = ['coupler_joint', 'rocker_joint']
    message.position = [-0.3 * angle, 0.5 * angle]
    message.velocity = [-0.3 * rate, 0.5 * rate]
    return message


def main() -> int:
    rclpy.init()
    node = MinimalRelay()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main())
