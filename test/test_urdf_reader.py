# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
model.urdf_reader: a URDF's links and joints, read once with urdf_parser_py, for every reader.

Each refusal is one line naming the element and what is wrong (UrdfError); every reader of a
description (``RobotTransforms``, the loops' ``read_robot``) takes the parsed tree. Where
urdf_parser_py and the hand-written reader it replaced part ways, the reader does what
robot_state_publisher's urdfdom does: a nameless ``<robot>``, two links or joints of one name, a
joint type urdfdom does not know, a number that is not finite, a malformed ``<link>`` (the old
reader read no link's contents) are refused. The parser's notes never reach stderr; they are kept
for the caller.
"""

from __future__ import annotations

import struct
import sys
import threading
import time

from linkage_kinematics.model.robot_transforms import RobotTransforms
from linkage_kinematics.model.urdf_reader import (
    JointLimit,
    JointType,
    Mimic,
    quaternion_from_rpy,
    read_urdf,
    UrdfError,
)
import pytest
from urdf_parser_py.xml_reflection import core as xml_reflection_core

LINKS = '<link name="a"/><link name="b"/>'
LIMIT = '<limit lower="-1" upper="1" effort="2" velocity="3"/>'


def robot(body: str, name: str = ' name="r"') -> str:
    """Return a robot of links a and b and ``body``."""
    return f'<?xml version="1.0" encoding="utf-8"?>\n<robot{name}>{LINKS}{body}</robot>'


def joint(extra: str = '', name: str = 'j', joint_type: str = 'fixed', parent: str = 'a',
          child: str = 'b') -> str:
    """Return a joint from ``parent`` to ``child`` with ``extra`` elements."""
    return (f'<joint name="{name}" type="{joint_type}"><parent link="{parent}"/>'
            f'<child link="{child}"/>{extra}</joint>')


@pytest.mark.parametrize('text, problem', [
    # urdfdom: 'No name given for the robot.'; the old reader took it
    (robot('', name=''), 'the <robot> element: no name attribute'),
    # urdfdom: "link 'a' is not unique."; urdf_parser_py and the old reader kept one of them
    (robot('<link name="a"/>'), "link 'a' is defined twice"),
    (robot(joint() * 2), "joint 'j' is defined twice"),
    # urdf_parser_py accepts 'unknown', urdfdom does not
    (robot(joint(joint_type='unknown')), "joint 'j': unknown type 'unknown'"),
    (robot('<joint name="j"><parent link="a"/><child link="b"/></joint>'),
     "joint 'j': no type attribute"),
    (robot('<joint type="fixed"><parent link="a"/><child link="b"/></joint>'),
     'joint 1: no name attribute'),
    (robot('<joint name="j" type="fixed"><child link="b"/></joint>'),
     "joint 'j': no <parent> element"),
    (robot(joint('<origin xyz="1 x 2"/>')),
     "joint 'j' origin xyz: 'x' in '1 x 2' is not a number"),
    (robot(joint('<origin rpy="1"/>')),
     "joint 'j' origin rpy: '1' is not the right count of numbers"),
    # urdfdom's strToDouble refuses nan and inf; urdf_parser_py's float() takes them
    (robot(joint('<origin rpy="0 nan 0"/>')), "joint 'j' origin rpy: nan is not a finite number"),
    (robot(joint('<axis xyz="0 1e400 0"/>', joint_type='revolute')),
     "joint 'j' axis: inf is not a finite number"),
    (robot(joint('<mimic joint="j" multiplier="x"/>', joint_type='revolute')),
     "joint 'j' mimic multiplier: 'x' is not a number"),
    # urdf_parser_py raises these without its path: the reader finds the element itself
    (robot(joint('<axis/>', joint_type='revolute')), "joint 'j' axis xyz: no xyz attribute"),
    (robot(joint('<axis xyz="1 0"/>', joint_type='revolute')),
     "joint 'j' axis xyz: '1 0' is not the right count of numbers"),
    (robot('<link name="c"><inertial><mass value="heavy"/></inertial></link>'),
     "link 'c' inertial mass value: 'heavy' is not a number"),
    (robot('<joint name="j" type="fixed"><parent/><child link="b"/></joint>'),
     "joint 'j' parent: no link attribute"),
    (robot(joint('<mimic joint="k"/>' + LIMIT, joint_type='revolute')),
     "joint 'j' mimics 'k', which is not a joint of the robot"),
    (robot(joint('<limit lower="0"/>', joint_type='revolute')),
     "joint 'j' limit: no effort attribute"),
    (robot(joint('<limit effort="1"/>', joint_type='prismatic')),
     "joint 'j' limit: no velocity attribute"),
    (robot(joint('<limit lower="-1" upper="x" effort="1" velocity="1"/>',
                 joint_type='revolute')), "joint 'j' limit upper: 'x' is not a number"),
    (robot(joint('<limit upper="inf" effort="1" velocity="1"/>', joint_type='revolute')),
     "joint 'j' limit: inf is not a finite number"),
    # urdfdom: 'Joint [j] is of type REVOLUTE but it does not specify limits'
    (robot(joint(joint_type='revolute')),
     "joint 'j': a revolute joint needs a <limit> (lower, upper, effort, velocity)"),
    (robot(joint(joint_type='prismatic')),
     "joint 'j': a prismatic joint needs a <limit> (lower, upper, effort, velocity)"),
    (robot('<link name="c"/>' + joint(name='j1') + joint(name='j2', parent='c')),
     "link 'b' is the child of more than one joint ('j1', 'j2')"),
    (robot('<link name="c"/>' + joint(name='j1', parent='b', child='c')
           + joint(name='j2', parent='c', child='b')),
     "links ['b', 'c'] are not reached from the root link 'a': the joints form a cycle"),
    # the old reader read no link's contents; urdfdom refuses the link, and so the URDF
    (robot('<link name="c"><visual><geometry><box size="1 2"/></geometry></visual></link>'),
     "link 'c' visual 1 geometry size: not the right count of numbers"),
    (robot(joint('<origin xyz="1 2"/>', name="j'x]")),
     'joint "j\'x]" origin xyz: \'1 2\' is not the right count of numbers'),
])
def test_a_bad_urdf_is_one_line_naming_the_element(
    text: str, problem: str, capfd: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(UrdfError) as raised:
        read_urdf(text)
    assert str(raised.value) == problem
    assert capfd.readouterr().err == ''


def test_urdfdoms_defaults_are_filled_in_and_every_number_is_a_float() -> None:
    tree = read_urdf(robot('<link name="c"/><link name="d"/>'
                           + joint('<limit effort="2" velocity="0"/>', joint_type='revolute')
                           + joint('<origin xyz="1 0 -0" rpy="0 0 1.5"/><axis xyz="0 3 4"/>'
                                   '<mimic joint="j"/>' + LIMIT, 'k', 'prismatic', 'b', 'c')
                           + joint('<mimic joint="k" multiplier="-2" offset="0.5"/>', 'm',
                                   'continuous', 'c', 'd')))
    assert (tree.name, tree.root_link, tree.links) == ('r', 'a', ('a', 'b', 'c', 'd'))
    assert list(tree.joints) == ['j', 'k', 'm']
    j, k, m = tree.joints.values()
    assert (j.joint_type, j.parent, j.child, j.mimic) == (JointType.REVOLUTE, 'a', 'b', None)
    # no origin: 0; no axis: (1, 0, 0); made unit; a mimic's multiplier 1 and offset 0
    assert (j.origin_translation, j.origin_rpy, j.origin_rotation, j.axis) == (
        (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0), (1.0, 0.0, 0.0))
    assert (k.axis, k.mimic, m.mimic) == ((0.0, 0.6, 0.8), Mimic('j', 1.0, 0.0),
                                          Mimic('k', -2.0, 0.5))
    assert k.origin_rotation == quaternion_from_rpy(0.0, 0.0, 1.5)
    assert struct.pack('<3d', *k.origin_translation) == struct.pack('<3d', 1.0, 0.0, -0.0)
    assert all(type(number) is float for one in tree.joints.values()
               for number in (*one.origin_translation, *one.origin_rpy, *one.origin_rotation,
                              *one.axis))
    assert [(one.movable, one.revolute) for one in (j, k, m)] == [
        (True, True), (True, False), (True, True)]
    # a <limit>'s lower and upper default to 0; a velocity or effort of 0 bounds nothing
    assert (j.limit, j.position_limits, j.velocity_limit, j.effort_limit) == (
        JointLimit(0.0, 0.0, 0.0, 2.0), (0.0, 0.0), None, 2.0)
    assert (k.limit, k.position_limits, k.velocity_limit, k.effort_limit) == (
        JointLimit(-1.0, 1.0, 3.0, 2.0), (-1.0, 1.0), 3.0, 2.0)
    assert (m.limit, m.position_limits, m.velocity_limit, m.effort_limit) == (
        None, None, None, None)


def test_a_continuous_joints_limit_bounds_its_velocity_and_effort_not_its_position() -> None:
    tree = read_urdf(robot(joint('<limit lower="-1" upper="1" effort="-5" velocity="7"/>',
                                 joint_type='continuous')))
    j = tree.joints['j']
    assert (j.limit, j.position_limits, j.velocity_limit, j.effort_limit) == (
        JointLimit(-1.0, 1.0, 7.0, -5.0), None, 7.0, None)
    assert all(type(number) is float for number in (j.limit.lower, j.limit.upper,
                                                    j.limit.velocity, j.limit.effort))


def test_the_parsers_notes_are_kept_not_printed_and_its_hook_is_restored(
    capfd: pytest.CaptureFixture[str]
) -> None:
    before = xml_reflection_core.on_error
    text = robot(joint('<origin xyz="1 0 0"/><origin xyz="2 0 0"/>')
                 + '<constraint name="pin"/><loop_joint name="ball"/><lab_extension/>'
                 ).replace('<robot ', '<robot x="1" ')
    tree = read_urdf(text)
    assert tree.parser_messages == (
        'Scalar element defined multiple times: origin',
        'Unknown attribute "x" in /robot[@name=\'r\']',
        'Unknown tag "lab_extension" in /robot[@name=\'r\']')
    # as urdfdom, the first of two origins
    assert tree.joints['j'].origin_translation == (1.0, 0.0, 0.0)
    # the <constraint> and the <loop_joint> are left to loops, in the tree the parser read
    assert [element.get('name') for element in tree.element.iter('constraint')] == ['pin']
    assert [element.get('name') for element in tree.element.iter('loop_joint')] == ['ball']
    RobotTransforms(read_urdf(text))
    assert xml_reflection_core.on_error is before
    assert capfd.readouterr().err == ''


def test_parses_in_threads_keep_their_own_notes(capfd: pytest.CaptureFixture[str]) -> None:
    """The hook is swapped under a lock: no thread's notes land in another's, or on stderr."""
    before = xml_reflection_core.on_error
    notes: dict[int, set[tuple[str, ...]]] = {}

    def parse(index: int) -> None:
        text = robot(joint() + f'<note_{index}/>')
        notes[index] = {read_urdf(text).parser_messages for _ in range(100)}

    threads = [threading.Thread(target=parse, args=(index,)) for index in range(4)]
    interval = sys.getswitchinterval()
    sys.setswitchinterval(1e-6)  # threads take turns within a parse, not only between parses
    try:
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
    finally:
        sys.setswitchinterval(interval)
    assert notes == {index: {(f'Unknown tag "note_{index}" in /robot[@name=\'r\']',)}
                     for index in range(4)}
    assert xml_reflection_core.on_error is before
    assert capfd.readouterr().err == ''


def chain(joints: int) -> str:
    """Return a serial chain of ``joints`` revolute joints on skew axes, every 7th a mimic."""
    parts = ['<robot name="chain"><link name="l0"/>']
    for index in range(1, joints + 1):
        mimic = f'<mimic joint="j{index - 1}" multiplier="0.5"/>' if index % 7 == 0 else ''
        parts.append(
            f'<link name="l{index}"/><joint name="j{index}" type="revolute">'
            f'<parent link="l{index - 1}"/><child link="l{index}"/>'
            f'<origin xyz="0.1 {index / 100} 0" rpy="{index / 10} 0.2 -0.3"/>'
            f'<axis xyz="0.3 -0.5 {index / 7}"/>{mimic}'
            '<limit lower="-3" upper="3" effort="1" velocity="1"/></joint>')
    return ''.join(parts) + '</robot>'


def test_a_30_joint_urdf_reads_in_well_under_a_second() -> None:
    """Some 2 ms on the development machine; read once per robot description."""
    text = chain(30)
    seconds = []
    for _ in range(3):
        start = time.perf_counter()
        transforms = RobotTransforms(read_urdf(text))
        seconds.append(time.perf_counter() - start)
    assert len(transforms.joints) == 30 and len(transforms.driven_joints) == 26
    assert min(seconds) < 0.1
