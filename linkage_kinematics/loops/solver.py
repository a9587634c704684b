# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A plan's loops closed sample by sample: the measured joints in, every passive loop joint out.

``LoopSolver`` turns each sample of the measured joints' positions and velocities into every
passive loop joint's, in URDF units (rad, m), loop by loop in the plan's order, keeping each loop
on its assembly through change points and continuous joints continuous across turns. A sample a
loop cannot be closed at is a ``LoopSampleError`` naming the loop. Pure: no ROS graph.
"""

from __future__ import annotations

from collections.abc import Mapping
import math

from linkage_kinematics.kinematics.geometry import TWO_PI
from linkage_kinematics.kinematics.planar_loop import (
    DeadPointError,
    driven_loop,
    JointKind,
    known_joint_range,
    UnreachableError,
)
from linkage_kinematics.kinematics.solver import unwrap_near
from linkage_kinematics.loops.plan import LoopPlan


class LoopSampleError(ValueError):
    """
    A sample the loops cannot be closed at (a dead point, out of reach, a missing joint).

    ``constraint`` names the loop that could not be closed (None: the sample itself is bad).
    """

    def __init__(self, message: str, constraint: str | None = None) -> None:
        super().__init__(message)
        self.constraint = constraint


class LoopSolver:
    """
    Closes a plan's loops sample by sample: measured joints in, passive loop joints out.

    Each loop starts on its planned branch at the zero pose and follows the known joint's motion
    from sample to sample (``DrivenLoop.continued_branch``), so that it stays on its assembly
    through change points; revolute and continuous joints are kept within π of their previous
    value (at first, of the zero pose), and a revolute known joint is followed across whole turns.
    A refused sample leaves that state as it was.
    """

    def __init__(self, plan: LoopPlan) -> None:
        self.plan = plan
        # A sample's joint values and rates are lists: the measured joints', then each passive
        # joint's as it is solved (plan.passive's order). Each loop's step, resolved once here
        # rather than at every sample: its constraint, its known joint's name, place in those
        # lists and sign, whether its branch flips with each whole turn of that joint (a
        # revolute known joint meeting an odd number of change points per turn), the loop
        # driven at that joint, and each passive joint's place among the passive joints, sign,
        # index and revolute-ness.
        self._passive = plan.passive
        places = {name: place for place, name in enumerate(plan.measured + self._passive)}
        passive_places = {name: place for place, name in enumerate(self._passive)}
        self._steps = tuple(
            (planned.loop.constraint, planned.known.name, places[planned.known.name],
             planned.known.sign,
             planned.known.kind is JointKind.REVOLUTE and len(known_joint_range(
                 planned.loop.planar, planned.known.index).change_points) % 2 == 1,
             driven_loop(planned.loop.planar, planned.known.index),
             tuple((passive_places[joint.name], joint.sign, joint.index,
                    joint.kind is JointKind.REVOLUTE) for joint in planned.passive))
            for planned in plan.loops)
        self.reset()

    def reset(self) -> None:
        """Start again from the zero pose on the planned branches."""
        # each loop's known value and branch at the last sample, in solve order
        self._known_values = [0.0] * len(self.plan.loops)
        self._branches = [planned.branch for planned in self.plan.loops]
        self._previous = [0.0] * len(self._passive)  # in plan.passive's order

    def solve(self, positions: Mapping[str, float],
              velocities: Mapping[str, float]) -> tuple[dict[str, float], dict[str, float]]:
        """
        Return every passive loop joint's position and velocity (rad or m, rad/s or m/s).

        From the measured joints' ``positions`` and ``velocities`` (by joint name, URDF units;
        other names are ignored). Raises LoopSampleError, naming the constraint and the
        joint, at a dead point, out of reach, or for a measured joint missing or not finite.
        """
        values = []
        rates = []
        isfinite = math.isfinite
        for name in self.plan.measured:
            if name not in positions or name not in velocities:
                raise LoopSampleError(f'no position and velocity for measured joint {name!r}')
            value = float(positions[name])
            rate = float(velocities[name])
            if not (isfinite(value) and isfinite(rate)):
                raise LoopSampleError(f'measured joint {name!r}: position {value} and '
                                      f'velocity {rate} are not both finite')
            values.append(value)
            rates.append(rate)
        known_values, branches = [], []
        solved = len(values)  # where the passive joints start
        previous = self._previous
        for step, last_value, last_branch in zip(self._steps, self._known_values,
                                                 self._branches):
            constraint, known, place, sign, flips_with_turns, driven, passive = step
            value = sign * values[place]
            try:
                branch = driven.continued_branch(last_value, last_branch, value)
                # A revolute known joint is followed across whole turns (an encoder that wraps
                # at ±π): the motion went the short way, the whole turns between it and the way
                # just counted holding an odd number of change points each where it flips.
                if flips_with_turns and round((last_value - value) / TWO_PI) % 2:
                    branch = -branch
                state = driven.solve(value, sign * rates[place], branch)
            except (DeadPointError, UnreachableError) as error:
                raise LoopSampleError(f'constraint {constraint!r} at {known} = '
                                      f'{values[place]:.9g}: {error}', constraint) from None
            known_values.append(value)
            branches.append(state.branch)
            coordinates, state_rates = state.coordinates, state.rates
            for passive_place, joint_sign, index, revolute in passive:
                position = joint_sign * coordinates[index]
                if revolute:
                    position = unwrap_near(position, previous[passive_place])
                values.append(position)
                rates.append(joint_sign * state_rates[index])
        self._known_values, self._branches = known_values, branches
        self._previous = values[solved:]
        return (dict(zip(self._passive, self._previous)),
                dict(zip(self._passive, rates[solved:])))
