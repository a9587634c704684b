# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A lab's URDF read for its kinematic loops: the tree at the zero pose and its ``<constraint>``s.

The links and joints come from ROS's own Python URDF parser (``urdf_parser_py``, the urdfdom_py
package), so the joints mean what they mean to ROS. A ``<constraint>`` is the cut joint of a
closed loop as proposed for URDF (urdfdom PR #264, urdfdom_headers PR #108), a direct child of
``<robot>``::

    <constraint name="N" type="revolute">
      <parent link="L1"/><parent_origin xyz="…" rpy="…"/><parent_axis xyz="…"/>
      <child link="L2"/><child_origin xyz="…" rpy="…"/><child_axis xyz="…"/>
    </constraint>

The parser does not know the element, so the constraints are read from the same text with
``xml.etree.ElementTree``. Every link's world pose at the zero pose (every joint at 0) is kept,
in float64 as a URDF reader computes it. Pure: numpy and urdf_parser_py, no ROS graph.
"""

from __future__ import annotations

from collections.abc import Iterator
import contextlib
from dataclasses import dataclass
import math
import re
import xml.etree.ElementTree as ElementTree

from linkage_kinematics.model.robot_transforms import JointType, parse_vector, UrdfError
import lxml.etree
import numpy as np
from urdf_parser_py import urdf as urdf_parser
from urdf_parser_py.xml_reflection import core as xml_reflection_core


class LoopError(ValueError):
    """A URDF, or one of its loops, that cannot be closed; the message names it and says why."""


ROTATING_TYPES = frozenset({JointType.REVOLUTE, JointType.CONTINUOUS})
MOVING_TYPES = ROTATING_TYPES | {JointType.PRISMATIC}


@dataclass(frozen=True)
class Pose:
    """A frame in the world: its rotation (3×3, columns the frame's axes) and origin (m)."""

    rotation: np.ndarray
    position: np.ndarray

    def then(self, xyz: np.ndarray, rpy: np.ndarray) -> Pose:
        """Return this frame followed by the URDF origin ``xyz`` (m), ``rpy`` (rad)."""
        return Pose(self.rotation @ rpy_matrix(rpy), self.position + self.rotation @ xyz)


@dataclass(frozen=True)
class TreeJoint:
    """A URDF joint at the zero pose: its world frame, unit world axis and mimic, if any."""

    name: str
    joint_type: JointType
    parent: str
    child: str
    frame: Pose
    axis: np.ndarray
    mimic: str | None


@dataclass(frozen=True)
class ConstraintFrame:
    """One side of a constraint: its link, and its frame and unit axis in the world (zero pose)."""

    link: str
    frame: Pose
    axis: np.ndarray | None


@dataclass(frozen=True)
class Constraint:
    """A ``<constraint>`` as written: its name, type and the two sides."""

    name: str
    constraint_type: str
    parent: ConstraintFrame
    child: ConstraintFrame


@dataclass(frozen=True)
class Robot:
    """A URDF's tree at the zero pose, its constraints, and the link above each link."""

    name: str
    root: str
    joints: dict[str, TreeJoint]
    # link → the joint whose child it is (the root has none)
    joint_above: dict[str, TreeJoint]
    links: dict[str, Pose]
    constraints: tuple[Constraint, ...]
    # one line for each <constraint> that cannot be read (its name, and why)
    constraint_problems: tuple[str, ...]
    # what urdf_parser_py said about the text, other than that it does not know <constraint>
    parser_messages: tuple[str, ...]


def rpy_matrix(rpy: np.ndarray) -> np.ndarray:
    """Return the rotation of URDF roll–pitch–yaw (about fixed x, y, z): Rz·Ry·Rx."""
    roll, pitch, yaw = (float(angle) for angle in rpy)
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return np.array([
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ])


# urdf_parser_py reports what it does not know through the module-level function
# xml_reflection.core.on_error, which by default writes each message to stderr; Reflection's
# set_from_xml looks the name up in that module at call time. A <constraint> is not known to it,
# so every lab's good URDF with loops would print 'Unknown tag "constraint" in /robot[...]'. The
# parse below swaps the function for one that drops exactly that message (a <constraint> directly
# under <robot>, whose path is /robot[@name='…']) and keeps every other one, a <constraint>
# misplaced inside a <joint> included, which the caller gets back; then it restores the function.
_CONSTRAINT_COMPLAINT = re.compile(r'Unknown tag "constraint" in /robot(\[@name=\'[^/]*\'\])?')


@contextlib.contextmanager
def _parser_messages() -> Iterator[list[str]]:
    messages: list[str] = []

    def keep(message: str) -> None:
        if not _CONSTRAINT_COMPLAINT.fullmatch(message):
            messages.append(message)

    previous = xml_reflection_core.on_error
    xml_reflection_core.on_error = keep
    try:
        yield messages
    finally:
        xml_reflection_core.on_error = previous


def _vector(text: str | None, default: tuple[float, float, float], where: str) -> np.ndarray:
    try:
        return np.array(parse_vector(text, default, where), dtype=float)
    except UrdfError as error:
        raise LoopError(str(error)) from None


def _unit(vector: np.ndarray, where: str) -> np.ndarray:
    length = float(np.linalg.norm(vector))
    if length == 0.0:
        raise LoopError(f'{where}: the axis is zero')
    return vector / length


def _parse_tree(data: bytes) -> tuple[urdf_parser.Robot, tuple[str, ...]]:
    with _parser_messages() as messages:
        try:
            robot = urdf_parser.URDF.from_xml_string(data)
        except lxml.etree.XMLSyntaxError as error:
            raise LoopError(f'the URDF is not XML: {error}') from None
        except Exception as error:  # urdf_parser_py raises ParseError, AssertionError, ...
            raise LoopError(f'urdf_parser_py cannot read the URDF: {error}') from None
    return robot, tuple(messages)


def _tree_joints(robot: urdf_parser.Robot) -> tuple[str, dict[str, TreeJoint], dict[str, Pose]]:
    """Return the root link, every joint at the zero pose, and every link's world pose."""
    links = set(robot.link_map)
    by_parent: dict[str, list[urdf_parser.Joint]] = {}
    children: set[str] = set()
    for joint in robot.joints:
        for role, link in (('parent', joint.parent), ('child', joint.child)):
            if link not in links:
                raise LoopError(f'joint {joint.name!r}: {role} link {link!r} is not a <link>')
        if joint.child in children:
            raise LoopError(f'link {joint.child!r} is the child of more than one joint')
        children.add(joint.child)
        by_parent.setdefault(joint.parent, []).append(joint)
    roots = sorted(links - children)
    if len(roots) != 1:
        raise LoopError(f'the URDF has {len(roots)} root links {roots}, not one')
    poses = {roots[0]: Pose(np.eye(3), np.zeros(3))}
    joints: dict[str, TreeJoint] = {}
    stack = [roots[0]]
    while stack:
        link = stack.pop()
        for joint in by_parent.get(link, []):
            where = f'joint {joint.name!r}'
            origin = joint.origin
            frame = poses[link].then(
                np.array(origin.xyz if origin is not None else (0.0, 0.0, 0.0), dtype=float),
                np.array(origin.rpy if origin is not None else (0.0, 0.0, 0.0), dtype=float))
            try:
                joint_type = JointType(joint.type)
            except ValueError:
                raise LoopError(f'{where}: unknown type {joint.type!r}') from None
            axis = np.array(joint.axis if joint.axis is not None else (1.0, 0.0, 0.0), float)
            if joint_type in MOVING_TYPES:
                axis = _unit(axis, where)
            joints[joint.name] = TreeJoint(
                joint.name, joint_type, joint.parent, joint.child, frame, frame.rotation @ axis,
                joint.mimic.joint if joint.mimic is not None else None)
            poses[joint.child] = frame
            stack.append(joint.child)
    # links reached from the root; any other link with a parent sits on a cycle of joints
    unreached = sorted(links - set(poses))
    if unreached:
        raise LoopError(f'links {unreached} are not reached from the root link {roots[0]!r}: '
                        'the joints form a cycle')
    return roots[0], joints, poses


def _constraint_side(element: ElementTree.Element, side: str, links: dict[str, Pose],
                     where: str) -> ConstraintFrame:
    link_element = element.find(side)
    link = link_element.get('link') if link_element is not None else None
    if not link:
        raise LoopError(f'{where}: no <{side} link="…"/>')
    if link not in links:
        raise LoopError(f'{where}: {side} link {link!r} is not a <link> of the robot')
    origin = element.find(f'{side}_origin')
    xyz = _vector(origin.get('xyz') if origin is not None else None, (0.0, 0.0, 0.0),
                  f'{where} {side}_origin xyz')
    rpy = _vector(origin.get('rpy') if origin is not None else None, (0.0, 0.0, 0.0),
                  f'{where} {side}_origin rpy')
    frame = links[link].then(xyz, rpy)
    axis_element = element.find(f'{side}_axis')
    axis = None
    if axis_element is not None:
        local = _unit(_vector(axis_element.get('xyz'), (1.0, 0.0, 0.0), f'{where} {side}_axis'),
                      f'{where} {side}_axis')
        axis = frame.rotation @ local
    return ConstraintFrame(link, frame, axis)


def _constraints(root: ElementTree.Element,
                 links: dict[str, Pose]) -> tuple[tuple[Constraint, ...], tuple[str, ...]]:
    """Return the constraints that can be read, and one line for each that cannot."""
    constraints, problems = [], []
    names: set[str] = set()
    for element in root.findall('constraint'):
        name = element.get('name')
        where = f'constraint {name!r}'
        try:
            if not name:
                raise LoopError('a <constraint> has no name')
            if name in names:
                raise LoopError(f'{where}: the name is used twice')
            names.add(name)
            constraints.append(Constraint(
                name, element.get('type', ''), _constraint_side(element, 'parent', links, where),
                _constraint_side(element, 'child', links, where)))
        except LoopError as error:
            problems.append(str(error))
    return tuple(constraints), tuple(problems)


def read_robot(urdf: str) -> Robot:
    """
    Read a URDF's tree at the zero pose and its ``<constraint>`` elements.

    Raises LoopError, naming the element, for a text that is not a URDF robot or joints that do
    not form a tree; a constraint that names an unknown link or holds a malformed number is one
    line of ``constraint_problems``.
    """
    # bytes: lxml refuses a str that carries an XML encoding declaration, as xacro writes one
    data = urdf.encode('utf-8')
    parsed, messages = _parse_tree(data)
    root, joints, links = _tree_joints(parsed)
    constraints, problems = _constraints(ElementTree.fromstring(data), links)
    return Robot(str(parsed.name), root, joints,
                 {joint.child: joint for joint in joints.values()}, links, constraints, problems,
                 messages)


def tree_path(robot: Robot, start: str, end: str) -> list[tuple[TreeJoint, bool]]:
    """
    Return the joints on the tree path from link ``start`` to link ``end``, in order.

    Each with whether the path crosses it from its parent to its child (``True``) or from its
    child to its parent.
    """
    def up(link: str) -> list[TreeJoint]:
        path = []
        while link in robot.joint_above:
            joint = robot.joint_above[link]
            path.append(joint)
            link = joint.parent
        return path

    start_side, end_side = up(start), up(end)
    shared = {joint.name for joint in start_side} & {joint.name for joint in end_side}
    rising = [(joint, False) for joint in start_side if joint.name not in shared]
    falling = [(joint, True) for joint in end_side if joint.name not in shared]
    return rising + falling[::-1]
