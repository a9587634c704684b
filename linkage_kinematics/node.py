# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
``linkage_node``.

Turns the disk under the drive law and publishes the linkage's exact state.

A thin shell over two pure modules: ``parameters`` validates the parameter values into a frozen
RunConfiguration, ``motion`` maps node-clock time or a step index to the crank angle to solve
at; the state comes from ``kinematics.solve`` and the messages from ``messages``. Topics,
parameters, diagnostics and exit statuses are documented in README.md.
"""

from __future__ import annotations

from collections.abc import Callable
import json
import math
import os
import re
import signal
import sys
import time
from typing import Any

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from linkage_kinematics import diagnostics, messages
from linkage_kinematics.bag.cdr import encode_cdr
from linkage_kinematics.bag.errors import LogFolderError
from linkage_kinematics.bag.metadata import BagMetadata, package_version
from linkage_kinematics.bag.recorder import Recorder
from linkage_kinematics.bag.writer_process import set_process_affinity
from linkage_kinematics.geometry import FourBar, GeometryError, UnreachableError
from linkage_kinematics.kinematics import DeadPointError, LinkageState
from linkage_kinematics.motion import (
    blocked_note,
    dead_point_problem,
    met_dead_point,
    MotionSample,
    sample_at_step,
    sample_at_time,
    solve_sample,
)
from linkage_kinematics.parameters import (
    build_configuration,
    ConfigurationError,
    describe_value,
    EndBehavior,
    MotionMode,
    NO_CPU_AFFINITY,
    NODE_NAME,
    PARAMETER_NAMES,
    parameter_specs,
    ParameterSpec,
    REAL_PARAMETERS,
    RunConfiguration,
    unknown_parameters,
)
from linkage_kinematics.run_control import RunControl, ServiceAnswer
from linkage_kinematics.urdf import urdf_text
from rcl_interfaces.msg import (
    FloatingPointRange,
    IntegerRange,
    ParameterDescriptor,
    SetParametersResult,
)
import rclpy
from rclpy.duration import Duration
from rclpy.executors import Executor, SingleThreadedExecutor
from rclpy.experimental import EventsExecutor
from rclpy.logging import get_logger
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions
from rclpy.time import Time
from sensor_msgs.msg import JointState
from std_msgs.msg import String
from std_srvs.srv import Trigger
from trajectory_msgs.msg import JointTrajectory
from visualization_msgs.msg import MarkerArray

DIAGNOSTIC_TASK = 'crank motion'
DIAGNOSTICS_PERIOD = 1.0  # s

EXIT_OK = 0
EXIT_FAILED = 1  # the crank met a dead point before alpha_end, or the log could not be closed
EXIT_CONFIGURATION = 2

DATA_QOS = QoSProfile(depth=10)
# TF is logged, never published (see docs/logging.md), with tf2_ros's broadcaster QoS: the
# static one keeps the last message for late subscribers, as robot_state_publisher's does.
TF_TOPIC = '/tf'
TF_STATIC_TOPIC = '/tf_static'
TF_QOS = QoSProfile(depth=100)
TF_STATIC_QOS = QoSProfile(
    depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE
)
# robot_state_publisher's convention: late joiners get the latest description.
ROBOT_DESCRIPTION_QOS = QoSProfile(
    depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE
)


class StartupError(Exception):
    """The node cannot start for a reason other than a parameter; the message names it."""


def parameter_descriptor(spec: ParameterSpec, with_range: bool = True) -> ParameterDescriptor:
    """Return a parameter's ROS descriptor (range and read-only flag only ``with_range``)."""
    # dynamic_typing lets a wrongly typed value reach build_configuration, whose message
    # names the parameter; rclpy's own type check does not.
    descriptor = ParameterDescriptor(
        name=spec.name,
        description=spec.description,
        # rclpy refuses a later descriptor, with its range, for a read-only parameter
        read_only=spec.read_only and with_range,
        dynamic_typing=True,
    )
    if with_range and spec.floating_range is not None:
        low, high = spec.floating_range
        descriptor.floating_point_range = [FloatingPointRange(from_value=low, to_value=high)]
    if with_range and spec.integer_range is not None:
        low_integer, high_integer, step = spec.integer_range
        descriptor.integer_range = [
            IntegerRange(from_value=low_integer, to_value=high_integer, step=step)
        ]
    return descriptor


