# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The sample intake: the measured joints of one JointState after another, taken in or refused.

Both measured followers take their messages through one ``Intake``: the robot's loops
(``follower``) and the four-bar's measured mode (``run.measured``). ``Intake.take`` finds the
joints by name, checks that each has a position and that the positions and velocities are
finite, that the stamp is newer than the last sample kept, unwraps each wrapping (revolute)
joint across whole turns to within π of its last value and refuses it further than
``measured.max_jump`` from there, and gives each joint's velocity: the message's own, or the
backward difference over the header stamps (``joint_velocity``, 0 for a first sample). A
follower ``keep``s a sample once it has used it, so that a refused one leaves nothing behind.
``Intake.efforts`` gives some joints' efforts in the message last taken, where it carries them.

``DropReason`` is the one set of reasons a measured message is dropped for, in either mode; its
texts are what diagnostics show. No ROS.
"""

from __future__ import annotations

from collections.abc import Collection, Sequence
from dataclasses import dataclass
from enum import StrEnum
import math

from linkage_kinematics.kinematics.geometry import TWO_PI
from linkage_kinematics.model.joints import JointMapping


class DropReason(StrEnum):
    """
    Why a measured message was dropped; the text names it in diagnostics.

    Where the two measured modes word a reason each its own way, each has its member: the
    four-bar's ``NO_DRIVER`` and ``DRIVER_UNREACHABLE``, the loops' ``NO_JOINT`` and
    ``JOINTS_UNREACHABLE``. A closure group of the general closure refuses a sample for one of
    three reasons (``refusals.Refusal``), each its own member: ``NO_ASSEMBLY``,
    ``ASSEMBLY_JUMP``, ``SINGULAR``. ``FOUR_BAR_DROPS`` and ``LOOPS_DROPS`` are the reasons
    each mode counts, in the order its diagnostics list them (the groups' last, after those
    bags already hold).
    """

    NO_DESCRIPTION = 'before the robot description was closed'
    NOT_PLANNED = 'while the measured joints cannot close the loops'
    NO_DRIVER = 'without the driver joint'
    NO_JOINT = 'without every measured joint'
    NON_FINITE = 'with a NaN or infinite position or velocity'
    STAMP_NOT_NEWER = 'with a stamp not newer than the last one used'
    DRIVER_UNREACHABLE = 'at a driver angle the loop cannot reach (or at a dead point)'
    JOINTS_UNREACHABLE = 'at joint values a loop cannot reach (or at a dead point)'
    JUMP = 'jumping further than measured.max_jump'
    MALFORMED = 'whose bytes are not a well-formed JointState'
    NO_ASSEMBLY = 'at joint values no assembly of a closure group reaches'
    ASSEMBLY_JUMP = 'that would jump a closure group to another assembly'
    SINGULAR = 'too near a singular configuration of a closure group'


FOUR_BAR_DROPS = (DropReason.NO_DRIVER, DropReason.NON_FINITE, DropReason.STAMP_NOT_NEWER,
                  DropReason.DRIVER_UNREACHABLE, DropReason.JUMP, DropReason.MALFORMED)
LOOPS_DROPS = (DropReason.NO_DESCRIPTION, DropReason.NOT_PLANNED, DropReason.NO_JOINT,
               DropReason.NON_FINITE, DropReason.STAMP_NOT_NEWER, DropReason.JOINTS_UNREACHABLE,
               DropReason.JUMP, DropReason.MALFORMED, DropReason.NO_ASSEMBLY,
               DropReason.ASSEMBLY_JUMP, DropReason.SINGULAR)


class Estimate(StrEnum):
    """How a measured joint's velocity was obtained."""

    MEASURED = 'measured'
    BACKWARD_DIFFERENCE = 'estimated (backward difference of angles)'
    FIRST_SAMPLE = 'estimated (0: first sample without velocity)'


def joint_velocity(stamp_ns: int, value: float, measured: float | None,
                   last: tuple[int, float] | None) -> tuple[float, Estimate]:
    """
    Return a measured joint's velocity at ``value`` (stamp ``stamp_ns``) and how it was obtained.

    ``measured`` when the message carries it; else the backward difference from ``last``
    (its stamp in ns and its value, unwrapped to ``value``'s turn) over the header stamps, and 0
    for a first sample (``last`` None).
    """
    if measured is not None:
        return measured, Estimate.MEASURED
    if last is None:
        return 0.0, Estimate.FIRST_SAMPLE
    last_stamp_ns, last_value = last
    return (value - last_value) / ((stamp_ns - last_stamp_ns) * 1e-9), Estimate.BACKWARD_DIFFERENCE


@dataclass(frozen=True)
class IntakeDrop:
    """A message the intake refused: why, the joints it concerns (none: the message) and detail."""

    reason: DropReason
    joints: tuple[str, ...]
    detail: str


# A sample taken in, each list in the order of ``Intake.joints``: the positions as measured, the
# values in the follower's convention (unwrapped), the velocities in it, and how each was obtained.
Taken = tuple[list[float], list[float], list[float], list[Estimate]]


