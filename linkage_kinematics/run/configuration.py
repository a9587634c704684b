# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The validation of the node's parameter values into a RunConfiguration.

Pure functions of parameter values (name → value), no ROS: ``build_configuration`` checks
every value against its spec (``parameter_values.parameter_value``) and then what they imply
together (the geometry, distinct joint names, the motion), raising ConfigurationError naming
the first bad parameter; the node, the demo and the tests all validate through it.
docs/parameters.md documents each parameter.

A ``RunConfiguration`` holds the values in the groups ``parameter_specs`` declares them in, one
frozen dataclass each: ``geometry``, ``motion`` (with the pass it implies), ``outputs``,
``logging`` (with cpu_affinity, as its group has it), ``joints`` (the source, its driver, the
lab's joints), ``measured`` and ``loops``; and ``autostart``. The command relay's values
(``build_relay_configuration``) are a ``RelayConfiguration``: the same ``loops``, ``measured``
and ``logging`` groups, built by the same functions, and its ``commands``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
import math
from pathlib import Path
from typing import Any

from linkage_kinematics.kinematics.drive import DriveError, DriveLaw
from linkage_kinematics.kinematics.geometry import (
    DIMENSIONS,
    FourBar,
    GeometryError,
    preset,
    TWO_PI,
    UnreachableError,
)
from linkage_kinematics.kinematics.inversion import seen_from_rocker
from linkage_kinematics.kinematics.solver import continued_branch, DeadPointError, solve
from linkage_kinematics.model.joints import Driver, JointMap, JointMapping, Link
from linkage_kinematics.run.limits import MIN_PASS_DURATION
from linkage_kinematics.run.parameter_specs import (
    CommandInterface,
    EndBehavior,
    LoopsSource,
    MotionMode,
    NODE_NAME,
    RELAY_SPECS,
    SourceKind,
    SPECS,
)
from linkage_kinematics.run.parameter_values import ConfigurationError, parameter_value
import yaml

# A step count within this fraction of a step of a whole number ends exactly on the segment
# end, so 90° in 0.5° steps is 180 steps and not 180 plus a rounding-sized 181st.
_STEP_COUNT_TOLERANCE = 1e-9
# α − alpha_start within this of a whole number of turns is a whole-turn loop.
_WHOLE_TURN_TOLERANCE = 1e-9


@dataclass(frozen=True)
class Geometry:
    """The four-bar: its preset ('' for explicit dimensions) and the linkage."""

    preset: str
    linkage: FourBar
    # The linkage as its driver turns it: ``linkage``, or seen from C for the rocker.
    driven_linkage: FourBar


@dataclass(frozen=True)
class Motion:
    """
    The drive law's motion: branch, drive law, the pass and its pace, and what they imply.

    ``segment_end`` is where one pass of the motion ends: alpha_end, or ``blocked_at``, the
    first dead point the crank meets on its way there (change points do not stop it).
    ``segment_duration`` is the drive-law time of that pass (s), ``direction`` the sign of the
    crank's travel and ``step_count`` the number of fixed steps strictly before ``segment_end``;
    with ``source`` measured there is no pass, and these five are those of a motion that never
    starts (no dead point, duration 0).
    """

    drive: DriveLaw
    branch: int
    alpha_start: float
    alpha_end: float
    end_behavior: EndBehavior
    mode: MotionMode
    alpha_step: float
    rate_hz: float
    direction: int
    segment_end: float
    blocked_at: float | None
    segment_duration: float
    whole_turns: bool
    step_count: int

    @property
    def reverse_drive(self) -> DriveLaw:
        """
        Return the drive law of the motion played backwards.

        ω and all rates negated, accelerations unchanged.
        """
        return DriveLaw(-self.drive.omega0, -self.drive.k)


@dataclass(frozen=True)
class Outputs:
    """The marker rate, the frames the node publishes in, and the diagnostics' thresholds (rad)."""

    display_rate_hz: float
    frame_id: str
    frame_prefix: str
    min_transmission_angle: float
    dead_point_warning: float


@dataclass(frozen=True)
class Logging:
    """The bag (``log.*``), and the CPU the node's process and its bag writer run on."""

    enabled: bool
    folder: Path
    max_bag_size: int
    max_bag_duration: float
    cpu_affinity: int


@dataclass(frozen=True)
class Joints:
    """Where the motion comes from, the joint that drives it, the lab's joints, the URDF's."""

    source: SourceKind
    driver: Driver
    lab: JointMap
    publish_robot_description: bool


@dataclass(frozen=True)
class Measured:
    """How the measured source judges and filters its samples (``measured.*``)."""

    timeout: float
    max_jump: float
    acceleration_time_constant: float


@dataclass(frozen=True)
class Loops:
    """
    Which loops the measured source closes (``loops``), and how.

    With ``loops:=robot_description``: the measured joints (empty: the closure file's actuated
    ones, else those of the first message), each planar loop's assembly branch override (name,
    ±1), each group's assembly seeds (joint, value in rad or m), the URDF ('': from the topic),
    the closure file's text ('': none) and the output joints of the transmission (none: no
    efforts or commands through the loops).
    """

    source: LoopsSource
    measured_joints: tuple[str, ...]
    branches: tuple[tuple[str, int], ...]
    robot_description: str
    assemblies: tuple[tuple[str, float], ...] = ()
    robot_description_closures: str = ''
    output_joints: tuple[str, ...] = ()


@dataclass(frozen=True)
class Commands:
    """
    The relay's forward commands (``commands.*``).

    ``interface``: what ~/commands carries; ``joints``: its joints in order (output joints and
    joints passed through); ``controller_joints``: the actuators/commands message's joints in
    order (empty: the joints passed through, then each group's actuators).
    """

    interface: CommandInterface
    joints: tuple[str, ...]
    controller_joints: tuple[str, ...]


@dataclass(frozen=True)
class RelayConfiguration:
    """The command relay's validated parameters, by group (``build_relay_configuration``)."""

    loops: Loops
    commands: Commands
    measured: Measured
    logging: Logging


@dataclass(frozen=True)
class RunConfiguration:
    """Validated parameters plus the motion they imply, by group; replaced whole, never mutated."""

    geometry: Geometry
    motion: Motion
    outputs: Outputs
    logging: Logging
    joints: Joints
    measured: Measured
    loops: Loops
    autostart: bool

    def restarts_motion(self, other: RunConfiguration) -> bool:
        """
        Whether switching from ``other`` to this configuration changes the motion itself.

        The geometry or the motion (docs/parameters.md: run-time changes); a threshold, a rate
        of the display, the lab's joint names change what is reported or how, not where the
        crank is.
        The pass follows from these, and the read-only parameters never change at run time.
        """
        return (self.geometry.linkage != other.geometry.linkage
                or self.motion != other.motion)


# --- validation: pure functions from parameter values to a RunConfiguration ---------------


def _geometry(values: Mapping[str, Any]) -> tuple[str, FourBar]:
    preset_name = parameter_value(values, 'preset')
    if preset_name:
        try:
            preset(preset_name)
        except GeometryError as error:
            raise ConfigurationError('preset', str(error)) from None
    for name in DIMENSIONS:
        if values.get(name) is None:
            raise ConfigurationError(name, "has no value: with preset '' all five of "
                                     f"{', '.join(DIMENSIONS)} must be given")
    dimensions = {name: parameter_value(values, name) for name in DIMENSIONS}
    try:
        linkage = FourBar(**dimensions)
    except GeometryError as error:
        raise ConfigurationError(', '.join(DIMENSIONS), str(error)) from None
    return preset_name, linkage


def _joints(checked: Mapping[str, Any]) -> JointMap:
    """Return the joints' mapping from checked values, whose three names must differ."""
    joints = JointMap(**{
        link.value: JointMapping(*(checked[f'joints.{link.value}.{field}']
                                   for field in ('name', 'direction', 'offset')))
        for link in Link
    })
    names = joints.names(tuple(Link))
    if len(set(names)) < len(names):
        raise ConfigurationError(
            'joints.crank.name, joints.coupler.name, joints.rocker.name',
            f"the three joint names must differ, got {', '.join(names)}")
    return joints


def _loop_branches(entries: list[str]) -> tuple[tuple[str, int], ...]:
    """Return ``loops.branches`` as (constraint, ±1) pairs."""
    branches = []
    for entry in entries:
        name, _, value = entry.rpartition('=')
        if not name or value not in ('1', '-1', '+1'):
            raise ConfigurationError(
                'loops.branches', f'entry {entry!r} is not CONSTRAINT=1 or CONSTRAINT=-1')
        branches.append((name, int(value)))
    names = [name for name, _ in branches]
    if len(set(names)) < len(names):
        raise ConfigurationError('loops.branches', 'gives a constraint more than one branch')
    return tuple(branches)


def _loop_assemblies(entries: list[str]) -> tuple[tuple[str, float], ...]:
    """Return ``loops.assemblies`` as (joint, value) pairs."""
    assemblies = []
    for entry in entries:
        name, _, text = entry.rpartition('=')
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not name or not math.isfinite(value):
            raise ConfigurationError(
                'loops.assemblies', f'entry {entry!r} is not JOINT=VALUE (a finite number, rad '
                'or m)')
        assemblies.append((name, value))
    names = [name for name, _ in assemblies]
    if len(set(names)) < len(names):
        raise ConfigurationError('loops.assemblies', 'gives a joint more than one value')
    return tuple(assemblies)


def _check_loops(checked: Mapping[str, Any]) -> None:
    """Refuse loop settings that the chosen ``loops`` and ``source`` do not use."""
    if checked['loops'] is LoopsSource.ROBOT_DESCRIPTION:
        if checked['source'] is not SourceKind.MEASURED:
            raise ConfigurationError(
                'loops', 'robot_description closes the loops of measured joints: it needs '
                f"source measured, got source {checked['source'].value}")
        return
    for name in ('loops.measured_joints', 'loops.branches', 'loops.assemblies',
                 'loops.output_joints', 'robot_description_closures'):
        if checked[name]:
            raise ConfigurationError(
                name, 'is used only with loops robot_description (and source measured), got '
                f"loops {checked['loops']}")


def _motion(
    linkage: FourBar, drive: DriveLaw, branch: int, alpha_start: float, alpha_end: float
) -> tuple[float | None, float]:
    """Check the start and the end of one pass; return (blocked_at, pass duration in s)."""
    try:
        linkage.reachability.require(alpha_start)
        solve(linkage, alpha_start, drive, branch)
    except (UnreachableError, DeadPointError) as error:
        raise ConfigurationError('alpha_start', str(error)) from None
    if drive.angular_velocity(alpha_start) == 0.0:
        raise ConfigurationError(
            'omega0', 'the crank is at rest at alpha_start (omega0 + k·alpha_start = 0 rad/s)'
        )
    if alpha_end == alpha_start:
        raise ConfigurationError('alpha_end', 'equals alpha_start, so a pass would be empty')
    try:
        drive.time_to(alpha_start, alpha_end)
    except DriveError as error:
        raise ConfigurationError('alpha_end', str(error)) from None
    # Change points do not stop the crank: it goes through them on its smooth branch.
    blocked_at = linkage.reachability.first_dead_point(alpha_start, alpha_end)
    if blocked_at is None:
        try:
            solve(linkage, alpha_end, drive,
                  continued_branch(linkage, alpha_start, branch, alpha_end))
        except DeadPointError:
            blocked_at = alpha_end
    segment_end = alpha_end if blocked_at is None else blocked_at
    duration = drive.time_to(alpha_start, segment_end)
    if duration < MIN_PASS_DURATION:
        raise ConfigurationError(
            'alpha_end',
            f'a pass from alpha_start to {math.degrees(segment_end):.6g}° would last only '
            f'{duration:.3g} s under this drive law; it must last at least '
            f'{MIN_PASS_DURATION:g} s',
        )
    return blocked_at, duration


def _pass(
    checked: Mapping[str, Any], linkage: FourBar, drive: DriveLaw
) -> tuple[float | None, float, float, int]:
    """
    Return the drive law's pass: (blocked_at, duration in s, segment_end, step_count).

    With ``source`` measured there is no pass: the drive-law parameters are not used, so not
    checked against the geometry.
    """
    alpha_start, alpha_end = checked['alpha_start'], checked['alpha_end']
    if checked['source'] is SourceKind.MEASURED:
        return None, 0.0, alpha_end, 1
    if checked['driver'] is not Driver.CRANK:
        raise ConfigurationError(
            'driver', 'the drive law turns the crank: driver rocker needs source measured')
    blocked_at, duration = _motion(linkage, drive, checked['branch'], alpha_start, alpha_end)
    segment_end = alpha_end if blocked_at is None else blocked_at
    travel = abs(segment_end - alpha_start)
    steps = travel / checked['alpha_step']
    if not math.isfinite(steps):
        raise ConfigurationError('alpha_step', f'is too small for a pass of {travel!r} rad')
    return blocked_at, duration, segment_end, max(1, math.ceil(steps - _STEP_COUNT_TOLERANCE))


def build_configuration(values: Mapping[str, Any]) -> RunConfiguration:
    """
    Validate parameter values (name → value) into a RunConfiguration.

    Raises ConfigurationError naming the first offending parameter: the geometry first, then
    each value on its own in the order the node declares them, then what they imply together.
    Integers are accepted for real-valued parameters; anything else of the wrong type is
    rejected.
    """
    preset_name, linkage = _geometry(values)
    checked = {name: parameter_value(values, name) for name in SPECS}
    joints = _joints(checked)
    _check_loops(checked)
    drive = DriveLaw(checked['omega0'], checked['k'])
    blocked_at, segment_duration, segment_end, step_count = _pass(checked, linkage, drive)
    alpha_start, alpha_end = checked['alpha_start'], checked['alpha_end']
    driver = checked['driver']
    return RunConfiguration(
        geometry=Geometry(
            preset=preset_name,
            linkage=linkage,
            driven_linkage=linkage if driver is Driver.CRANK else seen_from_rocker(linkage),
        ),
        motion=Motion(
            drive=drive,
            branch=checked['branch'],
            alpha_start=alpha_start,
            alpha_end=alpha_end,
            end_behavior=checked['end_behavior'],
            mode=checked['mode'],
            alpha_step=checked['alpha_step'],
            rate_hz=checked['rate_hz'],
            direction=1 if segment_end > alpha_start else -1,
            segment_end=segment_end,
            blocked_at=blocked_at,
            segment_duration=segment_duration,
            whole_turns=(
                blocked_at is None
                and abs(math.remainder(alpha_end - alpha_start, TWO_PI)) <= _WHOLE_TURN_TOLERANCE
            ),
            step_count=step_count,
        ),
        outputs=Outputs(
            display_rate_hz=checked['display_rate_hz'],
            frame_id=checked['frame_id'],
            frame_prefix=checked['frame_prefix'],
            min_transmission_angle=checked['diagnostics.min_transmission_angle'],
            dead_point_warning=checked['diagnostics.dead_point_warning'],
        ),
        logging=_logging(checked),
        joints=Joints(
            source=checked['source'],
            driver=driver,
            lab=joints,
            publish_robot_description=checked['publish_robot_description'],
        ),
        measured=_measured(checked),
        loops=_loops(checked),
        autostart=checked['autostart'],
    )


def _logging(checked: Mapping[str, Any]) -> Logging:
    return Logging(
        enabled=checked['log.enabled'],
        folder=Path(checked['log.folder']),
        max_bag_size=checked['log.max_bag_size'],
        max_bag_duration=checked['log.max_bag_duration'],
        cpu_affinity=checked['cpu_affinity'],
    )


def _measured(checked: Mapping[str, Any]) -> Measured:
    return Measured(
        timeout=checked['measured.timeout'],
        max_jump=checked['measured.max_jump'],
        # the relay has no acceleration estimate
        acceleration_time_constant=checked.get('measured.acceleration_time_constant', 0.0),
    )


def _loops(checked: Mapping[str, Any]) -> Loops:
    return Loops(
        # the relay always closes a description's loops
        source=checked.get('loops', LoopsSource.ROBOT_DESCRIPTION),
        measured_joints=tuple(checked['loops.measured_joints']),
        branches=_loop_branches(checked['loops.branches']),
        robot_description=checked['robot_description'],
        assemblies=_loop_assemblies(checked['loops.assemblies']),
        robot_description_closures=checked['robot_description_closures'],
        output_joints=tuple(checked['loops.output_joints']),
    )


def build_relay_configuration(values: Mapping[str, Any]) -> RelayConfiguration:
    """
    Validate the command relay's parameter values (name → value) into a RelayConfiguration.

    Each value on its own (``RELAY_SPECS``, in declaration order), then what the relay needs:
    output joints to write commands in, and ``commands.joints`` among them or outside the
    loops (checked against the description when it is read). ConfigurationError names the first
    bad parameter.
    """
    checked = {name: parameter_value(values, name, RELAY_SPECS) for name in RELAY_SPECS}
    if not checked['loops.output_joints']:
        raise ConfigurationError('loops.output_joints', 'the command relay needs the output '
                                 "joints commands are written in (each closure group's, as "
                                 'many as its degrees of freedom)')
    return RelayConfiguration(
        loops=_loops(checked),
        commands=Commands(
            interface=checked['commands.interface_name'],
            joints=tuple(checked['commands.joints'] or checked['loops.output_joints']),
            controller_joints=tuple(checked['commands.controller_joints']),
        ),
        measured=_measured(checked),
        logging=_logging(checked),
    )


def mechanism_entries(parameters_file: str | Path) -> dict[str, dict[str, Any]]:
    """
    Return the ``/<namespace>/linkage_node`` entries of a parameters file: namespace → parameters.

    In file order: one mechanism each (launch/mechanisms.launch.py). ValueError names a bad entry.
    """
    path = Path(parameters_file)
    try:
        entries = yaml.safe_load(path.read_text(encoding='utf-8'))
    except (OSError, yaml.YAMLError) as error:
        raise ValueError(f'cannot read parameters file {path}: {error}') from None
    if not isinstance(entries, dict) or not entries:
        raise ValueError(f'{path} has no /<namespace>/{NODE_NAME} entries')
    mechanisms = {}
    for key, entry in entries.items():
        namespace, _, name = str(key).rpartition('/')
        if name != NODE_NAME or not namespace.startswith('/') or '*' in namespace:
            raise ValueError(f'{path}: entry {key!r} is not /<namespace>/{NODE_NAME}')
        parameters = entry.get('ros__parameters') if isinstance(entry, dict) else None
        if not isinstance(parameters, dict):
            raise ValueError(f'{path}: entry {key!r} has no ros__parameters mapping')
        mechanisms[namespace] = parameters
    return mechanisms