def assess(
    config: RunConfiguration, state: LinkageState | None, problem: str | None, activity: str
) -> tuple[bytes, str]:
    """
    Diagnostic level and message.

    ERROR for ``problem`` (the crank cannot go on, or the log failed), WARN near a dead point or at
    a poor transmission angle, else OK with ``activity``.
    """
    if problem is not None:
        return DiagnosticStatus.ERROR, problem
    if state is None:
        return DiagnosticStatus.OK, activity
    warnings = []
    deviation = min(state.transmission_angle, math.pi - state.transmission_angle)
    if deviation < config.min_transmission_angle:
        warnings.append(
            f'transmission angle {math.degrees(state.transmission_angle):.2f}° is within '
            f'{math.degrees(config.min_transmission_angle):.2f}° of a straight line'
        )
    reachability = config.linkage.reachability
    distance = reachability.dead_point_distance(state.alpha)
    if distance is not None and distance < config.dead_point_warning:
        warnings.append(f'{math.degrees(distance):.3f}° from a dead point')
    distance = reachability.change_point_distance(state.alpha)
    if distance is not None and distance < config.dead_point_warning:
        warnings.append(
            f'{math.degrees(distance):.3f}° from a change point (the assemblies meet; the '
            'motion continues smoothly on its branch)'
        )
    note = blocked_note(config)
    if note is not None:
        warnings.append(note)
    if warnings:
        return DiagnosticStatus.WARN, '; '.join(warnings)
    return DiagnosticStatus.OK, activity


# --- the node ------------------------------------------------------------------------------


