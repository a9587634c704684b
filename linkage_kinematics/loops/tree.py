# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A URDF tree as a kinematic model: its coordinates and the forward kinematics of every link.

``KinematicTree`` is built from the one parsed ``UrdfTree`` (never a second parse) and the
closure file's ``JointOverride``s. Its coordinates are the robot's joint values in URDF units:

* a revolute or continuous joint turns its child about its unit axis by the value (rad), a
  prismatic joint slides it along the axis (m), as robot_state_publisher poses them;
* a mimic joint moves by multiplier·(its joint's value) + offset and has no coordinate of its
  own (a mimic of a joint without a coordinate, a fixed one, is held at its offset);
* an overridden joint is two or three revolute coordinates about its joint frame's own axes, in
  the override's order, each about the axis as the previous ones turned it (``UJOINT_ZY``: about
  z, then about the turned y), named ``<joint>_<axis>`` (``knee_z``, ``knee_y``);
* fixed joints are rigid; floating and planar joints are rigid too, as kdl_parser makes them,
  and are refused by name on a closure's loop.

Joints joined by fixed joints are one body: its pose is the frame of the last moving joint above
it (the "moving frame") times a fixed offset, so a fixed joint costs nothing per evaluation.
``LoopEquations`` (``equations``) evaluates closures' residuals and their exact Jacobian on that
model. Pure: no ROS.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
import enum

from linkage_kinematics.loops.closures import Closure, ClosureSide, JointOverride
from linkage_kinematics.loops.spatial import (
    add,
    apply,
    axis_rotation,
    IDENTITY,
    multiply,
    norm,
    Rotation,
    rpy_rotation,
    scale,
    unit,
    Vector,
    ZERO,
)
from linkage_kinematics.model.urdf_reader import JointType, UrdfJoint, UrdfTree

_UNIT_AXES: dict[str, Vector] = {'x': (1.0, 0.0, 0.0), 'y': (0.0, 1.0, 0.0),
                                 'z': (0.0, 0.0, 1.0)}
# URDF's default joint axis, taken for a pin closure side that names no axis
DEFAULT_PIN_AXIS: Vector = (1.0, 0.0, 0.0)
_UNSUPPORTED = frozenset({JointType.FLOATING, JointType.PLANAR})


class TreeError(ValueError):
    """A tree or closure the kinematic model cannot hold; the message names it and says why."""


class MotionKind(enum.Enum):
    """How a coordinate moves its joint's child."""

    TURN = 'revolute'
    SLIDE = 'prismatic'


@dataclass(frozen=True)
class Coordinate:
    """One coordinate of the tree: its name, the URDF joint it moves, and how."""

    name: str
    joint: str
    kind: MotionKind


@dataclass(frozen=True)
class Pose:
    """A frame: its rotation (9-tuple, row-major, columns its axes) and origin (m)."""

    rotation: Rotation
    position: Vector

    def then(self, other: Pose) -> Pose:
        """Return this frame followed by ``other`` (given in this frame)."""
        return Pose(multiply(self.rotation, other.rotation),
                    add(self.position, apply(self.rotation, other.position)))


IDENTITY_POSE = Pose(IDENTITY, ZERO)


@dataclass(frozen=True)
class Step:
    """
    One elementary motion of the tree, which makes moving frame (its index in the steps) + 1.

    From moving frame ``parent``, the fixed ``origin``, then a turn about (or a slide along) the
    unit ``axis`` of that joint frame by multiplier·q + offset, q the value of coordinate
    ``coordinate``.
    """

    joint: str
    parent: int
    origin: Pose
    axis: Vector
    kind: MotionKind
    coordinate: int
    multiplier: float
    offset: float


@dataclass(frozen=True)
class Loop:
    """
    A closure's loop: the frame its residual is written in and the steps down to each side.

    ``base`` is a moving frame; ``paths`` the steps from it down to the parent side's link and
    to the child side's, in order.
    """

    closure: Closure
    base: int
    paths: tuple[tuple[int, ...], tuple[int, ...]]
    # the two sides' frames in their moving frames: (moving frame, offset) each
    sides: tuple[tuple[int, Pose], tuple[int, Pose]]


