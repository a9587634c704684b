"""``linkage_node``: turns the disk under the drive law and publishes the linkage's exact state.

A thin shell around the library: parameters are validated into a frozen RunConfiguration by
pure functions (``build_configuration``), the motion maps node-clock time or a step index to a
crank angle by pure functions (``sample_at_time``, ``sample_at_step``), the state comes from
``kinematics.solve`` and the messages from ``messages``. Topics, parameters, diagnostics and
exit statuses are documented in README.md.
"""

from __future__ import annotations

import json
import math
import signal
import sys
import time
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import rclpy
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from rcl_interfaces.msg import (
    FloatingPointRange,
    IntegerRange,
    ParameterDescriptor,
    SetParametersResult,
)
from rclpy.duration import Duration
from rclpy.executors import SingleThreadedExecutor
from rclpy.logging import get_logger
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions
from rclpy.time import Time
from sensor_msgs.msg import JointState
from std_msgs.msg import String
from trajectory_msgs.msg import JointTrajectory
from visualization_msgs.msg import MarkerArray

from linkage_kinematics import messages
from linkage_kinematics.bag_writer import package_version
from linkage_kinematics.drive import DriveError, DriveLaw
from linkage_kinematics.geometry import (
    ANGLE_TOLERANCE,
    TWO_PI,
    FourBar,
    GeometryError,
    UnreachableError,
    preset,
)
from linkage_kinematics.kinematics import (
    DeadPointError,
    LinkageState,
    loop_closure_residual,
    solve,
)
from linkage_kinematics.recording import Recorder
from linkage_kinematics.urdf import DEFAULT_FRAME_ID, urdf_text

NODE_NAME = "linkage_node"
DIAGNOSTIC_TASK = "crank motion"
END_BEHAVIORS = ("stop", "loop", "bounce")
MODES = ("real_time", "fixed_step")
GEOMETRY_PARAMETERS = ("crank_length", "coupler_length", "rocker_length", "ground_x", "ground_y")
MAX_RATE_HZ = 10000.0
MAX_DISPLAY_RATE_HZ = 1000.0
MAX_LENGTH = 1e6  # m; lengths and ground coordinates, far beyond any mechanism
MAX_ANGLE = 1e6  # rad; a double near 1e6 rad still resolves 1.2e-10 rad
MAX_OMEGA0 = 1e4  # rad/s
MAX_DRIVE_GAIN = 1e4  # 1/s, the largest |k|
# s; shorter passes would fall between clock ticks, and elapsed / pass duration could overflow.
MIN_PASS_DURATION = 1e-6
DIAGNOSTICS_PERIOD = 1.0  # s

EXIT_OK = 0
EXIT_FAILED = 1  # the crank met a dead point before alpha_end, or the log could not be closed
EXIT_CONFIGURATION = 2

# A step count within this fraction of a step of a whole number ends exactly on the segment
# end, so 90° in 0.5° steps is 180 steps and not 180 plus a rounding-sized 181st.
_STEP_COUNT_TOLERANCE = 1e-9
# α − alpha_start within this of a whole number of turns is a whole-turn loop.
_WHOLE_TURN_TOLERANCE = 1e-9

DATA_QOS = QoSProfile(depth=10)
# robot_state_publisher's convention: late joiners get the latest description.
ROBOT_DESCRIPTION_QOS = QoSProfile(
    depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE
)


class ConfigurationError(ValueError):
    """A parameter value (or a combination of them) the node cannot run with."""

    def __init__(self, parameter: str, reason: str) -> None:
        super().__init__(f"{parameter}: {reason}")
        self.parameter = parameter
        self.reason = reason


@dataclass(frozen=True)
class RunConfiguration:
    """Validated parameters plus the motion they imply; replaced as a whole, never mutated.

    ``segment_end`` is where one pass of the motion ends: alpha_end, or ``blocked_at``, the
    first dead (or change) point the crank meets on its way there. ``segment_duration`` is the
    drive-law time of that pass (s), ``direction`` the sign of the crank's travel and
    ``step_count`` the number of fixed steps strictly before ``segment_end``.
    """

    preset: str
    linkage: FourBar
    drive: DriveLaw
    branch: int
    alpha_start: float
    alpha_end: float
    end_behavior: str
    mode: str
    alpha_step: float
    rate_hz: float
    display_rate_hz: float
    frame_id: str
    min_transmission_angle: float
    dead_point_warning: float
    log_enabled: bool
    log_folder: Path
    direction: int
    segment_end: float
    blocked_at: float | None
    segment_duration: float
    whole_turns: bool
    step_count: int

    @property
    def reverse_drive(self) -> DriveLaw:
        """The drive law of the motion played backwards: ω and all rates negated, accelerations
        unchanged."""
        return DriveLaw(-self.drive.omega0, -self.drive.k)

    def restarts_motion(self, other: RunConfiguration) -> bool:
        """Whether switching from ``other`` to this configuration changes the motion itself."""
        display_only = replace(
            other,
            min_transmission_angle=self.min_transmission_angle,
            dead_point_warning=self.dead_point_warning,
            display_rate_hz=self.display_rate_hz,
        )
        return display_only != self


