# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The measured joints of a JointState taken in: how each velocity was obtained.

``joint_velocity`` gives a measured joint's velocity, the message's own or the backward
difference over the header stamps (0 for a first sample), and says which (``Estimate``). No ROS.
"""

from __future__ import annotations

from enum import StrEnum


class Estimate(StrEnum):
    """How the driver's angular velocity of a sample was obtained."""

    MEASURED = 'measured'
    BACKWARD_DIFFERENCE = 'estimated (backward difference of angles)'
    FIRST_SAMPLE = 'estimated (0: first sample without velocity)'


def joint_velocity(stamp_ns: int, value: float, measured: float | None,
                   last: tuple[int, float] | None) -> tuple[float, Estimate]:
    """
    Return a measured joint's velocity at ``value`` (stamp ``stamp_ns``) and how it was obtained.

    ``measured`` when the message carries it; else the backward difference from ``last``
    (its stamp in ns and its value, unwrapped to ``value``'s turn) over the header stamps, and 0
    for a first sample (``last`` None).
    """
    if measured is not None:
        return measured, Estimate.MEASURED
    if last is None:
        return 0.0, Estimate.FIRST_SAMPLE
    last_stamp_ns, last_value = last
    return (value - last_value) / ((stamp_ns - last_stamp_ns) * 1e-9), Estimate.BACKWARD_DIFFERENCE