class KinematicTree:
    """A URDF tree's coordinates and forward kinematics (module docstring)."""

    def __init__(self, tree: UrdfTree,
                 overrides: Mapping[str, JointOverride] | None = None) -> None:
        """Build the model; TreeError for an override or mimic it cannot hold, by name."""
        overrides = dict(overrides or {})
        for name in overrides:
            if name not in tree.joints:
                raise TreeError(f'joint override {name!r} names no joint of the robot')
        self.name = tree.name
        self.root = tree.root_link
        self.joint_above = {joint.child: joint for joint in tree.joints.values()}
        self.coordinates, self._coordinate_of = _coordinates(tree, overrides)
        self._overridden = frozenset(overrides)
        self.index = {coordinate.name: i for i, coordinate in enumerate(self.coordinates)}
        self.steps: list[Step] = []
        # link → (moving frame, offset of the link's frame in it)
        self.links: dict[str, tuple[int, Pose]] = {tree.root_link: (0, IDENTITY_POSE)}
        children: dict[str, list[UrdfJoint]] = {}
        for joint in tree.joints.values():
            children.setdefault(joint.parent, []).append(joint)
        stack = [tree.root_link]
        while stack:
            link = stack.pop()
            for joint in reversed(children.get(link, [])):
                self._add_joint(joint, overrides.get(joint.name))
                stack.append(joint.child)
        # moving frame → the frame above it (the root's frame, 0, has none)
        self.frame_parent = [-1] + [step.parent for step in self.steps]

    def _add_joint(self, joint: UrdfJoint, override: JointOverride | None) -> None:
        frame, offset = self.links[joint.parent]
        origin = offset.then(Pose(rpy_rotation(*joint.origin_rpy), joint.origin_translation))
        if override is not None:
            for place, (axis, name) in enumerate(zip(override.axes,
                                                     override.coordinates(joint.name))):
                self.steps.append(Step(
                    joint.name, frame, origin if place == 0 else IDENTITY_POSE, _UNIT_AXES[axis],
                    MotionKind.TURN, self.index[name], 1.0, 0.0))
                frame = len(self.steps)
            self.links[joint.child] = (frame, IDENTITY_POSE)
            return
        coordinate, multiplier, offset_value = self._coordinate_of.get(
            joint.name, (None, 0.0, 0.0))
        kind = MotionKind.SLIDE if joint.joint_type is JointType.PRISMATIC else MotionKind.TURN
        if not joint.movable:
            self.links[joint.child] = (frame, origin)
        elif coordinate is None:  # a mimic of a joint without a coordinate: held at its offset
            held = _motion(joint.axis, kind, offset_value)
            self.links[joint.child] = (frame, origin.then(held))
        else:
            self.steps.append(Step(joint.name, frame, origin, joint.axis, kind, coordinate,
                                   multiplier, offset_value))
            self.links[joint.child] = (len(self.steps), IDENTITY_POSE)

    @property
    def names(self) -> tuple[str, ...]:
        """Return the coordinates' names, in the order values are given."""
        return tuple(coordinate.name for coordinate in self.coordinates)

    def frames(self, values: Sequence[float]) -> list[Pose]:
        """Return every moving frame's pose in the root link's frame at coordinate ``values``."""
        poses = [IDENTITY_POSE]
        for step in self.steps:
            value = step.multiplier * values[step.coordinate] + step.offset
            poses.append(poses[step.parent].then(step.origin).then(
                _motion(step.axis, step.kind, value)))
        return poses

    def link_pose(self, link: str, values: Sequence[float]) -> Pose:
        """Return ``link``'s pose in the root link's frame at coordinate ``values``."""
        frame, offset = self._link(link)
        return self.frames(values)[frame].then(offset)

    def side_pose(self, side: ClosureSide, values: Sequence[float]) -> Pose:
        """Return a closure side's frame in the root link's frame at coordinate ``values``."""
        frame, offset = self.side_frame(side)
        return self.frames(values)[frame].then(offset)

    def side_frame(self, side: ClosureSide) -> tuple[int, Pose]:
        """Return the moving frame a closure side is fixed on, and its offset there."""
        frame, offset = self._link(side.link)
        return frame, offset.then(Pose(rpy_rotation(*side.rpy), side.xyz))

    def _link(self, link: str) -> tuple[int, Pose]:
        if link not in self.links:
            raise TreeError(f'link {link!r} is not a link of the robot')
        return self.links[link]

    def path(self, frame: int) -> list[int]:
        """Return the steps from the root down to moving ``frame``, in order."""
        steps = []
        while frame > 0:
            steps.append(frame - 1)
            frame = self.frame_parent[frame]
        return steps[::-1]

    def loop(self, closure: Closure) -> Loop:
        """
        Return a closure's loop; TreeError naming a floating or planar joint on it.

        The base is the deepest moving frame above both sides: no step above it moves the
        closure's frames relative to each other.
        """
        sides = (self.side_frame(closure.parent), self.side_frame(closure.child))
        for link in (closure.parent.link, closure.child.link):
            self._check_path(closure, link, closure.parent.link if link != closure.parent.link
                             else closure.child.link)
        paths = [self.path(frame) for frame, _ in sides]
        shared = 0
        while (shared < min(len(paths[0]), len(paths[1]))
               and paths[0][shared] == paths[1][shared]):
            shared += 1
        base = paths[0][shared - 1] + 1 if shared else 0
        return Loop(closure, base, (tuple(paths[0][shared:]), tuple(paths[1][shared:])),
                    (sides[0], sides[1]))

    def _check_path(self, closure: Closure, link: str, other: str) -> None:
        """Refuse a floating or planar joint between ``link`` and its common ancestor."""
        above_other = set()
        walker = other
        while walker in self.joint_above:
            above_other.add(walker)
            walker = self.joint_above[walker].parent
        above_other.add(walker)
        while link not in above_other and link in self.joint_above:
            joint = self.joint_above[link]
            if joint.joint_type in _UNSUPPORTED and joint.name not in self._overridden:
                raise TreeError(f'closure {closure.name!r}: joint {joint.name!r} on its loop is '
                                f'{joint.joint_type.value}; floating and planar joints are not '
                                'closed')
            link = joint.parent

    def loop_coordinates(self, loop: Loop) -> tuple[int, ...]:
        """Return the coordinates that move a loop, each once, in the tree's order."""
        return tuple(sorted({self.steps[step].coordinate for path in loop.paths
                             for step in path}))


