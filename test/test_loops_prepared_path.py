# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The loops path with its constants resolved at plan time gives the per-call path's bits.

``RobotLoopsFollower`` and ``LoopSolver`` resolve each planned loop once (``driven_loop``, the
indices of the measured joints, the output's encoder); ``loops_per_call.ReferenceFollower`` is
the path as it was before that, message by message through ``solve_loop`` and
``continued_branch_of`` as they were (each looking the loop's closed form up by its hash).
On a sweep of every test robot, there and back, across whole turns of its revolute measured
joints, with and without velocities, and through refusals, both give the same floats bit for
bit; and the published ``joint_states`` bytes are ``encode_cdr``'s of the same message, with
efforts (``loops.output_joints``) too.
"""

from __future__ import annotations

import math
from typing import Any

from builtin_interfaces.msg import Time
from linkage_kinematics.kinematics.geometry import TWO_PI
from linkage_kinematics.kinematics.planar_loop import JointKind
from linkage_kinematics.loops.follower import (
    LoopDrop,
    LoopSample,
    RobotLoopsFollower,
)
from linkage_kinematics.loops.intake import DropReason
from linkage_kinematics.loops.plan import read_loops
from linkage_kinematics.model.urdf_reader import read_urdf
from linkage_kinematics.ros.messages import JointStateEffortEncoder, JointStateEncoder
from linkage_kinematics.shared.cdr import encode_cdr
from loop_robots import ROBOTS
from loops_per_call import ReferenceFollower
import pytest
from sensor_msgs.msg import JointState

PERIOD_NS = 1_000_000
SAMPLES = 400


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
    follower = RobotLoopsFollower(read_loops(read_urdf(ROBOTS[name].urdf())),
                                  ROBOTS[name].measured_joints, {}, math.pi / 2)
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
    assert reasons == {DropReason.NON_FINITE, DropReason.STAMP_NOT_NEWER,
                       DropReason.JUMP if revolute else DropReason.JOINTS_UNREACHABLE}


@pytest.mark.parametrize('name', sorted(ROBOTS))
@pytest.mark.parametrize('stamp_ns', [0, 1_700_000_000_123_456_789, -1_500_000_001])
def test_the_output_encoder_writes_encode_cdrs_bytes(name: str, stamp_ns: int) -> None:
    """The prepared joint_states bytes equal encode_cdr of the message built field by field."""
    follower = RobotLoopsFollower(read_loops(read_urdf(ROBOTS[name].urdf())),
                                  ROBOTS[name].measured_joints, {}, math.pi / 2)
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


@pytest.mark.parametrize('stamp_ns', [0, 1_700_000_000_123_456_789, -1_500_000_001])
def test_the_output_encoder_with_efforts_writes_encode_cdrs_bytes(stamp_ns: int) -> None:
    """Each published joint's effort after its velocity, as encode_cdr writes the message."""
    excavator = ROBOTS['excavator']
    follower = RobotLoopsFollower(read_loops(read_urdf(excavator.urdf())),
                                  excavator.measured_joints, {}, math.pi / 2,
                                  outputs=('boom_joint', 'stick_joint', 'bucket_joint'))
    encoder = None
    for stamp, names, positions, velocities in sweep('excavator', False)[:SAMPLES:37]:
        sample = follower.follow(stamp, names, positions, velocities,
                                 [1e5 * (1 + k) for k in range(len(names))])
        assert isinstance(sample, LoopSample) and len(sample.efforts) == len(sample.names)
        encoder = encoder or JointStateEffortEncoder(sample.names)
        message = JointState(name=list(sample.names), position=list(sample.positions),
                             velocity=list(sample.velocities), effort=list(sample.efforts))
        message.header.stamp = Time(sec=stamp_ns // 1_000_000_000,
                                    nanosec=stamp_ns % 1_000_000_000)
        assert encoder.encode(stamp_ns, sample.positions, sample.velocities,
                              sample.efforts) == encode_cdr(message)
