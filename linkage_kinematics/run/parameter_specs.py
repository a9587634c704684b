# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The node's parameters as declared: each one's name, default, descriptor text and contract.

Pure, no ROS: one small function per group of parameters (geometry, motion, outputs, logging,
measured input and joints), in the order the node declares them. Each spec says what a value
must be (its kind, unit, range, the choices of a closed set) once: ``configuration`` checks
values against it and ``ros.parameters`` turns it into the ROS descriptor. The closed sets of
values (``EndBehavior``, ``MotionMode``, ``SourceKind``, ``LoopsSource``, ``CommandInterface``)
are defined here, with the parameters they are the values of, so that ``configuration`` imports
this module and not the other way round.

The command relay (``linkage_command_node``) declares ``relay_parameter_specs``: the loops
node's robot description, closure file and ``loops.*`` settings (the same specs, their texts
without "with loops robot_description"), its logging and measured-pose thresholds, and its own
``commands.*``.
"""

from __future__ import annotations

from collections.abc import Collection, Iterable, Mapping
from dataclasses import dataclass, replace
import difflib
from enum import Enum, StrEnum
import math
from typing import Any, NamedTuple

from linkage_kinematics.kinematics.geometry import DIMENSIONS, LINK_LENGTHS, preset, TWO_PI
from linkage_kinematics.model.joints import DEFAULT_JOINT_NAMES, Driver, Link
from linkage_kinematics.model.urdf import DEFAULT_FRAME_ID
from linkage_kinematics.run.limits import (
    MAX_ANGLE,
    MAX_BAG_DURATION,
    MAX_BAG_SIZE,
    MAX_CPU,
    MAX_DISPLAY_RATE_HZ,
    MAX_DRIVE_GAIN,
    MAX_OMEGA0,
    MAX_PARAMETER_LENGTH,
    MAX_RATE_HZ,
    MAX_TIME_CONSTANT,
    MAX_TIMEOUT,
    NO_CPU_AFFINITY,
)
from linkage_kinematics.shared.rosbag2_split import MIN_SPLIT_SIZE, NO_SPLIT

NODE_NAME = 'linkage_node'
RELAY_NODE_NAME = 'linkage_command_node'


class EndBehavior(StrEnum):
    """What the crank does at the end of a pass: parameter ``end_behavior``, by its value."""

    STOP = 'stop'
    LOOP = 'loop'
    BOUNCE = 'bounce'


class MotionMode(StrEnum):
    """When the node computes and publishes a state: parameter ``mode``, by its value."""

    REAL_TIME = 'real_time'
    FIXED_STEP = 'fixed_step'


class SourceKind(StrEnum):
    """Where the driver's motion comes from: parameter ``source``, by its value."""

    DRIVE_LAW = 'drive_law'  # a timer and the drive law ω = omega0 + k·α (the paper's run)
    MEASURED = 'measured'  # the driver joint of each measured_joint_states message


class LoopsSource(StrEnum):
    """Which loops the measured source closes: parameter ``loops``, by its value."""

    PARAMETERS = 'parameters'  # the node's own four-bar, from the geometry parameters
    ROBOT_DESCRIPTION = 'robot_description'  # every loop of a lab's URDF (and closure file)


class CommandInterface(StrEnum):
    """
    What the relay's forward commands carry: ``commands.interface_name``, by its value.

    forward_command_controller's ``interface_name``: the command interface of every joint.
    """

    POSITION = 'position'
    VELOCITY = 'velocity'
    EFFORT = 'effort'


class Kind(Enum):
    """What a parameter's values are, and so how ``configuration`` checks one."""

    REAL = 'real'  # a finite number in ``interval`` (a whole number is taken as that real)
    INTEGER = 'integer'  # an integer in ``interval``, or ``off``
    SIGN = 'sign'  # the integer 1 or -1
    FLAG = 'flag'  # true or false
    TEXT = 'text'  # a string, empty only where ``allow_empty``
    CHOICE = 'choice'  # a string, one of the values of the enum ``choices``
    TEXTS = 'texts'  # a list of non-empty strings, possibly empty


@dataclass(frozen=True)
class Interval:
    """The values of a numeric parameter: [low, high], or (low, high] where ``open_low``."""

    low: float
    high: float
    open_low: bool = False

    def __contains__(self, value: float) -> bool:
        """Whether ``value`` lies in the interval."""
        above_low = self.low < value if self.open_low else self.low <= value
        return above_low and value <= self.high


class Off(NamedTuple):
    """An integer parameter's value outside its interval that turns its feature off."""

    value: int
    meaning: str  # what the value does, e.g. 'no split'