class Intake:
    """
    Takes the ``joints`` of one JointState after another (module docstring); ``restart`` forgets.

    ``wrapping``: the joints unwrapped across turns, to which ``max_jump`` (rad) applies.
    ``missing``: the reason a message without every joint is dropped. ``own_output``: the names
    of the follower's own output: a message of only these is that output heard back, ignored;
    None: any message without one of the joints is ignored (a robot's other joints share the
    topic). ``mappings``: each joint's lab value mapped to the follower's convention
    (``JointMapping.from_lab``), in which it is unwrapped and its velocity taken; None: the
    values as measured (URDF units).
    """

    def __init__(self, joints: Sequence[str], wrapping: Collection[str], max_jump: float,
                 missing: DropReason, own_output: Collection[str] | None = None,
                 mappings: Sequence[JointMapping] | None = None) -> None:
        self.joints = tuple(joints)
        self.max_jump = max_jump
        self._missing = missing
        self._own_output = None if own_output is None else frozenset(own_output)
        self._mappings = None if mappings is None else tuple(mappings)
        # places in ``joints`` of the wrapping ones, in that order (their jumps are named so)
        self._wrapping = tuple(place for place, name in enumerate(self.joints)
                               if name in wrapping)
        self._names: Sequence[str] | None = None  # the names _indices were found in
        self.restart()

    def restart(self) -> None:
        """Forget the last sample kept: the next is a first sample again."""
        self._last_stamp_ns: int | None = None
        self._last: list[float] | None = None  # the values kept, in the follower's convention

    def keep(self, stamp_ns: int, values: list[float]) -> None:
        """Keep a sample the follower used (``values``: its ``take``'s), the next one's last."""
        self._last_stamp_ns, self._last = stamp_ns, values

    def _look_up(self, names: Sequence[str]) -> None:
        """
        Find the joints in ``names``: a name given twice counts at its first place.

        As robot_state_publisher reads a joint state (its map's insert keeps the first).
        """
        places: dict[str, int] = {}
        for place, name in enumerate(names):
            places.setdefault(name, place)
        indices = tuple(places.get(name) for name in self.joints)
        present = [index for index in indices if index is not None]
        if self._own_output is None:
            ignored = not present
        else:
            ignored = bool(names) and self._own_output.issuperset(names)
        self._names = names[:]
        self._indices = None if ignored else indices
        # with every joint named, the message needs this many positions
        self._needed = max(present) + 1 if len(present) == len(indices) else math.inf

    def take(self, stamp_ns: int, names: Sequence[str], positions: Sequence[float],
             velocities: Sequence[float]) -> Taken | IntakeDrop | None:
        """
        Return one message's sample of the joints (``Taken``), or why it was refused.

        None for a message to ignore (see ``own_output``): not counted.
        """
        if names != self._names:
            # A source sends the same names message after message: found once, not per message.
            self._look_up(names)
        indices = self._indices
        if indices is None:
            return None
        if self._needed > len(positions):
            count = len(positions)
            missing = [name for name, index in zip(self.joints, indices)
                       if index is None or index >= count]
            return IntakeDrop(self._missing, tuple(missing), f'no position of {missing}')
        count = len(velocities)
        measured, given, finite = [], [], True
        isfinite = math.isfinite
        for index in indices:
            value = positions[index]
            rate = velocities[index] if index < count else None
            measured.append(value)
            given.append(rate)
            if not isfinite(value) or (rate is not None and not isfinite(rate)):
                finite = False
        if not finite:
            bad = [name for name, value, rate in zip(self.joints, measured, given)
                   if not isfinite(value) or not isfinite(0.0 if rate is None else rate)]
            return IntakeDrop(DropReason.NON_FINITE, tuple(bad), f'{bad} not finite')
        last_stamp_ns = self._last_stamp_ns
        if last_stamp_ns is not None and stamp_ns <= last_stamp_ns:
            return IntakeDrop(DropReason.STAMP_NOT_NEWER, (), 'stamp not newer')
        mappings = self._mappings
        if mappings is None:
            values = measured[:]
        else:
            values = [mapping.from_lab(value) for mapping, value in zip(mappings, measured)]
            given = [None if rate is None else mapping.direction * rate
                     for mapping, rate in zip(mappings, given)]
        last = self._last
        if last is not None:
            jumps = []
            for place in self._wrapping:
                # An encoder that wraps (at ±π, or anywhere) is unwrapped: whole turns are
                # counted.
                previous = last[place]
                value = values[place] = (values[place]
                                         + round((previous - values[place]) / TWO_PI) * TWO_PI)
                if abs(value - previous) > self.max_jump:
                    jumps.append(self.joints[place])
            if jumps:
                return IntakeDrop(DropReason.JUMP, tuple(jumps), f'{jumps} jumped')
        if None not in given:  # every velocity measured, as an encoder's: joint_velocity's
            return measured, values, given, [Estimate.MEASURED] * len(given)
        rates, estimates = [], []
        for place, rate in enumerate(given):
            rate, estimate = joint_velocity(
                stamp_ns, values[place], rate,
                None if last is None else (last_stamp_ns, last[place]))
            rates.append(rate)
            estimates.append(estimate)
        return measured, values, rates, estimates

    def efforts(self, efforts: Sequence[float], places: Sequence[int]) -> list[float] | None:
        """
        Return the efforts of the joints at ``places`` (of ``joints``) in the message last taken.

        ``efforts``: that message's (N·m or N, as measured). None unless each of those joints has
        one and it is finite: a JointState without efforts, or with NaN where a joint has no
        effort interface (ros2_control's joint_state_broadcaster), carries none to use.
        """
        indices = self._indices
        count = len(efforts)
        found = []
        for place in places:
            index = indices[place]
            if index >= count or not math.isfinite(value := efforts[index]):
                return None
            found.append(value)
        return found
