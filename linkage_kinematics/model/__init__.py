# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
What a mechanism looks like to ROS tools, as pure data (no ROS).

``joints`` (each driver's URDF tree and the mapping to a lab's joint names, directions and
offsets), ``urdf`` (the node's URDF), ``scene`` (the colours and sizes the markers and the URDF
draw with), ``urdf_reader`` (a URDF's links and joints, read once with urdf_parser_py) and
``robot_transforms`` (robot_state_publisher's transforms of a URDF at a joint state). A lab's
URDF's closed loops are ``loops``'. Imports only ``kinematics`` (and urdf_parser_py, lxml).
"""
