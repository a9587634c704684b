# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A lab's URDF read for its kinematic loops: the tree at the zero pose and its ``<constraint>``s.

The links and joints are those ``urdf_reader`` read with ROS's own Python URDF parser
(``urdf_parser_py``, the urdfdom_py package), so the joints mean what they mean to ROS; the
parsed ``UrdfTree`` is handed in, never the text (a description is parsed once). A
``<constraint>`` is the cut joint of a closed loop as proposed for URDF (urdfdom PR #264,
urdfdom_headers PR #108), a direct child of ``<robot>``::

    <constraint name="N" type="revolute">
      <parent link="L1"/><parent_origin xyz="…" rpy="…"/><parent_axis xyz="…"/>
      <child link="L2"/><child_origin xyz="…" rpy="…"/><child_axis xyz="…"/>
    </constraint>

The parser does not know the element (nor does urdfdom), so the constraints are read here from
the XML tree the parser read, each with the tree path between its two links: the loop it closes.
Every link's world pose at the zero pose (every joint at 0) is kept, in float64 as a URDF reader
computes it. Pure: numpy and lxml, no ROS graph.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

from linkage_kinematics.model.urdf_reader import JointType, UrdfTree, Vector
import lxml.etree
import numpy as np


class LoopError(ValueError):
    """A URDF, or one of its loops, that cannot be closed; the message names it and says why."""


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
    """
    A ``<constraint>`` as written: its name, type and the two sides, and the loop it closes.

    ``path``: the tree joints from the parent side's link to the child side's, in order, each
    with whether the path crosses it from its parent to its child (``True``) or back.
    """

    name: str
    constraint_type: str
    parent: ConstraintFrame
    child: ConstraintFrame
    path: tuple[tuple[TreeJoint, bool], ...]


@dataclass(frozen=True)
class Robot:
    """A URDF's tree at the zero pose and its constraints."""

    name: str
    root: str
    joints: dict[str, TreeJoint]
    links: dict[str, Pose]
    constraints: tuple[Constraint, ...]
    # one line for each <constraint> that cannot be read (its name, and why)
    constraint_problems: tuple[str, ...]


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


def _vector(text: str | None, default: Vector, where: str) -> np.ndarray:
    """
    Return a constraint's attribute of three numbers (xyz, rpy, an axis); ``default`` if absent.

    urdf_parser_py does not read a <constraint>, so its numbers are read here, as finite as
    urdf_reader asks a joint's to be. Raises LoopError naming ``where`` for anything else.
    """
    if text is None:
        return np.array(default, dtype=float)
    try:
        values = [float(word) for word in text.split()]
    except ValueError:
        raise LoopError(f'{where}: {text!r} is not three numbers') from None
    if len(values) != 3 or not all(math.isfinite(value) for value in values):
        raise LoopError(f'{where}: {text!r} is not three finite numbers')
    return np.array(values, dtype=float)


def _unit(vector: np.ndarray, where: str) -> np.ndarray:
    length = float(np.linalg.norm(vector))
    if length == 0.0:
        raise LoopError(f'{where}: the axis is zero')
    return vector / length


def _tree_joints(tree: UrdfTree) -> tuple[dict[str, TreeJoint], dict[str, Pose]]:
    """Return every joint at the zero pose, and every link's world pose."""
    by_parent: dict[str, list[str]] = {}
    for joint in tree.joints.values():
        by_parent.setdefault(joint.parent, []).append(joint.name)
    poses = {tree.root_link: Pose(np.eye(3), np.zeros(3))}
    joints: dict[str, TreeJoint] = {}
    stack = [tree.root_link]
    while stack:
        link = stack.pop()
        for name in by_parent.get(link, []):
            joint = tree.joints[name]
            frame = poses[link].then(np.array(joint.origin_translation, dtype=float),
                                     np.array(joint.origin_rpy, dtype=float))
            joints[name] = TreeJoint(
                name, joint.joint_type, joint.parent, joint.child, frame,
                frame.rotation @ np.array(joint.axis, dtype=float),
                joint.mimic.joint if joint.mimic is not None else None)
            poses[joint.child] = frame
            stack.append(joint.child)
    return joints, poses


def _constraint_side(element: lxml.etree._Element, side: str, links: dict[str, Pose],
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


def _constraints(root: lxml.etree._Element, links: dict[str, Pose],
                 joint_above: dict[str, TreeJoint]
                 ) -> tuple[tuple[Constraint, ...], tuple[str, ...]]:
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
            parent = _constraint_side(element, 'parent', links, where)
            child = _constraint_side(element, 'child', links, where)
            constraints.append(Constraint(name, element.get('type', ''), parent, child,
                                          _tree_path(joint_above, parent.link, child.link)))
        except LoopError as error:
            problems.append(str(error))
    return tuple(constraints), tuple(problems)


def read_robot(tree: UrdfTree) -> Robot:
    """
    Return a parsed URDF's tree at the zero pose and its ``<constraint>`` elements.

    A constraint that names an unknown link or holds a malformed number is one line of
    ``constraint_problems``.
    """
    joints, links = _tree_joints(tree)
    constraints, problems = _constraints(
        tree.element, links, {joint.child: joint for joint in joints.values()})
    return Robot(tree.name, tree.root_link, joints, links, constraints, problems)


def _tree_path(joint_above: dict[str, TreeJoint], start: str,
               end: str) -> tuple[tuple[TreeJoint, bool], ...]:
    """
    Return the joints on the tree path from link ``start`` to link ``end``, in order.

    ``joint_above``: link → the joint whose child it is (the root has none). Each joint with
    whether the path crosses it from its parent to its child (``True``) or from its child to its
    parent.
    """
    def up(link: str) -> list[TreeJoint]:
        path = []
        while link in joint_above:
            joint = joint_above[link]
            path.append(joint)
            link = joint.parent
        return path

    start_side, end_side = up(start), up(end)
    shared = {joint.name for joint in start_side} & {joint.name for joint in end_side}
    rising = [(joint, False) for joint in start_side if joint.name not in shared]
    falling = [(joint, True) for joint in end_side if joint.name not in shared]
    return tuple(rising + falling[::-1])
