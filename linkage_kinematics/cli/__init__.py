# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The command-line tools over the library: ``linkage-sweep``, ``linkage-demo``, ``linkage-replay``.

``arguments`` holds the argument types they share.
"""