@dataclass(frozen=True)
class ParameterSpec:
    """
    One node parameter: its default (None: no default), descriptor text and contract.

    ``kind`` says which of the other fields apply: ``unit`` and ``interval`` to numbers, ``off``
    and ``noun`` (what a value in the interval is, for messages) to integers, ``allow_empty``
    to text, ``choices`` to choices.
    """

    name: str
    default: Any
    description: str
    kind: Kind
    read_only: bool = False
    unit: str = ''
    interval: Interval | None = None
    off: Off | None = None
    noun: str = ''
    allow_empty: bool = False
    choices: type[StrEnum] | None = None

    def __post_init__(self) -> None:
        """Refuse a spec without the fields its kind needs (at import, so no check lacks them)."""
        needs = {Kind.REAL: ('interval', 'unit'), Kind.INTEGER: ('interval', 'off', 'noun'),
                 Kind.CHOICE: ('choices',)}.get(self.kind, ())
        missing = [field for field in needs if not getattr(self, field)]
        if missing:
            raise TypeError(f"{self.kind.value} parameter {self.name} needs {', '.join(missing)}")

    @property
    def floating_range(self) -> tuple[float, float] | None:
        """Return the descriptor's floating-point range (from, to), None if not a real."""
        if self.kind is not Kind.REAL:
            return None
        return self.interval.low, self.interval.high

    @property
    def integer_range(self) -> tuple[int, int, int] | None:
        """Return the descriptor's integer range (from, to, step), None if not an integer."""
        if self.kind is Kind.SIGN:
            return -1, 1, 2
        if self.kind is not Kind.INTEGER:
            return None
        # A descriptor holds one range: from the off value, which lies below the interval.
        return self.off.value, int(self.interval.high), 1


_DIMENSION_TEXTS = {
    'crank_length': 'disk radius OA, greater than 0',
    'coupler_length': 'coupler length AB, greater than 0',
    'rocker_length': 'rocker length BC, greater than 0',
    'ground_x': 'x of the fixed pivot C relative to O',
    'ground_y': 'y of the fixed pivot C relative to O',
}


def _geometry_specs(preset_name: str) -> tuple[ParameterSpec, ...]:
    """Return the preset and the five dimensions, which default to the preset's."""
    geometry = preset(preset_name).geometry if preset_name else None
    return (
        ParameterSpec(
            'preset', 'paper',
            "mechanism whose dimensions are the geometry parameters' defaults: "
            "paper, paper_full_turn, grashof_crank_rocker, or '' for none",
            Kind.TEXT, read_only=True, allow_empty=True,
        ),
        *(
            ParameterSpec(
                name,
                getattr(geometry, name) if geometry is not None else None,
                f"{_DIMENSION_TEXTS[name]} (m); defaults to the preset's value, required when "
                "preset is ''",
                Kind.REAL, unit='m',
                interval=(Interval(0.0, MAX_PARAMETER_LENGTH, open_low=True)
                          if name in LINK_LENGTHS
                          else Interval(-MAX_PARAMETER_LENGTH, MAX_PARAMETER_LENGTH)),
            )
            for name in DIMENSIONS
        ),
    )


def _motion_specs() -> tuple[ParameterSpec, ...]:
    """Return the assembly branch, the drive law, the pass and how it is stepped."""
    return (
        ParameterSpec('branch', 1,
                      'assembly at alpha_start: +1 (B left of A→C) or −1; through change points '
                      'the motion continues on its smooth branch',
                      Kind.SIGN),
        ParameterSpec('omega0', 2.0, 'drive law ω = omega0 + k·α: omega0 (rad/s)',
                      Kind.REAL, unit='rad/s', interval=Interval(-MAX_OMEGA0, MAX_OMEGA0)),
        ParameterSpec('k', 0.0, 'drive law ω = omega0 + k·α: k (1/s)',
                      Kind.REAL, unit='1/s', interval=Interval(-MAX_DRIVE_GAIN, MAX_DRIVE_GAIN)),
        ParameterSpec('alpha_start', 0.0, 'crank angle where the motion starts (rad)',
                      Kind.REAL, unit='rad', interval=Interval(-MAX_ANGLE, MAX_ANGLE)),
        ParameterSpec('alpha_end', math.pi / 2.0,
                      'crank angle where one pass ends (rad), not alpha_start',
                      Kind.REAL, unit='rad', interval=Interval(-MAX_ANGLE, MAX_ANGLE)),
        # A node runs until it is stopped, as every ROS node does: by default the crank swings
        # to and fro over its pass, which suits the paper's mechanism (it cannot turn fully).
        ParameterSpec('end_behavior', EndBehavior.BOUNCE.value,
                      'at the end of a pass: stop (and exit), loop or bounce',
                      Kind.CHOICE, choices=EndBehavior),
        ParameterSpec('mode', MotionMode.REAL_TIME.value,
                      'real_time: α from node-clock time at rate_hz; fixed_step: steps of '
                      'alpha_step, each published when the drive law reaches it',
                      Kind.CHOICE, choices=MotionMode),
        ParameterSpec('alpha_step', math.radians(0.5),
                      'crank step in fixed_step mode (rad), greater than 0',
                      Kind.REAL, unit='rad', interval=Interval(0.0, TWO_PI, open_low=True)),
        ParameterSpec('rate_hz', 100.0,
                      'state compute and publish rate in real_time mode (Hz), greater than 0; '
                      'unused in fixed_step mode',
                      Kind.REAL, unit='Hz', interval=Interval(0.0, MAX_RATE_HZ, open_low=True)),
    )