@dataclass(frozen=True)
class ParameterSpec:
    """One node parameter: its default (None: no default), descriptor text and limits."""

    name: str
    default: Any
    description: str
    read_only: bool = False
    floating_range: tuple[float, float] | None = None
    integer_range: tuple[int, int, int] | None = None

    def descriptor(self, with_range: bool = True) -> ParameterDescriptor:
        # dynamic_typing lets a wrongly typed value reach build_configuration, whose message
        # names the parameter; rclpy's own type check does not.
        descriptor = ParameterDescriptor(
            name=self.name,
            description=self.description,
            read_only=self.read_only,
            dynamic_typing=True,
        )
        if with_range and self.floating_range is not None:
            low, high = self.floating_range
            descriptor.floating_point_range = [FloatingPointRange(from_value=low, to_value=high)]
        if with_range and self.integer_range is not None:
            low_integer, high_integer, step = self.integer_range
            descriptor.integer_range = [
                IntegerRange(from_value=low_integer, to_value=high_integer, step=step)
            ]
        return descriptor


def parameter_specs(preset_name: str) -> tuple[ParameterSpec, ...]:
    """All parameters; the geometry defaults come from ``preset_name`` ('' → no defaults)."""
    geometry = preset(preset_name).geometry if preset_name else None
    geometry_specs = tuple(
        ParameterSpec(
            name,
            getattr(geometry, name) if geometry is not None else None,
            f"{text} (m); defaults to the preset's value, required when preset is ''",
        )
        for name, text in (
            ("crank_length", "disk radius OA"),
            ("coupler_length", "coupler length AB"),
            ("rocker_length", "rocker length BC"),
            ("ground_x", "x of the fixed pivot C relative to O"),
            ("ground_y", "y of the fixed pivot C relative to O"),
        )
    )
    return (
        ParameterSpec(
            "preset", "paper",
            "mechanism whose dimensions are the geometry parameters' defaults: "
            "paper, paper_full_turn, grashof_crank_rocker, or '' for none",
            read_only=True,
        ),
        *geometry_specs,
        ParameterSpec("branch", 1, "assembly branch: +1 (B left of A→C) or −1",
                      integer_range=(-1, 1, 2)),
        ParameterSpec("omega0", 2.0, "drive law ω = omega0 + k·α: omega0 (rad/s)"),
        ParameterSpec("k", 0.0, "drive law ω = omega0 + k·α: k (1/s)"),
        ParameterSpec("alpha_start", 0.0, "crank angle where the motion starts (rad)"),
        ParameterSpec("alpha_end", math.pi / 2.0, "crank angle where one pass ends (rad)"),
        ParameterSpec("end_behavior", "stop",
                      "at the end of a pass: stop (and exit), loop or bounce"),
        ParameterSpec("mode", "real_time",
                      "real_time: α from node-clock time; fixed_step: one alpha_step per tick"),
        ParameterSpec("alpha_step", math.radians(0.5), "crank step in fixed_step mode (rad)",
                      floating_range=(0.0, TWO_PI)),
        ParameterSpec("rate_hz", 100.0, "compute and publish rate of the state (Hz)",
                      floating_range=(0.0, MAX_RATE_HZ)),
        ParameterSpec("display_rate_hz", 30.0, "publish rate of /linkage/markers (Hz)",
                      floating_range=(0.0, MAX_DISPLAY_RATE_HZ)),
        ParameterSpec("frame_id", DEFAULT_FRAME_ID,
                      "frame of markers and /linkage/state, root link of the URDF",
                      read_only=True),
        ParameterSpec("diagnostics.min_transmission_angle", math.radians(10.0),
                      "WARN when min(μ, π − μ) of the transmission angle μ is below this (rad)",
                      floating_range=(0.0, math.pi / 2.0)),
        ParameterSpec("diagnostics.dead_point_warning", math.radians(1.0),
                      "WARN when the crank is closer than this to a dead point (rad)",
                      floating_range=(0.0, math.pi)),
        ParameterSpec("log.enabled", True, "record every published message to a bag",
                      read_only=True),
        ParameterSpec("log.folder", "bags",
                      "folder that receives a new bag per run (relative to the working "
                      "directory)", read_only=True),
    )


PARAMETER_NAMES = tuple(spec.name for spec in parameter_specs(""))


# --- validation: pure functions from parameter values to a RunConfiguration ---------------


def _describe(value: object) -> str:
    if value is None:
        return "no value"
    return f"{type(value).__name__} {value!r}"


def _real(values: Mapping[str, Any], name: str) -> float:
    value = values.get(name)
    # bool is an int in Python but a different parameter type in ROS.
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ConfigurationError(name, f"must be a number, got {_describe(value)}")
    value = float(value)
    if not math.isfinite(value):
        raise ConfigurationError(name, f"must be finite, got {value!r}")
    return value


