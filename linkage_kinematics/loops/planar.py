# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
One pin closure's loop as a ``PlanarLoop``, derived from the URDF's zero pose.

A pin (``closures.ClosureKind.PIN``, of any encoding) whose loop has three moving joints (at
most one prismatic) is a four-bar or a slider loop: ``four_joint_pin`` says which closures are,
``derive_loop`` derives the loop or refuses it by name (not planar, a floating joint on it). The
loop is the tree path between the closure's two links, closed by its pin. Its joints in the
``PlanarLoop``'s cyclic order: the cut pin is joint 0, then the path's moving joints in order
from the closure's parent link to its child link; body k joins joint k to joint k + 1, so body 0
is the closure's parent link and body 3 its child link (fixed joints on the path are rigid: they
belong to a body). Every other closure is the general closure's (``structure``, ``newton``).

Everything comes from the URDF at the zero pose, nothing is assumed about how it was drawn:

* the plane's normal n is the pin's parent-side axis in the world (a ``<constraint>`` without
  ``parent_axis``: the first revolute joint's axis); every revolute axis, the pin's child-side
  axis included, must be parallel to it (either sense), every prismatic axis perpendicular;
* an in-plane basis (e1, e2) with e1 × e2 = n, so angles count counterclockwise about n;
* each joint's point is its joint frame's origin (the cut pin's: the closure frame's origin
  on each side), projected into the plane: offsets along n (links stacked in depth) do not move
  the loop in its plane and are dropped;
* each tree joint's map between its URDF value q and the loop coordinate, φ = s·q or δ = s·q:
  s is the sense of the joint's axis along n for a revolute joint, times −1 where the path
  crosses the joint from its child to its parent; a prismatic joint's slide is its axis.

The closure residual at the zero pose (the distance between the closure's two frame origins)
says how well the drawing closes the loop.
"""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import dataclass
import math

from linkage_kinematics.kinematics.geometry import GeometryError
from linkage_kinematics.kinematics.planar_loop import JointKind, PlanarLoop
from linkage_kinematics.loops.closures import Closure, ClosureKind
from linkage_kinematics.loops.description import (
    LoopError,
    Pose,
    Robot,
    side_frame,
    tree_path,
    TreeJoint,
)
from linkage_kinematics.model.urdf_reader import JointType, MOVABLE_TYPES, ROTATING_TYPES
import numpy as np

# How far (rad, as the sine of the angle) a revolute axis may lean from the loop normal, or a
# prismatic axis from the plane: exporters' rounding of π/2 tilts frames by about 1e-16 rad.
PARALLEL_TOLERANCE = 1e-9


@dataclass(frozen=True)
class LoopJoint:
    """A tree joint of a loop: its place (1–3) in the ``PlanarLoop`` and its sign."""

    name: str
    index: int
    kind: JointKind
    # loop coordinate (φ rad or δ m) = sign · URDF value (rad or m)
    sign: int
    continuous: bool
    mimic: str | None


@dataclass(frozen=True)
class Loop:
    """A pin closure's planar loop: the ``PlanarLoop`` and how it sits in the URDF."""

    # the closure's name, and how messages name it (``constraint 'knee_pin'``)
    constraint: str
    label: str
    planar: PlanarLoop
    joints: tuple[LoopJoint, LoopJoint, LoopJoint]
    normal: np.ndarray
    # the prismatic joint's slide in the world at the zero pose (unit), if the loop has one
    slide_world: np.ndarray | None
    # distance between the closure's two frame origins at the zero pose (m)
    closure_residual: float

    @property
    def names(self) -> tuple[str, str, str]:
        """Return the tree joints' names in loop order (joints 1, 2, 3)."""
        return (self.joints[0].name, self.joints[1].name, self.joints[2].name)

    def joint(self, name: str) -> LoopJoint:
        """Return the loop joint named ``name``; KeyError if it is not in the loop."""
        for joint in self.joints:
            if joint.name == name:
                return joint
        raise KeyError(name)

    @property
    def prismatic(self) -> LoopJoint | None:
        """Return the loop's prismatic joint, if it has one."""
        return next((joint for joint in self.joints if joint.kind is JointKind.PRISMATIC), None)


def _lean(direction: np.ndarray, normal: np.ndarray, along: bool) -> float:
    """Return how far a unit ``direction`` is from ``normal`` (along) or from its plane."""
    if along:
        return float(np.linalg.norm(np.cross(direction, normal)))
    return abs(float(direction @ normal))


def _moving(path: tuple[tuple[TreeJoint, bool], ...]) -> list[tuple[JointType, str, bool]]:
    return [(joint.joint_type, joint.name, forward) for joint, forward in path
            if joint.joint_type in MOVABLE_TYPES]


def four_joint_pin(robot: Robot, closure: Closure, overridden: Collection[str]) -> bool:
    """
    Return whether a closure is a planar loop's to derive (``derive_loop``), or refuse.

    A pin whose loop has three moving joints, at most one prismatic, and no joint the closure
    file reads otherwise (``overridden``): a four-bar or a slider loop if it is planar. A pin
    joining a link to itself or with a floating or planar joint on its loop is one too, so that
    ``derive_loop`` refuses it as the planar loops always have.
    """
    if closure.kind is not ClosureKind.PIN:
        return False
    if closure.parent.link == closure.child.link:
        return True
    path = tree_path(robot, closure.parent.link, closure.child.link)
    if any(joint.name in overridden for joint, _ in path):
        return False
    if any(joint.joint_type in (JointType.FLOATING, JointType.PLANAR) for joint, _ in path):
        return True
    moving = _moving(path)
    return len(moving) == 3 and sum(
        joint_type is JointType.PRISMATIC for joint_type, _, _ in moving) <= 1


def _moving_path(robot: Robot, closure: Closure,
                 where: str) -> list[tuple[JointType, str, bool]]:
    if closure.parent.link == closure.child.link:
        raise LoopError(f'{where}: joins link {closure.parent.link!r} to itself')
    path = tree_path(robot, closure.parent.link, closure.child.link)
    free = [joint.name for joint, _ in path
            if joint.joint_type in (JointType.FLOATING, JointType.PLANAR)]
    if free:
        raise LoopError(f'{where}: the loop holds floating or planar joints {free}, which have '
                        'no single coordinate to solve')
    moving = _moving(path)
    if len(moving) != 3:
        raise LoopError(f'{where}: the loop has {len(moving)} moving joints '
                        f'{[name for _, name, _ in moving]}, not 3: only a four-bar (or a '
                        'slider-crank) loop is a planar loop')
    prismatic = [name for joint_type, name, _ in moving if joint_type is JointType.PRISMATIC]
    if len(prismatic) > 1:
        raise LoopError(f'{where}: the loop has {len(prismatic)} prismatic joints {prismatic}; '
                        'a planar loop has at most one')
    return moving


def _side_axis(frame: Pose, axis: tuple[float, float, float] | None) -> np.ndarray | None:
    """Return a pin side's unit axis in the world, None where the closure gives none."""
    return None if axis is None else frame.rotation @ np.array(axis, dtype=float)


def _normal(robot: Robot, parent_axis: np.ndarray | None, child_axis: np.ndarray | None,
            moving: list[tuple[JointType, str, bool]], where: str) -> np.ndarray:
    """Return the loop's unit normal, after checking every axis against it."""
    if parent_axis is not None:
        normal = parent_axis
    else:
        normal = next(robot.joints[name].axis for joint_type, name, _ in moving
                      if joint_type in ROTATING_TYPES)
    directions = [(f'joint {name!r}', robot.joints[name].axis, joint_type in ROTATING_TYPES)
                  for joint_type, name, _ in moving]
    if child_axis is not None:
        directions.append(('its child_axis', child_axis, True))
    for what, direction, along in directions:
        lean = _lean(direction, normal, along)
        if lean > PARALLEL_TOLERANCE:
            relation = ('is not parallel to' if along
                        else 'slides out of the plane perpendicular to')
            raise LoopError(
                f'{where}: {what} {relation} the loop normal {_world(normal)} at the zero pose '
                f'({math.degrees(math.asin(min(lean, 1.0))):.3g}° off): the loop is not planar')
    return normal


def _world(vector: np.ndarray) -> str:
    return '(' + ', '.join(f'{component + 0.0:.6g}' for component in vector) + ')'


def plane_basis(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Return unit e1, e2 spanning the plane perpendicular to unit ``normal``, e1 × e2 = n."""
    # the world axis least along the normal, made perpendicular to it: well conditioned
    helper = np.eye(3)[int(np.argmin(np.abs(normal)))]
    first = helper - (helper @ normal) * normal
    first /= np.linalg.norm(first)
    return first, np.cross(normal, first)


def derive_loop(robot: Robot, closure: Closure) -> Loop:
    """
    Return a pin ``closure``'s loop as a ``PlanarLoop`` with its joints' signs.

    Raises LoopError, naming the closure, for anything but a planar four-bar (or slider loop)
    closed by a pin: another closure kind, a loop of other than 3 moving joints or with floating
    or planar joints, non-parallel revolute axes, a prismatic axis out of the plane, more than
    one prismatic joint.
    """
    where = closure.label
    if closure.kind is not ClosureKind.PIN:
        raise LoopError(f'{where}: a {closure.kind.value} closure is not a pin: only a pin closes '
                        'a planar loop')
    moving = _moving_path(robot, closure, where)
    parent_frame, child_frame = side_frame(robot, closure.parent), side_frame(robot, closure.child)
    normal = _normal(robot, _side_axis(parent_frame, closure.parent.axis),
                     _side_axis(child_frame, closure.child.axis), moving, where)
    first, second = plane_basis(normal)

    def in_plane(vector: np.ndarray) -> tuple[float, float]:
        return (float(vector @ first), float(vector @ second))

    points = ([parent_frame.position]
              + [robot.joints[name].frame.position for _, name, _ in moving]
              + [child_frame.position])
    links = tuple(in_plane(points[k + 1] - points[k]) for k in range(4))
    kinds = [JointKind.REVOLUTE]
    joints = []
    slide = slide_world = None
    for index, (joint_type, name, forward) in enumerate(moving, start=1):
        tree_joint = robot.joints[name]
        crossing = 1 if forward else -1
        if joint_type is JointType.PRISMATIC:
            kind, sign = JointKind.PRISMATIC, crossing
            slide_world = tree_joint.axis - (tree_joint.axis @ normal) * normal
            slide_world /= np.linalg.norm(slide_world)
            slide = in_plane(slide_world)
        else:
            kind = JointKind.REVOLUTE
            sign = crossing * (1 if tree_joint.axis @ normal > 0.0 else -1)
        kinds.append(kind)
        joints.append(LoopJoint(name, index, kind, sign,
                                joint_type is JointType.CONTINUOUS, tree_joint.mimic))
    try:
        planar = PlanarLoop(kinds=tuple(kinds), links=links, slide=slide)
    except GeometryError as error:
        raise LoopError(f'{where}: {error}') from None
    residual = float(np.linalg.norm(parent_frame.position - child_frame.position))
    return Loop(closure.name, where, planar, (joints[0], joints[1], joints[2]), normal,
                slide_world, residual)
