# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The loops path as it was before each planned loop's constants were resolved at plan time.

``ReferenceFollower`` follows a ``RobotLoopsFollower``'s plan message by message through
``solve_loop`` and ``continued_branch_of`` as they were written then (each looking the loop's
closed form up by the loop's hash at every call), with the per-message dicts and sets of the
follower and solver of that time. test_loops_prepared_path compares the package's path with it
bit for bit; bench/loops_bench.py times both.
"""

from __future__ import annotations

from collections.abc import Sequence
import math

from linkage_kinematics.kinematics.closed_form import CrankRates
from linkage_kinematics.kinematics.continuation import continued_branch
from linkage_kinematics.kinematics.geometry import TWO_PI, wrap_angle
from linkage_kinematics.kinematics.planar_loop import (
    _four_bar,
    _prismatic,
    DeadPointError,
    JointKind,
    known_joint_range,
    LoopState,
    PlanarLoop,
    UnreachableError,
)
from linkage_kinematics.kinematics.solver import solve, unwrap_near
from linkage_kinematics.loops.follower import (
    LoopDrop,
    LoopSample,
    RobotLoopsFollower,
)
from linkage_kinematics.loops.intake import DropReason, joint_velocity
from linkage_kinematics.loops.solver import LoopSampleError


def solve_loop(loop: PlanarLoop, known: int, value: float, rate: float,
               branch: int) -> LoopState:
    """Return ``planar_loop.solve_loop``'s state as it was computed call by call."""
    if loop.prismatic is not None:
        coordinates, rates = _prismatic(loop, known).solve(value, rate, branch)
        return LoopState(coordinates, rates, branch)
    state = solve(_four_bar(loop, known), value, CrankRates(rate, 0.0), branch)
    links = loop.links
    turn = math.atan2(links[known][1], links[known][0]) + 0.5 * math.pi
    following, next_but_one = links[(known + 1) % 4], links[(known + 2) % 4]
    coupler = state.gamma + turn - math.atan2(following[1], following[0])
    rocker = -state.beta + turn - math.atan2(next_but_one[1], next_but_one[0])
    coordinates = [0.0] * 4
    rates = [0.0] * 4
    coordinates[known] = value
    coordinates[(known + 1) % 4] = wrap_angle(coupler - value)
    coordinates[(known + 2) % 4] = wrap_angle(rocker - coupler)
    coordinates[(known + 3) % 4] = wrap_angle(-rocker)
    rates[known] = rate
    rates[(known + 1) % 4] = state.omega_ab - rate
    rates[(known + 2) % 4] = state.omega_bc - state.omega_ab
    rates[(known + 3) % 4] = -state.omega_bc
    return LoopState(tuple(coordinates), tuple(rates), branch)


def continued_branch_of(loop: PlanarLoop, known: int, value_from: float, branch: int,
                        value_to: float) -> int:
    """Return ``planar_loop.continued_branch_of``'s branch as it was found call by call."""
    if loop.prismatic is not None:
        return _prismatic(loop, known).continued_branch(value_from, branch, value_to)
    return int(continued_branch(_four_bar(loop, known), value_from, branch, value_to))


class ReferenceFollower:
    """The follower's and the solver's per-call path before constants were resolved per plan."""

    def __init__(self, follower: RobotLoopsFollower) -> None:
        plan = follower.plan
        self.plan = plan
        self.max_jump = follower.max_jump
        self.revolute = frozenset(planned.known.name for planned in plan.loops
                                  if planned.measured and planned.known.kind is JointKind.REVOLUTE)
        self.odd_turns = frozenset(
            planned.loop.constraint for planned in plan.loops
            if planned.known.kind is JointKind.REVOLUTE and len(known_joint_range(
                planned.loop.planar, planned.known.index).change_points) % 2)
        self.restart()

    def restart(self) -> None:
        """Forget the motion, as ``RobotLoopsFollower.restart`` does."""
        plan = self.plan
        self.known_values = {planned.loop.constraint: 0.0 for planned in plan.loops}
        self.branches = {planned.loop.constraint: planned.branch for planned in plan.loops}
        self.previous = {name: 0.0 for name in plan.passive}
        self.last_stamp_ns: int | None = None
        self.last: dict[str, float] = {}

    def solve(self, values: dict[str, float],
              rates: dict[str, float]) -> tuple[dict[str, float], dict[str, float]]:
        """Return the passive joints' positions and velocities, as ``LoopSolver.solve``."""
        known_values, branches, solved_positions, solved_velocities = {}, {}, {}, {}
        for planned in self.plan.loops:
            constraint, known = planned.loop.constraint, planned.known
            value = known.sign * values[known.name]
            planar = planned.loop.planar
            try:
                branch = continued_branch_of(planar, known.index, self.known_values[constraint],
                                             self.branches[constraint], value)
                if (known.kind is JointKind.REVOLUTE and constraint in self.odd_turns
                        and round((self.known_values[constraint] - value) / TWO_PI) % 2):
                    branch = -branch
                state = solve_loop(planar, known.index, value, known.sign * rates[known.name],
                                   branch)
            except (DeadPointError, UnreachableError) as error:
                raise LoopSampleError(f'constraint {constraint!r} at {known.name} = '
                                      f'{values[known.name]:.9g}: {error}',
                                      constraint) from None
            known_values[constraint], branches[constraint] = value, state.branch
            for joint in planned.passive:
                position = joint.sign * state.coordinates[joint.index]
                if joint.kind is JointKind.REVOLUTE:
                    position = unwrap_near(position, self.previous[joint.name])
                values[joint.name] = solved_positions[joint.name] = position
                rates[joint.name] = solved_velocities[joint.name] = (
                    joint.sign * state.rates[joint.index])
        self.known_values, self.branches = known_values, branches
        self.previous = dict(solved_positions)
        return solved_positions, solved_velocities

    def follow(self, stamp_ns: int, names: Sequence[str], positions: Sequence[float],
               velocities: Sequence[float]) -> LoopSample | LoopDrop | None:
        """Return what ``RobotLoopsFollower.follow`` returns (drops without their loops)."""
        index = {name: i for i, name in enumerate(names)}
        measured = self.plan.measured
        if not any(name in index for name in measured):
            return None
        missing = [name for name in measured
                   if name not in index or index[name] >= len(positions)]
        if missing:
            return LoopDrop(DropReason.NO_JOINT, (), f'no position of {missing}')
        values = {name: positions[index[name]] for name in measured}
        given = {name: velocities[index[name]] for name in measured
                 if index[name] < len(velocities)}
        bad = [name for name in measured if not math.isfinite(values[name])
               or not math.isfinite(given.get(name, 0.0))]
        if bad:
            return LoopDrop(DropReason.NON_FINITE, (), f'{bad} not finite')
        if self.last_stamp_ns is not None and stamp_ns <= self.last_stamp_ns:
            return LoopDrop(DropReason.STAMP_NOT_NEWER, (), 'stamp not newer')
        for name in self.revolute & self.last.keys():
            last = self.last[name]
            values[name] += round((last - values[name]) / TWO_PI) * TWO_PI
        jumps = [name for name in self.revolute & self.last.keys()
                 if abs(values[name] - self.last[name]) > self.max_jump]
        if jumps:
            return LoopDrop(DropReason.JUMP, (), f'{jumps} jumped')
        rates, estimates = {}, {}
        for name in measured:
            last = None if name not in self.last else (self.last_stamp_ns, self.last[name])
            rates[name], estimates[name] = joint_velocity(stamp_ns, values[name],
                                                          given.get(name), last)
        try:
            solved, solved_rates = self.solve({name: float(values[name]) for name in measured},
                                              {name: float(rates[name]) for name in measured})
        except LoopSampleError as error:
            return LoopDrop(DropReason.JOINTS_UNREACHABLE,
                            () if error.constraint is None else (error.constraint,), str(error))
        self.last_stamp_ns, self.last = stamp_ns, values
        joints = {**values, **solved}
        return LoopSample(
            stamp_ns, tuple(solved), tuple(solved.values()), tuple(solved_rates.values()),
            joints, estimates,
            {planned.loop.constraint: joints[planned.known.name] for planned in self.plan.loops})