def _output_specs() -> tuple[ParameterSpec, ...]:
    """Return the marker rate, the frames published in, and the diagnostics' thresholds."""
    return (
        ParameterSpec('display_rate_hz', 30.0,
                      'publish rate of linkage/markers (Hz), greater than 0',
                      Kind.REAL, unit='Hz',
                      interval=Interval(0.0, MAX_DISPLAY_RATE_HZ, open_low=True)),
        ParameterSpec('frame_id', DEFAULT_FRAME_ID,
                      'frame of the markers and linkage/state, root link of the URDF',
                      Kind.TEXT, read_only=True),
        ParameterSpec('frame_prefix', '',
                      "prefix of every frame id the node publishes (robot_state_publisher's "
                      "frame_prefix, e.g. 'left/'); the URDF stays unprefixed",
                      Kind.TEXT, read_only=True, allow_empty=True),
        ParameterSpec('diagnostics.min_transmission_angle', math.radians(10.0),
                      'WARN when min(μ, π − μ) of the transmission angle μ is below this (rad)',
                      Kind.REAL, unit='rad', interval=Interval(0.0, math.pi / 2.0)),
        ParameterSpec('diagnostics.dead_point_warning', math.radians(1.0),
                      'WARN when the crank is closer than this to a dead point or a change '
                      'point (rad)',
                      Kind.REAL, unit='rad', interval=Interval(0.0, math.pi)),
    )


def _logging_specs() -> tuple[ParameterSpec, ...]:
    """Return the bag's parameters and where the node's process and its bag writer run."""
    return (
        ParameterSpec('log.enabled', True, 'record every published message to a bag',
                      Kind.FLAG, read_only=True),
        ParameterSpec('log.folder', 'bags',
                      'folder that receives a new bag per run (relative to the working '
                      'directory)', Kind.TEXT, read_only=True),
        ParameterSpec('log.max_bag_size', NO_SPLIT,
                      "bytes after which the bag goes on in a new file (rosbag2's "
                      f'--max-bag-size); 0 never splits, else at least {MIN_SPLIT_SIZE}',
                      Kind.INTEGER, read_only=True, unit='bytes',
                      interval=Interval(MIN_SPLIT_SIZE, MAX_BAG_SIZE),
                      off=Off(NO_SPLIT, 'no split'), noun='size'),
        ParameterSpec('log.max_bag_duration', float(NO_SPLIT),
                      "seconds after which the bag goes on in a new file (rosbag2's "
                      '--max-bag-duration, here also a fraction); 0 never splits',
                      Kind.REAL, read_only=True, unit='s',
                      interval=Interval(0.0, MAX_BAG_DURATION)),
        ParameterSpec('cpu_affinity', NO_CPU_AFFINITY,
                      "CPU that every thread of the node's process runs on, its bag writer "
                      "process on the others (as ros2_control's cpu_affinity); -1 leaves "
                      'both to the operating system',
                      Kind.INTEGER, interval=Interval(0, MAX_CPU),
                      off=Off(NO_CPU_AFFINITY, 'no pinning'), noun='CPU number'),
    )