def _positive(values: Mapping[str, Any], name: str, unit: str, upper: float = math.inf) -> float:
    value = _real(values, name)
    if not 0.0 < value <= upper:
        bound = f" and at most {upper:g} {unit}" if math.isfinite(upper) else ""
        raise ConfigurationError(name, f"must be greater than 0 {unit}{bound}, got {value!r}")
    return value


def _within(
    values: Mapping[str, Any], name: str, low: float, high: float, unit: str = "rad"
) -> float:
    value = _real(values, name)
    if not low <= value <= high:
        raise ConfigurationError(name, f"must lie in [{low:g}, {high:g}] {unit}, got {value!r}")
    return value


def _text(values: Mapping[str, Any], name: str, choices: tuple[str, ...] | None = None) -> str:
    value = values.get(name)
    if not isinstance(value, str):
        raise ConfigurationError(name, f"must be a string, got {_describe(value)}")
    if choices is not None and value not in choices:
        raise ConfigurationError(name, f"must be one of {', '.join(choices)}; got {value!r}")
    if choices is None and not value:
        raise ConfigurationError(name, "must not be empty")
    return value


def _flag(values: Mapping[str, Any], name: str) -> bool:
    value = values.get(name)
    if not isinstance(value, bool):
        raise ConfigurationError(name, f"must be true or false, got {_describe(value)}")
    return value


def _geometry(values: Mapping[str, Any]) -> tuple[str, FourBar]:
    preset_name = values.get("preset")
    if not isinstance(preset_name, str):
        raise ConfigurationError("preset", f"must be a string, got {_describe(preset_name)}")
    if preset_name:
        try:
            preset(preset_name)
        except GeometryError as error:
            raise ConfigurationError("preset", str(error)) from None
    for name in GEOMETRY_PARAMETERS:
        if values.get(name) is None:
            raise ConfigurationError(name, "has no value: with preset '' all five of "
                                     f"{', '.join(GEOMETRY_PARAMETERS)} must be given")
    for name in ("crank_length", "coupler_length", "rocker_length"):
        _positive(values, name, "m", MAX_LENGTH)
    for name in ("ground_x", "ground_y"):
        _within(values, name, -MAX_LENGTH, MAX_LENGTH, "m")
    try:
        linkage = FourBar(*(_real(values, name) for name in GEOMETRY_PARAMETERS))
    except GeometryError as error:
        raise ConfigurationError(", ".join(GEOMETRY_PARAMETERS), str(error)) from None
    return preset_name, linkage


def _branch(values: Mapping[str, Any]) -> int:
    branch = values.get("branch")
    if isinstance(branch, bool) or not isinstance(branch, int) or branch not in (1, -1):
        raise ConfigurationError("branch", f"must be the integer 1 or -1, got {_describe(branch)}")
    return int(branch)


def first_singular_point(linkage: FourBar, alpha_start: float, alpha_end: float) -> float | None:
    """The first dead or change point the crank meets going from alpha_start to alpha_end
    (inclusive of alpha_end), as an unwrapped crank angle; None if the way is clear."""
    reachability = linkage.reachability
    direction = 1.0 if alpha_end > alpha_start else -1.0
    travel = abs(alpha_end - alpha_start)
    nearest = None
    for point in reachability.dead_points + reachability.change_points:
        distance = (direction * (point - alpha_start)) % TWO_PI
        if distance <= travel + ANGLE_TOLERANCE and (nearest is None or distance < nearest):
            nearest = distance
    return None if nearest is None else alpha_start + direction * nearest


def _motion(
    linkage: FourBar, drive: DriveLaw, branch: int, alpha_start: float, alpha_end: float
) -> tuple[float | None, float]:
    """Check the start and the end of one pass; return (blocked_at, pass duration in s)."""
    try:
        linkage.reachability.require(alpha_start)
        solve(linkage, alpha_start, drive, branch)
    except (UnreachableError, DeadPointError) as error:
        raise ConfigurationError("alpha_start", str(error)) from None
    if drive.angular_velocity(alpha_start) == 0.0:
        raise ConfigurationError(
            "omega0", "the crank is at rest at alpha_start (omega0 + k·alpha_start = 0 rad/s)"
        )
    if alpha_end == alpha_start:
        raise ConfigurationError("alpha_end", "equals alpha_start, so a pass would be empty")
    try:
        drive.time_to(alpha_start, alpha_end)
    except DriveError as error:
        raise ConfigurationError("alpha_end", str(error)) from None
    blocked_at = first_singular_point(linkage, alpha_start, alpha_end)
    if blocked_at is None:
        try:
            solve(linkage, alpha_end, drive, branch)
        except DeadPointError:
            blocked_at = alpha_end
    segment_end = alpha_end if blocked_at is None else blocked_at
    duration = drive.time_to(alpha_start, segment_end)
    if duration < MIN_PASS_DURATION:
        raise ConfigurationError(
            "alpha_end",
            f"a pass from alpha_start to {math.degrees(segment_end):.6g}° would last only "
            f"{duration:.3g} s under this drive law; it must last at least "
            f"{MIN_PASS_DURATION:g} s",
        )
    return blocked_at, duration