class LinkageNode(Node):
    """
    Publishes the linkage's state as the drive law moves the crank.

    Markers at display_rate_hz, diagnostics at 1 Hz and whenever the motion's activity changes.

    Construction raises ConfigurationError for bad parameters before anything is published or
    written. ``exit_code`` becomes an int when the node has finished (see README).
    """

    def __init__(self, **node_options: Any) -> None:
        super().__init__(NODE_NAME, **node_options)
        self.exit_code: int | None = None
        specs = self._declare_parameters()
        # rclpy has no public accessor of the overrides given for this node; they include the
        # `-p` arguments and the /** entries of parameter files, which rcl keeps as one set.
        for warning in unknown_parameters(self._parameter_overrides,
                                          self.list_parameters([], 0).names):
            self.get_logger().warning(warning)
        self.config = build_configuration(self.parameter_values())
        self._control = RunControl(self.config.autostart)
        # Ranges go into the descriptors only now, so that a bad start-up value gets
        # build_configuration's message; from here on rclpy enforces them too.
        for spec in specs:
            if (spec.floating_range is not None or spec.integer_range is not None
                    or spec.read_only):
                self.set_descriptor(spec.name, parameter_descriptor(spec))
        if blocked_note(self.config) is not None:
            self.get_logger().warning(blocked_note(self.config))
        self._pending: tuple[RunConfiguration, list[str]] | None = None
        self._problem: str | None = None
        self._activity = 'starting'
        self._recording_error: str | None = None
        self._described_linkage: FourBar | None = None
        self._robot_transforms: messages.RobotStateTransforms | None = None
        # frame_id and frame_prefix are read-only: one frame for the node's life.
        self._frame_id = self.config.frame_prefix + self.config.frame_id
        # The per-tick messages and the scene are encoded straight from the state; the
        # encoders of the state and the scene are prepared for each geometry.
        self._joint_state_encoder = messages.JointStateEncoder()
        self._joint_positions: tuple[float, float, float] = (0.0, 0.0, 0.0)
        self._encoded_linkage: FourBar | None = None
        self._state_encoder: messages.LinkageStateEncoder | None = None
        self._marker_encoder: messages.MarkerArrayEncoder | None = None
        self._rate_meter = diagnostics.RateMeter()
        self._status_schedule = diagnostics.StatusSchedule()
        self._missed_deadlines = 0
        self._missed_before_restart = 0
        self._restart_motion()
        # Relative names resolve under the node's namespace (as joint_state_publisher's and
        # robot_state_publisher's do), so mechanisms in different namespaces never mix;
        # /diagnostics is absolute, diagnostic_updater's convention.
        publishers = (
            self.create_publisher(JointState, 'joint_states', DATA_QOS),
            self.create_publisher(JointTrajectory, 'linkage/state', DATA_QOS),
            self.create_publisher(String, 'robot_description', ROBOT_DESCRIPTION_QOS),
            self.create_publisher(MarkerArray, 'linkage/markers', DATA_QOS),
            self.create_publisher(DiagnosticArray, '/diagnostics', DATA_QOS),
        )
        self._topic_publishers = {publisher.topic_name: publisher for publisher in publishers}
        (
            self._joint_states_topic,
            self._state_topic,
            self._description_topic,
            self._markers_topic,
            self._diagnostics_topic,
        ) = self._topic_publishers
        self._available_cpus = (
            os.sched_getaffinity(0) if hasattr(os, 'sched_getaffinity') else set()
        )
        self._bag_writer_cpus: set[int] | None = None
        self._bag_writer_cpus = self._place(self.config.cpu_affinity)
        self._recorder = self._open_recorder() if self.config.log_enabled else None
        if self._recorder is not None:
            self.get_logger().info(f'recording to {self._recorder.bag_path}')
        self._state_timer = self.create_timer(self._timer_period(), self._tick)
        self._marker_timer = self.create_timer(
            1.0 / self.config.display_rate_hz, self._publish_markers
        )
        self._diagnostics_timer = self.create_timer(DIAGNOSTICS_PERIOD, self._publish_diagnostics)
        self.add_pre_set_parameters_callback(self._keep_declared_types)
        self.add_on_set_parameters_callback(self._validate_change)
        self.add_post_set_parameters_callback(self._apply_change)
        self.create_service(Trigger, '~/pause', self._answer(self._pause))
        self.create_service(Trigger, '~/resume', self._answer(self._resume))
        self.create_service(Trigger, '~/reset', self._answer(self._reset))
        # The motion starts now (its first state, scene first, is published at once), or with
        # autostart false the node shows alpha_start and waits; either unless the clock does not
        # run yet (use_sim_time before the first /clock).
        self._tick()

    # parameters

    def _declare_parameters(self) -> tuple[ParameterSpec, ...]:
        """Declare every parameter up front (without ranges); return their specs."""
        preset_spec = parameter_specs('paper')[0]
        self.declare_parameter(preset_spec.name, preset_spec.default,
                               parameter_descriptor(preset_spec, with_range=False))
        preset_name = self.get_parameter('preset').value
        if not isinstance(preset_name, str):
            raise ConfigurationError(
                'preset', f'must be a string, got {describe_value(preset_name)}'
            )
        try:
            specs = parameter_specs(preset_name)
        except GeometryError as error:
            raise ConfigurationError('preset', str(error)) from None
        for spec in specs[1:]:
            self.declare_parameter(
                spec.name, spec.default, parameter_descriptor(spec, with_range=False)
            )
        # A whole number given for a real parameter (`-p rate_hz:=50`) is stored as that real.
        whole_numbers = [
            self.get_parameter(name) for name in REAL_PARAMETERS
            if self.get_parameter(name).type_ == Parameter.Type.INTEGER
        ]
        if whole_numbers:
            self.set_parameters(self._keep_declared_types(whole_numbers))
        return specs

    def parameter_values(self) -> dict[str, Any]:
        """Return the current values of the node's own parameters (name → value)."""
        return {name: self.get_parameter(name).value for name in PARAMETER_NAMES}

    @staticmethod
    def _keep_declared_types(changed: list[Parameter]) -> list[Parameter]:
        """
        Whole numbers given for real parameters become those reals.

        So that a parameter never changes type (`ros2 param set /linkage_node rate_hz 50`).
        """
        return [
            Parameter(p.name, Parameter.Type.DOUBLE, float(p.value))
            if p.name in REAL_PARAMETERS and p.type_ == Parameter.Type.INTEGER
            else p
            for p in changed
        ]

    def _validate_change(self, changed: list[Parameter]) -> SetParametersResult:
        """
        Validate the whole configuration the change would produce.

        Keep it for the post-set callback, which swaps it in once rclpy has stored the values.
        """
        current = self.parameter_values()
        updates = {p.name: p.value for p in changed if p.name in PARAMETER_NAMES}
        try:
            config = build_configuration({**current, **updates})
            self._check_cpu(config.cpu_affinity)
        except ConfigurationError as error:
            self._pending = None
            return SetParametersResult(successful=False, reason=str(error))
        differing = [name for name, value in updates.items() if value != current[name]]
        self._pending = (config, differing)
        return SetParametersResult(successful=True)

    def _apply_change(self, changed: list[Parameter]) -> None:
        if self._pending is None:
            return
        (new, differing), self._pending = self._pending, None
        if not differing:
            return  # e.g. `ros2 param load` of the node's own dump: nothing changes
        old, self.config = self.config, new
        restarts = new.restarts_motion(old)
        self.get_logger().info(
            'parameters changed: '
            + ', '.join(f'{name}={self.get_parameter(name).value!r}' for name in differing)
            + ('; motion restarts at alpha_start' if restarts else '')
        )
        note = blocked_note(new)
        if note is not None:
            self.get_logger().warning(note)
        if new.display_rate_hz != old.display_rate_hz:
            self.destroy_timer(self._marker_timer)
            self._marker_timer = self.create_timer(1.0 / new.display_rate_hz,
                                                   self._publish_markers)
        if new.cpu_affinity != old.cpu_affinity:
            self._bag_writer_cpus = self._place(new.cpu_affinity)
            if self._recorder is not None:
                self._recorder.run_writer_on(self._bag_writer_cpus or self._available_cpus)
        if restarts:
            self._restart_motion()
            self.destroy_timer(self._state_timer)
            self._state_timer = self.create_timer(self._timer_period(), self._tick)
            self._tick()

    # placement

    def _check_cpu(self, cpu: int) -> None:
        """Raise ConfigurationError naming cpu_affinity unless this process may use ``cpu``."""
        if cpu == NO_CPU_AFFINITY:
            return
        if not hasattr(os, 'sched_setaffinity'):
            raise ConfigurationError('cpu_affinity', 'CPU affinity is not supported here')
        if cpu not in self._available_cpus:
            raise ConfigurationError(
                'cpu_affinity',
                f'CPU {cpu} is not one this process may run on (it may run on '
                f"{', '.join(map(str, sorted(self._available_cpus)))})",
            )

    def _place(self, cpu: int) -> set[int] | None:
        """
        Pin every thread of this process.

        (Fast DDS's included; threads started later inherit it) to ``cpu``, or give a pinned
        process back every CPU it could use for -1; return the CPUs for the bag writer process,
        None when the node is not pinned.

        On one CPU the executor's timer thread and the thread running the callbacks wake each
        other without crossing CPUs, and the bag writer cannot delay either
        (docs/benchmarks.md, section 3).
        """
        self._check_cpu(cpu)
        if cpu == NO_CPU_AFFINITY and self._bag_writer_cpus is None:
            return None  # never pinned: the process stays as it was started
        node_cpus = self._available_cpus if cpu == NO_CPU_AFFINITY else {cpu}
        set_process_affinity(os.getpid(), node_cpus)
        if cpu == NO_CPU_AFFINITY:
            self.get_logger().info('no longer pinned to a CPU')
            return None
        bag_writer_cpus = (self._available_cpus - node_cpus) or node_cpus
        self.get_logger().info(
            f'running on CPU {cpu}; the bag writer on CPU '
            f"{', '.join(map(str, sorted(bag_writer_cpus)))}"
        )
        return bag_writer_cpus

    # recording

    def _open_recorder(self) -> Recorder:
        """
        Return a recorder for every topic, before anything is published.

        ConfigurationError naming log.folder if it cannot be written; StartupError for any other
        reason, such as a message definition that cannot be found (before any folder is made).
        """
        metadata = {
            'parameters': json.dumps(self.parameter_values(), sort_keys=True),
            'package_version': package_version(),
        }
        # The latest status starts every file of a split bag, as the latched URDF does.
        topics = [
            (topic, publisher.msg_type, publisher.qos_profile,
             True if topic == self._diagnostics_topic else None)
            for topic, publisher in self._topic_publishers.items()
        ]
        # and the TF robot_state_publisher would publish, logged only (docs/logging.md)
        topics += [(TF_STATIC_TOPIC, messages.TFMessage, TF_STATIC_QOS, None),
                   (TF_TOPIC, messages.TFMessage, TF_QOS, None)]
        try:
            return Recorder(
                self.config.log_folder, topics=topics, metadata=metadata,
                cpus=self._bag_writer_cpus, max_bag_size=self.config.log_max_bag_size,
                max_bag_duration=self.config.log_max_bag_duration,
            )
        except LogFolderError as error:
            raise ConfigurationError('log.folder', str(error)) from None
        except OSError as error:  # every BagError
            raise StartupError(f'cannot record: {error}') from None

    def _publish(self, topic: str, message: Any, log_time_ns: int) -> None:
        self._send(topic, encode_cdr(message), log_time_ns)

    def _send(self, topic: str, data: bytes, log_time_ns: int) -> None:
        """
        Publish a message encoded by ``encode_cdr``.

        (or an encoder equal to it) and log it: subscribers get the very bytes that are logged.
        """
        self._topic_publishers[topic].publish(data)
        self._record(topic, data, log_time_ns)

    def _record(self, topic: str, data: bytes, log_time_ns: int) -> None:
        if self._recorder is None or self._recording_error is not None:
            return
        try:
            self._recorder.record(topic, data, log_time_ns)
        except OSError as error:
            # The data keep flowing; diagnostics report the lost log.
            self._recording_error = f'recording stopped: {error}'
            self.get_logger().error(self._recording_error)

    def flush_publishers(self, timeout: float = 1.0) -> None:
        """
        Give subscribers up to ``timeout`` seconds in all to acknowledge what was published.

        The final state of a 'stop' run must not die with the process.
        """
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
            self.get_logger().error(f'could not finalize the log: {error}')
            return False
        bag = self._recorder.bag_path
        count = BagMetadata.read(bag).message_count
        self.get_logger().info(f'bag finalized: {bag}, {count} messages')
        return True

    # motion

    def _timer_period(self) -> float:
        """
        Return the state timer's period: rate_hz in real_time mode.

        In fixed_step mode the timer is re-armed for each step's time, and this first period only
        starts it.
        """
        if self.config.mode == MotionMode.REAL_TIME:
            return 1.0 / self.config.rate_hz
        return 1e-3

    def _restart_motion(self) -> None:
        self._motion_start: Time | None = None
        self._state: LinkageState | None = None
        self._motion_started = False  # no state of this motion published yet
        self._control.back_to_start()
        self._state_time: Time | None = None
        self._step = 0
        self._ticks = 0
        self._pass_index = 0
        # Missed deadlines count over the whole run, across restarts.
        self._missed_before_restart = self._missed_deadlines

    def _tick(self) -> None:
        if self.exit_code is not None:
            return
        now = self.get_clock().now()
        if now.nanoseconds == 0:
            return  # use_sim_time and no /clock yet: the motion has no time to start at
        if self._control.paused:
            if self._state is None:
                self._wait_at_alpha_start(now)
            self._state_timer.cancel()  # ~/resume or a restart re-arms it
            return
        if self._motion_start is None or now < self._motion_start:
            # First tick, or ROS time jumped back (e.g. a simulation restarted): start over.
            self._restart_motion()
            self._motion_start = now
        if self.config.mode == MotionMode.REAL_TIME:
            self._advance_in_real_time(now)
        else:
            self._advance_steps(now)

    def _advance_in_real_time(self, now: Time) -> None:
        elapsed = (now - self._motion_start).nanoseconds * 1e-9
        self._count_tick(elapsed)
        sample = sample_at_time(self.config, elapsed)
        if sample is None:
            self._cannot_go_on(None)
            return
        # The end of a 'stop' pass is published at the time the drive law reaches it.
        at = self._motion_time(sample.motion_time) if sample.final else now
        self._publish_sample(sample, at)

    def _advance_steps(self, now: Time) -> None:
        """
        Publish every step whose drive-law time has come, each stamped with that time.

        Then re-arm the timer for the next step's time.
        """
        published = 0
        while self.exit_code is None:
            sample = sample_at_step(self.config, self._step)
            if sample is None:
                self._cannot_go_on(None)
                return
            due = self._motion_time(sample.motion_time)
            if due > now:
                self._state_timer.timer_period_ns = (due - now).nanoseconds
                self._state_timer.reset()
                return
            if published:
                # The step before this one went out only once this one's time had come.
                self._missed_deadlines += 1
            published += 1
            self._step += 1
            self._ticks += 1
            self._rate_meter.tick()
            self._publish_sample(sample, due)

    def _motion_time(self, seconds: float) -> Time:
        """Return the node-clock time ``seconds`` of drive-law time after the motion started."""
        return self._motion_start + Duration(nanoseconds=round(seconds * 1e9))

    def _publish_sample(self, sample: MotionSample, at: Time) -> None:
        config = self.config
        if met_dead_point(config, self._pass_index, sample.pass_index):
            self._publish_diagnostics(dead_point_problem(config), at)
        self._pass_index = sample.pass_index
        try:
            state = solve_sample(config, sample)
        except (DeadPointError, UnreachableError) as error:
            if config.end_behavior == EndBehavior.STOP:
                self._cannot_go_on(str(error))
            # loop and bounce turn round at the dead point itself, which has no state to show.
            return
        self._publish_state(state, sample.motion_time, at)
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
        self._rate_meter.tick()

    def _publish_state(self, state: LinkageState, motion_time: float, at: Time) -> None:
        """
        Publish a state stamped ``at``.

        The first of a motion comes after its scene (so a viewer knows the frame before anything
        refers to it), the URDF if the geometry is new, and the status that says the crank moves.
        """
        first = not self._motion_started
        self._motion_started = True
        self._state = state
        self._state_time = at
        if first:
            if self._encoded_linkage != self.config.linkage:
                self._prepare_encoders()
            self._publish_markers()
            if self._described_linkage != self.config.linkage:
                self._publish_robot_description(at)
            self._activity = 'moving'
            self._publish_diagnostics()
        nanoseconds = at.nanoseconds
        self._joint_positions = messages.joint_positions(state, self._joint_positions)
        self._send(
            self._joint_states_topic,
            self._joint_state_encoder.encode(state, nanoseconds, self._joint_positions),
            nanoseconds,
        )
        if self._robot_transforms is not None:
            self._record(
                TF_TOPIC,
                self._robot_transforms.message(
                    dict(zip(messages.JOINT_NAMES, self._joint_positions)), nanoseconds),
                nanoseconds,
            )
        self._send(
            self._state_topic,
            self._state_encoder.encode(state, nanoseconds, motion_time),
            nanoseconds,
        )
        if self._status_schedule.due(nanoseconds):
            self._publish_diagnostics()

    def _wait_at_alpha_start(self, now: Time) -> None:
        """
        Publish the scene at alpha_start, the URDF if the geometry is new, and the status.

        No state: the first one comes after ~/resume.
        """
        self._state = solve_sample(self.config, MotionSample(self.config.alpha_start))
        self._state_time = now
        if self._encoded_linkage != self.config.linkage:
            self._prepare_encoders()
        self._publish_markers()
        if self._described_linkage != self.config.linkage:
            self._publish_robot_description(now)
        self._activity = self._control.activity(None)
        self._publish_diagnostics()

    # start control (~/pause, ~/resume, ~/reset)

    def _answer(self, act: Callable[[], ServiceAnswer]) -> Callable[..., Trigger.Response]:
        """Return a Trigger service callback that answers with what ``act`` did."""
        def callback(_request: Trigger.Request, response: Trigger.Response) -> Trigger.Response:
            answer = act()
            response.success, response.message = answer.success, answer.message
            if answer.success:
                self.get_logger().info(answer.message)
            return response
        return callback

    def _pause(self) -> ServiceAnswer:
        now = self.get_clock().now()
        started = self._motion_started and self._motion_start is not None
        answer = self._control.pause(
            (now - self._motion_start).nanoseconds if started else None,
            self._state.alpha if started else None,
        )
        if answer.success:
            self._activity = self._control.activity(self._state.alpha if started else None)
            self._publish_diagnostics()
        return answer

    def _resume(self) -> ServiceAnswer:
        answer, held = self._control.resume()
        if not answer.success:
            return answer
        if held is None:
            self._restart_motion()  # from alpha_start
        else:
            self._motion_start = self.get_clock().now() - Duration(nanoseconds=held)
            self._activity = 'moving'
            self._publish_diagnostics()
        self._state_timer.reset()
        self._tick()
        return answer

    def _reset(self) -> ServiceAnswer:
        answer = self._control.reset(self.config.alpha_start)
        self._restart_motion()
        self._state_timer.reset()
        self._tick()
        return answer

    def _prepare_encoders(self) -> None:
        linkage = self.config.linkage
        self._state_encoder = messages.LinkageStateEncoder(linkage, self._frame_id)
        self._marker_encoder = messages.MarkerArrayEncoder(linkage, self._frame_id)
        self._encoded_linkage = linkage

    def _finish_at_end(self) -> None:
        self._activity = (
            f'reached alpha_end = {math.degrees(self.config.alpha_end):.6f}°; stopped'
        )
        self.get_logger().info(self._activity)
        self._publish_markers()
        self._flush_log()
        self._publish_diagnostics()
        self.exit_code = EXIT_OK

    def _cannot_go_on(self, detail: str | None) -> None:
        config = self.config
        if config.blocked_at is not None:
            problem = dead_point_problem(config)
        else:
            problem = f'the crank cannot go on: {detail}'
        self._problem = problem
        self.get_logger().error(problem)
        self._flush_log()
        self._publish_diagnostics()
        self.exit_code = EXIT_FAILED

    # display and diagnostics

    def _publish_robot_description(self, at: Time) -> None:
        self._described_linkage = self.config.linkage
        message = String(data=urdf_text(self.config.linkage, self.config.frame_id))
        self._publish(self._description_topic, message, at.nanoseconds)
        if self._recorder is not None:
            # What robot_state_publisher publishes for this description, for the bag only.
            self._robot_transforms = messages.RobotStateTransforms(
                message.data, self.config.frame_prefix)
            self._record(TF_STATIC_TOPIC, self._robot_transforms.static_message(at.nanoseconds),
                         at.nanoseconds)

    def _publish_markers(self) -> None:
        """Return the scene of the latest state, stamped with that state's time."""
        if self._state is None:
            return
        nanoseconds = self._state_time.nanoseconds
        self._send(
            self._markers_topic, self._marker_encoder.encode(self._state, nanoseconds),
            nanoseconds,
        )

    def _publish_diagnostics(self, event: str | None = None, at: Time | None = None) -> None:
        """
        Publish the status.

        Stamped ``at`` (by default the latest state's time, so that log times never fall behind the
        states'); ``event``, a problem of this moment only, makes it ERROR.
        """
        now = self.get_clock().now()
        if at is None:
            at = self._state_time if self._state_time is not None else now
        self._rate_meter.update(now.nanoseconds)
        self._status_schedule.sent(at.nanoseconds)
        problem = event or self._problem or self._recording_error
        level, text = assess(self.config, self._state, problem, self._activity)
        message = messages.diagnostic_array(
            at.to_msg(),
            f'{self.get_name()}: {DIAGNOSTIC_TASK}',
            f"four-bar linkage ({self.config.preset or 'explicit geometry'})",
            level,
            text,
            self._diagnostic_values(),
        )
        self._publish(self._diagnostics_topic, message, at.nanoseconds)

    def _diagnostic_values(self) -> dict[str, str]:
        recorder = self._recorder
        return diagnostics.key_values(
            self.config, self._control.state, self._state, self._rate_meter.rate,
            self._missed_deadlines,
            None if recorder is None else str(recorder.bag_path),
            None if recorder is None else recorder.size_bytes,
        )

    def _flush_log(self) -> None:
        """
        Have the bag writer write out what it holds before the run's last status.

        So that its log size is the bag's.
        """
        if self._recorder is None or self._recording_error is not None:
            return
        try:
            self._recorder.flush()
        except OSError as error:
            self._recording_error = f'recording stopped: {error}'
            self.get_logger().error(self._recording_error)


