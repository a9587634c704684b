# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The rclpy shell: ``linkage_node`` and ``linkage_command_node`` wire the pure layers to ROS.

``node`` (``linkage_node``), ``command_node`` (``linkage_command_node``, the command relay),
``process`` (the process either runs in: start-up, signals, the collector frozen, timer slack,
the executor, the exit status), ``parameters`` (declaring both nodes' parameters and reading
them), ``source`` (what a source is, and what it may ask of the node), one module per source:
``drive_law_source`` (the drive law on a timer), ``measured_source`` (the four-bar's measured
driver) and ``loop_source`` (a lab's URDF's loops), with ``measured_input`` (the input both
measured sources share: ~/pause, ~/resume, ~/reset, freshness), ``outputs`` (linkage_node's
publishers, the topics and QoS both nodes share), ``node_log`` (either node's bag),
``messages`` (each message built one way) and ``exit_codes`` (both nodes' exit statuses).
"""