def build_configuration(values: Mapping[str, Any]) -> RunConfiguration:
    """Validate parameter values (name → value) into a RunConfiguration.

    Raises ConfigurationError naming the first offending parameter. Integers are accepted for
    real-valued parameters; anything else of the wrong type is rejected.
    """
    preset_name, linkage = _geometry(values)
    branch = _branch(values)
    omega0 = _within(values, "omega0", -MAX_OMEGA0, MAX_OMEGA0, "rad/s")
    k = _within(values, "k", -MAX_DRIVE_GAIN, MAX_DRIVE_GAIN, "1/s")
    drive = DriveLaw(omega0, k)
    alpha_start = _within(values, "alpha_start", -MAX_ANGLE, MAX_ANGLE)
    alpha_end = _within(values, "alpha_end", -MAX_ANGLE, MAX_ANGLE)
    end_behavior = _text(values, "end_behavior", END_BEHAVIORS)
    mode = _text(values, "mode", MODES)
    alpha_step = _positive(values, "alpha_step", "rad", TWO_PI)
    rate_hz = _positive(values, "rate_hz", "Hz", MAX_RATE_HZ)
    display_rate_hz = _positive(values, "display_rate_hz", "Hz", MAX_DISPLAY_RATE_HZ)
    frame_id = _text(values, "frame_id")
    min_transmission_angle = _within(
        values, "diagnostics.min_transmission_angle", 0.0, math.pi / 2.0
    )
    dead_point_warning = _within(values, "diagnostics.dead_point_warning", 0.0, math.pi)
    log_enabled = _flag(values, "log.enabled")
    log_folder = Path(_text(values, "log.folder"))
    blocked_at, segment_duration = _motion(linkage, drive, branch, alpha_start, alpha_end)
    segment_end = alpha_end if blocked_at is None else blocked_at
    travel = abs(segment_end - alpha_start)
    steps = travel / alpha_step
    if not math.isfinite(steps):
        raise ConfigurationError("alpha_step", f"is too small for a pass of {travel!r} rad")
    step_count = max(1, math.ceil(steps - _STEP_COUNT_TOLERANCE))
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
        min_transmission_angle=min_transmission_angle,
        dead_point_warning=dead_point_warning,
        log_enabled=log_enabled,
        log_folder=log_folder,
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


# --- motion: pure functions from time or step index to the crank angle to solve at ---------


@dataclass(frozen=True)
class MotionSample:
    """Where the motion is: the crank angle of the first pass to solve at, whether that pass
    plays backwards (bounce), the whole turns to add to the published α (loop over whole turns),
    the drive-law time since the motion left alpha_start (s), whether this is the final
    state of a 'stop' motion, and how many passes have ended before this one (for bounce the
    forward passes are the even ones)."""

    alpha: float
    reversed: bool = False
    turn_offset: float = 0.0
    motion_time: float = 0.0
    final: bool = False
    pass_index: int = 0


def _clamp_to_segment(config: RunConfiguration, alpha: float) -> float:
    # alpha_at near the end of a pass may overshoot the end by a rounding error.
    if config.direction * (alpha - config.segment_end) > 0.0:
        return config.segment_end
    return alpha


def sample_at_time(config: RunConfiguration, elapsed: float) -> MotionSample | None:
    """The motion ``elapsed`` seconds after it started (real_time mode).

    None when a 'stop' motion has reached a dead point before alpha_end: the crank cannot go on.
    """
    duration = config.segment_duration
    if config.end_behavior == "stop":
        if elapsed >= duration:
            if config.blocked_at is not None:
                return None
            return MotionSample(config.alpha_end, motion_time=duration, final=True)
        return MotionSample(
            _clamp_to_segment(config, config.drive.alpha_at(config.alpha_start, elapsed)),
            motion_time=elapsed,
        )
    if config.end_behavior == "loop":
        passes = math.floor(elapsed / duration)
        in_pass = elapsed - passes * duration
        return MotionSample(
            _clamp_to_segment(config, config.drive.alpha_at(config.alpha_start, in_pass)),
            turn_offset=passes * (config.alpha_end - config.alpha_start) if config.whole_turns
            else 0.0,
            motion_time=elapsed,
            pass_index=passes,
        )
    cycles = math.floor(elapsed / (2.0 * duration))
    in_cycle = elapsed - cycles * 2.0 * duration
    backwards = in_cycle > duration
    in_pass = 2.0 * duration - in_cycle if backwards else in_cycle
    return MotionSample(
        _clamp_to_segment(config, config.drive.alpha_at(config.alpha_start, in_pass)),
        reversed=backwards,
        motion_time=elapsed,
        pass_index=2 * cycles + backwards,
    )


