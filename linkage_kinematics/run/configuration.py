# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The node's parameters: their limits, and the validation of their values into a RunConfiguration.

Pure functions of parameter values (name → value), no ROS: ``build_configuration`` checks every
value and the motion they imply and raises ConfigurationError naming the first bad parameter; the
node, the demo and the tests all validate through it. ``parameter_specs`` declares each parameter
(default, descriptor text, range) from these limits. README.md documents each parameter.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from enum import StrEnum
import math
from pathlib import Path
from typing import Any

from linkage_kinematics.kinematics.drive import DriveError, DriveLaw
from linkage_kinematics.kinematics.geometry import (
    DIMENSIONS,
    FourBar,
    GeometryError,
    GROUND_COORDINATES,
    LINK_LENGTHS,
    preset,
    TWO_PI,
    UnreachableError,
)
from linkage_kinematics.kinematics.inversion import seen_from_rocker
from linkage_kinematics.kinematics.solver import continued_branch, DeadPointError, solve
from linkage_kinematics.model.joints import Driver, JointMap, JointMapping, Link
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
    MIN_PASS_DURATION,
    MIN_SPLIT_SIZE,
    NO_CPU_AFFINITY,
    NO_SPLIT,
)
import yaml

NODE_NAME = 'linkage_node'

# A step count within this fraction of a step of a whole number ends exactly on the segment
# end, so 90° in 0.5° steps is 180 steps and not 180 plus a rounding-sized 181st.
_STEP_COUNT_TOLERANCE = 1e-9
# α − alpha_start within this of a whole number of turns is a whole-turn loop.
_WHOLE_TURN_TOLERANCE = 1e-9


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


# The fields whose change restarts the motion from alpha_start (README: Run-time changes); a
# field not named here (a threshold, a rate of the display, the lab's joint names) changes what
# is reported or how, not where the crank is. The rest of the motion (segment_end, blocked_at,
# ...) follows from these, and the read-only parameters never change at run time.
MOTION_FIELDS = ('linkage', 'drive', 'branch', 'alpha_start', 'alpha_end', 'end_behavior', 'mode',
                 'alpha_step', 'rate_hz')


class ConfigurationError(ValueError):
    """A parameter value (or a combination of them) the node cannot run with."""

    def __init__(self, parameter: str, reason: str) -> None:
        super().__init__(f'{parameter}: {reason}')
        self.parameter = parameter
        self.reason = reason


@dataclass(frozen=True)
class RunConfiguration:
    """
    Validated parameters plus the motion they imply; replaced as a whole, never mutated.

    ``segment_end`` is where one pass of the motion ends: alpha_end, or ``blocked_at``, the
    first dead point the crank meets on its way there (change points do not stop it).
    ``segment_duration`` is the drive-law time of that pass (s), ``direction`` the sign of the
    crank's travel and ``step_count`` the number of fixed steps strictly before ``segment_end``;
    with ``source`` measured there is no pass, and these five are those of a motion that never
    starts (no dead point, duration 0).
    """

    preset: str
    linkage: FourBar
    drive: DriveLaw
    branch: int
    alpha_start: float
    alpha_end: float
    end_behavior: EndBehavior
    mode: MotionMode
    alpha_step: float
    rate_hz: float
    display_rate_hz: float
    frame_id: str
    frame_prefix: str
    min_transmission_angle: float
    dead_point_warning: float
    log_enabled: bool
    log_folder: Path
    log_max_bag_size: int
    log_max_bag_duration: float
    cpu_affinity: int
    source: SourceKind
    driver: Driver
    # The linkage as its driver turns it: ``linkage``, or seen from C for the rocker.
    driven_linkage: FourBar
    joints: JointMap
    publish_robot_description: bool
    measured_timeout: float
    max_jump: float
    acceleration_time_constant: float
    autostart: bool
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

    def restarts_motion(self, other: RunConfiguration) -> bool:
        """Whether switching from ``other`` to this configuration changes the motion itself."""
        return any(getattr(self, name) != getattr(other, name) for name in MOTION_FIELDS)


# --- validation: pure functions from parameter values to a RunConfiguration ---------------


def describe_value(value: object) -> str:
    """Return a parameter value and its type, for error messages."""
    if value is None:
        return 'no value'
    return f'{type(value).__name__} {value!r}'


def _real(values: Mapping[str, Any], name: str) -> float:
    value = values.get(name)
    # bool is an int in Python but a different parameter type in ROS.
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ConfigurationError(name, f'must be a number, got {describe_value(value)}')
    value = float(value)
    if not math.isfinite(value):
        raise ConfigurationError(name, f'must be finite, got {value!r}')
    return value


