# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
loops.transmission_range: the mechanical advantage over the output joints' reachable range.

The knee's output swept to its dead points (where its planar closed form says the loop stops
closing), the excavator's boom to its cylinder's stroke, the knee driven from its crank to its
rocker's dead points (a singular configuration of the measured direction), the ankle's pitch
and roll in slices to their URDF limits and the motors'; the group left at its assembled pose.
"""

from __future__ import annotations

import math

import closure_robots
from linkage_kinematics.kinematics.planar_loop import known_joint_range
from linkage_kinematics.loops.command import CommandGroup, CommandRefusal
from linkage_kinematics.loops.plan import find_loops
from linkage_kinematics.loops.transmission import Transmission
from linkage_kinematics.loops.transmission_range import (
    advantage_range,
    LIMIT,
    SAMPLES,
)
from linkage_kinematics.model.urdf_reader import read_urdf
import transmission_robots

UNREACHABLE = CommandRefusal.UNREACHABLE.value
SINGULAR = CommandRefusal.SINGULAR.value
ACTUATOR_LIMIT = CommandRefusal.LIMIT.value


def test_the_knees_output_is_swept_to_its_dead_points():
    knee = transmission_robots.build('knee')
    command = knee.commands[0]
    start = command.position('knee_motor')
    found = advantage_range(command)
    loop = find_loops(read_urdf(transmission_robots.KNEE)).loops[0]
    joint = loop.joint('knee_output')
    # the planar closed form's own reach, in the loop's coordinate (sign × the URDF value)
    low, high = sorted(joint.sign * end for end in
                       known_joint_range(loop.planar, joint.index).interval_containing(0.0))
    (sweep,) = found.sweeps
    step = 2.0 * math.pi / SAMPLES
    assert 0.0 <= sweep.low - low <= step * 2.0 ** -19
    assert 0.0 <= high - sweep.high <= step * 2.0 ** -19
    assert (sweep.low_end, sweep.high_end) == (UNREACHABLE, UNREACHABLE)
    # the ratio grows without bound towards the output's dead points (a toggle)
    lowest, highest = found.ratio
    assert 1.9 < lowest < 2.0 and highest > 1e3
    assert found.singular_values == (lowest, highest)
    assert found.actuator_load == (1.0 / lowest,)
    assert found.samples > SAMPLES * (high - low) / (2.0 * math.pi)
    assert command.position('knee_motor') == start
    assert found.describe() == [
        "  output joints ['knee_output'] -> actuators ['knee_motor'] (swept by continuation "
        f'in {SAMPLES} steps of its span, {found.samples} samples)',
        f'    knee_output: [{sweep.low:.6g}, {sweep.high:.6g}] (low end: no assembly reaches '
        'it; high end: no assembly reaches it)',
        f'    transmission ratio d(knee_motor)/d(knee_output) from {lowest:.6g} to '
        f'{highest:.6g} (output effort per actuator effort)',
        f'    actuator effort per unit output effort, at worst: knee_motor {1 / lowest:.6g}']


def test_the_boom_is_swept_to_its_cylinders_stroke():
    excavator = transmission_robots.build('excavator')
    command = excavator.commands[0]
    found = advantage_range(command)
    (sweep,) = found.sweeps
    assert (sweep.low_end, sweep.high_end) == (ACTUATOR_LIMIT, ACTUATOR_LIMIT)
    # at each end the cylinder is at its stroke's end (±0.5 m), to the refined step
    for end in (sweep.low, sweep.high):
        cylinder = command.solve((end,)).actuators.positions[0]
        assert 0.5 - 1e-6 < abs(cylinder) <= 0.5
    command.reset()
    lowest, highest = found.ratio
    assert -0.7 < lowest < highest < -0.3  # m of cylinder per rad of boom


def test_the_crank_as_output_stops_at_the_rockers_dead_points():
    knee = transmission_robots.build('knee_reversed')
    (sweep,) = advantage_range(knee.commands[0]).sweeps
    # a continuous output joint: half a turn each way, stopped where the actuator stops
    assert (sweep.low_end, sweep.high_end) == (SINGULAR, SINGULAR)
    assert -math.pi < sweep.low < 0.0 < sweep.high < math.pi


def test_the_ankle_is_swept_in_slices_within_its_limits_and_the_motors():
    ankle = transmission_robots.build('ankle')
    command = ankle.commands[0]
    found = advantage_range(command)
    pitch, roll = found.sweeps
    assert found.method.startswith('slices: ankle_pitch swept by continuation')
    assert (pitch.high, pitch.high_end) == (0.5, LIMIT)  # the URDF's upper pitch
    assert pitch.low_end == ACTUATOR_LIMIT and -0.8 < pitch.low < -0.5
    assert (roll.low, roll.high) == (-0.35, 0.35)
    assert found.ratio is None
    smallest, largest = found.singular_values
    assert 0.5 < smallest < largest < 10.0
    advantage = command.solve(found.weakest_at).linearization.ratio
    weakest = min(math.sqrt(abs(x)) for x in _eigenvalues_of_mtm(advantage))
    assert abs(weakest - smallest) <= 1e-12 * smallest
    assert found.samples > 1000
    assert all(load > 0.0 for load in found.actuator_load)


def _eigenvalues_of_mtm(ratio) -> tuple[float, float]:
    """Return the eigenvalues of MᵀM for a 2×2 M (the squared singular values)."""
    (a, b), (c, d) = ratio
    p, q, r = a * a + c * c, a * b + c * d, b * b + d * d
    middle, spread = 0.5 * (p + r), math.hypot(0.5 * (p - r), q)
    return middle + spread, middle - spread


def test_three_output_joints_are_not_swept():
    delta = closure_robots.plan(closure_robots.delta_like())
    transmission = Transmission(delta.tree, delta.group, delta.structure,
                                ['elbow0_Y', 'elbow1_Y', 'elbow2_Y'], delta.assembly.values)
    command = CommandGroup(delta.tree, transmission, delta.assembly.values)
    assert advantage_range(command) is None
