# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Exact kinematics of a planar four-bar linkage for ROS 2.

The linkage is the paper's disk (crank), coupler and rocker.

The kinematics (``geometry``, ``drive``, and ``kinematics`` over ``closed_form``,
``singular_points`` and ``continuation``) is a pure library that needs only numpy; the ROS node
and the command-line tools are thin shells around it.
"""
