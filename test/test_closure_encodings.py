# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""loops.encodings: one description's closures from the three encodings, mixed; their document."""

from pathlib import Path
import re

from closure_urdf import tree
from linkage_kinematics.loops.closures import ClosureError, ClosureKind, Encoding, JointOverride
from linkage_kinematics.loops.encodings import read_closures
from linkage_kinematics.model.urdf_reader import read_urdf
import pytest

MIXED = """
  <constraint name="knee" type="revolute"><parent link="rod"/><child link="foot"/>
    <parent_axis xyz="0 0 1"/></constraint>
  <loop_joint name="ankle_ball" type="spherical"><link1 link="crank"/><link2 link="toe"/>
  </loop_joint>
  <constraint name="weld" type="fixed"><parent link="tip"/><child link="rod"/></constraint>
"""
FILE = """closed_loop: [[heel, crank]]
type: [3d]
name_mot: [motor, ankle]
joint_name: [elbow]
joint_type: [UJOINT_ZY]
"""


def test_kinds_and_encodings_mix_in_one_description() -> None:
    description = read_closures(tree(MIXED), FILE)
    assert description.problems == ()
    assert [(closure.name, closure.kind, closure.encoding)
            for closure in description.closures] == [
        ('knee', ClosureKind.PIN, Encoding.CONSTRAINT),
        ('weld', ClosureKind.WELD, Encoding.CONSTRAINT),
        ('ankle_ball', ClosureKind.BALL, Encoding.LOOP_JOINT),
        ('heelCcrank', ClosureKind.BALL, Encoding.CLOSURE_FILE)]
    assert description.actuated == ('motor', 'ankle')
    assert description.overrides == {'elbow': JointOverride.UJOINT_ZY}


def test_without_a_closure_file_nothing_names_actuated_joints() -> None:
    description = read_closures(tree(MIXED))
    assert [closure.name for closure in description.closures] == ['knee', 'weld', 'ankle_ball']
    assert (description.actuated, description.overrides, description.problems) == (None, {}, ())


def test_a_name_two_encodings_use_is_refused_and_the_first_kept() -> None:
    description = read_closures(
        tree(MIXED + '<loop_joint name="knee" type="fixed"><link1 link="rod"/>'
                     '<link2 link="heel"/></loop_joint>'),
        'closed_loop: [[heel, crank]]\ntype: [3d]')
    assert [(closure.name, closure.encoding) for closure in description.closures] == [
        ('knee', Encoding.CONSTRAINT), ('weld', Encoding.CONSTRAINT),
        ('ankle_ball', Encoding.LOOP_JOINT), ('heelCcrank', Encoding.CLOSURE_FILE)]
    assert description.problems == (
        "closure 'knee': the name is used twice, by a <constraint> and a <loop_joint>",)
    clash = read_closures(tree('<loop_joint name="heelCcrank" type="fixed"><link1 link="rod"/>'
                               '<link2 link="heel"/></loop_joint>'),
                          'closed_loop: [[heel, crank]]\ntype: [3d]')
    assert clash.problems == (
        "closure 'heelCcrank': the name is used twice, by a <loop_joint> and the closure file",)


def test_every_readers_problems_are_kept_in_order() -> None:
    description = read_closures(
        tree(MIXED + '<constraint name="bad" type="universal"/><loop_joint type="fixed"/>'),
        FILE + 'name_mots: []')
    assert description.problems == (
        "constraint 'bad': type 'universal' is not supported: a constraint is 'revolute' (a pin),"
        " 'spherical' (a ball) or 'fixed' (a weld)",
        'a <loop_joint> has no name',
        "'name_mots': not a key of a closure file (closed_loop, type, name_mot, joint_name, "
        'joint_type)')
    assert len(description.closures) == 4


DOCUMENT = Path(__file__).resolve().parents[1] / 'docs' / 'following_loops.md'
# The document's section on the three encodings, whose examples are read here
SECTION = ('### Three encodings, one model', '### Adding a `<constraint>` to a xacro')
# A tree holding every link and joint the document's examples name
JOINTS = {'rear_joint': 'rear_link', 'shank_joint': 'shank', 'rod_joint': 'rod',
          'foot_joint': 'foot', 'motor_ankle_1': 'crank_tip', 'motor_ankle_2': 'ankle_rod_end',
          'rod_top_joint': 'rod_top', 'socket_joint': 'foot_socket'}


def test_the_documents_examples_read_as_it_says() -> None:
    text = DOCUMENT.read_text()
    section = text[text.index(SECTION[0]):text.index(SECTION[1])]
    blocks = re.findall(r'```(xml|yaml)\n(.*?)```', section, re.DOTALL)
    elements = [text for language, text in blocks if language == 'xml']
    (closure_file,) = [text for language, text in blocks if language == 'yaml']
    urdf = '<robot name="doc"><link name="base"/>' + ''.join(
        f'<link name="{link}"/><joint name="{joint}" type="continuous"><parent link="base"/>'
        f'<child link="{link}"/></joint>' for joint, link in JOINTS.items()
    ) + ''.join(elements) + '</robot>'
    description = read_closures(read_urdf(urdf), closure_file)
    assert description.problems == ()
    assert [(closure.name, closure.kind, closure.encoding, closure.parent.link,
             closure.child.link) for closure in description.closures] == [
        ('knee_pin', ClosureKind.PIN, Encoding.CONSTRAINT, 'rear_link', 'shank'),
        ('ankle_ball', ClosureKind.BALL, Encoding.LOOP_JOINT, 'rod', 'foot'),
        ('ankle_rod_endCfoot_socket', ClosureKind.BALL, Encoding.CLOSURE_FILE, 'ankle_rod_end',
         'foot_socket'),
        ('crank_tipCrod_top', ClosureKind.WELD, Encoding.CLOSURE_FILE, 'crank_tip', 'rod_top')]
    knee = description.closures[0]
    assert (knee.parent.xyz, knee.parent.axis, knee.child.xyz, knee.child.axis) == (
        (0.1, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, 0.2, 0.0), (0.0, 0.0, 1.0))
    assert description.closures[1].parent.xyz == (0.0, 0.0, -0.25)
    assert description.actuated == ('motor_ankle_1', 'motor_ankle_2')
    assert description.overrides == {'rod_top_joint': JointOverride.UJOINT_ZY}


def test_a_closure_file_that_is_not_yaml_is_unreadable_input() -> None:
    with pytest.raises(ClosureError, match='^the closure file is not YAML: '):
        read_closures(tree(MIXED), 'closed_loop: [')