def _joint_specs() -> tuple[ParameterSpec, ...]:
    """Return the source, its driver joint, and each joint's lab name, direction and offset."""
    return (
        ParameterSpec('source', SourceKind.DRIVE_LAW.value,
                      'drive_law: a timer turns the crank under the drive law; measured: the '
                      'driver joint of each message on measured_joint_states',
                      Kind.CHOICE, read_only=True, choices=SourceKind),
        ParameterSpec('driver', Driver.CRANK.value,
                      'joint that moves the linkage: crank (at O) or rocker (at C, '
                      'source measured only)',
                      Kind.CHOICE, read_only=True, choices=Driver),
        *(
            spec
            for link in Link
            for spec in (
                ParameterSpec(f'joints.{link.value}.name', DEFAULT_JOINT_NAMES[link],
                              f'name of the {link.value} joint in joint_states and the URDF',
                              Kind.TEXT),
                ParameterSpec(f'joints.{link.value}.direction', 1,
                              f'+1 or -1: lab value of the {link.value} joint = direction · '
                              'node value + offset', Kind.SIGN),
                ParameterSpec(f'joints.{link.value}.offset', 0.0,
                              f'offset of the {link.value} joint (rad): lab value = '
                              'direction · node value + offset',
                              Kind.REAL, unit='rad', interval=Interval(-MAX_ANGLE, MAX_ANGLE)),
            )
        ),
        ParameterSpec('publish_robot_description', True,
                      "publish the node's URDF on robot_description (false where the lab's "
                      'robot_state_publisher has its own)', Kind.FLAG, read_only=True),
    )


def _measured_specs() -> tuple[ParameterSpec, ...]:
    """Return how the measured source judges and filters its samples."""
    return (
        ParameterSpec('measured.timeout', 1.0,
                      'diagnostics ERROR after this long without a valid measured sample (s), '
                      'greater than 0',
                      Kind.REAL, unit='s', interval=Interval(0.0, MAX_TIMEOUT, open_low=True)),
        ParameterSpec('measured.max_jump', math.pi / 2.0,
                      'a measured driver angle further than this from the last one used is '
                      'dropped (rad, greater than 0; π drops none)',
                      Kind.REAL, unit='rad', interval=Interval(0.0, math.pi, open_low=True)),
        ParameterSpec('measured.acceleration_time_constant', 0.02,
                      "time constant of the low-pass filter on the driver's angular "
                      'acceleration estimate (s); 0 for the raw difference of velocities',
                      Kind.REAL, unit='s', interval=Interval(0.0, MAX_TIME_CONSTANT)),
    )


# How the loops node's specs of a robot's loops begin; the relay's texts are without it.
LOOPS_ONLY = 'with loops robot_description: '


def _loop_specs() -> tuple[ParameterSpec, ...]:
    """Return which loops the measured source closes, and how (docs/following_loops.md)."""
    return (
        ParameterSpec('loops', LoopsSource.PARAMETERS.value,
                      'parameters: the four-bar of the geometry parameters; robot_description: '
                      "every loop closure of the robot's URDF and closure file (source measured "
                      'only)',
                      Kind.CHOICE, read_only=True, choices=LoopsSource),
        ParameterSpec('loops.measured_joints', [],
                      LOOPS_ONLY + 'the measured joints; empty: the closure '
                      "file's actuated joints (name_mot), else the loop joints the first "
                      'measured_joint_states message carries',
                      Kind.TEXTS, read_only=True),
        ParameterSpec('loops.branches', [],
                      LOOPS_ONLY + 'CONSTRAINT=1 or CONSTRAINT=-1, the assembly '
                      "branch of that planar loop; by default the zero pose's",
                      Kind.TEXTS, read_only=True),
        ParameterSpec('loops.assemblies', [],
                      LOOPS_ONLY + 'JOINT=VALUE (rad or m), a start value of a '
                      'joint a closure group solves, assembling its group nearer another '
                      'assembly; by default the one nearest the zero pose',
                      Kind.TEXTS, read_only=True),
        ParameterSpec('loops.output_joints', [],
                      LOOPS_ONLY + "each closure group's independent joints as "
                      "the lab's controllers see them (as many as the group's degrees of freedom, "
                      'none measured), whose efforts and commands the transmission gives; empty: '
                      'none',
                      Kind.TEXTS, read_only=True),
        ParameterSpec('robot_description', '',
                      LOOPS_ONLY + "the robot's URDF (as robot_state_publisher's "
                      "parameter); '': from the robot_description topic",
                      Kind.TEXT, read_only=True, allow_empty=True),
        ParameterSpec('robot_description_closures', '',
                      LOOPS_ONLY + "the text of the URDF's closure file "
                      "(toolbox-parallel-robots' YAML: closed_loop, type, name_mot, joint_name, "
                      "joint_type), for every description; '': none",
                      Kind.TEXT, read_only=True, allow_empty=True),
    )


