# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""loops.closure_file: toolbox-parallel-robots' YAML side file read against its URDF."""

from closure_urdf import tree
from linkage_kinematics.loops.closure_file import read_closure_file
from linkage_kinematics.loops.closures import (
    Closure,
    ClosureDescription,
    ClosureError,
    ClosureKind,
    ClosureSide,
    Encoding,
    JointOverride,
)
import pytest

ZERO = (0.0, 0.0, 0.0)
KEYS = '(closed_loop, type, name_mot, joint_name, joint_type)'


def read(text: str, extra: str = '') -> ClosureDescription:
    return read_closure_file(tree(extra), text)


def side(link: str) -> ClosureSide:
    return ClosureSide(link, ZERO, ZERO)


def test_a_file_of_the_example_models_kind() -> None:
    description = read("""
closed_loop: [['rod', 'foot'], ['tip_mount', 'elbow'], ["motor", "heel"], [toe, crank]]
type: ['6d', '3d', '3D', '6D']
name_mot: ['motor', 'ankle']
joint_name: ["elbow", "toe_joint"]
joint_type: ["UJOINT_ZY", "SPHERICAL"]
""".replace('toe_joint', 'heel'))
    assert description.problems == ()
    # a joint's frame is its child link's: tip_mount → tip, elbow → rod, motor → crank
    assert description.closures == (
        Closure('rodCfoot', ClosureKind.WELD, side('rod'), side('foot'), Encoding.CLOSURE_FILE),
        Closure('tip_mountCelbow', ClosureKind.BALL, side('tip'), side('rod'),
                Encoding.CLOSURE_FILE),
        Closure('motorCheel', ClosureKind.BALL, side('crank'), side('heel'),
                Encoding.CLOSURE_FILE),
        Closure('toeCcrank', ClosureKind.WELD, side('toe'), side('crank'),
                Encoding.CLOSURE_FILE))
    assert description.actuated == ('motor', 'ankle')
    assert description.overrides == {'elbow': JointOverride.UJOINT_ZY,
                                     'heel': JointOverride.SPHERICAL}
    assert list(description.overrides) == ['elbow', 'heel']


def test_every_key_may_be_left_out() -> None:
    assert read('name_mot: []') == ClosureDescription(actuated=())
    assert read("closed_loop: [[rod, foot]]\ntype: ['3d']").actuated is None


def test_the_overrides_read_as_the_loaders_joints() -> None:
    """completeRobotLoader: RA at the joint's origin named <joint>_A, then RB named <joint>_B."""
    assert JointOverride.UJOINT_ZY.axes == ('z', 'y')
    assert JointOverride.UJOINT_ZY.coordinates('knee') == ('knee_Z', 'knee_Y')
    assert JointOverride.SPHERICAL.coordinates('ball') == ('ball_X', 'ball_Y', 'ball_Z')
    assert JointOverride.FIXED.coordinates('lock') == ()
    assert read('joint_name: [elbow]\njoint_type: [FIXED]').overrides == {
        'elbow': JointOverride.FIXED}


@pytest.mark.parametrize(('text', 'problem'), [
    ('closed_loop: [[a, b]', "the closure file is not YAML: expected ',' or ']', but got "
                             "'<stream end>' at line 1, column 21"),
    ('\tclosed_loop: []', "the closure file is not YAML: found character '\\t' that cannot "
                          'start any token at line 1, column 1'),
    ('name_mot: [\x07]', 'the closure file is not YAML: unacceptable character #x0007: special '
                         'characters are not allowed in "<unicode string>", position 11'),
    ('', 'the closure file is empty'),
    ('- closed_loop', f'the closure file is not a mapping of keys {KEYS}'),
])
def test_a_text_that_is_no_closure_file_is_unreadable(text: str, problem: str) -> None:
    with pytest.raises(ClosureError) as raised:
        read(text)
    assert str(raised.value) == problem


PAIR = "closed_loop: [[rod, foot]]\ntype: ['6d']\n"
WELD = Closure('rodCfoot', ClosureKind.WELD, side('rod'), side('foot'), Encoding.CLOSURE_FILE)


