# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A robot's closed kinematic loops: read from its description, structured, solved and followed.

Pure (numpy, urdf_parser_py, lxml, PyYAML; no ROS). ``closures`` is the one model of a loop
closure, whichever of the three encodings it was read from.
"""
