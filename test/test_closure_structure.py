# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
loops.structure: closure groups, degrees of freedom from the rank, idle freedoms, determinacy.

Each mechanism of test/closure_robots.py at its assembled pose: its rows, rank, degrees of
freedom, idle freedoms (named by the joints they move) and how it is solved; an
under-determined and an over-determined group refused by one line naming the group, its
joints, its degrees of freedom and the known ones.
"""

from __future__ import annotations

from pathlib import Path
import xml.etree.ElementTree as ElementTree

import closure_robots
from linkage_kinematics.loops.assembly import assemble
from linkage_kinematics.loops.closures import ClosureKind
from linkage_kinematics.loops.structure import (
    analyse,
    classify,
    closure_groups,
    Determinacy,
    GroupKind,
    reducible_rods,
    StructureError,
)
from linkage_kinematics.loops.tree import KinematicTree
from linkage_kinematics.model.urdf_reader import read_urdf
import pytest

# mechanism, known joints → (rows, rank, dof, idle freedoms' joints, how it is solved)
EXPECTED = {
    ('ankle', None): (6, 6, 2, [], GroupKind.NEWTON),
    ('five_bar', None): (5, 2, 2, [], GroupKind.FIVE_BAR),
    ('five_bar', ('j1', 'j2')): (5, 2, 2, [], GroupKind.FIVE_BAR),
    ('five_bar', ('j3', 'j4')): (5, 2, 2, [], GroupKind.FIVE_BAR),
    ('five_bar', ('j2', 'j4')): (5, 2, 2, [], GroupKind.NEWTON),
    ('planar_weld', None): (6, 3, 1, [], GroupKind.NEWTON),
    ('rod_two_balls', None): (3, 3, 2, [('ball_X',)], GroupKind.NEWTON),
    ('collinear_pins', None): (5, 2, 2, [('p1', 'p2')], GroupKind.NEWTON),
    ('delta_like', None): (6, 6, 6, [('elbow0_X',), ('elbow1_X',), ('elbow2_X',)],
                           GroupKind.NEWTON),
}


@pytest.mark.parametrize(('name', 'known'), list(EXPECTED))
def test_each_mechanism_has_its_rank_freedoms_and_solution(name, known):
    planned = closure_robots.plan(getattr(closure_robots, name)(), known)
    structure = planned.structure
    rows, rank, dof, idle, kind = EXPECTED[(name, known)]
    assert (structure.rows, structure.rank, structure.dof) == (rows, rank, dof)
    assert [freedom.joints for freedom in structure.idle] == idle
    assert structure.determinacy is Determinacy.DETERMINED and structure.problem is None
    assert planned.solver.kind is kind
    assert len(structure.known) == dof - len(idle)


def test_an_idle_direction_is_a_unit_vector_over_the_solved_joints():
    structure = closure_robots.plan(closure_robots.collinear_pins()).structure
    assert structure.solved == ('p1', 'p2', 'p3')
    (idle,) = structure.idle
    assert idle.direction == pytest.approx((2 ** -0.5, -2 ** -0.5, 0.0), abs=1e-15)


def test_closures_sharing_an_unknown_joint_are_one_group():
    mechanism = closure_robots.ankle()
    tree = KinematicTree(read_urdf(mechanism.urdf))
    (group,) = closure_groups(tree, mechanism.closures, ['motor_left', 'motor_right'])
    assert group.name == 'ball_left+ball_right'
    assert [tree.names[i] for i in group.unknown] == [
        'ankle_pitch', 'ankle_roll', 'rod_left_u1', 'rod_left_u2', 'rod_right_u1',
        'rod_right_u2']
    # with the foot's joints known (issue 30's direction) each leg is a group of its own
    legs = closure_groups(tree, mechanism.closures, ['ankle_pitch', 'ankle_roll'])
    assert [(leg.name, [tree.names[i] for i in leg.unknown]) for leg in legs] == [
        ('ball_left', ['motor_left', 'rod_left_u1', 'rod_left_u2']),
        ('ball_right', ['motor_right', 'rod_right_u1', 'rod_right_u2'])]
    with pytest.raises(StructureError, match=r"known joints \['knee'\] are not joints"):
        closure_groups(tree, mechanism.closures, ['motor_left', 'knee'])


def test_each_leg_of_the_ankle_is_a_crank_rod_ball_inverse():
    for place in (0, 1):
        planned = closure_robots.plan(closure_robots.ankle(), ('ankle_pitch', 'ankle_roll'),
                                      place=place)
        assert planned.solver.kind is GroupKind.LEG_INVERSE


def test_rods_hung_from_a_universal_joint_are_reduced_to_distances():
    for make, expected in ((closure_robots.ankle, ['ball_left', 'ball_right']),
                           # a spherical elbow: its spin (x, idle, held) then y and z
                           (closure_robots.delta_like, ['ball1', 'ball2']),
                           (closure_robots.rod_two_balls, ['rod_end'])):
        planned = closure_robots.plan(make())
        assert list(reducible_rods(planned.tree, planned.group, planned.structure)) == expected


def test_the_lab_knee_is_a_planar_loop_for_the_planar_closed_forms():
    text = (Path(closure_robots.REPOSITORY) / 'urdf' / 'lab_knee.urdf').read_text()
    element = ElementTree.fromstring(text).find('constraint')
    ends = [closure_robots.side(element.find(end).get('link'),
                                [float(v) for v in element.find(f'{end}_origin').get('xyz')
                                 .split()], axis=(0, 0, 1)) for end in ('parent', 'child')]
    pin = closure_robots.closure(element.get('name'), ClosureKind.PIN, *ends)
    tree = KinematicTree(read_urdf(text))
    (group,) = closure_groups(tree, [pin], ['knee_motor'])
    assembly = assemble(tree, group, [0.0] * 3)
    structure = analyse(tree, group, assembly.values)
    assert classify(tree, group, structure, assembly.values) is GroupKind.PLANAR_LOOPS


def refused(mechanism, known) -> str:
    tree = KinematicTree(read_urdf(mechanism.urdf), mechanism.overrides)
    (group,) = closure_groups(tree, mechanism.closures, known)
    assembly = assemble(tree, group, [0.0] * len(tree.names), fixed=())
    structure = analyse(tree, group, assembly.values)
    assert classify(tree, group, structure, assembly.values) is GroupKind.NEWTON
    return structure.problem


def test_an_under_determined_group_is_refused_in_one_line():
    assert refused(closure_robots.five_bar(), ['j1']) == (
        "group tip (joints ['j1', 'j2', 'j3', 'j4']): 2 degrees of freedom (0 idle), known "
        "['j1']: under-determined, a free motion moves ['j2', 'j3', 'j4']; 2 known joints "
        'are needed')


def test_an_over_determined_group_is_refused_in_one_line():
    assert refused(closure_robots.planar_weld(), ['k1', 'k3']) == (
        "group weld_c (joints ['k1', 'k2', 'k3', 'k4']): 1 degrees of freedom (0 idle), known "
        "['k1', 'k3']: over-determined, 2 known joints for 1 determining freedoms")
    # two known joints where the idle link leaves one freedom to determine
    assert refused(closure_robots.collinear_pins(), ['c1', 'p3']) == (
        "group pin_c (joints ['c1', 'p1', 'p2', 'p3']): 2 degrees of freedom (1 idle), known "
        "['c1', 'p3']: over-determined, 2 known joints for 1 determining freedoms")