@pytest.mark.parametrize(('text', 'problem'), [
    (PAIR + 'name_mots: [motor]', f"'name_mots': not a key of a closure file {KEYS}"),
    (PAIR + 'closed_loop_2: [[crank, rod]]',
     f"'closed_loop_2': not a key of a closure file {KEYS}"),
    ("closed_loop: [[rod, foot], [crank, rod]]\ntype: ['6d']",
     'closed_loop and type: 2 and 1 entries, not as many'),
    ('closed_loop: [[rod, foot]]', 'type: missing: closed_loop needs it, entry for entry'),
    ('type: [6d]', 'closed_loop: missing: type needs it, entry for entry'),
    ('closed_loop: rod\ntype: [6d]', "closed_loop: 'rod' is not a list"),
    ('closed_loop: [[rod, foot, tip]]\ntype: [6d]',
     "closed_loop: entry 1 ['rod', 'foot', 'tip'] is not a pair of frame names"),
    ('closed_loop: [[rod, 3]]\ntype: [6d]',
     "closed_loop: entry 1 ['rod', 3] is not a pair of frame names"),
    ('closed_loop: [[rod, foot]]\ntype: [4d]',
     "type: entry 1 '4d' is not '3d' (a ball: the frames' origins coincide) or '6d' (a weld: "
     'the frames coincide)'),
    ('closed_loop: [[rod, foot]]\ntype: [[6d]]',
     "type: entry 1 ['6d'] is not '3d' (a ball: the frames' origins coincide) or '6d' (a "
     'weld: the frames coincide)'),
    ('closed_loop: [[rod, wing]]\ntype: [6d]',
     "closed_loop: entry 1: 'wing' is not a link or joint of the URDF"),
    ('closed_loop: [[rod, foot], [rod, foot]]\ntype: [6d, 3d]',
     "closed_loop: entry 2: the pair 'rod', 'foot' is listed twice"),
    ('name_mot: motor', "name_mot: 'motor' is not a list"),
    ('name_mot: [motor, 7]', 'name_mot: entry 2 7 is not a joint name'),
    ('name_mot: [motor, wing]', "name_mot: 'wing' is not a joint of the URDF"),
    ('name_mot: [motor, tip_mount]', "name_mot: 'tip_mount' is a fixed joint: it moves nothing "
                                     'to measure'),
    ('name_mot: [motor, motor]', "name_mot: 'motor' is listed twice"),
    ('name_mot: [motor, elbow]\njoint_name: [elbow]\njoint_type: [UJOINT_XY]',
     "name_mot: 'elbow' is read as UJOINT_XY (joint_type): an actuated joint is measured as the "
     'one URDF joint it is'),
    ('joint_name: [elbow]', 'joint_type: missing: joint_name needs it, entry for entry'),
    ('joint_name: [elbow]\njoint_type: [SPHERICAL, FIXED]',
     'joint_name and joint_type: 1 and 2 entries, not as many'),
    ('joint_name: [elbow]\njoint_type: SPHERICAL', "joint_type: 'SPHERICAL' is not a list"),
    ('joint_name: [[elbow]]\njoint_type: [SPHERICAL]',
     "joint_name: entry 1 ['elbow'] is not a joint name"),
    ('joint_name: [elbow]\njoint_type: [UJOINT_XX]',
     "joint_type: entry 1 'UJOINT_XX' (for 'elbow') is not one of SPHERICAL, UJOINT_XY, "
     'UJOINT_XZ, UJOINT_YX, UJOINT_YZ, UJOINT_ZX, UJOINT_ZY, FIXED'),
    ('joint_name: [wing]\njoint_type: [SPHERICAL]', "joint_name: 'wing' is not a joint of the "
                                                    'URDF'),
    ('joint_name: [tip_mount]\njoint_type: [SPHERICAL]',
     "joint_name: 'tip_mount' is a fixed joint, which Pinocchio merges into its links: "
     'toolbox-parallel-robots does not read it as SPHERICAL'),
    ('joint_name: [toe_joint]\njoint_type: [UJOINT_XY]',
     "joint_name: 'toe_joint' mimics 'ankle': a joint read as UJOINT_XY has no one position to "
     'mimic by'),
    ('joint_name: [ankle]\njoint_type: [FIXED]',
     "joint_name: 'ankle' is mimicked by 'toe_joint': a joint read as FIXED has no one "
     'position to mimic by'),
    ('joint_name: [elbow, elbow]\njoint_type: [SPHERICAL, FIXED]',
     "joint_name: 'elbow' is listed twice"),
])
def test_each_malformed_entry_is_one_line_naming_its_key(text: str, problem: str) -> None:
    whole = text.startswith(('closed_loop', 'type'))
    description = read(text if whole else PAIR + text)
    assert description.problems == (problem,)
    if not whole:  # the rest is still read
        assert description.closures == (WELD,)


def test_a_coordinate_name_the_urdf_uses_is_refused() -> None:
    extra = ('<link name="plate"/><joint name="elbow_Y" type="fixed"><parent link="rod"/>'
             '<child link="plate"/></joint>')
    assert read('joint_name: [elbow]\njoint_type: [UJOINT_ZX]', extra).problems == ()
    assert read('joint_name: [elbow]\njoint_type: [UJOINT_XY]', extra).problems == (
        "joint_name: 'elbow' would be read as elbow_X, elbow_Y, but the URDF has a joint "
        "'elbow_Y'",)


def test_a_name_of_a_link_and_of_a_joint_with_another_child_is_two_frames() -> None:
    extra = ('<link name="elbow"/><joint name="elbow_mount" type="fixed"><parent link="rod"/>'
             '<child link="elbow"/></joint>')
    assert read('closed_loop: [[elbow, foot], [heel, foot]]\ntype: [3d, 3d]',
                extra).problems == (
        "closed_loop: entry 1: 'elbow' names a link and a joint of another child link ('rod'): "
        'two frames',)