# --- process ------------------------------------------------------------------------------


def _report_start_up_failure(text: str) -> None:
    """
    Report the one line saying why the node cannot start.

    To the node's logger (console, /rosout, log file) and plainly to stderr.
    """
    get_logger(NODE_NAME).fatal(text)
    print(f'{NODE_NAME}: {text}', file=sys.stderr, flush=True)


def main(args: list[str] | None = None) -> int:
    """Run the node until it finishes, or until SIGINT or SIGTERM; return the exit status."""
    # rclpy's own SIGINT handler would shut the context down under our feet; ours lets the
    # loop below finalize the log first.
    try:
        rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    except RuntimeError as error:  # rclpy's RCLError: ROS arguments rcl cannot use
        # rcl's text, without the source locations it appends ('…, at /src/rcl/x.c:352')
        _report_start_up_failure(
            'cannot start ROS: ' + re.sub(r', at \S+:\d+', '', str(error)))
        return EXIT_CONFIGURATION
    received: list[int] = []

    def request_stop(signal_number: int, _frame: object) -> None:
        received.append(signal_number)

    signal.signal(signal.SIGINT, request_stop)
    signal.signal(signal.SIGTERM, request_stop)
    try:
        try:
            node = LinkageNode()
        except ConfigurationError as error:
            _report_start_up_failure(f'invalid parameter {error}')
            return EXIT_CONFIGURATION
        except StartupError as error:
            _report_start_up_failure(str(error))
            return EXIT_CONFIGURATION
        # The events executor dispatches timers and services from C++ instead of rebuilding a
        # wait set in Python for every callback: at 1 kHz it halves the process's CPU
        # (docs/benchmarks.md, section 3). On simulated time rclpy 7.1.6's events executor
        # runs a timer created at run time (a rate_hz change) twice at its first /clock step,
        # which also shifts its schedule by a period, so there the node keeps rclpy's default
        # executor. The events executor's spin() busy-waits without running timers; spin_once
        # returns after each callback, and at the latest after the timeout, so the signal
        # handlers above run and the loop sees the end of the run.
        if node.get_parameter('use_sim_time').value:
            executor: Executor = SingleThreadedExecutor()
        else:
            executor = EventsExecutor()
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


if __name__ == '__main__':
    sys.exit(main())
