# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""loops.loop_joint_element: Isaac Sim's <loop_joint> read as closures, its refusals."""

from closure_urdf import tree
from linkage_kinematics.loops.closures import Closure, ClosureKind, ClosureSide, Encoding
from linkage_kinematics.loops.loop_joint_element import read_loop_joints
import pytest

ZERO = (0.0, 0.0, 0.0)
ENDS = '<link1 link="rod"/><link2 link="foot"/>'


def read(*elements: str) -> tuple[tuple[Closure, ...], tuple[str, ...]]:
    return read_loop_joints(tree('\n'.join(elements)))


def loop_joint(name: str = 'j', body: str = ENDS, kind: str = 'spherical') -> str:
    return f'<loop_joint name="{name}" type="{kind}">{body}</loop_joint>'


def test_a_spherical_loop_joint_as_isaac_sims_exporter_writes_it() -> None:
    closures, problems = read(loop_joint(body="""
        <link1 link="rod" xyz="1 0.5 0" rpy="0 0 0.25"/>
        <link2 link="foot" xyz="0 1.5 -0.001" rpy="0.5 0 0"/>"""))
    assert problems == ()
    assert closures == (Closure(
        'j', ClosureKind.BALL, ClosureSide('rod', (1.0, 0.5, 0.0), (0.0, 0.0, 0.25)),
        ClosureSide('foot', (0.0, 1.5, -0.001), (0.5, 0.0, 0.0)), Encoding.LOOP_JOINT),)


def test_xyz_and_rpy_default_to_zero_as_isaac_sims_parser() -> None:
    closures, _ = read(loop_joint(kind='fixed'))
    assert closures == (Closure('j', ClosureKind.WELD, ClosureSide('rod', ZERO, ZERO),
                                ClosureSide('foot', ZERO, ZERO), Encoding.LOOP_JOINT),)


@pytest.mark.parametrize('written', ['revolute', 'continuous'])
def test_a_revolute_loop_joint_turns_about_its_frames_x_axis(written: str) -> None:
    """A USD revolute joint turns about physics:axis, X by default; the exporter writes none."""
    closures, problems = read(loop_joint(kind=written))
    assert problems == ()
    assert closures[0].kind is ClosureKind.PIN
    assert (closures[0].parent.axis, closures[0].child.axis) == ((1.0, 0.0, 0.0),) * 2


def test_an_axis_element_gives_a_revolute_loop_joint_another_axis_in_both_frames() -> None:
    """As Drake's RigidBodyTree read <loop_joint><axis xyz/>, where the element began."""
    closures, _ = read(loop_joint(body=ENDS + '<axis xyz="0 0 -2"/>', kind='revolute'),
                       loop_joint('b', ENDS + '<axis xyz="0 0 1"/>'))
    assert (closures[0].parent.axis, closures[0].child.axis) == ((0.0, 0.0, -1.0),) * 2
    assert (closures[1].parent.axis, closures[1].child.axis) == (None, None)  # a ball has none


SUPPORTED = "'revolute' (a pin), 'spherical' (a ball) or 'fixed' (a weld)"


@pytest.mark.parametrize(('element', 'problem'), [
    (f'<loop_joint type="fixed">{ENDS}</loop_joint>', 'a <loop_joint> has no name'),
    (f'<loop_joint name="j">{ENDS}</loop_joint>', f"loop_joint 'j': no type: a loop_joint is "
                                                  f'{SUPPORTED}'),
    (loop_joint(kind='prismatic'),
     f"loop_joint 'j': type 'prismatic' is not supported: a loop_joint is {SUPPORTED}"),
    (loop_joint(kind='ball'),
     f"loop_joint 'j': type 'ball' is not supported: a loop_joint is {SUPPORTED}"),
    (loop_joint(body='<link2 link="foot"/>'), 'loop_joint \'j\': no <link1 link="…"/>'),
    (loop_joint(body='<link1 link="rod"/><link2/>'), 'loop_joint \'j\': no <link2 link="…"/>'),
    (loop_joint(body='<link1 link="wing"/><link2 link="foot"/>'),
     "loop_joint 'j': link1 link 'wing' is not a <link> of the robot"),
    (loop_joint(body='<link1 link="rod" xyz="0,1,0"/><link2 link="foot"/>'),
     "loop_joint 'j' link1 xyz: '0,1,0' is not three numbers"),
    (loop_joint(body='<link1 link="rod"/><link2 link="foot" rpy="0 0 0 0"/>'),
     "loop_joint 'j' link2 rpy: '0 0 0 0' is not three finite numbers"),
    (loop_joint(body=ENDS + '<axis xyz="0 0 0"/>', kind='revolute'),
     "loop_joint 'j' axis: the axis is zero"),
    (loop_joint(body=ENDS + '<axis xyz="x"/>', kind='revolute'),
     "loop_joint 'j' axis: 'x' is not three numbers"),
])
def test_each_refusal_is_one_line_naming_the_loop_joint(element: str, problem: str) -> None:
    good = loop_joint('good', kind='fixed')
    assert read(element, good) == (read(good)[0], (problem,))


def test_a_name_used_twice_keeps_the_first() -> None:
    closures, problems = read(loop_joint(kind='fixed'), loop_joint())
    assert [closure.kind for closure in closures] == [ClosureKind.WELD]
    assert problems == ("loop_joint 'j': the name is used twice",)
