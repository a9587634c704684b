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

    Most revolute joints of a URDF have no rotation in their origin and an axis along one of
    their frame's axes. Then the product origin · (a·sin(q/2), cos(q/2)) has in w cos(q/2)
    minus zeros, in the axis's component ±sin(q/2) plus zeros, and in the other two only
    zeros (each term a zero times sin(q/2) or cos(q/2)): a product and a sum, not sixteen
    products and twelve sums. Adding zeros leaves a nonzero number as it is (and cos(q/2) of a
    finite q is never zero), and the sign of a sum of zeros depends only on the signs of
    sin(q/2) and cos(q/2). So each such joint is checked here against the product itself at
    a sine of either sign and a zero of either sign and a cosine of either sign: the two
    other components must be the same zeros at every sign (along a negative axis, or after
    an origin rotation with negative zeros, their signs follow the sine's and the cosine's,
    and the joint keeps the product), the axis's component ±sin(q/2) + 0.0 (a zero sine gives
    +0.0) and w cos(q/2), to the bit. Then every transform is the product's, bit for bit, for
    every finite position; a joint state with a NaN (which the product spreads to every
    component) takes the product throughout, and an infinite angle raises ValueError
    (``math.sin``) either way.
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
        # The values that do not move, with each revolute joint along a frame axis as its slot,
        # the place of its axis component, the axis's sign and the place of w; every other
        # joint (``joints``' entry) computed by the product and put at its place.
        self._fixed: list[float] = []
        axis_turns, others, places = [], [], []
        for joint in joints:
            revolute, slot, tx, ty, tz = joint[:5]
            place = len(self._fixed)
            turn = _axis_turn(joint) if revolute else None
            if turn is None:
                self._fixed += joint[2:9]
                others.append(joint)
                places.append(place)
            else:
                component, sign, rotation = turn
                self._fixed += (tx, ty, tz, *rotation)
                axis_turns.append((slot, place + 3 + component, sign, place + 6))
        self._axis_turns = tuple(axis_turns)
        self._others = tuple(others)
        self._other_places = tuple(places)

    def values(self, positions: Iterable[float]) -> tuple[float, ...]:
        """
        Return translation xyz and rotation xyzw of each transform in turn, 7 floats each.

        At ``positions`` (rad or m), the positions of the names the transforms were made for,
        in that order.
        """
        slots = list(positions)
        for source, multiplier, offset in self._mimics:
            slots.append(multiplier * slots[source] + offset)
        if not self._axis_turns:
            return _product_values(self._joints, slots)
        # sum() only to find a NaN: finite floats and infinities of one sign never sum to NaN
        # (nor does 3.12's compensation make one), so a NaN total means a NaN or infinities of
        # both signs, and the product decides
        total = sum(slots)
        if total != total:
            return _product_values(self._joints, slots)
        values = self._fixed[:]
        sin, cos = math.sin, math.cos
        for slot, component, sign, last in self._axis_turns:
            half = 0.5 * slots[slot]
            values[component] = sign * sin(half) + 0.0
            values[last] = cos(half)
        if self._others:
            others = _product_values(self._others, slots)
            for start, place in zip(range(0, len(others), 7), self._other_places):
                values[place:place + 7] = others[start:start + 7]
        return tuple(values)


def _product_values(joints: Iterable[tuple[Any, ...]], slots: Sequence[float]
                    ) -> tuple[float, ...]:
    """Return ``MovingTransforms.values`` of ``joints`` at ``slots``, by the product per joint."""
    values: list[float] = []
    for revolute, slot, tx, ty, tz, x, y, z, w, ax, ay, az in joints:
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


# sin(q/2) of either sign and zero of either sign, cos(q/2) of either sign: the signs on which
# the zeros of the product depend
_SIGNS = tuple((sine, cosine) for sine in (0.25, -0.25, 0.0, -0.0) for cosine in (0.5, -0.5))


def _axis_turn(joint: tuple[Any, ...]) -> tuple[int, float, tuple[float, ...]] | None:
    """
    Return a revolute joint's axis component (0–2), its sign and its fixed rotation, or None.

    The fixed rotation: the product's components, with its axis component and w as 0. None
    unless the origin has no rotation, the axis is along a frame axis and the product gives the
    same zeros in the other two components, ±sin(q/2) + 0.0 in the axis component and cos(q/2)
    in w at every sign of ``_SIGNS`` (``MovingTransforms``).
    """
    origin, axis = joint[5:9], joint[9:]
    moving = [index for index, component in enumerate(axis) if component != 0.0]
    # an origin without rotation: every term of the product but one per component is a zero
    if origin != (0.0, 0.0, 0.0, 1.0) or len(moving) != 1 or abs(axis[moving[0]]) != 1.0:
        return None
    component, sign = moving[0], axis[moving[0]]
    ax, ay, az = axis
    fixed: list[float] | None = None
    for sine, cosine in _SIGNS:
        product = quaternion_product(origin, (ax * sine, ay * sine, az * sine, cosine))
        expected = list(product)
        expected[component], expected[3] = sign * sine + 0.0, cosine
        if [value.hex() for value in product] != [value.hex() for value in expected]:
            return None
        rotation = [*product[:component], 0.0, *product[component + 1:3], 0.0]
        if fixed is None:
            fixed = rotation
        elif [value.hex() for value in rotation] != [value.hex() for value in fixed]:
            return None
    return component, sign, tuple(fixed)
