# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
loops.tree and loops.equations: forward kinematics, the closures' residuals and Jacobians.

Forward kinematics against urchin (an independent URDF library) and against the 50-digit
reference (test/closure_reference.py, which also holds overrides); the Jacobian's position rows
against the reference's derivatives at 50 digits, every row against central differences of the
residual, and J̇ against central differences of the Jacobian along the motion.
"""

from __future__ import annotations

import math
from pathlib import Path
import random
import tempfile

from closure_reference import Reference
import closure_robots
from linkage_kinematics.loops.closures import ClosureKind, JointOverride
from linkage_kinematics.loops.equations import LoopEquations
from linkage_kinematics.loops.rods import universal_rod
from linkage_kinematics.loops.spatial import (
    axis_rotation,
    log_rate_matrix,
    log_rotation,
    multiply,
    rpy_rotation,
)
from linkage_kinematics.loops.tree import KinematicTree, MotionKind, TreeError
from linkage_kinematics.model.urdf_reader import read_urdf
from mpmath import mp, mpf
import pytest
import urchin

MECHANISMS = [closure_robots.ankle, closure_robots.five_bar, closure_robots.planar_weld,
              closure_robots.rod_two_balls, closure_robots.collinear_pins,
              closure_robots.delta_like]


def tree_of(mechanism: closure_robots.Mechanism) -> KinematicTree:
    return KinematicTree(read_urdf(mechanism.urdf), mechanism.overrides)


def random_values(tree: KinematicTree, seed: int) -> list[float]:
    generator = random.Random(seed)
    return [generator.uniform(-1.0, 1.0) for _ in tree.names]


@pytest.mark.parametrize('make', [closure_robots.ankle, closure_robots.five_bar,
                                  closure_robots.planar_weld, closure_robots.collinear_pins])
def test_every_link_is_where_urchin_puts_it(make):
    mechanism = make()
    tree = tree_of(mechanism)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / 'robot.urdf'
        path.write_text(mechanism.urdf, encoding='utf-8')
        robot = urchin.URDF.load(str(path), lazy_load_meshes=True)
    for seed in range(5):
        values = random_values(tree, seed)
        poses = robot.link_fk(cfg=dict(zip(tree.names, values)), use_names=True)
        for link, matrix in poses.items():
            pose = tree.link_pose(link, values)
            for i in range(3):
                assert abs(pose.position[i] - matrix[i, 3]) <= 1e-15
                for j in range(3):
                    assert abs(pose.rotation[3 * i + j] - matrix[i, j]) <= 1e-15


@pytest.mark.parametrize('make', [closure_robots.rod_two_balls, closure_robots.delta_like])
def test_overridden_joints_turn_as_the_reference_turns_them(make):
    mechanism = make()
    tree = tree_of(mechanism)
    reference = Reference(mechanism.urdf, mechanism.closures, mechanism.reference_overrides)
    values = random_values(tree, 3)
    with mp.workdps(30):
        for link in tree.links:
            rotation, position = reference.link(dict(zip(tree.names, values)), link)
            pose = tree.link_pose(link, values)
            for i in range(3):
                assert abs(pose.position[i] - float(position[i])) <= 1e-15
                for j in range(3):
                    assert abs(pose.rotation[3 * i + j] - float(rotation[i, j])) <= 1e-15


def test_an_override_names_its_coordinates_after_the_joint_and_axis():
    tree = tree_of(closure_robots.rod_two_balls())
    assert tree.names == ('crank', 'ball_X', 'ball_Y', 'ball_Z', 'rocker')
    assert [c.kind for c in tree.coordinates] == [MotionKind.TURN] * 5
    assert [c.joint for c in tree.coordinates] == ['crank', 'ball', 'ball', 'ball', 'rocker']


def test_overrides_and_mimics_it_cannot_hold_are_refused_by_name():
    text = closure_robots.robot('r', [
        closure_robots.joint('a', 'revolute', 'base', 'l1'),
        closure_robots.joint('a_Y', 'revolute', 'l1', 'l2')])
    with pytest.raises(TreeError, match="joint override 'a': its coordinate 'a_Y' is also"):
        KinematicTree(read_urdf(text), {'a': JointOverride.UJOINT_XY})
    with pytest.raises(TreeError, match="joint override 'nothing' names no joint"):
        KinematicTree(read_urdf(text), {'nothing': JointOverride.SPHERICAL})
    mimic = text.replace('<joint name="a_Y" type="revolute">',
                         '<joint name="a_Y" type="revolute"><mimic joint="a" multiplier="2"/>')
    with pytest.raises(TreeError, match="joint 'a_Y' mimics the overridden joint 'a'"):
        KinematicTree(read_urdf(mimic), {'a': JointOverride.UJOINT_XZ})


def test_a_mimic_chain_moves_by_its_composed_multiplier_and_offset():
    text = closure_robots.robot('r', [
        closure_robots.joint('a', 'revolute', 'base', 'l1'),
        closure_robots.joint('b', 'revolute', 'l1', 'l2', xyz=(1, 0, 0)),
        closure_robots.joint('c', 'revolute', 'l2', 'l3', xyz=(1, 0, 0))])
    text = text.replace('<joint name="b" type="revolute">',
                        '<joint name="b" type="revolute">'
                        '<mimic joint="a" multiplier="2" offset="0.5"/>')
    text = text.replace('<joint name="c" type="revolute">',
                        '<joint name="c" type="revolute">'
                        '<mimic joint="b" multiplier="-3" offset="0.25"/>')
    tree = KinematicTree(read_urdf(text))
    assert tree.names == ('a',)
    step = tree.steps[2]
    assert (step.multiplier, step.offset) == (-6.0, -1.25)


def test_a_floating_joint_on_a_loop_is_refused_and_elsewhere_is_rigid():
    mechanism = closure_robots.five_bar()
    floating = mechanism.urdf.replace(
        '<joint name="j2" type="revolute">', '<joint name="j2" type="floating">')
    tree = KinematicTree(read_urdf(floating))
    with pytest.raises(TreeError, match="closure 'tip': joint 'j2' on its loop is floating"):
        tree.loop(mechanism.closures[0])
    world = mechanism.urdf.replace(
        '<robot name="five_bar">',
        '<robot name="five_bar"><link name="world"/><joint name="w" type="floating">'
        '<parent link="world"/><child link="base"/><origin xyz="1 2 3"/></joint>')
    tree = KinematicTree(read_urdf(world))
    assert tree.loop_coordinates(tree.loop(mechanism.closures[0])) == (0, 1, 2, 3)
    assert tree.link_pose('base', [0.0] * 4).position == (1.0, 2.0, 3.0)


@pytest.mark.parametrize('make', MECHANISMS)
def test_the_position_rows_derivatives_are_the_references(make):
    mechanism = make()
    tree = tree_of(mechanism)
    equations = LoopEquations(tree, mechanism.closures)
    reference = Reference(mechanism.urdf, mechanism.closures, mechanism.reference_overrides)
    values = random_values(tree, 7)
    local = [values[i] for i in equations.coordinates]
    jacobian = equations.jacobian(equations.evaluate(local))
    with mp.workdps(50):
        exact = reference.jacobian(dict(zip(tree.names, map(mpf, values))), equations.names)
    # the reference's rows: each closure's three position rows, then 0, 3 or 9 more
    row = 0
    for start, closure in zip((start for _, start, _ in equations.closure_rows),
                              mechanism.closures):
        for i in range(3):
            for j in range(len(local)):
                assert abs(jacobian[start + i][j] - float(exact[row + i, j])) <= 1e-15
        row += {ClosureKind.BALL: 3, ClosureKind.PIN: 6, ClosureKind.WELD: 12}[closure.kind]


def central_difference(function, values: list[float], direction: list[float], h: float = 1e-6):
    plus = function([v + h * d for v, d in zip(values, direction)])
    minus = function([v - h * d for v, d in zip(values, direction)])
    if isinstance(plus[0], list):
        return [[(a - b) / (2 * h) for a, b in zip(p, m)] for p, m in zip(plus, minus)]
    return [(a - b) / (2 * h) for a, b in zip(plus, minus)]


@pytest.mark.parametrize('kind', list(ClosureKind))
def test_every_row_and_its_rate_follow_the_residual(kind):
    mechanism = closure_robots.ankle()
    tree = tree_of(mechanism)
    closures = [closure_robots.closure(c.name, kind, c.parent, c.child)
                for c in mechanism.closures]
    equations = LoopEquations(tree, closures)
    values = random_values(tree, 11)
    rates = random_values(tree, 12)
    width = len(values)
    jacobian = equations.jacobian(equations.evaluate(values))
    for j in range(width):
        unit = [1.0 if k == j else 0.0 for k in range(width)]
        column = central_difference(equations.residual, values, unit)
        assert all(abs(jacobian[i][j] - column[i]) <= 2e-9 for i in range(equations.rows))
    if kind is ClosureKind.WELD:
        return  # its rotation rows' rate is exact at an assembled pose: the next test
    rate = equations.jacobian_rate(equations.evaluate(values), rates)
    numeric = central_difference(
        lambda point: equations.jacobian(equations.evaluate(point)), values, rates)
    assert all(abs(rate[i][j] - numeric[i][j]) <= 2e-9
               for i in range(equations.rows) for j in range(width))


def test_a_welds_rows_and_rate_at_an_assembled_pose_moving_as_the_loop_allows():
    planned = closure_robots.plan(closure_robots.planar_weld())
    equations = planned.solver.derivatives.full
    state = planned.solver.solve([0.4], [1.3])
    values = [0.4] + list(state.positions)
    rates = [1.3] + list(state.velocities)
    rate = equations.jacobian_rate(equations.evaluate(values), rates)

    def jacobian_at(time: float) -> list[list[float]]:
        solver = closure_robots.plan(closure_robots.planar_weld()).solver
        moved = solver.solve([0.4 + 1.3 * time], [1.3])
        return equations.jacobian(equations.evaluate([0.4 + 1.3 * time]
                                                     + list(moved.positions)))

    h = 1e-6
    plus, minus = jacobian_at(h), jacobian_at(-h)
    for i in range(equations.rows):
        for j in range(4):
            assert abs(rate[i][j] - (plus[i][j] - minus[i][j]) / (2 * h)) <= 1e-8


def test_the_log_map_matches_50_digits_from_zero_to_a_half_turn():
    axis = (0.48, -0.6, 0.64)
    for angle in (0.0, 1e-12, 1e-6, 0.04, 0.06, 1.0, math.pi / 2, 3.0, math.pi - 1e-9,
                  math.pi):
        e = log_rotation(axis_rotation(axis, angle))
        for component, a in zip(e, axis):
            assert abs(component - angle * a) <= 4e-16 * max(1.0, angle)
    # the rate matrix: ė = J⁻¹(e)·w for Ṙ = [w]×·R, checked by a small turn
    turn = multiply(rpy_rotation(0.3, -0.2, 1.1), rpy_rotation(0.1, 0.4, -0.5))
    e = log_rotation(turn)
    w = (0.2, -0.7, 0.4)
    h = 1e-6
    plus = log_rotation(multiply(axis_rotation((w[0] / 0.8307, w[1] / 0.8307, w[2] / 0.8307),
                                               h * 0.8307), turn))
    rate = log_rate_matrix(e)
    predicted = [sum(rate[3 * i + k] * w[k] for k in range(3)) for i in range(3)]
    assert all(abs((p - q) / h - r) <= 1e-5 for p, q, r in zip(plus, e, predicted))


def test_the_ankles_rods_hang_from_universal_joints():
    mechanism = closure_robots.ankle()
    tree = tree_of(mechanism)
    rods = [universal_rod(tree, tree.loop(closure), 0) for closure in mechanism.closures]
    assert [(rod.length, rod.center, rod.rod) for rod in rods] == [
        (0.23, (-0.045, 0.0, 0.0), (0.0, 0.0, -0.23))] * 2
    assert [tree.names[c] for rod in rods for c in rod.coordinates] == [
        'rod_left_u1', 'rod_left_u2', 'rod_right_u1', 'rod_right_u2']
    # the foot hangs from the ankle's pitch and roll, a universal joint too; the group shares
    # those (structure.reducible_rods keeps it whole)
    foot = universal_rod(tree, tree.loop(mechanism.closures[0]), 1)
    assert [tree.names[c] for c in foot.coordinates] == ['ankle_pitch', 'ankle_roll']
    assert foot.length == math.sqrt(0.065 ** 2 + 0.035 ** 2 + 0.02 ** 2)
