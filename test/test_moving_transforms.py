# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The prepared /tf path (``RobotTransforms.moving``) against the generic forward kinematics.

``reference_transforms`` is the generic forward kinematics the package used before (per joint
and state: the mimic positions from a copy of the joint state, then origin · motion(q) from the
joint's parameters, ``quaternion_product`` and ``rotate`` called afresh). The prepared path
must give the same bits for every transform, and ``RobotStateTransforms`` the same bytes as
``encode_cdr`` of the reference's message, so the bag's /tf is what it was: on the node's URDF
(both drivers, a lab's names, directions and offsets) and on URDFs with axes off the coordinate
axes, rpy origins, prismatic joints and mimic joints (of a prismatic joint, of a mimic).
"""

from __future__ import annotations

from collections.abc import Mapping
import math
import random
import struct

from hypothesis import example, given, settings
from hypothesis import strategies as st
from linkage_kinematics.kinematics.geometry import preset
from linkage_kinematics.model.joints import Driver, JointMap, JointMapping
from linkage_kinematics.model.robot_transforms import (
    quaternion_product,
    RobotTransforms,
    rotate,
    Transform,
)
from linkage_kinematics.model.urdf import urdf_text
from linkage_kinematics.model.urdf_reader import read_urdf
from linkage_kinematics.ros import messages
from linkage_kinematics.shared.cdr import encode_cdr
import pytest
from test_bag_transforms import EVERY_JOINT_URDF, moving_transforms

SAMPLES = 2000
STAMP_NS = 1_790_000_000_123_456_789
# Mimics of a prismatic joint and of mimics: 'b_follows' follows 'a_mimic' (whose name sorts
# first), 'a_early' mimics 'c_late', which sorts after it, so it follows only when the joint
# state names 'c_late' itself; joints at rpy origins with skew and negative axes.
MIMIC_URDF = """<?xml version="1.0"?>
<robot name="mimics">
  <link name="base"/><link name="l1"/><link name="l2"/><link name="l3"/><link name="l4"/>
  <link name="l5"/><link name="l6"/>
  <joint name="drive" type="revolute">
    <parent link="base"/><child link="l1"/>
    <origin xyz="0.2 -0.1 0.4" rpy="2.9 -1.3 0.7"/>
    <axis xyz="-0.3 0.5 -0.8"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <joint name="slide" type="prismatic">
    <parent link="l1"/><child link="l2"/>
    <origin xyz="0 0 0.3" rpy="0.1 0.2 0.3"/>
    <axis xyz="0 0 -1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <joint name="a_mimic" type="prismatic">
    <parent link="l2"/><child link="l3"/>
    <origin xyz="0.1 0.1 0" rpy="-3.1 0.05 1.6"/>
    <axis xyz="1 1 0"/>
    <mimic joint="slide" multiplier="-1.7" offset="0.01"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <joint name="b_follows" type="continuous">
    <parent link="l3"/><child link="l4"/>
    <origin xyz="-0.4 0 0.05" rpy="0 0 -2.2"/>
    <axis xyz="0 -1 0"/>
    <mimic joint="a_mimic" multiplier="3.3" offset="-0.2"/>
  </joint>
  <joint name="a_early" type="revolute">
    <parent link="l4"/><child link="l5"/>
    <origin xyz="0 0.3 0" rpy="1.5707963267948966 0 0"/>
    <axis xyz="0 0 1"/>
    <mimic joint="c_late" multiplier="0.5"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <joint name="c_late" type="revolute">
    <parent link="l5"/><child link="l6"/>
    <origin xyz="0.01 0.02 0.03" rpy="0.4 0.4 0.4"/>
    <axis xyz="1 0 0"/>
    <mimic joint="drive" multiplier="-1" offset="3.0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
</robot>
"""
# Revolute joints without an origin rotation along +x, +z and +y (a mimic): the short form;
# along −y and −x (a negative zero in its axis), and along +z and +x with origin rotations that
# hold negative zeros (rpy of negative zeros): the product, since the signs of its zeros follow
# those of sin(q/2) and cos(q/2); one off the axes, one with an rpy origin and a prismatic
# joint: the product; all in one joint state.
AXES_URDF = """<?xml version="1.0"?>
<robot name="axes">
  <link name="base"/><link name="l1"/><link name="l2"/><link name="l3"/><link name="l4"/>
  <link name="l5"/><link name="l6"/><link name="l7"/><link name="l8"/><link name="l9"/>
  <link name="l10"/>
  <joint name="j1_x" type="revolute">
    <parent link="base"/><child link="l1"/><origin xyz="0.1 0 0"/><axis xyz="1 0 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <joint name="j2_minus_y" type="continuous">
    <parent link="l1"/><child link="l2"/><origin xyz="0 0.2 0" rpy="0 0 0"/>
    <axis xyz="0 -2 0"/>
  </joint>
  <joint name="j3_z" type="continuous">
    <parent link="l2"/><child link="l3"/><origin xyz="0 0 -0.3"/><axis xyz="0 0 1"/>
  </joint>
  <joint name="j4_minus_x" type="continuous">
    <parent link="l3"/><child link="l4"/><axis xyz="-1 -0 0"/>
  </joint>
  <joint name="j5_z_negative_zero_rpy" type="continuous">
    <parent link="l4"/><child link="l5"/><origin xyz="0.1 0.1 0" rpy="0 0 -0"/>
    <axis xyz="0 0 1"/>
  </joint>
  <joint name="j6_x_negative_zero_rpy" type="continuous">
    <parent link="l5"/><child link="l6"/><origin rpy="-0 -0 -0"/><axis xyz="1 0 0"/>
  </joint>
  <joint name="j7_skew" type="continuous">
    <parent link="l6"/><child link="l7"/><axis xyz="0 1 1"/>
  </joint>
  <joint name="j8_rpy" type="continuous">
    <parent link="l7"/><child link="l8"/><origin rpy="0 0 1.5707963267948966"/>
    <axis xyz="0 1 0"/>
  </joint>
  <joint name="j9_slide" type="prismatic">
    <parent link="l8"/><child link="l9"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <joint name="j10_mimic" type="continuous">
    <parent link="l9"/><child link="l10"/><axis xyz="0 1 0"/>
    <mimic joint="j3_z" multiplier="-1" offset="0"/>
  </joint>
</robot>
"""
AXES_NAMES = ['j1_x', 'j2_minus_y', 'j3_z', 'j4_minus_x', 'j5_z_negative_zero_rpy',
              'j6_x_negative_zero_rpy', 'j7_skew', 'j8_rpy', 'j9_slide']
# Positions whose half-angle has each sign of sin(q/2) and cos(q/2): zeros of both signs, the
# smallest subnormal (its half rounds to +0.0), small and large angles in all four quadrants,
# ±π and ±2π (a sine of a few ulp, a cosine near ±1), a huge angle; and NaN.
SIGN_CASES = [0.0, -0.0, 5e-324, -5e-324, 1e-300, -1e-300, 1.0, -1.0, 4.0, -4.0, 7.0, -7.0,
              10.0, -10.0, math.pi, -math.pi, 2 * math.pi, -2 * math.pi, 1e22, -1e22, math.nan]
LAB_JOINTS = JointMap(JointMapping('wheel', -1, 0.25), JointMapping('link_2', 1, -1.5),
                      JointMapping('a_rocker', -1, 4.0))


def reference_transforms(robot: RobotTransforms,
                         positions: Mapping[str, float]) -> list[Transform]:
    """Return the transforms by the generic forward kinematics the package had before."""
    positions = dict(positions)
    for name, joint in robot.joints.items():
        if (joint.mimic is not None and joint.mimic.joint in positions
                and name not in positions):
            positions[joint.name] = (joint.mimic.multiplier * positions[joint.mimic.joint]
                                     + joint.mimic.offset)
    transforms = []
    for name, joint in robot.joints.items():
        if not joint.movable or name not in positions:
            continue
        position = positions[name]
        translation = joint.origin_translation
        rotation = joint.origin_rotation
        if joint.revolute:
            half = 0.5 * position
            sine = math.sin(half)
            motion = (joint.axis[0] * sine, joint.axis[1] * sine, joint.axis[2] * sine,
                      math.cos(half))
            rotation = quaternion_product(rotation, motion)
        else:
            along = rotate(rotation, joint.axis)
            translation = (translation[0] + along[0] * position,
                           translation[1] + along[1] * position,
                           translation[2] + along[2] * position)
        prefix = robot.frame_prefix
        transforms.append(Transform(prefix + joint.parent, prefix + joint.child, translation,
                                    rotation))
    return transforms


def bits(transforms: list[Transform]) -> bytes:
    """Return the transforms' numbers as float64 bits: equal bits, and -0.0 is not 0.0."""
    numbers = [number for transform in transforms
               for number in (*transform.translation, *transform.rotation)]
    return struct.pack(f'<{len(numbers)}d', *numbers)


def random_positions(robot: RobotTransforms, names: list[str],
                     generator: random.Random) -> list[dict[str, float]]:
    """
    Return SAMPLES joint states of ``names``.

    Angles over several turns and metres over ±2 m, after the values where signs of zero and
    the half-angle's special values could part two ways of computing: 0, −0, ±π, ±2π.
    """
    special = [0.0, -0.0, math.pi, -math.pi, 2 * math.pi, -2 * math.pi]
    samples = [{name: value for name in names} for value in special]
    while len(samples) < SAMPLES:
        samples.append({name: (generator.uniform(-4 * math.pi, 4 * math.pi)
                               if robot.joints[name].revolute else generator.uniform(-2.0, 2.0))
                        for name in names})
    return samples


def check_against_reference(urdf: str, names: list[str], seed: int) -> int:
    """Check every sample's transforms and /tf bytes; return how many transforms were checked."""
    tree = read_urdf(urdf)
    robot = RobotTransforms(tree, 'robot_1/')
    tf = messages.RobotStateTransforms(tree, 'robot_1/')
    checked = 0
    for positions in random_positions(robot, names, random.Random(seed)):
        expected = reference_transforms(robot, positions)
        actual = moving_transforms(robot, positions)
        assert [(t.parent_frame, t.child_frame) for t in actual] == [
            (t.parent_frame, t.child_frame) for t in expected]
        assert bits(actual) == bits(expected), positions
        assert tf.message(positions, STAMP_NS) == encode_cdr(
            messages.tf_message(expected, STAMP_NS)), positions
        checked += len(expected)
    return checked


@pytest.mark.parametrize('driver', list(Driver))
@pytest.mark.parametrize('joints', [JointMap(), LAB_JOINTS])
def test_node_urdf_transforms_and_bytes_are_the_generic_ones(
    driver: Driver, joints: JointMap
) -> None:
    urdf = urdf_text(preset('paper').geometry, 'linkage_base', joints, driver)
    names = list(RobotTransforms(read_urdf(urdf)).joints)
    assert len(names) == 3
    assert check_against_reference(urdf, names, seed=7) == 3 * SAMPLES


@pytest.mark.parametrize('urdf, names, transforms', [
    # every movable joint named; follower_joint follows arm_joint
    (EVERY_JOINT_URDF, ['wheel_joint', 'arm_joint', 'slider_joint'], 4),
    # a named mimic keeps its own position
    (EVERY_JOINT_URDF, ['follower_joint', 'slider_joint', 'arm_joint', 'wheel_joint'], 4),
    # a_mimic follows slide and b_follows a_mimic; c_late follows drive, a_early does not
    (MIMIC_URDF, ['slide', 'drive'], 5),
    # c_late named: a_early follows it
    (MIMIC_URDF, ['c_late', 'slide', 'drive'], 6),
])
def test_varied_urdf_transforms_and_bytes_are_the_generic_ones(
    urdf: str, names: list[str], transforms: int
) -> None:
    assert check_against_reference(urdf, names, seed=11) == transforms * SAMPLES


def test_new_names_prepare_new_transforms() -> None:
    tree = read_urdf(MIMIC_URDF)
    tf = messages.RobotStateTransforms(tree, '')
    robot = RobotTransforms(tree)
    for positions in ({'slide': 0.3, 'drive': 1.0}, {'c_late': -0.5, 'drive': 2.0},
                      {'slide': 0.3, 'drive': 1.0, 'unknown': 5.0}, {'slide': 0.1}):
        assert tf.message(positions, STAMP_NS) == encode_cdr(
            messages.tf_message(reference_transforms(robot, positions), STAMP_NS))


@pytest.mark.parametrize('urdf', [EVERY_JOINT_URDF, MIMIC_URDF])
def test_the_whole_trees_tf_is_the_generic_one(urdf: str) -> None:
    """``tree_message`` of every driven joint's position in order: the reference's bytes."""
    tree = read_urdf(urdf)
    tf = messages.RobotStateTransforms(tree, 'robot_1/')
    robot = RobotTransforms(tree, 'robot_1/')
    names = list(tf.driven_joints)
    assert len(names) >= 2
    for positions in random_positions(robot, names, random.Random(5)):
        assert tf.tree_message([positions[name] for name in names], STAMP_NS) == encode_cdr(
            messages.tf_message(reference_transforms(robot, positions), STAMP_NS)), positions


def assert_same_bits_as_the_product(urdf: str, positions: dict[str, float]) -> None:
    """
    Check ``moving``'s transforms at ``positions`` against the product, bit for bit.

    NaN included (``bits`` packs its sign and payload); a position the sine refuses (±inf)
    raises ValueError both ways.
    """
    robot = RobotTransforms(read_urdf(urdf))
    try:
        expected = reference_transforms(robot, positions)
    except ValueError:
        with pytest.raises(ValueError):
            moving_transforms(robot, positions)
        return
    assert bits(moving_transforms(robot, positions)) == bits(expected), positions


def test_joints_along_a_frame_axis_take_the_short_form() -> None:
    """Which joints of AXES_URDF the sign cases below test the short form on, and why not all."""
    robot = RobotTransforms(read_urdf(AXES_URDF))
    moving = robot.moving(AXES_NAMES)
    # white box: slots of the joints computed as ±sin(q/2) + 0.0 and cos(q/2)
    assert [slot for slot, *_ in moving._axis_turns] == [9, 0, 2]  # j10_mimic, j1_x, j3_z
    assert len(moving._others) == 7
    # along −y, at sin(q/2) < 0 and cos(q/2) < 0 the product's x is −0.0 (+0.0 at other
    # signs): no fixed zero to copy
    rotations = {transform.child_frame: transform.rotation
                 for transform in reference_transforms(robot, dict.fromkeys(AXES_NAMES, -4.0))}
    assert math.copysign(1.0, rotations['l2'][0]) == -1.0
    assert math.copysign(1.0, rotations['l3'][0]) == 1.0


@pytest.mark.parametrize('position', SIGN_CASES)
def test_every_sign_case_gives_the_products_bits(position: float) -> None:
    positions = dict.fromkeys(AXES_NAMES, position)
    assert_same_bits_as_the_product(AXES_URDF, positions)
    # one joint at the sign case, the others ordinary: a NaN in any slot takes the product
    for name in AXES_NAMES:
        assert_same_bits_as_the_product(AXES_URDF, {**dict.fromkeys(AXES_NAMES, 0.7),
                                                    name: position})


@settings(max_examples=300, deadline=None)
@given(st.lists(st.one_of(st.floats(), st.sampled_from(SIGN_CASES)),
                min_size=len(AXES_NAMES), max_size=len(AXES_NAMES)))
@example([math.inf] + [0.0] * (len(AXES_NAMES) - 1))
@example([0.0] * (len(AXES_NAMES) - 1) + [math.inf])
@example([math.inf, -math.inf] + [0.0] * (len(AXES_NAMES) - 2))
def test_any_positions_give_the_products_bits(positions: list[float]) -> None:
    """Any floats: ±0, subnormals, huge, NaN, ±inf (revolute: ValueError; the slide: ±inf)."""
    assert_same_bits_as_the_product(AXES_URDF, dict(zip(AXES_NAMES, positions)))
