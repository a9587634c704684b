# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The rclpy shell: ``linkage_node`` wires the pure layers to ROS.

``node`` (the node and its process), ``parameters`` (declaring the parameters and reading them),
``source`` (what a source is, and what it may ask of the node), one module per source:
``drive_law_source`` (the drive law on a timer), ``measured_source`` (the four-bar's measured
driver) and ``loop_source`` (a lab's URDF's loops), with ``measured_input`` (the input both
measured sources share: ~/pause, ~/resume, ~/reset, freshness), ``outputs`` (the publishers and
the bag), ``messages`` (each message built one way) and ``exit_codes``.
"""
