# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""``linkage_node``'s exit statuses (docs/parameters.md: exit statuses), defined once."""

from enum import IntEnum


class ExitCode(IntEnum):
    """How ``linkage_node`` ended."""

    OK = 0  # reached alpha_end with end_behavior stop, or stopped by SIGINT or SIGTERM
    FAILED = 1  # the crank met a dead point before alpha_end, or the log could not be closed
    CONFIGURATION = 2  # it could not start: a bad parameter, or ROS or the log refused