def _step_alpha(config: RunConfiguration, index: int) -> float:
    if index >= config.step_count:
        return config.segment_end
    return config.alpha_start + config.direction * index * config.alpha_step


def sample_at_step(config: RunConfiguration, step: int) -> MotionSample | None:
    """The motion at tick ``step`` (fixed_step mode): α = alpha_start + n·alpha_step exactly.

    One pass visits the ``step_count`` steps before its end and then alpha_end itself (not a
    dead point, which has no state). None as in ``sample_at_time``.
    """
    points = config.step_count + (0 if config.blocked_at is not None else 1)
    duration = config.segment_duration

    def time_of(alpha: float) -> float:
        return config.drive.time_to(config.alpha_start, alpha)

    if config.end_behavior == "stop":
        if step >= points:
            return None
        alpha = _step_alpha(config, step)
        return MotionSample(alpha, motion_time=time_of(alpha), final=(
            config.blocked_at is None and step == points - 1))
    if config.end_behavior == "loop":
        # Over whole turns the end of one pass is the start of the next: visit it once.
        per_pass = config.step_count if config.whole_turns else points
        passes, index = divmod(step, per_pass)
        alpha = _step_alpha(config, index)
        return MotionSample(
            alpha,
            turn_offset=passes * (config.alpha_end - config.alpha_start) if config.whole_turns
            else 0.0,
            motion_time=passes * duration + time_of(alpha),
            pass_index=passes,
        )
    per_cycle = max(2 * (points - 1), 1)
    cycles, index = divmod(step, per_cycle)
    if index < points:
        alpha = _step_alpha(config, index)
        return MotionSample(alpha, motion_time=cycles * 2.0 * duration + time_of(alpha),
                            pass_index=2 * cycles)
    alpha = _step_alpha(config, per_cycle - index)
    return MotionSample(
        alpha, reversed=True, motion_time=(cycles + 1) * 2.0 * duration - time_of(alpha),
        pass_index=2 * cycles + 1,
    )


def solve_sample(config: RunConfiguration, sample: MotionSample) -> LinkageState:
    """The library's state for a motion sample (raises as ``kinematics.solve``)."""
    drive = config.reverse_drive if sample.reversed else config.drive
    state = solve(config.linkage, sample.alpha, drive, config.branch)
    if sample.turn_offset:
        state = replace(state, alpha=state.alpha + sample.turn_offset)
    return state


def blocked_note(config: RunConfiguration) -> str | None:
    """What happens at a dead point that lies before alpha_end; None if there is none."""
    if config.blocked_at is None:
        return None
    outcome = {
        "stop": "the run will end there with an error",
        "loop": "the crank restarts from alpha_start there",
        "bounce": "the crank reverses there",
    }[config.end_behavior]
    return (
        f"dead point at {math.degrees(config.blocked_at):.6f}° before alpha_end = "
        f"{math.degrees(config.alpha_end):.6f}°: {outcome}"
    )


def met_dead_point(config: RunConfiguration, previous_pass: int, current_pass: int) -> bool:
    """Whether the crank met the dead point that cuts a pass short (``blocked_at``) between a
    sample of pass ``previous_pass`` and one of pass ``current_pass``: 'loop' meets it at the
    end of every pass, 'bounce' at the end of every forward (even) pass."""
    if config.blocked_at is None or current_pass <= previous_pass:
        return False
    if config.end_behavior == "bounce":
        return previous_pass % 2 == 0 or current_pass - previous_pass >= 2
    return True


def dead_point_problem(config: RunConfiguration) -> str:
    """The ERROR message for the crank meeting ``blocked_at``: where, and what it does."""
    outcome = {
        "stop": "stops; the run cannot go on",
        "loop": "restarts from alpha_start",
        "bounce": "reverses",
    }[config.end_behavior]
    return (
        f"the crank cannot go past the dead point at {math.degrees(config.blocked_at):.6f}° "
        f"before alpha_end = {math.degrees(config.alpha_end):.6f}°: it {outcome}"
    )


def assess(
    config: RunConfiguration, state: LinkageState | None, problem: str | None, activity: str
) -> tuple[bytes, str]:
    """Diagnostic level and message: ERROR for ``problem`` (the crank cannot go on, or the log
    failed), WARN near a dead point or at a poor transmission angle, else OK with ``activity``."""
    if problem is not None:
        return DiagnosticStatus.ERROR, problem
    if state is None:
        return DiagnosticStatus.OK, activity
    warnings = []
    deviation = min(state.transmission_angle, math.pi - state.transmission_angle)
    if deviation < config.min_transmission_angle:
        warnings.append(
            f"transmission angle {math.degrees(state.transmission_angle):.2f}° is within "
            f"{math.degrees(config.min_transmission_angle):.2f}° of a straight line"
        )
    distance = config.linkage.reachability.dead_point_distance(state.alpha)
    if distance is not None and distance < config.dead_point_warning:
        warnings.append(f"{math.degrees(distance):.3f}° from a dead point")
    note = blocked_note(config)
    if note is not None:
        warnings.append(note)
    if warnings:
        return DiagnosticStatus.WARN, "; ".join(warnings)
    return DiagnosticStatus.OK, activity


