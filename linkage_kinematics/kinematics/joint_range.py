# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Where the known joint of a planar loop can go: its reachable intervals, dead and change points.

A revolute joint's coordinate is an angle (rad) and its intervals repeat every turn, each written
with its centre in (−π, π]; a prismatic joint's is a displacement (m) along a line, and its
intervals are plain. Interval ends are dead points (the known joint cannot drive on); change
points lie inside an interval, where the two assemblies meet and a motion continues smoothly.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

from linkage_kinematics.kinematics.geometry import (
    ANGLE_TOLERANCE,
    TWO_PI,
    UnreachableError,
    wrap_angle,
)


@dataclass(frozen=True)
class KnownJointRange:
    """
    The reachable set of one joint's coordinate when that joint drives the loop.

    ``periodic`` is True for a revolute joint (angles in rad, modulo 2π) and False for a
    prismatic one (displacements in m). ``intervals`` are closed; ``dead_points`` are their ends
    (empty where a revolute joint turns fully); ``change_points`` lie inside them.
    """

    joint: int
    periodic: bool
    intervals: tuple[tuple[float, float], ...]
    dead_points: tuple[float, ...]
    change_points: tuple[float, ...]

    @property
    def full_rotation(self) -> bool:
        """Return True when the (revolute) joint can turn all the way round."""
        return self.periodic and not self.dead_points

    def _gap(self, value: float, point: float) -> float:
        return abs(wrap_angle(value - point)) if self.periodic else abs(value - point)

    def contains(self, value: float) -> bool:
        """Return True when the loop closes at ``value`` (modulo 2π for a revolute joint)."""
        if not math.isfinite(value):
            return False
        for low, high in self.intervals:
            if self.periodic:
                past_low = (value - low) % TWO_PI
                if (past_low <= high - low + ANGLE_TOLERANCE
                        or past_low >= TWO_PI - ANGLE_TOLERANCE):
                    return True
            elif low <= value <= high:
                return True
        return False

    def describe(self) -> str:
        """Return the reachable set for messages (degrees for a revolute joint, m otherwise)."""
        if self.full_rotation:
            return 'all angles (full rotation)'
        if self.periodic:
            return ' and '.join(
                f'[{math.degrees(low):.6f}°, {math.degrees(high):.6f}°]'
                for low, high in self.intervals) + ' (mod 360°)'
        return ' and '.join(f'[{low:.9g} m, {high:.9g} m]' for low, high in self.intervals)

    def unreachable(self, value: float) -> UnreachableError:
        """Return the error for a ``value`` at which the loop does not close."""
        shown = f'{math.degrees(value):.9f}°' if self.periodic else f'{value!r} m'
        return UnreachableError(
            f'joint {self.joint} at {shown} is not reachable: the loop closes only for '
            f'{self.describe()}'
        )

    def dead_point_distance(self, value: float) -> float | None:
        """Distance from ``value`` to the nearest dead point (rad or m); None if there is none."""
        if not self.dead_points:
            return None
        return min(self._gap(value, point) for point in self.dead_points)

    def change_point_distance(self, value: float) -> float | None:
        """Distance from ``value`` to the nearest change point (rad or m); None if none."""
        if not self.change_points:
            return None
        return min(self._gap(value, point) for point in self.change_points)
