# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Why a closure group refuses a sample or a plan, and the conditioning it refuses beyond.

Each refusal is by name with its own reason (``Refusal``), never NaN: no assembly reaches the
known joints (no continuation converges, as beyond a dead point); the answer would jump to
another assembly (det A changed sign along the motion: it crossed a singular configuration);
too near a singular configuration: the conditioning κ (1-norm, rows and columns
dimensionless) such that the answer would lose ``ACCURACY``. Positions carry κ·ε of the
inputs' rounding, velocities and accelerations κ²·ε (their Jacobian is taken at positions off
by κ·ε), so κ above ``CONDITION_LIMIT`` (κ²·ε > 1e-3) is refused: by the closure
(newton.py), the transmission and the command direction alike. ``PlanError``: a group that
cannot be solved per sample from its assembled pose. Pure: no ROS.
"""

from __future__ import annotations

import enum
import math
import sys

EPSILON = sys.float_info.epsilon
ACCURACY = 1e-3
CONDITION_LIMIT = math.sqrt(ACCURACY / EPSILON)


class Refusal(enum.Enum):
    """Why a sample is refused."""

    UNREACHABLE = 'no assembly reaches the known joints'
    ASSEMBLY_CHANGE = 'the answer would jump to another assembly'
    SINGULAR = 'too near a singular configuration'


class SampleRefused(ValueError):
    """A sample a group cannot be closed at; ``reason`` says why, the message in full."""

    def __init__(self, group: str, reason: Refusal, detail: str) -> None:
        super().__init__(f'group {group}: {reason.value} ({detail})')
        self.group = group
        self.reason = reason


class PlanError(ValueError):
    """A group that cannot be solved per sample from its assembled pose; the message says why."""
