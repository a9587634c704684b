# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Exact kinematics of a planar four-bar linkage for ROS 2.

The linkage is the paper's disk (crank), coupler and rocker.

One subpackage per layer, each importing only those before it: ``kinematics`` (the pure
library, numpy only), ``model`` (the mechanism as ROS tools see it), ``run`` (what the node
decides, no rclpy), ``bag`` (MCAP bags), ``ros`` (the thin rclpy shell of ``linkage_node``) and
``cli`` (the command-line tools). README.md, Architecture, shows the tree.
"""
