# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The rclpy shell: ``linkage_node`` wires the pure layers to ROS.

``node`` (the node and its process), ``parameters`` (declaring the parameters and reading them),
``sources`` (the timer or the subscription that feeds each source), ``outputs`` (the
publishers and the bag), ``messages`` (each message built one way) and ``exit_codes``.
"""