def _positive(values: Mapping[str, Any], name: str, unit: str, upper: float = math.inf) -> float:
    value = _real(values, name)
    if not 0.0 < value <= upper:
        bound = f' and at most {upper:g} {unit}' if math.isfinite(upper) else ''
        raise ConfigurationError(name, f'must be greater than 0 {unit}{bound}, got {value!r}')
    return value


def _within(
    values: Mapping[str, Any], name: str, low: float, high: float, unit: str = 'rad'
) -> float:
    value = _real(values, name)
    if not low <= value <= high:
        raise ConfigurationError(name, f'must lie in [{low:g}, {high:g}] {unit}, got {value!r}')
    return value


def _text(
    values: Mapping[str, Any],
    name: str,
    choices: tuple[str, ...] | None = None,
    allow_empty: bool = False,
) -> str:
    value = values.get(name)
    if not isinstance(value, str):
        raise ConfigurationError(name, f'must be a string, got {describe_value(value)}')
    if choices is not None and value not in choices:
        raise ConfigurationError(name, f"must be one of {', '.join(choices)}; got {value!r}")
    if choices is None and not value and not allow_empty:
        raise ConfigurationError(name, 'must not be empty')
    return value


def _flag(values: Mapping[str, Any], name: str) -> bool:
    value = values.get(name)
    if not isinstance(value, bool):
        raise ConfigurationError(name, f'must be true or false, got {describe_value(value)}')
    return value


def _cpu(values: Mapping[str, Any]) -> int:
    value = values.get('cpu_affinity')
    if (isinstance(value, bool) or not isinstance(value, int)
            or not NO_CPU_AFFINITY <= value <= MAX_CPU):
        raise ConfigurationError(
            'cpu_affinity',
            f'must be {NO_CPU_AFFINITY} (no pinning) or a CPU number in [0, {MAX_CPU}], got '
            f'{describe_value(value)}',
        )
    return value


def _bag_size(values: Mapping[str, Any]) -> int:
    value = values.get('log.max_bag_size')
    if (isinstance(value, bool) or not isinstance(value, int)
            or not (value == NO_SPLIT or MIN_SPLIT_SIZE <= value <= MAX_BAG_SIZE)):
        raise ConfigurationError(
            'log.max_bag_size',
            f'must be {NO_SPLIT} (no split) or a size in [{MIN_SPLIT_SIZE}, {MAX_BAG_SIZE}] '
            f'bytes, got {describe_value(value)}',
        )
    return value


def _geometry(values: Mapping[str, Any]) -> tuple[str, FourBar]:
    preset_name = values.get('preset')
    if not isinstance(preset_name, str):
        raise ConfigurationError('preset', f'must be a string, got {describe_value(preset_name)}')
    if preset_name:
        try:
            preset(preset_name)
        except GeometryError as error:
            raise ConfigurationError('preset', str(error)) from None
    for name in DIMENSIONS:
        if values.get(name) is None:
            raise ConfigurationError(name, "has no value: with preset '' all five of "
                                     f"{', '.join(DIMENSIONS)} must be given")
    for name in LINK_LENGTHS:
        _positive(values, name, 'm', MAX_PARAMETER_LENGTH)
    for name in GROUND_COORDINATES:
        _within(values, name, -MAX_PARAMETER_LENGTH, MAX_PARAMETER_LENGTH, 'm')
    try:
        linkage = FourBar(**{name: _real(values, name) for name in DIMENSIONS})
    except GeometryError as error:
        raise ConfigurationError(', '.join(DIMENSIONS), str(error)) from None
    return preset_name, linkage


def _joints(values: Mapping[str, Any]) -> JointMap:
    mappings = {}
    for link in Link:
        prefix = f'joints.{link.value}.'
        direction = values.get(prefix + 'direction')
        if isinstance(direction, bool) or direction not in (1, -1):
            raise ConfigurationError(
                prefix + 'direction',
                f'must be the integer 1 or -1, got {describe_value(direction)}')
        mappings[link.value] = JointMapping(
            _text(values, prefix + 'name'), int(direction),
            _within(values, prefix + 'offset', -MAX_ANGLE, MAX_ANGLE),
        )
    joints = JointMap(**mappings)
    names = joints.names(tuple(Link))
    if len(set(names)) < len(names):
        raise ConfigurationError(
            'joints.crank.name, joints.coupler.name, joints.rocker.name',
            f"the three joint names must differ, got {', '.join(names)}")
    return joints


def _branch(values: Mapping[str, Any]) -> int:
    branch = values.get('branch')
    if isinstance(branch, bool) or not isinstance(branch, int) or branch not in (1, -1):
        raise ConfigurationError(
            'branch', f'must be the integer 1 or -1, got {describe_value(branch)}')
    return int(branch)


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