def parameter_specs(preset_name: str) -> tuple[ParameterSpec, ...]:
    """All parameters; the geometry defaults come from ``preset_name`` ('' → no defaults)."""
    return (
        *_geometry_specs(preset_name),
        *_motion_specs(),
        *_output_specs(),
        *_logging_specs(),
        *_joint_specs(),
        *_measured_specs(),
        *_loop_specs(),
        ParameterSpec('autostart', True,
                      'start the motion at once; false: publish the scene at alpha_start, the '
                      'URDF and the status, then wait for ~/resume',
                      Kind.FLAG, read_only=True),
    )


# Every parameter's spec by name, in declaration order: the contract values are checked against
# (the geometry's defaults, which depend on the preset, are not part of it).
SPECS = {spec.name: spec for spec in parameter_specs('')}
PARAMETER_NAMES = tuple(SPECS)
REAL_PARAMETERS = frozenset(name for name, spec in SPECS.items() if spec.kind is Kind.REAL)


def _command_specs() -> tuple[ParameterSpec, ...]:
    """Return the relay's forward commands: their interface and joint orders each side."""
    return (
        ParameterSpec('commands.interface_name', CommandInterface.POSITION.value,
                      "what ~/commands carries, as the actuators' forward_command_controller's "
                      'interface_name: position, velocity or effort (velocity and effort at the '
                      'pose measured on measured_joint_states)',
                      Kind.CHOICE, read_only=True, choices=CommandInterface),
        ParameterSpec('commands.joints', [],
                      'the joints of each ~/commands message, in order: output joints (every '
                      'output joint of a group commanded) and joints outside the loops, passed '
                      'through; empty: loops.output_joints',
                      Kind.TEXTS, read_only=True),
        ParameterSpec('commands.controller_joints', [],
                      "the joints of each actuators/commands message, in order: the actuators' "
                      "forward_command_controller's joints parameter (the groups' actuators and "
                      'the joints passed through); empty: the joints passed through, then each '
                      "group's actuators",
                      Kind.TEXTS, read_only=True),
    )


def relay_parameter_specs() -> tuple[ParameterSpec, ...]:
    """
    Return the command relay's parameters, in the order it declares them, every one read-only.

    The loops node's specs where the relay reads the same setting (each contract defined once,
    only the text changed where the relay reads it otherwise), then its own.
    """
    texts = {
        'loops.measured_joints': "the actuators (the loops node's measured joints); empty: the "
                                 "closure file's actuated joints (name_mot)",
        'measured.timeout': 'velocity and effort commands are refused when the pose measured on '
                            'measured_joint_states is older than this (s), greater than 0',
        'measured.max_jump': 'a measured revolute actuator further than this from the last '
                             'sample used is dropped (rad, greater than 0; π drops none)',
        'log.enabled': 'record every message received and published to a bag',
    }
    by_name = {spec.name: spec for spec in parameter_specs('')}
    # read-only all: the relay reads its settings once, at start (the loops node changes its
    # measured.* and cpu_affinity while it runs; a set that the relay ignored would mislead)
    shared = [replace(by_name[name], read_only=True, description=texts.get(
        name, by_name[name].description.removeprefix(LOOPS_ONLY))) for name in _RELAY_SHARED]
    commands = _command_specs()
    return (*shared[:_RELAY_LOOPS], *commands, *shared[_RELAY_LOOPS:])


# The loops node's parameters the relay reads too, in the relay's order: its robot and loops
# (the first _RELAY_LOOPS), then after its own commands.* the measured pose and the log.
_RELAY_SHARED = ('robot_description', 'robot_description_closures', 'loops.measured_joints',
                 'loops.output_joints', 'loops.branches', 'loops.assemblies',
                 'measured.timeout', 'measured.max_jump', 'log.enabled', 'log.folder',
                 'log.max_bag_size', 'log.max_bag_duration', 'cpu_affinity')
_RELAY_LOOPS = 6
RELAY_SPECS = {spec.name: spec for spec in relay_parameter_specs()}


def unknown_parameters(given: Iterable[str], declared: Collection[str],
                       node_name: str = NODE_NAME,
                       specs: Mapping[str, ParameterSpec] = SPECS) -> list[str]:
    """
    Return one warning per parameter in ``given`` that is not in ``declared``, sorted by name.

    Each names the parameter and the closest of the node's own parameters (``specs``), if one
    is close (``rate`` → ``rate_hz``).
    """
    warnings = []
    for name in sorted(set(given) - set(declared)):
        closest = difflib.get_close_matches(name, tuple(specs), n=1)
        hint = f"; did you mean '{closest[0]}'?" if closest else ''
        warnings.append(f"unknown parameter '{name}' ignored: {node_name} has no such "
                        f'parameter{hint}')
    return warnings
