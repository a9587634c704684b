# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
One run of either node, as pure Python (no rclpy): what the nodes decide, without ROS.

``limits`` (every parameter's limits), ``parameter_specs`` (each parameter's default,
descriptor text and contract: kind, unit, range; both nodes'), ``parameter_values`` (one value
checked against its spec, and the ``ConfigurationError`` naming a bad one), ``configuration``
(all values into a RunConfiguration or a RelayConfiguration), the four-bar's two sources
``motion`` (the drive law in time) and ``measured`` (a measured joint completed), ``control``
(~/pause, ~/resume, ~/reset), ``diagnostics`` (the four-bar's status, the ``Status`` every
source reports in, and the measured samples' ``Freshness``), ``loop_diagnostics`` (the health
and statuses of ``loops:=robot_description``), ``relay`` (the command relay's conversions and
refusals) and ``relay_diagnostics`` (what the relay counts, logs and reports), and
``placement`` (cpu_affinity). Imports only ``kinematics``, ``model``, ``loops`` and ``shared``
(rosbag2's split numbers and process affinity, both plain Python), never ``bag``.
"""