# --- the node ------------------------------------------------------------------------------


class LinkageNode(Node):
    """Publishes the linkage's state at rate_hz, markers at display_rate_hz, diagnostics at 1 Hz.

    Construction raises ConfigurationError for bad parameters before anything is published or
    written. ``exit_code`` becomes an int when the node has finished (see README).
    """

    def __init__(self, **node_options: Any) -> None:
        super().__init__(NODE_NAME, **node_options)
        self.exit_code: int | None = None
        specs = self._declare_parameters()
        self.config = build_configuration(self.parameter_values())
        # Ranges go into the descriptors only now, so that a bad start-up value gets
        # build_configuration's message; from here on rclpy enforces them too.
        for spec in specs:
            if spec.floating_range is not None or spec.integer_range is not None:
                self.set_descriptor(spec.name, spec.descriptor())
        if blocked_note(self.config) is not None:
            self.get_logger().warning(blocked_note(self.config))
        self._pending: RunConfiguration | None = None
        self._problem: str | None = None
        self._activity = "starting"
        self._recording_error: str | None = None
        self._state: LinkageState | None = None
        self._joint_state = JointState(name=list(messages.JOINT_NAMES), position=[0.0] * 3)
        self._linkage_state: JointTrajectory | None = None
        self._markers: MarkerArray | None = None
        self._window_start: Time | None = None
        self._window_ticks = 0
        self._achieved_rate = 0.0
        self._missed_deadlines = 0
        self._restart_motion()
        self._topic_publishers = {
            "/joint_states": self.create_publisher(JointState, "/joint_states", DATA_QOS),
            "/linkage/state": self.create_publisher(JointTrajectory, "/linkage/state", DATA_QOS),
            "/robot_description": self.create_publisher(
                String, "/robot_description", ROBOT_DESCRIPTION_QOS
            ),
            "/linkage/markers": self.create_publisher(MarkerArray, "/linkage/markers", DATA_QOS),
            "/diagnostics": self.create_publisher(DiagnosticArray, "/diagnostics", DATA_QOS),
        }
        self._recorder = self._open_recorder() if self.config.log_enabled else None
        self._publish_robot_description()
        self._publish_diagnostics()
        self._state_timer = self.create_timer(1.0 / self.config.rate_hz, self._tick)
        self._marker_timer = self.create_timer(
            1.0 / self.config.display_rate_hz, self._publish_markers
        )
        self._diagnostics_timer = self.create_timer(DIAGNOSTICS_PERIOD, self._publish_diagnostics)
        self.add_on_set_parameters_callback(self._validate_change)
        self.add_post_set_parameters_callback(self._apply_change)

    # parameters

    def _declare_parameters(self) -> tuple[ParameterSpec, ...]:
        """Declare every parameter up front (without ranges); return their specs."""
        preset_spec = parameter_specs("paper")[0]
        self.declare_parameter(preset_spec.name, preset_spec.default,
                               preset_spec.descriptor(with_range=False))
        preset_name = self.get_parameter("preset").value
        if not isinstance(preset_name, str):
            raise ConfigurationError("preset", f"must be a string, got {_describe(preset_name)}")
        try:
            specs = parameter_specs(preset_name)
        except GeometryError as error:
            raise ConfigurationError("preset", str(error)) from None
        for spec in specs[1:]:
            self.declare_parameter(spec.name, spec.default, spec.descriptor(with_range=False))
        return specs

    def parameter_values(self) -> dict[str, Any]:
        """Current values of the node's own parameters (name → value)."""
        return {name: self.get_parameter(name).value for name in PARAMETER_NAMES}

    def _validate_change(self, changed: list[Parameter]) -> SetParametersResult:
        """Validate the whole configuration the change would produce; keep it for the post-set
        callback, which swaps it in once rclpy has stored the values."""
        updates = {p.name: p.value for p in changed if p.name in PARAMETER_NAMES}
        if not updates:
            self._pending = None
            return SetParametersResult(successful=True)
        try:
            self._pending = build_configuration({**self.parameter_values(), **updates})
        except ConfigurationError as error:
            self._pending = None
            return SetParametersResult(successful=False, reason=str(error))
        return SetParametersResult(successful=True)

    def _apply_change(self, changed: list[Parameter]) -> None:
        new, self._pending = self._pending, None
        if new is None:
            return
        old, self.config = self.config, new
        self.get_logger().info(
            "parameters changed: "
            + ", ".join(f"{p.name}={p.value!r}" for p in changed)
            + ("; motion restarts at alpha_start" if new.restarts_motion(old) else "")
        )
        note = blocked_note(new)
        if note is not None:
            self.get_logger().warning(note)
        if new.linkage != old.linkage:
            self._publish_robot_description()
            self._markers = None
        if new.rate_hz != old.rate_hz:
            self._state_timer.destroy()
            self._state_timer = self.create_timer(1.0 / new.rate_hz, self._tick)
        if new.display_rate_hz != old.display_rate_hz:
            self._marker_timer.destroy()
            self._marker_timer = self.create_timer(1.0 / new.display_rate_hz,
                                                   self._publish_markers)
        if new.restarts_motion(old):
            self._restart_motion()

    # recording

    def _open_recorder(self) -> Recorder:
        """A recorder for every topic, before anything is published; ConfigurationError naming
        log.folder if it cannot be written."""
        metadata = {
            "parameters": json.dumps(self.parameter_values(), sort_keys=True),
            "package_version": package_version(),
        }
        try:
            recorder = Recorder(self.config.log_folder, metadata=metadata)
        except OSError as error:
            raise ConfigurationError("log.folder", str(error)) from None
        try:
            for topic, publisher in self._topic_publishers.items():
                recorder.add_topic(topic, publisher.msg_type, publisher.qos_profile)
        except OSError as error:
            recorder.close()
            raise ConfigurationError("log.folder", str(error)) from None
        return recorder

    def _publish(self, topic: str, message: Any, log_time_ns: int) -> None:
        if self._recorder is None or self._recording_error is not None:
            self._topic_publishers[topic].publish(message)
            return
        # Serialized once: subscribers get the very bytes that are logged.
        data = self._recorder.serialize(topic, message)
        self._topic_publishers[topic].publish(data)
        try:
            self._recorder.record(topic, data, log_time_ns)
        except OSError as error:
            # The data keep flowing; diagnostics report the lost log.
            self._recording_error = f"recording stopped: {error}"
            self.get_logger().error(self._recording_error)

    def flush_publishers(self, timeout: float = 1.0) -> None:
        """Give subscribers up to ``timeout`` seconds in all to acknowledge what was published
        (the final state of a 'stop' run must not die with the process)."""
        deadline = time.monotonic() + timeout
        for publisher in self._topic_publishers.values():
            publisher.wait_for_all_acked(Duration(seconds=max(deadline - time.monotonic(), 0.0)))

    def close_log(self) -> bool:
        """Finalize the bag (idempotent); False, with an error logged, if that failed."""
        if self._recorder is None:
            return True
        try:
            self._recorder.close()
        except OSError as error:
            self.get_logger().error(f"could not finalize the log: {error}")
            return False
        return True

    # motion

    def _restart_motion(self) -> None:
        self._motion_start: Time | None = None
        self._step = 0
        self._ticks = 0
        self._pass_index = 0
        # Missed deadlines count over the whole run, across restarts.
        self._missed_before_restart = self._missed_deadlines

    def _tick(self) -> None:
        if self.exit_code is not None:
            return
        now = self.get_clock().now()
        if self._motion_start is None or now < self._motion_start:
            # First tick, or ROS time jumped back (e.g. a simulation restarted): start over.
            self._restart_motion()
            self._motion_start = now
        elapsed = (now - self._motion_start).nanoseconds * 1e-9
        self._count_tick(elapsed)
        config = self.config
        if config.mode == "real_time":
            sample = sample_at_time(config, elapsed)
        else:
            sample = sample_at_step(config, self._step)
            self._step += 1
        if sample is None:
            self._cannot_go_on(None)
            return
        if met_dead_point(config, self._pass_index, sample.pass_index):
            # Stamped with the tick's time, like the state that follows, so log times never fall.
            self._publish_diagnostics(dead_point_problem(config), now)
        self._pass_index = sample.pass_index
        try:
            state = solve_sample(config, sample)
        except (DeadPointError, UnreachableError) as error:
            if config.end_behavior == "stop":
                self._cannot_go_on(str(error))
            # loop and bounce turn round at the dead point itself, which has no state to show.
            return
        self._publish_state(state, sample.motion_time, now)
        if sample.final:
            self._finish_at_end()

    def _count_tick(self, elapsed: float) -> None:
        # A period that passed without a tick is a missed deadline; rcl timers skip such periods
        # rather than firing twice, so the shortfall stays visible.
        self._ticks += 1
        due = math.floor(elapsed * self.config.rate_hz + 1e-6) + 1
        self._missed_deadlines = max(
            self._missed_deadlines, self._missed_before_restart + due - self._ticks
        )
        self._window_ticks += 1

    def _publish_state(self, state: LinkageState, motion_time: float, now: Time) -> None:
        stamp = now.to_msg()
        nanoseconds = now.nanoseconds
        self._state = state
        self._activity = "moving"
        joint_state = messages.joint_state(
            state, stamp, self._joint_state.position, out=self._joint_state
        )
        self._publish("/joint_states", joint_state, nanoseconds)
        self._linkage_state = messages.linkage_state(
            state, stamp, motion_time, self.config.frame_id, out=self._linkage_state
        )
        self._publish("/linkage/state", self._linkage_state, nanoseconds)

    def _finish_at_end(self) -> None:
        self._activity = (
            f"reached alpha_end = {math.degrees(self.config.alpha_end):.6f}°; stopped"
        )
        self.get_logger().info(self._activity)
        self._publish_markers()
        self._publish_diagnostics()
        self.exit_code = EXIT_OK

    def _cannot_go_on(self, detail: str | None) -> None:
        config = self.config
        if config.blocked_at is not None:
            problem = dead_point_problem(config)
        else:
            problem = f"the crank cannot go on: {detail}"
        self._problem = problem
        self.get_logger().error(problem)
        self._publish_diagnostics()
        self.exit_code = EXIT_FAILED

    # display and diagnostics

    def _publish_robot_description(self) -> None:
        message = String(data=urdf_text(self.config.linkage, self.config.frame_id))
        self._publish("/robot_description", message, self.get_clock().now().nanoseconds)

    def _publish_markers(self) -> None:
        if self._state is None:
            return
        now = self.get_clock().now()
        self._markers = messages.marker_array(
            self.config.linkage, self._state, now.to_msg(), self.config.frame_id,
            out=self._markers,
        )
        self._publish("/linkage/markers", self._markers, now.nanoseconds)

    def _publish_diagnostics(self, event: str | None = None, now: Time | None = None) -> None:
        """Publish the status (at ``now``, by default the clock's); ``event``, a problem of this
        moment only, makes it ERROR."""
        if now is None:
            now = self.get_clock().now()
        if self._window_start is not None:
            window = (now - self._window_start).nanoseconds * 1e-9
            if window > 0.0:
                self._achieved_rate = self._window_ticks / window
        self._window_start = now
        self._window_ticks = 0
        problem = event or self._problem or self._recording_error
        level, text = assess(self.config, self._state, problem, self._activity)
        message = messages.diagnostic_array(
            now.to_msg(),
            f"{self.get_name()}: {DIAGNOSTIC_TASK}",
            f"four-bar linkage ({self.config.preset or 'explicit geometry'})",
            level,
            text,
            self._diagnostic_values(),
        )
        self._publish("/diagnostics", message, now.nanoseconds)

    def _diagnostic_values(self) -> dict[str, str]:
        config = self.config
        values = {
            "end behavior": config.end_behavior,
            "mode": config.mode,
            "achieved rate (Hz)": f"{self._achieved_rate:.1f}",
            "rate_hz": f"{config.rate_hz:g}",
            "missed deadlines": str(self._missed_deadlines),
        }
        state = self._state
        if state is not None:
            distance = config.linkage.reachability.dead_point_distance(state.alpha)
            residual = float(loop_closure_residual(config.linkage, state))
            values.update({
                "alpha (rad)": repr(state.alpha),
                "alpha (deg)": f"{math.degrees(state.alpha):.6f}",
                "dead point distance (deg)": (
                    "none (full rotation)" if distance is None
                    else f"{math.degrees(distance):.6f}"
                ),
                "transmission angle (deg)": f"{math.degrees(state.transmission_angle):.6f}",
                "loop closure residual": f"{residual:.3g}",
            })
        if self._recorder is None:
            values["log file"] = "disabled"
        else:
            values["log file"] = str(self._recorder.bag_path)
            values["log size (bytes)"] = str(self._recorder.size_bytes)
        return values


