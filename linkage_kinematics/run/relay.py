# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The command relay's conversions, without ROS (``linkage_command_node``, issue 30).

A ``Relay`` holds a robot's command direction (``robot_command.plan_command``, built from the
description by ``relay_for``) and the ``commands.*`` settings, and turns what a planner or a
controller writes in the output joints into what the actuators' ros2_control controllers take:

* ``trajectory``: a ``JointTrajectory``'s joint names and points (``RobotCommand.trajectory``:
  joints outside the loops passed through, every point converted, refused whole naming the
  first point refused);
* ``forward``: one ``Float64MultiArray``'s values in ``commands.joints`` order, as the
  forward_command_controller's ``interface_name`` says (position; velocity or effort at the
  pose last measured, ``MeasuredPose``), out in ``commands.controller_joints`` order.

A refusal is a ``CommandRefused`` (the conversion's reasons) or a ``RelayRefused`` (the relay's
own: bytes that are no such message, no description yet, no measured pose within
``measured.timeout``); either way nothing of the message is relayed and the groups stay at their
last accepted point. Settings that do not fit the description are a ``RelayError``, one line;
``read_relay`` reads a description's text into its relay, or raises one of ``RELAY_ERRORS``,
one line naming the problem.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
import enum

from linkage_kinematics.loops.closures import ClosureError
from linkage_kinematics.loops.command import CommandRefusal, CommandRefused, getter, JointPoint
from linkage_kinematics.loops.description import LoopError
from linkage_kinematics.loops.follower import LoopSample, RobotLoopsFollower
from linkage_kinematics.loops.plan import read_loops, RobotLoops
from linkage_kinematics.loops.refusals import PlanError
from linkage_kinematics.loops.robot_command import plan_command, RobotCommand
from linkage_kinematics.loops.transmission import TransmissionError
from linkage_kinematics.model.urdf_reader import read_urdf, UrdfError
from linkage_kinematics.run.configuration import RelayConfiguration
from linkage_kinematics.run.parameter_specs import CommandInterface


class RelayRefusal(enum.Enum):
    """Why the relay refused a message, beyond the conversion's ``CommandRefusal``."""

    MALFORMED = 'its bytes are not such a message'
    NO_DESCRIPTION = 'no robot description is closed yet'
    NO_POSE = 'no pose measured on measured_joint_states within measured.timeout'


# every reason a message can be refused for, in the order diagnostics list them
REFUSALS: tuple[CommandRefusal | RelayRefusal, ...] = (*CommandRefusal, *RelayRefusal)


class RelayRefused(ValueError):
    """A message the relay refused for a ``RelayRefusal``; ``detail`` says what."""

    def __init__(self, reason: RelayRefusal, detail: str) -> None:
        super().__init__(f'{reason.value}: {detail}')
        self.reason = reason
        self.detail = detail


class RelayError(ValueError):
    """Relay settings that do not fit the robot; the message is one line naming the setting."""


# What reading a description into a relay may refuse, each with its one line.
RELAY_ERRORS = (UrdfError, ClosureError, LoopError, TransmissionError, PlanError, RelayError)


class MessageKind(enum.Enum):
    """What the relay relays: its two inputs, by their topics' names."""

    TRAJECTORY = 'joint_trajectory'
    COMMANDS = 'commands'


class MeasuredPose:
    """
    The output joints at the pose last measured on ``measured_joint_states``.

    The loops node's follower closes the loops from the measured actuators (the same plan);
    ``positions`` gives ``joints``' positions there (0 for a joint passed through: a velocity
    or effort command does not use it), or None when no sample closed within ``timeout`` s.
    """

    def __init__(self, follower: RobotLoopsFollower, joints: Sequence[str],
                 timeout: float) -> None:
        self.follower = follower
        self.timeout = timeout
        self._joints = tuple(joints)
        self._positions: tuple[float, ...] | None = None
        self.measured_ns: int | None = None  # node clock time of the last closed sample

    def take(self, stamp_ns: int, names: Sequence[str], positions: Sequence[float],
             velocities: Sequence[float], now_ns: int) -> bool:
        """Close the loops at one measured sample; whether it closed (else it is not used)."""
        sample = self.follower.follow(stamp_ns, names, positions, velocities)
        if not isinstance(sample, LoopSample):
            return False
        joints = sample.joints
        self._positions = tuple(joints.get(name, 0.0) for name in self._joints)
        self.measured_ns = now_ns
        return True

    def positions(self, now_ns: int) -> tuple[float, ...] | None:
        """Return the joints' positions at the last closed sample; None if there is none."""
        if self.measured_ns is None or (now_ns - self.measured_ns) * 1e-9 > self.timeout:
            return None
        return self._positions

    def age(self, now_ns: int) -> float | None:
        """Return the seconds since the last closed sample (None before one)."""
        return None if self.measured_ns is None else (now_ns - self.measured_ns) * 1e-9