def build_configuration(values: Mapping[str, Any]) -> RunConfiguration:
    """
    Validate parameter values (name → value) into a RunConfiguration.

    Raises ConfigurationError naming the first offending parameter. Integers are accepted for
    real-valued parameters; anything else of the wrong type is rejected.
    """
    preset_name, linkage = _geometry(values)
    branch = _branch(values)
    omega0 = _within(values, 'omega0', -MAX_OMEGA0, MAX_OMEGA0, 'rad/s')
    k = _within(values, 'k', -MAX_DRIVE_GAIN, MAX_DRIVE_GAIN, '1/s')
    drive = DriveLaw(omega0, k)
    alpha_start = _within(values, 'alpha_start', -MAX_ANGLE, MAX_ANGLE)
    alpha_end = _within(values, 'alpha_end', -MAX_ANGLE, MAX_ANGLE)
    end_behavior = EndBehavior(_text(values, 'end_behavior', tuple(EndBehavior)))
    mode = MotionMode(_text(values, 'mode', tuple(MotionMode)))
    alpha_step = _positive(values, 'alpha_step', 'rad', TWO_PI)
    rate_hz = _positive(values, 'rate_hz', 'Hz', MAX_RATE_HZ)
    display_rate_hz = _positive(values, 'display_rate_hz', 'Hz', MAX_DISPLAY_RATE_HZ)
    frame_id = _text(values, 'frame_id')
    frame_prefix = _text(values, 'frame_prefix', allow_empty=True)
    min_transmission_angle = _within(
        values, 'diagnostics.min_transmission_angle', 0.0, math.pi / 2.0
    )
    dead_point_warning = _within(values, 'diagnostics.dead_point_warning', 0.0, math.pi)
    log_enabled = _flag(values, 'log.enabled')
    log_folder = Path(_text(values, 'log.folder'))
    log_max_bag_size = _bag_size(values)
    log_max_bag_duration = _within(values, 'log.max_bag_duration', 0.0, MAX_BAG_DURATION, 's')
    cpu_affinity = _cpu(values)
    source = SourceKind(_text(values, 'source', tuple(SourceKind)))
    driver = Driver(_text(values, 'driver', tuple(Driver)))
    joints = _joints(values)
    publish_robot_description = _flag(values, 'publish_robot_description')
    measured_timeout = _positive(values, 'measured.timeout', 's', MAX_TIMEOUT)
    max_jump = _positive(values, 'measured.max_jump', 'rad', math.pi)
    acceleration_time_constant = _within(
        values, 'measured.acceleration_time_constant', 0.0, MAX_TIME_CONSTANT, 's')
    if source is SourceKind.MEASURED:
        # No pass: the drive-law parameters are not used, so not checked against the geometry.
        blocked_at, segment_duration, segment_end, step_count = None, 0.0, alpha_end, 1
    else:
        if driver is not Driver.CRANK:
            raise ConfigurationError(
                'driver', 'the drive law turns the crank: driver rocker needs source measured')
        blocked_at, segment_duration = _motion(linkage, drive, branch, alpha_start, alpha_end)
        segment_end = alpha_end if blocked_at is None else blocked_at
        travel = abs(segment_end - alpha_start)
        steps = travel / alpha_step
        if not math.isfinite(steps):
            raise ConfigurationError('alpha_step', f'is too small for a pass of {travel!r} rad')
        step_count = max(1, math.ceil(steps - _STEP_COUNT_TOLERANCE))
    autostart = _flag(values, 'autostart')
    return RunConfiguration(
        preset=preset_name,
        linkage=linkage,
        drive=drive,
        branch=branch,
        alpha_start=alpha_start,
        alpha_end=alpha_end,
        end_behavior=end_behavior,
        mode=mode,
        alpha_step=alpha_step,
        rate_hz=rate_hz,
        display_rate_hz=display_rate_hz,
        frame_id=frame_id,
        frame_prefix=frame_prefix,
        min_transmission_angle=min_transmission_angle,
        dead_point_warning=dead_point_warning,
        log_enabled=log_enabled,
        log_folder=log_folder,
        log_max_bag_size=log_max_bag_size,
        log_max_bag_duration=log_max_bag_duration,
        cpu_affinity=cpu_affinity,
        source=source,
        driver=driver,
        driven_linkage=linkage if driver is Driver.CRANK else seen_from_rocker(linkage),
        joints=joints,
        publish_robot_description=publish_robot_description,
        measured_timeout=measured_timeout,
        max_jump=max_jump,
        acceleration_time_constant=acceleration_time_constant,
        autostart=autostart,
        direction=1 if segment_end > alpha_start else -1,
        segment_end=segment_end,
        blocked_at=blocked_at,
        segment_duration=segment_duration,
        whole_turns=(
            blocked_at is None
            and abs(math.remainder(alpha_end - alpha_start, TWO_PI)) <= _WHOLE_TURN_TOLERANCE
        ),
        step_count=step_count,
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
