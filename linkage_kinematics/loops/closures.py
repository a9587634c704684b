# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The one model of a loop closure, whichever encoding a robot description wrote it in.

A closure cuts a closed kinematic loop of a URDF tree: two frames, each fixed on a link, that
the mechanism keeps together. Its ``ClosureKind`` says how much of them coincides:

* ``PIN``: the two origins coincide and the two axes are aligned; the frames may turn about
  that axis (a revolute joint, five equations);
* ``BALL``: the two origins coincide (a spherical joint, three equations);
* ``WELD``: the two frames coincide (a fixed joint, six equations).

Three encodings are read (one reader module each): urdfdom PR #264's ``<constraint>`` element,
Isaac Sim's ``<loop_joint>`` element, and the closure file of Pinocchio's
toolbox-parallel-robots (the "Extended URDF" YAML side file). The closure file may also name
the actuated joints and override URDF joints as spherical or universal joints
(``JointOverride``). Lengths in metres, angles in radians. What a reader cannot read is a
``ClosureError`` of one line naming the element and what is wrong.
"""

from __future__ import annotations

from dataclasses import dataclass, field
import enum

Vector = tuple[float, float, float]
ORIGIN: Vector = (0.0, 0.0, 0.0)


class ClosureError(ValueError):
    """A closure, or a closure file's entry, that cannot be read; the message names it and why."""


class ClosureKind(enum.Enum):
    """How much of the two frames of a closure coincides."""

    PIN = 'pin'
    BALL = 'ball'
    WELD = 'weld'

    @property
    def equations(self) -> int:
        """Return the number of scalar equations the closure imposes."""
        return {ClosureKind.PIN: 5, ClosureKind.BALL: 3, ClosureKind.WELD: 6}[self]


class Encoding(enum.Enum):
    """Where a closure was read from; its value names the element or file for people."""

    CONSTRAINT = '<constraint>'
    LOOP_JOINT = '<loop_joint>'
    CLOSURE_FILE = 'closure file'

    @property
    def word(self) -> str:
        """Return the word a message names one of its closures by: its element, or 'closure'."""
        return {Encoding.CONSTRAINT: 'constraint', Encoding.LOOP_JOINT: 'loop_joint',
                Encoding.CLOSURE_FILE: 'closure'}[self]


@dataclass(frozen=True)
class ClosureSide:
    """
    One frame of a closure: fixed on ``link``, at ``xyz`` (m) turned by ``rpy`` (rad) from it.

    Without ``xyz`` and ``rpy``, the link's own frame.

    ``axis`` is the unit axis of a pin in this frame, None for a ball or a weld. The readers
    give a pin's axis on both sides (each in its own frame, the encoding's default filled in),
    except for a ``<constraint>`` without ``<parent_axis>``: its parent's axis is None, and its
    pin turns about the axis of its loop's first revolute joint, as the planar loops read it
    (its child's axis is then the ``<child_axis>`` if any, else None too).
    """

    link: str
    xyz: Vector = ORIGIN
    rpy: Vector = ORIGIN
    axis: Vector | None = None


@dataclass(frozen=True)
class Closure:
    """A loop closure: its name, kind and two frames, and the encoding it was read from."""

    name: str
    kind: ClosureKind
    parent: ClosureSide
    child: ClosureSide
    encoding: Encoding

    @property
    def label(self) -> str:
        """Return the closure as messages name it: ``constraint 'knee_pin'``, as it was written."""
        return f'{self.encoding.word} {self.name!r}'


class JointOverride(enum.Enum):
    """
    A URDF joint the closure file reads as another joint, about its joint frame's axes.

    The value lists the rotation axes in order (the joint frame's, as toolbox-parallel-robots
    names them: ``UJOINT_ZY`` turns about z, then about the turned y). The joint's own type and
    axis no longer count: example-parallel-robots' loader (``completeRobotLoader``) puts
    Pinocchio's RX, RY, RZ (or spherical) joints at the URDF joint's origin in its place, the
    second of a universal joint at the first's origin, the child link on the last. ``FIXED``
    holds the joint at 0 (the loader freezes it at Pinocchio's neutral configuration).
    """

    SPHERICAL = 'xyz'
    UJOINT_XY = 'xy'
    UJOINT_XZ = 'xz'
    UJOINT_YX = 'yx'
    UJOINT_YZ = 'yz'
    UJOINT_ZX = 'zx'
    UJOINT_ZY = 'zy'
    FIXED = ''

    @property
    def axes(self) -> tuple[str, ...]:
        """Return the joint frame's axes it turns about, in order."""
        return tuple(self.value)

    def coordinates(self, joint: str) -> tuple[str, ...]:
        """
        Return the names of the coordinates that read URDF joint ``joint``, one per axis.

        The loader names a universal joint's two joints ``<joint>_Z``, ``<joint>_Y``; a
        spherical joint stays one Pinocchio joint (a quaternion), whose three angles are named
        here the same way (``<joint>_X``, ``<joint>_Y``, ``<joint>_Z``).
        """
        return tuple(f'{joint}_{axis.upper()}' for axis in self.axes)


@dataclass(frozen=True)
class ClosureDescription:
    """
    What a robot description says of its loops, and one line for each part that cannot be read.

    ``actuated`` is the closure file's ``name_mot`` (the default measured joints), None where
    nothing names them; ``overrides`` maps a URDF joint to the joint the closure file reads in
    its place, in the file's order.
    """

    closures: tuple[Closure, ...] = ()
    actuated: tuple[str, ...] | None = None
    overrides: dict[str, JointOverride] = field(default_factory=dict)
    problems: tuple[str, ...] = ()
