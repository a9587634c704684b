# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A lab's URDF at its zero pose: every joint's world frame and axis, every link's world pose.

The links and joints are those ``urdf_reader`` read with ROS's own Python URDF parser
(``urdf_parser_py``, the urdfdom_py package), so the joints mean what they mean to ROS; the
parsed ``UrdfTree`` is handed in, never the text (a description is parsed once). Every link's
world pose at the zero pose (every joint at 0) is kept, in float64 as a URDF reader computes
it: the planar loops (``planar``) are derived from it. The closures themselves are read by
``encodings`` (one reader per encoding); ``side_frame`` and ``tree_path`` place a closure's
side and find the loop it closes in this tree. Pure: numpy, no ROS graph.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

from linkage_kinematics.loops.closures import ClosureSide
from linkage_kinematics.model.urdf_reader import JointType, UrdfTree
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
class Robot:
    """A URDF's tree at the zero pose: its joints and its links' world poses, by name."""

    name: str
    root: str
    joints: dict[str, TreeJoint]
    links: dict[str, Pose]
    # link → the joint whose child it is (the root has none)
    joint_above: dict[str, TreeJoint]


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


def read_robot(tree: UrdfTree) -> Robot:
    """Return a parsed URDF's tree at the zero pose."""
    joints, links = _tree_joints(tree)
    return Robot(tree.name, tree.root_link, joints, links,
                 {joint.child: joint for joint in joints.values()})


def side_frame(robot: Robot, side: ClosureSide) -> Pose:
    """Return a closure side's frame in the world at the zero pose."""
    return robot.links[side.link].then(np.array(side.xyz, dtype=float),
                                       np.array(side.rpy, dtype=float))


def tree_path(robot: Robot, start: str, end: str) -> tuple[tuple[TreeJoint, bool], ...]:
    """
    Return the joints on the tree path from link ``start`` to link ``end``, in order.

    Each joint with whether the path crosses it from its parent to its child (``True``) or from
    its child to its parent.
    """
    joint_above = robot.joint_above

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