# --- process ------------------------------------------------------------------------------


def _report_configuration_error(error: ConfigurationError) -> None:
    """The one line saying which parameter is bad and why: to the node's logger (console,
    /rosout, log file) and plainly to stderr."""
    get_logger(NODE_NAME).fatal(f"invalid parameter {error}")
    print(f"{NODE_NAME}: invalid parameter {error}", file=sys.stderr, flush=True)


def main(args: list[str] | None = None) -> int:
    """Run the node until it finishes, or until SIGINT or SIGTERM; return the exit status."""
    # rclpy's own SIGINT handler would shut the context down under our feet; ours lets the
    # loop below finalize the log first.
    rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    received: list[int] = []

    def request_stop(signal_number: int, _frame: object) -> None:
        received.append(signal_number)

    signal.signal(signal.SIGINT, request_stop)
    signal.signal(signal.SIGTERM, request_stop)
    try:
        try:
            node = LinkageNode()
        except ConfigurationError as error:
            _report_configuration_error(error)
            return EXIT_CONFIGURATION
        executor = SingleThreadedExecutor()
        executor.add_node(node)
        try:
            while node.exit_code is None and not received:
                executor.spin_once(timeout_sec=0.1)
        finally:
            node.flush_publishers()
            log_closed = node.close_log()
            executor.remove_node(node)
            node.destroy_node()
        exit_code = EXIT_OK if received else node.exit_code
        return exit_code if log_closed else EXIT_FAILED
    finally:
        rclpy.try_shutdown()


if __name__ == "__main__":
    sys.exit(main())
