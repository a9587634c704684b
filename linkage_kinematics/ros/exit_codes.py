# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""The nodes' exit statuses (docs/parameters.md: exit statuses), defined once."""

from enum import IntEnum


class ExitCode(IntEnum):
    """How ``linkage_node`` or ``linkage_command_node`` ended."""

    OK = 0  # stopped by SIGINT or SIGTERM, or linkage_node reached alpha_end (end_behavior stop)
    FAILED = 1  # the log could not be closed, or linkage_node's crank met a dead point first
    CONFIGURATION = 2  # it could not start: a bad parameter, or ROS or the log refused
