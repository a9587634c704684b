# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""loops.constraint_element: urdfdom PR #264's <constraint> read as closures, its refusals."""

from closure_urdf import tree
from linkage_kinematics.loops.closures import Closure, ClosureKind, ClosureSide, Encoding
from linkage_kinematics.loops.constraint_element import read_constraints
import pytest


def read(*elements: str) -> tuple[tuple[Closure, ...], tuple[str, ...]]:
    return read_constraints(tree('\n'.join(elements)))


def pin(name: str = 'c', body: str = '', kind: str = 'revolute') -> str:
    return f'<constraint name="{name}" type="{kind}">{body}</constraint>'


ENDS = '<parent link="rod"/><child link="foot"/>'


def test_a_revolute_constraint_is_a_pin_with_its_frames_and_unit_axes() -> None:
    closures, problems = read(pin(body="""
        <parent link="rod"/><parent_origin xyz="1 0.5 0" rpy="0 0 0.25"/>
        <parent_axis xyz="0 0 2"/>
        <child link="foot"/><child_origin xyz="0 1.5 -1e-3" rpy="0.5 0 0"/>
        <child_axis xyz="0 0 -3"/>"""))
    assert problems == ()
    assert closures == (Closure(
        'c', ClosureKind.PIN,
        ClosureSide('rod', (1.0, 0.5, 0.0), (0.0, 0.0, 0.25), (0.0, 0.0, 1.0)),
        ClosureSide('foot', (0.0, 1.5, -1e-3), (0.5, 0.0, 0.0), (0.0, 0.0, -1.0)),
        Encoding.CONSTRAINT),)


def test_missing_origins_are_the_identity_and_the_child_turns_about_the_parents_axis() -> None:
    closures, _ = read(pin(body=ENDS + '<parent_axis xyz="0 1 0"/>'))
    assert closures[0].parent == ClosureSide('rod', (0.0, 0.0, 0.0), (0.0, 0.0, 0.0),
                                             (0.0, 1.0, 0.0))
    assert closures[0].child == ClosureSide('foot', (0.0, 0.0, 0.0), (0.0, 0.0, 0.0),
                                            (0.0, 1.0, 0.0))


def test_a_pin_without_a_parent_axis_has_none_and_its_child_axis_if_written() -> None:
    """As the planar loops read it: the loop's first revolute joint gives the axis."""
    (bare, child_only), problems = read(pin('bare', ENDS),
                                        pin('child_only', ENDS + '<child_axis xyz="0 0 1"/>'))
    assert problems == ()
    assert (bare.parent.axis, bare.child.axis) == (None, None)
    assert (child_only.parent.axis, child_only.child.axis) == (None, (0.0, 0.0, 1.0))


def test_an_axis_element_without_xyz_is_the_x_axis() -> None:
    closures, _ = read(pin(body=ENDS + '<parent_axis/>'))
    assert (closures[0].parent.axis, closures[0].child.axis) == ((1.0, 0.0, 0.0),) * 2


@pytest.mark.parametrize(('written', 'kind'), [
    ('revolute', ClosureKind.PIN), ('revolute_joint', ClosureKind.PIN),
    ('spherical', ClosureKind.BALL), ('spherical_joint', ClosureKind.BALL),
    ('fixed', ClosureKind.WELD), ('link', ClosureKind.WELD)])
def test_the_prs_type_words_and_fixed(written: str, kind: ClosureKind) -> None:
    closures, problems = read(pin(body=ENDS + '<parent_axis xyz="0 0 1"/>', kind=written))
    assert problems == ()
    assert closures[0].kind is kind
    # only a pin has an axis: the PR reads none for a spherical or a cut link
    expected = (0.0, 0.0, 1.0) if kind is ClosureKind.PIN else None
    assert (closures[0].parent.axis, closures[0].child.axis) == (expected, expected)


def test_only_constraints_directly_under_robot_are_read_in_urdf_order() -> None:
    closures, problems = read(pin('b', ENDS, 'fixed'), pin('a', ENDS, 'spherical'),
                              f'<link name="l"><constraint name="inside" type="fixed">{ENDS}'
                              '</constraint></link><joint name="j" type="fixed"><parent '
                              'link="tip"/><child link="l"/></joint>')
    assert ([closure.name for closure in closures], problems) == (['b', 'a'], ())


@pytest.mark.parametrize(('element', 'problem'), [
    ('<constraint type="fixed"><parent link="rod"/><child link="foot"/></constraint>',
     'a <constraint> has no name'),
    (f'<constraint name="c">{ENDS}</constraint>',
     "constraint 'c': no type: a constraint is 'revolute' (a pin), 'spherical' (a ball) or "
     "'fixed' (a weld)"),
    (pin(body=ENDS, kind='prismatic'),
     "constraint 'c': type 'prismatic' is not supported: a constraint is 'revolute' (a pin), "
     "'spherical' (a ball) or 'fixed' (a weld)"),
    (pin(body=ENDS, kind='universal_joint'),
     "constraint 'c': type 'universal_joint' is not supported: a constraint is 'revolute' "
     "(a pin), 'spherical' (a ball) or 'fixed' (a weld)"),
    (pin(body='<child link="foot"/>'), 'constraint \'c\': no <parent link="…"/>'),
    (pin(body='<parent/><child link="foot"/>'), 'constraint \'c\': no <parent link="…"/>'),
    (pin(body='<parent link="rod"/>'), 'constraint \'c\': no <child link="…"/>'),
    (pin(body='<parent link="rod"/><child link="rocket"/>'),
     "constraint 'c': child link 'rocket' is not a <link> of the robot"),
    (pin(body=ENDS + '<parent_origin xyz="1 a 0"/>'),
     "constraint 'c' parent_origin xyz: '1 a 0' is not three numbers"),
    (pin(body=ENDS + '<child_origin rpy="1 0"/>'),
     "constraint 'c' child_origin rpy: '1 0' is not three finite numbers"),
    (pin(body=ENDS + '<child_origin xyz="nan 0 0"/>'),
     "constraint 'c' child_origin xyz: 'nan 0 0' is not three finite numbers"),
    (pin(body=ENDS + '<parent_axis xyz="1e400 0 0"/>'),
     "constraint 'c' parent_axis: '1e400 0 0' is not three finite numbers"),
    (pin(body=ENDS + '<parent_axis xyz="0 0 1"/><child_axis xyz="0 0 0"/>'),
     "constraint 'c' child_axis: the axis is zero"),
])
def test_each_refusal_is_one_line_naming_the_constraint(element: str, problem: str) -> None:
    assert read(element, pin('good', ENDS, 'fixed')) == (
        read(pin('good', ENDS, 'fixed'))[0], (problem,))


def test_a_name_used_twice_keeps_the_first() -> None:
    closures, problems = read(pin('c', ENDS, 'fixed'), pin('c', ENDS, 'spherical'))
    assert [closure.kind for closure in closures] == [ClosureKind.WELD]
    assert problems == ("constraint 'c': the name is used twice",)
