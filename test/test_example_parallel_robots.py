# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""Gepetto/example-parallel-robots' models read in the three encodings: the same closures."""

import example_parallel_robots as models
from linkage_kinematics.loops.closures import (
    ClosureDescription,
    ClosureKind,
    ClosureSide,
    Encoding,
    JointOverride,
)
from linkage_kinematics.loops.encodings import read_closures
from linkage_kinematics.model.urdf_reader import read_urdf
import pytest

ZERO = (0.0, 0.0, 0.0)


def described(urdf: str, closure_file: str | None = None) -> ClosureDescription:
    description = read_closures(read_urdf(urdf), closure_file)
    assert description.problems == ()
    return description


Frames = list[tuple[str, ClosureKind, ClosureSide, ClosureSide]]


def frames(description: ClosureDescription) -> Frames:
    return [(closure.name, closure.kind, closure.parent, closure.child)
            for closure in description.closures]


@pytest.mark.parametrize('model', models.MODELS)
def test_the_three_encodings_of_a_model_are_the_same_closures(model: str) -> None:
    in_file = described(models.urdf(model), models.closure_file(model))
    expected = [(name, {'3d': ClosureKind.BALL, '6d': ClosureKind.WELD}[kind],
                 ClosureSide(parent, ZERO, ZERO), ClosureSide(child, ZERO, ZERO))
                for name, kind, parent, child in models.closures(model)]
    assert frames(in_file) == expected
    assert {closure.encoding for closure in in_file.closures} == {Encoding.CLOSURE_FILE}
    for urdf, encoding in ((models.with_constraints(model), Encoding.CONSTRAINT),
                           (models.with_loop_joints(model), Encoding.LOOP_JOINT)):
        in_urdf = described(urdf)
        assert frames(in_urdf) == expected
        assert {closure.encoding for closure in in_urdf.closures} == {encoding}
        # an element says no actuated joints; a closure file beside it without closures does
        assert (in_urdf.actuated, in_urdf.overrides) == (None, {})
        mixed = described(urdf, models.without_closures(model))
        assert frames(mixed) == expected
        assert (mixed.actuated, mixed.overrides) == (in_file.actuated, in_file.overrides)
    assert in_file.actuated == tuple(models.closure_file_content(model)['name_mot'])


# How many closures each model has (every one a weld, '6d'), and its first actuated joints
SHAPES = {
    '5bar_linkage': (1, ('mot1', 'mot2')),
    'robot_delta': (3, ('mot1_rod1', 'mot1_rod2')),
    'cassie_like': (2, ('motor_hip1', 'motor_hip2')),
    'digit_like': (3, ('motor_hip_x', 'motor_hip_y')),
    'kangaroo_like': (11, ('motor_hipz', 'motor_hip_xy1')),
    'battobot_6d': (6, ('hipz_left', 'hipy_left')),
    'wl16_like': (5, ('motor_4', 'motor_1')),
    'disney_like': (3, ('motor_4barlink2', 'motor_4barlink4')),
}


@pytest.mark.parametrize('model', models.MODELS)
def test_each_model_reads_whole(model: str) -> None:
    description = described(models.urdf(model), models.closure_file(model))
    count, actuated = SHAPES[model]
    assert len(description.closures) == count
    assert {closure.kind for closure in description.closures} == {ClosureKind.WELD}
    assert description.actuated[:2] == actuated


def test_a_joints_frame_is_its_child_links() -> None:
    """The five-bar's and the delta's closure frames are joints' (revolute) frames."""
    (five_bar,) = described(models.urdf('5bar_linkage'),
                            models.closure_file('5bar_linkage')).closures
    assert (five_bar.name, five_bar.parent.link, five_bar.child.link) == (
        'closedloop1_ACclosedloop1_B', 'sphere', 'sphere_2')
    tree = read_urdf(models.urdf('5bar_linkage'))
    assert (tree.joints['closedloop1_A'].child, tree.joints['closedloop1_B'].child) == (
        'sphere', 'sphere_2')


def test_battobots_ankles_and_knees_are_read_as_its_file_overrides_them() -> None:
    description = described(models.urdf('battobot_6d'), models.closure_file('battobot_6d'))
    overrides = description.overrides
    assert len(overrides) == 12
    assert overrides['left_spherical_ankle_1'] is JointOverride.UJOINT_ZY
    assert overrides['free_knee_right'] is JointOverride.UJOINT_YZ
    assert overrides['transmission_knee_left'] is JointOverride.SPHERICAL
    assert [name for name, override in overrides.items()
            if override is JointOverride.SPHERICAL] == [
        'right_spherical_foot_1', 'right_spherical_foot_2', 'left_spherical_foot_1',
        'left_spherical_foot_2', 'transmission_knee_right', 'transmission_knee_left']
    assert len(description.actuated) == 12
