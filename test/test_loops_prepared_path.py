# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The loops path with its constants resolved at plan time gives the per-call path's bits.

``RobotLoopsFollower`` and ``LoopSolver`` resolve each planned loop once (``driven_loop``, the
indices of the measured joints, the output's encoder); ``ReferenceFollower`` below is the path
as it was before that, message by message through ``solve_loop`` and ``continued_branch_of`` as
they were (each looking the loop's closed form up by the loop's hash).
On a sweep of every test robot, there and back, across whole turns of its revolute measured
joints, with and without velocities, and through refusals, both give the same floats bit for
bit; and the published ``joint_states`` bytes are ``encode_cdr``'s of the same message.
"""

from __future__ import annotations

from collections.abc import Sequence
import math
from typing import Any

from builtin_interfaces.msg import Time
from linkage_kinematics.bag.cdr import encode_cdr
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
from linkage_kinematics.model.loops import LoopSampleError
from linkage_kinematics.ros.messages import JointStateEncoder
from linkage_kinematics.run.measured import joint_velocity
from linkage_kinematics.run.robot_loops import (
    LoopDrop,
    LoopRejection,
    LoopSample,
    read_loops,
    RobotLoopsFollower,
)
from loop_robots import ROBOTS
import pytest
from sensor_msgs.msg import JointState

PERIOD_NS = 1_000_000
SAMPLES = 400


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
        self.known_values = {planned.loop.constraint: 0.0 for planned in plan.loops}
        self.branches = {planned.loop.constraint: planned.branch for planned in plan.loops}
        self.previous = {name: 0.0 for name in plan.passive}
        self.last_stamp_ns: int | None = None
        self.last: dict[str, float] = {}

    def solve(self, values: dict[str, float],
              rates: dict[str, float]) -> tuple[dict[str, float], dict[str, float]]:
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
        index = {name: i for i, name in enumerate(names)}
        measured = self.plan.measured
        if not any(name in index for name in measured):
            return None
        missing = [name for name in measured
                   if name not in index or index[name] >= len(positions)]
        if missing:
            return LoopDrop(LoopRejection.NO_JOINT, (), f'no position of {missing}')
        values = {name: positions[index[name]] for name in measured}
        given = {name: velocities[index[name]] for name in measured
                 if index[name] < len(velocities)}
        bad = [name for name in measured if not math.isfinite(values[name])
               or not math.isfinite(given.get(name, 0.0))]
        if bad:
            return LoopDrop(LoopRejection.NON_FINITE, (), f'{bad} not finite')
        if self.last_stamp_ns is not None and stamp_ns <= self.last_stamp_ns:
            return LoopDrop(LoopRejection.STAMP_NOT_NEWER, (), 'stamp not newer')
        for name in self.revolute & self.last.keys():
            last = self.last[name]
            values[name] += round((last - values[name]) / TWO_PI) * TWO_PI
        jumps = [name for name in self.revolute & self.last.keys()
                 if abs(values[name] - self.last[name]) > self.max_jump]
        if jumps:
            return LoopDrop(LoopRejection.JUMP, (), f'{jumps} jumped')
        rates, estimates = {}, {}
        for name in measured:
            last = None if name not in self.last else (self.last_stamp_ns, self.last[name])
            rates[name], estimates[name] = joint_velocity(stamp_ns, values[name],
                                                          given.get(name), last)
        try:
            solved, solved_rates = self.solve({name: float(values[name]) for name in measured},
                                              {name: float(rates[name]) for name in measured})
        except LoopSampleError as error:
            return LoopDrop(LoopRejection.UNREACHABLE,
                            () if error.constraint is None else (error.constraint,), str(error))
        self.last_stamp_ns, self.last = stamp_ns, values
        joints = {**values, **solved}
        return LoopSample(
            stamp_ns, tuple(solved), tuple(solved.values()), tuple(solved_rates.values()),
            joints, estimates,
            {planned.loop.constraint: joints[planned.known.name] for planned in self.plan.loops})


def bits(values: Any) -> Any:
    """Return ``values`` with every float as its hex text: -0.0 and 0.0 differ, as bits do."""
    if isinstance(values, float):
        return values.hex()
    if isinstance(values, dict):
        return {key: bits(value) for key, value in values.items()}
    if isinstance(values, (tuple, list)):
        return [bits(value) for value in values]
    return values


def sweep(name: str, revolute: bool) -> list[tuple[int, list[str], list[float], list[float]]]:
    """
    Return messages moving each measured joint over its range there and back, twice.

    The second pass adds a whole turn to ``revolute`` measured joints (an encoder that wraps),
    leaves the velocities out (the backward difference), and ends with refusals: NaN, an old
    stamp, a move by 2.5 of the first joint (a jump if revolute, else out of reach), a message
    without the measured joints.
    """
    robot = ROBOTS[name]
    names = [*robot.measured_joints, 'other']
    messages = []
    for index in range(2 * SAMPLES):
        phase = math.sin(2 * math.pi * index / SAMPLES)
        positions = [low + (high - low) * (0.5 + 0.5 * phase) * (0.5 + 0.5 * (k + 1) / len(names))
                     for k, (low, high) in enumerate(robot.measured_ranges.values())]
        second = index >= SAMPLES
        if second and revolute:
            positions = [value + TWO_PI for value in positions]
        velocities = [] if second else [0.3 * phase + k for k in range(len(positions))] + [0.0]
        messages.append(((index + 1) * PERIOD_NS, names, [*positions, 4.0], velocities))
    stamp, _, positions, velocities = messages[-1]
    messages += [
        (stamp + 2 * PERIOD_NS, names, [math.nan, *positions[1:]], []),
        (stamp, names, positions, []),
        (stamp + 3 * PERIOD_NS, names, [positions[0] + 2.5, *positions[1:]], []),
        (stamp + 4 * PERIOD_NS, ['other'], [1.0], []),
        (stamp + 5 * PERIOD_NS, names, positions, velocities),
    ]
    return messages


@pytest.mark.parametrize('name', sorted(ROBOTS))
def test_the_prepared_path_gives_the_per_call_paths_bits(name: str) -> None:
    """Every sample, drop and estimate of the sweep equals the reference's, float bits too."""
    follower = RobotLoopsFollower(read_loops(ROBOTS[name].urdf()), ROBOTS[name].measured_joints,
                                  {}, math.pi / 2)
    reference = ReferenceFollower(follower)
    revolute = follower.plan.loops[0].known.kind is JointKind.REVOLUTE
    reasons = set()
    for stamp_ns, names, positions, velocities in sweep(name, revolute):
        got = follower.follow(stamp_ns, names, positions, velocities)
        expected = reference.follow(stamp_ns, names, positions, velocities)
        if isinstance(expected, LoopDrop):
            assert isinstance(got, LoopDrop)
            assert (got.reason, got.detail) == (expected.reason, expected.detail)
            if expected.constraints:
                assert got.constraints == expected.constraints
            reasons.add(got.reason)
            continue
        if expected is None:
            assert got is None
            continue
        assert isinstance(got, LoopSample)
        assert bits(vars(got)) == bits(vars(expected))
    # the sweep reached every refusal it means to (a reference that never refuses proves less)
    assert reasons == {LoopRejection.NON_FINITE, LoopRejection.STAMP_NOT_NEWER,
                       LoopRejection.JUMP if revolute else LoopRejection.UNREACHABLE}


@pytest.mark.parametrize('name', sorted(ROBOTS))
@pytest.mark.parametrize('stamp_ns', [0, 1_700_000_000_123_456_789, -1_500_000_001])
def test_the_output_encoder_writes_encode_cdrs_bytes(name: str, stamp_ns: int) -> None:
    """The prepared joint_states bytes equal encode_cdr of the message built field by field."""
    follower = RobotLoopsFollower(read_loops(ROBOTS[name].urdf()), ROBOTS[name].measured_joints,
                                  {}, math.pi / 2)
    encoder = None
    for stamp, names, positions, velocities in sweep(name, False)[:SAMPLES:37]:
        sample = follower.follow(stamp, names, positions, velocities)
        assert isinstance(sample, LoopSample)
        encoder = encoder or JointStateEncoder(sample.names)
        message = JointState(name=list(sample.names), position=list(sample.positions),
                             velocity=list(sample.velocities))
        message.header.stamp = Time(sec=stamp_ns // 1_000_000_000,
                                    nanosec=stamp_ns % 1_000_000_000)
        assert encoder.encode(stamp_ns, sample.positions, sample.velocities) == encode_cdr(
            message)
