# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The limits of the node's parameters, one owner for each: their validation and descriptors.

``parameter_specs`` puts them into each parameter's contract (which ``configuration`` checks
values against and the descriptors show), and ``configuration`` checks the pass against
MIN_PASS_DURATION. rosbag2's split numbers, which the bag writer applies too, have their owner
beneath both (``shared.rosbag2_split``).
"""

MAX_RATE_HZ = 10000.0
MAX_DISPLAY_RATE_HZ = 1000.0
MAX_BAG_SIZE = 2**63 - 1  # bytes; the largest int64 parameter
MAX_BAG_DURATION = 1e9  # s, about 32 years
MAX_CPU = 1023  # Linux's CPU_SETSIZE − 1: the highest CPU number an affinity mask holds
NO_CPU_AFFINITY = -1
# m; the largest length and |ground coordinate| the node's parameters take, far beyond any
# mechanism (geometry.MAX_SOLVABLE_LENGTH is what the library itself can solve)
MAX_PARAMETER_LENGTH = 1e6
MAX_ANGLE = 1e6  # rad; a double near 1e6 rad still resolves 1.2e-10 rad
MAX_OMEGA0 = 1e4  # rad/s
MAX_DRIVE_GAIN = 1e4  # 1/s, the largest |k|
# s; shorter passes would fall between clock ticks, and elapsed / pass duration could overflow.
MIN_PASS_DURATION = 1e-6
MAX_TIMEOUT = 3600.0  # s
MAX_TIME_CONSTANT = 10.0  # s
