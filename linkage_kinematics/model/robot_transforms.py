# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The transforms robot_state_publisher publishes for a URDF and a joint state.

A pure module: ``RobotTransforms`` takes a URDF's joints as ``urdf_reader`` read them (with
urdf_parser_py, as robot_state_publisher reads them with urdfdom; the parsed ``UrdfTree`` is
handed in, so a description is parsed once for every reader) and computes, as
robot_state_publisher (Jazzy) does through kdl_parser and KDL,

* for each fixed joint, the transform parent link → child link, published once on /tf_static
  (kdl_parser turns ``floating`` and ``planar`` joints into fixed ones, so they are fixed here
  too, at their origin);
* for each movable joint (``revolute``, ``continuous``, ``prismatic``) named in a joint state,
  origin · motion(q): the joint's origin (xyz, then roll-pitch-yaw about fixed axes), then a
  rotation by q about the joint's unit axis, or a translation by q along it; published on /tf
  with the joint state's stamp. A ``mimic`` joint follows its joint as
  multiplier · q + offset, as robot_state_publisher adds it whenever the mimicked joint is in the
  message (unless the message names the mimic joint itself). ``RobotTransforms.moving``
  prepares them once for a joint state's names (``MovingTransforms``): per state only the
  motion's terms are computed.

Both prefix their frame ids with ``frame_prefix`` (robot_state_publisher's parameter, a plain
string prepended to the link names). Transforms come out ordered by joint name, as
robot_state_publisher's maps hold them.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
import math
from typing import Any

from linkage_kinematics.model.urdf_reader import Quaternion, UrdfJoint, UrdfTree, Vector


@dataclass(frozen=True)
class Transform:
    """One geometry_msgs/TransformStamped without its stamp: child frame in parent frame."""

    parent_frame: str
    child_frame: str
    translation: Vector
    rotation: Quaternion


def quaternion_product(first: Quaternion, second: Quaternion) -> Quaternion:
    """Return ``first`` · ``second`` (rotate by ``second``, then by ``first``)."""
    x1, y1, z1, w1 = first
    x2, y2, z2, w2 = second
    return (
        w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
        w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
        w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
        w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
    )


def rotate(rotation: Quaternion, vector: Vector) -> Vector:
    """Return ``vector`` rotated by the unit quaternion ``rotation``."""
    x, y, z, w = quaternion_product(
        quaternion_product(rotation, (*vector, 0.0)),
        (-rotation[0], -rotation[1], -rotation[2], rotation[3]),
    )
    return (x, y, z)


class RobotTransforms:
    """The joints of a parsed URDF, and the transforms robot_state_publisher publishes for them."""

    def __init__(self, tree: UrdfTree, frame_prefix: str = '') -> None:
        self.root_link: str = tree.root_link
        self.frame_prefix = frame_prefix
        # robot_state_publisher keeps its joints in maps keyed by name
        self.joints: dict[str, UrdfJoint] = dict(sorted(tree.joints.items()))

    @property
    def driven_joints(self) -> tuple[str, ...]:
        """Return the movable joints a joint state sets, in name order (mimic joints follow)."""
        return tuple(name for name, joint in self.joints.items()
                     if joint.movable and joint.mimic is None)

    def fixed_transforms(self) -> list[Transform]:
        """Return the transforms of every fixed joint (robot_state_publisher's /tf_static)."""
        prefix = self.frame_prefix
        return [Transform(prefix + joint.parent, prefix + joint.child, joint.origin_translation,
                          joint.origin_rotation)
                for joint in self.joints.values() if not joint.movable]

    def moving(self, names: Sequence[str]) -> MovingTransforms:
        """
        Return the movable joints' transforms for joint states of ``names`` (unique), prepared.

        Those of the joints named and the mimic joints that follow them (robot_state_publisher's
        /tf for one joint state; a mimic joint named keeps the joint state's position); other
        names are ignored.
        """
        slots = {name: index for index, name in enumerate(names)}
        # Mimic positions are appended to the joint state's in joint name order, as
        # robot_state_publisher adds them from its map of mimic joints: a mimic of a mimic
        # follows it only if the mimicked joint's name sorts first.
        mimics = []
        for name, joint in self.joints.items():
            if joint.mimic is not None and joint.mimic.joint in slots and name not in slots:
                mimics.append((slots[joint.mimic.joint], joint.mimic.multiplier,
                               joint.mimic.offset))
                slots[name] = len(slots)
        prefix = self.frame_prefix
        moved = [joint for name, joint in self.joints.items()
                 if joint.movable and name in slots]
        return MovingTransforms(
            tuple((prefix + joint.parent, prefix + joint.child) for joint in moved),
            tuple(mimics),
            tuple((joint.revolute, slots[joint.name], *joint.origin_translation,
                   *joint.origin_rotation,
                   *(joint.axis if joint.revolute
                     else rotate(joint.origin_rotation, joint.axis)))
                  for joint in moved),
        )


class MovingTransforms:
    """
    The transforms of the movable joints of one joint state's names, all but their motion fixed.

    Made once per URDF and names by ``RobotTransforms.moving``; ``frames`` are the (parent,
    child) frames of the transforms, ordered by joint name. Everything that does not depend on
    the positions is computed here once: each joint's origin as a translation and a quaternion,
    its unit axis, and for a prismatic joint the axis turned by the origin (the direction it
    slides in its parent's frame); so a state costs only the motion's terms: per revolute joint
    one sine, one cosine and one quaternion product, per prismatic joint three products.
    """

    def __init__(
        self,
        frames: tuple[tuple[str, str], ...],
        mimics: tuple[tuple[int, float, float], ...],
        joints: tuple[tuple[Any, ...], ...],
    ) -> None:
        self.frames = frames
        # (the mimicked joint's slot, multiplier, offset): appended to the positions in order
        self._mimics = mimics
        # (revolute, slot, origin translation xyz, origin rotation xyzw, axis xyz; for a
        # prismatic joint the axis in the parent's frame)
        self._joints = joints

    def values(self, positions: Iterable[float]) -> tuple[float, ...]:
        """
        Return translation xyz and rotation xyzw of each transform in turn, 7 floats each.

        At ``positions`` (rad or m), the positions of the names the transforms were made for,
        in that order.
        """
        slots = list(positions)
        for source, multiplier, offset in self._mimics:
            slots.append(multiplier * slots[source] + offset)
        values: list[float] = []
        for revolute, slot, tx, ty, tz, x, y, z, w, ax, ay, az in self._joints:
            position = slots[slot]
            if revolute:
                half = 0.5 * position
                sine = math.sin(half)
                mx, my, mz, mw = ax * sine, ay * sine, az * sine, math.cos(half)
                # origin · (a·sin(q/2), cos(q/2)): quaternion_product's terms in its order,
                # written out (a call per joint costs more than its arithmetic)
                values += (tx, ty, tz,
                           w * mx + x * mw + y * mz - z * my,
                           w * my - x * mz + y * mw + z * mx,
                           w * mz + x * my - y * mx + z * mw,
                           w * mw - x * mx - y * my - z * mz)
            else:
                values += (tx + ax * position, ty + ay * position, tz + az * position,
                           x, y, z, w)
        return tuple(values)