def _motion(axis: Vector, kind: MotionKind, value: float) -> Pose:
    """Return a joint's motion by ``value`` about or along its unit ``axis``."""
    if kind is MotionKind.TURN:
        return Pose(axis_rotation(axis, value), ZERO)
    return Pose(IDENTITY, scale(value, axis))


def _coordinates(tree: UrdfTree, overrides: Mapping[str, JointOverride]) -> tuple[
        tuple[Coordinate, ...], dict[str, tuple[int | None, float, float]]]:
    """
    Return the tree's coordinates, and per moving joint (coordinate, multiplier, offset).

    A mimic's chain is followed to the joint that has a coordinate; TreeError for a mimic of an
    overridden joint, an overridden mimic, a mimic cycle or an override's name taken.
    """
    coordinates: list[Coordinate] = []
    for joint in tree.joints.values():
        if joint.name in overrides:
            if joint.mimic is not None:
                raise TreeError(f'joint {joint.name!r} is overridden but mimics '
                                f'{joint.mimic.joint!r}')
            coordinates += [Coordinate(name, joint.name, MotionKind.TURN)
                            for name in overrides[joint.name].coordinates(joint.name)]
        elif joint.movable and joint.mimic is None:
            kind = (MotionKind.SLIDE if joint.joint_type is JointType.PRISMATIC
                    else MotionKind.TURN)
            coordinates.append(Coordinate(joint.name, joint.name, kind))
    names = [coordinate.name for coordinate in coordinates]
    for coordinate in coordinates:
        if coordinate.name != coordinate.joint and (coordinate.name in tree.joints
                                                    or names.count(coordinate.name) > 1):
            raise TreeError(f'joint override {coordinate.joint!r}: its coordinate '
                            f'{coordinate.name!r} is also the name of a joint')
    index = {name: i for i, name in enumerate(names)}
    mapping: dict[str, tuple[int | None, float, float]] = {}
    for joint in tree.joints.values():
        if not joint.movable or joint.name in overrides:
            continue
        multiplier, offset, walker, seen = 1.0, 0.0, joint, {joint.name}
        while walker.mimic is not None:
            target = walker.mimic.joint
            if target in overrides:
                raise TreeError(f'joint {joint.name!r} mimics the overridden joint {target!r}')
            if target in seen:
                raise TreeError(f'joint {joint.name!r}: its mimics form a cycle')
            seen.add(target)
            offset = multiplier * walker.mimic.offset + offset
            multiplier *= walker.mimic.multiplier
            walker = tree.joints[target]
        mapping[joint.name] = (index.get(walker.name) if walker.movable else None,
                               multiplier, offset)
    return tuple(coordinates), mapping


def unit_axis(side: ClosureSide) -> Vector:
    """Return a pin side's unit axis in its frame (URDF's default x where none was given)."""
    axis = side.axis if side.axis is not None else DEFAULT_PIN_AXIS
    if norm(axis) == 0.0:
        raise TreeError(f'closure side on {side.link!r}: its axis is zero')
    return unit(axis)
