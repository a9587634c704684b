# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
One run of the node, as pure Python (no rclpy): what the node decides, without ROS.

``parameter_specs`` (each parameter's default, descriptor text and contract: kind, unit, range
from ``limits``), ``parameter_values`` (one value checked against its spec, and the
``ConfigurationError`` naming a bad one), ``configuration`` (all values into a
RunConfiguration), the
four-bar's two sources ``motion`` (the drive law in time) and ``measured`` (a measured joint
completed), ``control`` (~/pause, ~/resume, ~/reset), ``diagnostics`` (the four-bar's status,
the ``Status`` every source reports in, and the measured samples' ``Freshness``) and
``loop_diagnostics`` (the health and statuses of ``loops:=robot_description``), and
``placement`` (cpu_affinity). Imports only ``kinematics``, ``model``, ``loops`` and ``shared``
(rosbag2's split numbers and process affinity, both plain Python), never ``bag``.
"""
