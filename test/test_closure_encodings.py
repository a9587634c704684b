# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""loops.encodings: one description's closures from the three encodings, mixed."""

from closure_urdf import tree
from linkage_kinematics.loops.closures import ClosureKind, Encoding, JointOverride
from linkage_kinematics.loops.encodings import read_closures

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
    assert [(closure.name, closure.kind, closure.encoding) for closure in description.closures] == [
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
