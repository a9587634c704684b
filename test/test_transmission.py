# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
loops.transmission: output joints checked, and actuator efforts turned into output efforts.

The output joints' check and its one-line refusals; along measured motions of the humanoid
ankle, the lab knee and the excavator, τ_o = Mᵀ·τ_m against M from the 50-digit references'
velocities (test/closure_reference.py, test/loop_reference.py) within 1e-12 relative, the power
balance τ_mᵀ·ṁ = τ_oᵀ·q̇_o to rounding, every other joint's effort 0; the mechanical advantage
(the ratio, τ_o/τ_m, the singular values and the actuator load against the reference's M);
efforts refused at the knee's toggle, where M has no bound.
"""

from __future__ import annotations

import math
import sys

import closure_robots
from linkage_kinematics.loops.transmission import (
    assign_outputs,
    check_outputs,
    Transmission,
    TransmissionError,
    TransmissionSingular,
)
from mpmath import mp, mpf
import pytest
import transmission_robots
from transmission_robots import reference_ratio, relative

EPSILON = sys.float_info.epsilon


def test_output_joints_are_checked_one_line_each():
    planned = closure_robots.plan(closure_robots.ankle())
    tree, group, structure, values = (planned.tree, planned.group, planned.structure,
                                      planned.assembly.values)
    assert check_outputs(tree, group, structure, values, ['ankle_pitch', 'ankle_roll']) is None
    head = 'group ball_left+ball_right: output joints'
    assert check_outputs(tree, group, structure, values, ['ankle_pitch']) == (
        f"{head} ['ankle_pitch']: 1 joints for 2 degrees of freedom that move it (as many as "
        "its actuators ['motor_left', 'motor_right'])")
    assert check_outputs(tree, group, structure, values, ['ankle_pitch', 'motor_left']) == (
        f"{head} ['ankle_pitch', 'motor_left']: ['motor_left'] are measured; an output joint "
        "is one the actuators ['motor_left', 'motor_right'] move")
    assert check_outputs(tree, group, structure, values, ['ankle_pitch', 'elsewhere']) == (
        f"{head} ['ankle_pitch', 'elsewhere']: ['elsewhere'] are not joints of the group (its "
        "joints: ['ankle_pitch', 'ankle_roll', 'motor_left', 'motor_right', 'rod_left_u1', "
        "'rod_left_u2', 'rod_right_u1', 'rod_right_u2'])")
    with pytest.raises(TransmissionError, match='1 joints for 2 degrees'):
        Transmission(tree, group, structure, ['ankle_roll'], values)
    # the rod's spin about itself moves nothing: known, it leaves the crank free
    rod = closure_robots.plan(closure_robots.rod_two_balls())
    assert check_outputs(rod.tree, rod.group, rod.structure, rod.assembly.values,
                         ['ball_X']) == (
        "group rod_end: output joints ['ball_X'] are not independent at the assembled pose: "
        "group rod_end (joints ['crank', 'ball_X', 'ball_Y', 'ball_Z', 'rocker']): 2 degrees "
        "of freedom (0 idle), known ['ball_X']: under-determined, a free motion moves "
        "['crank', 'ball_Y', 'ball_Z', 'rocker']; 2 known joints are needed")
    assert check_outputs(rod.tree, rod.group, rod.structure, rod.assembly.values,
                         ['rocker']) is None


def test_the_parameters_names_are_split_among_the_groups():
    robot = transmission_robots.build('excavator')
    split, problems = assign_outputs(robot.tree, robot.groups,
                                     ['bucket_joint', 'boom_joint', 'boom_joint', 'tooth',
                                      'stick_joint'])
    assert split == {'boom_cylinder_pin': ('boom_joint',),
                     'stick_cylinder_pin': ('stick_joint',),
                     'bucket_cylinder_pin+bucket_pin': ('bucket_joint',)}
    assert problems == ("output joint 'boom_joint' is named twice",
                        "output joint 'tooth' is not a joint of the robot")
    split, problems = assign_outputs(robot.tree, robot.groups[:1], ['stick_joint'])
    assert split == {'boom_cylinder_pin': ()}
    assert problems == ("output joint 'stick_joint' is not a joint of any closure group",)


# robot → per measured joint (centre, amplitude, period in samples), and actuator efforts
MEASURED = {
    'ankle': ({'motor_left': (0.0, 0.4, 400), 'motor_right': (0.0, 0.3, 300)}, (2.0, -1.5)),
    'knee': ({'knee_motor': (0.0, 3.0, 400)}, (4.0,)),
    # within loop_robots' measured box, where every loop closes
    'excavator': ({'boom_cylinder': (0.0, 0.14, 400), 'stick_cylinder': (0.0, 0.19, 300),
                   'bucket_cylinder': (0.0, 0.14, 350)}, (2e5, -1e5, 5e4)),
}


@pytest.mark.parametrize('name', list(MEASURED))
def test_actuator_efforts_become_output_efforts_within_1e_12_and_balance_the_power(name):
    robot = transmission_robots.build(name)
    motion, efforts = MEASURED[name]
    checked = 0
    for sample in range(401):
        values = {joint: centre + amplitude * math.sin(2.0 * math.pi * sample / period + k)
                  for k, (joint, (centre, amplitude, period)) in enumerate(motion.items())}
        rates = {joint: amplitude * 2.0 * math.pi / period * math.cos(
            2.0 * math.pi * sample / period + k)
            for k, (joint, (centre, amplitude, period)) in enumerate(motion.items())}
        pose, answers = {}, []
        for planned, transmission in zip(robot.planned, robot.transmissions):
            known = [values[a] for a in transmission.actuators]
            given = [efforts[robot.measured.index(a)] for a in transmission.actuators]
            state = planned.solver.solve(known, [rates[a] for a in transmission.actuators])
            found = transmission.output_efforts(known, state.positions, given)
            solved = planned.structure.solved
            outputs = [solved.index(o) for o in transmission.outputs]
            # the serial model's unactuated joints carry no effort
            assert all(found[k] == 0.0 for k in range(len(solved)) if k not in outputs)
            actuator_power = math.fsum(t * rates[a]
                                       for t, a in zip(given, transmission.actuators))
            output_power = math.fsum(found[k] * state.velocities[k] for k in outputs)
            scale = math.fsum(abs(t * rates[a]) for t, a in zip(given, transmission.actuators))
            # M (from A', outputs known) times q̇_o (from A, actuators known) is ṁ to the
            # rounding of both solves: κ(A)·κ(A')·ε
            both = transmission.linearize(transmission.local(known, state.positions))
            bound = both.measured_conditioning * both.command_conditioning * EPSILON * scale
            assert abs(actuator_power - output_power) <= 4 * bound
            pose |= dict(zip(transmission.actuators, known))
            pose |= dict(zip(solved, state.positions))
            answers.append((given, [found[k] for k in outputs]))
        if sample % 200 == 100:
            exact = pose_for_reference(robot, pose)
            for place, (given, found) in enumerate(answers):
                with mp.workdps(50):
                    ratio = reference_ratio(robot, place, exact)
                    expected = ratio.T * mp.matrix([mpf(e) for e in given])
                assert relative(found, list(expected)) <= 1e-12
                checked += 1
    assert checked == 2 * len(robot.transmissions)


def pose_for_reference(robot, pose: dict[str, float]) -> dict[str, float]:
    """Return the pose with the outputs as given and the loops closed by the reference."""
    outputs = {name: pose[name] for name in robot.outputs}
    closed = transmission_robots.reference_pose(robot, outputs, pose)
    assert max(abs(float(closed[n]) - pose[n]) for n in closed) <= 1e-12
    return {**outputs, **closed}


def test_the_mechanical_advantage_is_the_ratio_or_ms_singular_values():
    knee = transmission_robots.build('knee')
    planned, transmission = knee.planned[0], knee.transmissions[0]
    state = planned.solver.solve([0.7], [1.0])
    advantage = transmission.advantage([0.7], state.positions)
    output_rate = state.velocities[planned.structure.solved.index('knee_output')]
    # one degree of freedom: dm/do, the output effort per unit actuator effort
    assert advantage.ratio[0][0] == pytest.approx(1.0 / output_rate, rel=1e-14)
    efforts = transmission.output_efforts([0.7], state.positions, [1.0])
    assert efforts[planned.structure.solved.index('knee_output')] == pytest.approx(
        advantage.ratio[0][0], rel=1e-15)
    assert advantage.singular_values == (abs(advantage.ratio[0][0]),)
    assert advantage.actuator_load == pytest.approx((1.0 / abs(advantage.ratio[0][0]),))
    assert advantage.describe().startswith('d(knee_motor)/d(knee_output) = ')
    ankle = transmission_robots.build('ankle')
    planned, transmission = ankle.planned[0], ankle.transmissions[0]
    state = planned.solver.solve([0.3, -0.2], [0.0, 0.0])
    advantage = transmission.advantage([0.3, -0.2], state.positions)
    pose = dict(zip(transmission.actuators, (0.3, -0.2))) | dict(
        zip(planned.structure.solved, state.positions))
    with mp.workdps(50):
        ratio = reference_ratio(ankle, 0, pose_for_reference(ankle, pose))
        singular = sorted(mp.svd_r(ratio, compute_uv=False), reverse=True)
        load = [sum(abs(x) for x in row) for row in
                (mp.inverse(ratio).T).tolist()]
    assert relative(advantage.singular_values, singular) <= 1e-12
    assert relative(advantage.actuator_load, load) <= 1e-12
    assert advantage.describe().startswith('singular values of d(actuators)/d(outputs) ')


def test_efforts_are_refused_at_the_knees_toggle_where_the_ratio_has_no_bound():
    """At the rocker's ends crank and coupler are in line: dm/do → ∞, A' singular."""
    knee = transmission_robots.build('knee')
    planned, transmission = knee.planned[0], knee.transmissions[0]
    solver, output = planned.solver, planned.structure.solved.index('knee_output')

    def output_rate(motor: float) -> float:
        return solver.solve([motor], [1.0]).velocities[output]

    # a rocker's end: where d(output)/d(motor) changes sign as the motor turns
    low = 0.0
    while output_rate(low + 0.05) * output_rate(low) > 0.0:
        low += 0.05
    high = low + 0.05
    for _ in range(50):
        middle = 0.5 * (low + high)
        same = output_rate(middle) * output_rate(low) > 0.0
        low, high = (middle, high) if same else (low, middle)
    state = solver.solve([low], [1.0])
    with pytest.raises(TransmissionSingular) as refused:
        transmission.output_efforts([low], state.positions, [1.0])
    assert str(refused.value).startswith(
        'group knee_output_pin: the output joints are too near a singular configuration of '
        'the transmission (conditioning ')
    state = solver.solve([low - 1e-4], [1.0])
    assert abs(transmission.output_efforts([low - 1e-4], state.positions, [1.0])[output]) > 1e3