@dataclass(frozen=True)
class GroupLine:
    """What one group relays: its name, output joints, actuators and how it is solved."""

    name: str
    outputs: tuple[str, ...]
    actuators: tuple[str, ...]
    solved_by: str

    def describe(self) -> str:
        """Return it in one line (the start's log, diagnostics)."""
        return (f'group {self.name}: {", ".join(self.outputs)} → {", ".join(self.actuators)} '
                f'({self.solved_by})')


class Relay:
    """
    A robot's commands relayed to its actuators' controllers (module docstring).

    ``command``: the robot's command direction; ``config``: the relay's settings
    (``commands.*``); ``pose``: the measured pose, which velocity and effort commands need.
    RelayError (one line) where ``commands.joints`` or ``commands.controller_joints`` do not
    fit the robot.
    """

    def __init__(self, command: RobotCommand, config: RelayConfiguration,
                 pose: MeasuredPose | None, robot_name: str = '') -> None:
        self.command = command
        self.robot_name = robot_name
        settings = config.commands
        self.interface = settings.interface
        self.joints = settings.joints
        self.pose = pose
        # how each group is solved: the kinds of the groups its outputs make, each once (the
        # ankle's two legs are one kind)
        self.groups = tuple(GroupLine(group.name, group.outputs, group.actuators,
                                      ', '.join(dict.fromkeys(kind.value
                                                              for kind in group.kinds)))
                            for group in command.groups)
        try:
            converted = command.names(settings.joints)
        except CommandRefused as error:
            raise RelayError(f'commands.joints {list(settings.joints)}: {error.detail}') from None
        order = settings.controller_joints or converted
        if sorted(order) != sorted(converted):
            raise RelayError(f'commands.controller_joints {list(order)}: not the joints '
                             f'commands.joints {list(settings.joints)} are relayed to, '
                             f'{list(converted)}, in some order')
        self.controller_joints = tuple(order)
        # the converted arrays in controller order: one C call per message
        self._order = getter([converted.index(name) for name in order])
        self._field = {CommandInterface.POSITION: 0, CommandInterface.VELOCITY: 1,
                       CommandInterface.EFFORT: 3}[self.interface]

    def forward(self, values: Sequence[float], now_ns: int) -> tuple[float, ...]:
        """
        Return one forward command's values for ``controller_joints``.

        ``values`` in ``joints`` order, of the interface ``interface``; ``now_ns`` judges the
        measured pose's age. CommandRefused or RelayRefused whole.
        """
        if len(values) != len(self.joints):
            raise CommandRefused(CommandRefusal.JOINTS, f'{len(values)} values for the '
                                 f'{len(self.joints)} joints of commands.joints')
        values = tuple(values)
        if self._field == 0:
            point = JointPoint(values)
        else:
            positions = None if self.pose is None else self.pose.positions(now_ns)
            if positions is None:
                raise RelayRefused(RelayRefusal.NO_POSE, f'{self.interface.value} commands '
                                   'are converted at the measured pose')
            point = (JointPoint(positions, values) if self._field == 1
                     else JointPoint(positions, (), (), values))
        converted = self.command.convert(self.joints, point)
        return self._order((converted.positions, converted.velocities, (),
                            converted.efforts)[self._field])

    def trajectory(self, names: Sequence[str], points: Sequence[JointPoint]
                   ) -> tuple[tuple[str, ...], tuple[JointPoint, ...]]:
        """
        Return a trajectory's joint names and points for the actuators' controller.

        The joints outside the loops passed through, then each commanded group's actuators;
        every point converted in order. CommandRefused whole, naming the first point refused.
        """
        return self.command.names(names), self.command.trajectory(names, points)


def relay_for(loops: RobotLoops, config: RelayConfiguration) -> Relay:
    """
    Return the relay of a robot description's loops under ``config``.

    The command direction planned as the loops node plans the loops (``plan_command``), the
    measured pose followed by the loops node's follower for velocity and effort commands.
    LoopError, TransmissionError, PlanError or RelayError, one line, where they do not fit.
    """
    settings = config.loops
    measured = settings.measured_joints or loops.actuated or ()
    if not measured:
        raise RelayError('loops.measured_joints: the relay needs the actuators, given here or '
                         "as the closure file's actuated joints (name_mot)")
    branches, assemblies = dict(settings.branches), dict(settings.assemblies)
    command = plan_command(loops, measured, settings.output_joints, branches, assemblies)
    pose = None
    if config.commands.interface is not CommandInterface.POSITION:
        pose = MeasuredPose(RobotLoopsFollower(loops, measured, branches,
                                               config.measured.max_jump, assemblies),
                            config.commands.joints, config.measured.timeout)
    return Relay(command, config, pose, loops.robot_name)


def read_relay(urdf: str, config: RelayConfiguration) -> Relay:
    """
    Return the relay of a description's text (and ``config``'s closure file).

    One of ``RELAY_ERRORS`` (one line) where the loops cannot be closed or the settings do not
    fit them.
    """
    loops = read_loops(read_urdf(urdf), config.loops.robot_description_closures or None)
    return relay_for(loops, config)
