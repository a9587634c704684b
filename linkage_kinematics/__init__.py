# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Exact kinematics of a planar four-bar linkage for ROS 2.

The linkage is the paper's disk (crank), coupler and rocker.

One subpackage per layer, each importing only those beneath it: ``shared`` (the contracts the
layers above share: CDR bytes, rosbag2's split numbers, process affinity), ``kinematics`` (the
pure library, numpy only), ``model`` (the mechanism as ROS tools see it), ``run`` (what the node
decides, no rclpy) and ``bag`` (MCAP bags) side by side, neither importing the other, ``ros``
(the thin rclpy shell of ``linkage_node``) and ``cli`` (the command-line tools). The contracts
in .importlinter state the layers; CONTRIBUTING.md, Architecture, shows the tree.
"""
