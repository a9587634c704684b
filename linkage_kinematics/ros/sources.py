# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The node's two sources wired to ROS: the drive law on a timer, the measured joint on a topic.

Each wraps a pure module (``motion.DriveLawRun``, ``measured.MeasuredFollower``) with the timer
or the subscription that feeds it, and hands the states it gives to its host, the node, which
publishes them. One of them runs per node (parameter ``source``). Both are a ``Source``, the
interface the node holds them by; each asks its host only what ``SourceHost`` declares, so a
source depends on no node, and a test can host one in a fake of its own.
"""

from __future__ import annotations

from collections.abc import Callable
import math
from typing import Any, Protocol

from linkage_kinematics.bag.cdr import JointStateDecoder
from linkage_kinematics.kinematics.solver import LinkageState
from linkage_kinematics.loops.intake import DropReason
from linkage_kinematics.model.joints import Link, TreeValues
from linkage_kinematics.ros.exit_codes import ExitCode
from linkage_kinematics.ros.outputs import MEASURED_QOS, MEASURED_TOPIC
from linkage_kinematics.run.configuration import EndBehavior, RunConfiguration
from linkage_kinematics.run.control import RunControl, ServiceAnswer
from linkage_kinematics.run.diagnostics import MeasuredHealth, Status, StatusInputs
from linkage_kinematics.run.measured import MeasuredFollower
from linkage_kinematics.run.motion import (
    dead_point_problem,
    DriveLawRun,
    MotionSample,
    solve_sample,
)
from rclpy.qos import QoSProfile
from sensor_msgs.msg import JointState


class Source(Protocol):
    """What the node asks of its source, whichever it is (README: Start control, Diagnostics)."""

    @property
    def health(self) -> MeasuredHealth | None:
        """Return the measured data's record for diagnostics (None: no measured data)."""

    @property
    def stale(self) -> bool:
        """Whether the measured data is stale: no valid sample within measured.timeout."""

    @property
    def missed_deadlines(self) -> int:
        """Return the deadlines missed since the start, for diagnostics."""

    def start(self) -> None:
        """Begin, once the node is built: publish what comes first."""

    def reconfigure(self, new: RunConfiguration) -> None:
        """Take the node's new configuration (the motion restarts only by ``restart``)."""

    def restart(self) -> None:
        """Start the motion again from its beginning."""

    def pause(self) -> ServiceAnswer:
        """Act on ``~/pause``."""

    def resume(self) -> ServiceAnswer:
        """Act on ``~/resume``."""

    def reset(self) -> ServiceAnswer:
        """Act on ``~/reset``."""

    def statuses(self, inputs: StatusInputs) -> tuple[Status, ...] | None:
        """Return the source's own statuses; None: the four-bar's (``diagnostics.report``)."""


class SourceTimer(Protocol):
    """What a source does with a timer its host made for it (rclpy's Timer does this)."""

    timer_period_ns: int

    def cancel(self) -> None:
        """Stop calling back until ``reset``."""

    def reset(self) -> None:
        """Call back a whole period from now, and on."""


class SourceHost(Protocol):
    """
    What a source may ask of the node that runs it.

    The node owns its status: a source says what the motion does (``set_activity``) and how a
    run ends (``finish``, ``fail``), and never writes the node's fields.
    """

    @property
    def config(self) -> RunConfiguration:
        """Return the current configuration."""

    @property
    def control(self) -> RunControl:
        """Return the run control, which ``~/pause``, ``~/resume`` and ``~/reset`` change."""

    @property
    def state(self) -> LinkageState | None:
        """Return the latest state shown (published, or the scene of a motion waiting)."""

    @property
    def motion_started(self) -> bool:
        """Whether a state of this motion was published (not only the scene of it waiting)."""

    @property
    def finished(self) -> bool:
        """Whether the run has ended (``finish`` or ``fail``)."""

    def now_ns(self) -> int:
        """Return the node clock's time (ns)."""

    def create_timer(self, timer_period_sec: float,
                     callback: Callable[[], None]) -> SourceTimer:
        """Return a timer that calls ``callback`` every ``timer_period_sec`` (s)."""

    def destroy_timer(self, timer: SourceTimer) -> bool:
        """Destroy a timer made by ``create_timer``."""

    def create_subscription(self, msg_type: type, topic: str,
                            callback: Callable[[Any], None], qos_profile: QoSProfile, *,
                            raw: bool = False) -> object:
        """
        Subscribe ``callback`` to ``topic`` (relative to the node's namespace).

        ``raw``: the callback receives the message's CDR bytes rather than the message.
        """

    def publish_state(self, state: LinkageState, stamp_ns: int, motion_time: float,
                      joints: TreeValues | None = None) -> None:
        """
        Publish a state; the first of a motion after its scene, URDF and status.

        ``joints``: the tree's lab joint values, where the source solved them.
        """

    def show_waiting(self, state: LinkageState, stamp_ns: int) -> None:
        """Publish the scene of ``state``, the URDF if new, and the status; no state."""

    def forget_state(self) -> None:
        """Make the next state a motion's first: its scene and status go out before it."""

    def publish_diagnostics(self, event: str | None = None, at_ns: int | None = None) -> None:
        """Publish the status now; ``event`` makes it ERROR, ``at_ns`` stamps it."""

    def publish_description(self) -> None:
        """Publish the URDF if it is new."""

    def set_activity(self, text: str) -> None:
        """Say what the motion does now (the status's message while all is well)."""

    def finish(self, message: str) -> None:
        """End the run where it was to end: ``message`` is the last status; exit status 0."""

    def fail(self, problem: str) -> None:
        """End the run because it cannot go on: ``problem`` is the last status; exit status 1."""


class RunStatus:
    """
    The status a source's host owns: what the motion does, what stopped it, how the run ended.

    A mixin for the host (the node, or a test's fake host), which gives it ``flush_log``,
    ``publish_markers``, ``publish_diagnostics`` and ``get_logger``: ``finish`` and ``fail`` end
    the run in the one order there is, the log written out before the last status (so that its
    log size is the bag's), and the exit code last (``main`` stops spinning once it is set).
    """

    activity = 'starting'
    problem: str | None = None
    exit_code: ExitCode | None = None
    flush_log: Callable[[], None]
    publish_markers: Callable[[], None]
    publish_diagnostics: Callable[..., None]
    get_logger: Callable[[], Any]

    @property
    def finished(self) -> bool:
        """Whether the run has ended (``finish`` or ``fail``)."""
        return self.exit_code is not None

    def set_activity(self, text: str) -> None:
        """Say what the motion does now (the status's message while all is well)."""
        self.activity = text

    def finish(self, message: str) -> None:
        """End the run where it was to end (``stop`` at alpha_end), with the final scene."""
        self.activity = message
        self.get_logger().info(message)
        self.publish_markers()
        self._end_run(ExitCode.OK)

    def fail(self, problem: str) -> None:
        """End the run because the motion cannot go on; ``problem`` makes the last status ERROR."""
        self.problem = problem
        self.get_logger().error(problem)
        self._end_run(ExitCode.FAILED)

    def _end_run(self, exit_code: ExitCode) -> None:
        self.flush_log()
        self.publish_diagnostics()
        self.exit_code = exit_code


class DriveLawTimer:
    """The drive_law source: a timer at rate_hz (or re-armed per step) over ``DriveLawRun``."""

    health = None  # diagnostics: no measured data
    stale = False

    def __init__(self, host: SourceHost) -> None:
        self._host = host
        self.run = DriveLawRun(host.config)
        self._timer = host.create_timer(self.run.timer_period, self.tick)
        # A ~/reset while paused shows the state at alpha_start at the next tick that can.
        self._reset_pose_due = False

    def start(self) -> None:
        """
        Start the motion now: its first state, scene first, is published at once.

        Unless the clock does not run yet (use_sim_time before the first /clock).
        """
        self.tick()

    @property
    def missed_deadlines(self) -> int:
        """Return the deadlines missed since the start (``DriveLawRun``)."""
        return self.run.missed_deadlines

    @staticmethod
    def statuses(_inputs: StatusInputs) -> None:
        """Return None: the drive law's status is the four-bar's (``diagnostics.report``)."""
        return None

    def reconfigure(self, new: RunConfiguration) -> None:
        """Take the node's new configuration; the motion changes at ``restart``."""
        self.run.config = new

    def restart(self) -> None:
        """Start the motion again from alpha_start, now (a paused one waits there)."""
        self._back_to_start()
        self._host.destroy_timer(self._timer)
        self._timer = self._host.create_timer(self.run.timer_period, self.tick)
        self.tick()

    def _back_to_start(self) -> None:
        self.run.restart()
        self._host.forget_state()
        self._host.control.back_to_start()

    # ~/pause, ~/resume, ~/reset

    def pause(self) -> ServiceAnswer:
        """Hold the motion where it is; the status says where."""
        host = self._host
        started = host.motion_started and self.run.start_ns is not None
        alpha = host.state.alpha if started else None
        answer = host.control.pause(
            host.now_ns() - self.run.start_ns if started else None, alpha)
        if answer.success:
            host.set_activity(host.control.activity(alpha))
            host.publish_diagnostics()
        return answer

    def resume(self) -> ServiceAnswer:
        """Go on from the held state, or start the motion from alpha_start."""
        host = self._host
        answer, held_ns = host.control.resume()
        if not answer.success:
            return answer
        if held_ns is None:
            self._back_to_start()  # from alpha_start
        else:
            # The motion goes on where it stopped: its time origin moves by the pause.
            self.run.start_ns = host.now_ns() - held_ns
            host.set_activity('moving')
            host.publish_diagnostics()
        self._timer.reset()
        self.tick()
        return answer

    def reset(self) -> ServiceAnswer:
        """
        Send the motion back to alpha_start: a running one starts again at once.

        A paused one stays paused there, and its state at alpha_start is published once, as a
        simulator's reset shows the initial pose, so that subscribers stop showing the held one.
        """
        answer = self._host.control.reset(self._host.config.alpha_start)
        self._back_to_start()
        self._reset_pose_due = self._host.control.paused
        self._timer.reset()
        self.tick()
        return answer

    def tick(self) -> None:
        """Publish the states the drive law has made due by now (the timer's callback)."""
        host = self._host
        now_ns = host.now_ns()
        if host.finished or now_ns == 0:
            return  # finished, or use_sim_time and no /clock yet: no time to start at
        reset_pose_due, self._reset_pose_due = self._reset_pose_due, False
        if host.control.paused:
            if host.state is None:
                # Waiting at alpha_start (autostart false, or reset while paused): its scene,
                # and after a reset its state too.
                config = host.config
                at_start = solve_sample(config, MotionSample(config.alpha_start))
                host.set_activity(host.control.activity(None))
                if reset_pose_due:
                    host.publish_state(at_start, now_ns, 0.0)
                else:
                    host.show_waiting(at_start, now_ns)
            self._timer.cancel()  # ~/resume or a restart re-arms it
            return
        if self.run.start_ns is None or now_ns < self.run.start_ns:
            host.forget_state()  # the motion starts (again): its scene and status come first
        due_states, next_ns, blocked = self.run.advance(now_ns)
        for due in due_states:
            if due.met_dead_point:
                host.publish_diagnostics(dead_point_problem(host.config), due.at_ns)
            if due.state is None:
                if host.config.end_behavior is EndBehavior.STOP:
                    self._cannot_go_on(due.refusal)
                    return
                continue  # loop and bounce turn round at the dead point, which has no state
            if not host.motion_started:
                host.set_activity('moving')
            host.publish_state(due.state, due.at_ns, due.sample.motion_time)
            if due.sample.final:
                host.finish(
                    f'reached alpha_end = {math.degrees(host.config.alpha_end):.6f}°; stopped')
                return
        if blocked:
            self._cannot_go_on(None)
        elif next_ns is not None:
            self._timer.timer_period_ns = next_ns - now_ns
            self._timer.reset()

    def _cannot_go_on(self, detail: str | None) -> None:
        config = self._host.config
        self._host.fail(dead_point_problem(config) if config.blocked_at is not None
                        else f'the crank cannot go on: {detail}')


class MeasuredSubscription:
    """The measured source: ``measured_joint_states`` into a ``MeasuredFollower``."""

    missed_deadlines = 0  # no deadlines: the input sets the pace

    def __init__(self, host: SourceHost) -> None:
        self._host = host
        config = host.config
        self._follower = MeasuredFollower(config)
        self.health = MeasuredHealth(host.now_ns())
        self.stale = False  # no valid sample within measured.timeout
        self._driver_name = config.joints[Link(config.driver.value)].name
        host.set_activity(
            f'paused: {self._driver_name} is not followed until ~/resume' if host.control.paused
            else f'waiting for {self._driver_name} on measured_joint_states')
        # raw: JointStateDecoder reads the bytes in a sixth of deserialize_message's time
        self._decoder = JointStateDecoder()
        host.create_subscription(
            JointState, MEASURED_TOPIC, self._on_message, MEASURED_QOS, raw=True)
        self._freshness_timer = host.create_timer(0.25 * config.measured_timeout,
                                                  self._check_freshness)

    def start(self) -> None:
        """Publish the URDF (before the first sample, for robot_state_publisher) and status."""
        self._host.publish_description()
        self._host.publish_diagnostics()

    @staticmethod
    def statuses(_inputs: StatusInputs) -> None:
        """Return None: the measured four-bar's status is ``diagnostics.report``'s."""
        return None

    def reconfigure(self, new: RunConfiguration) -> None:
        """Take the node's new configuration: thresholds, and the lab's names and mapping."""
        old = self._follower.config
        if new.joints != old.joints:
            # The lab's names and mapping: the driver is read anew under them.
            self._follower = MeasuredFollower(new)
            self._driver_name = new.joints[Link(new.driver.value)].name
        else:
            self._follower.reconfigure(new)
        if new.measured_timeout != old.measured_timeout:
            self._host.destroy_timer(self._freshness_timer)
            self._freshness_timer = self._host.create_timer(0.25 * new.measured_timeout,
                                                            self._check_freshness)

    def restart(self) -> None:
        """Forget the motion: the next valid sample starts it afresh on ``branch``."""
        self._follower.restart()
        self._host.publish_description()

    # ~/pause, ~/resume, ~/reset

    def pause(self) -> ServiceAnswer:
        """Ignore the samples until ~/resume."""
        host = self._host
        if not host.control.pause(None, None).success:
            return ServiceAnswer(False, 'already paused; ~/resume goes on')
        host.set_activity(f'paused: {self._driver_name} is not followed until ~/resume')
        host.publish_diagnostics()
        return ServiceAnswer(True, f'paused: samples of {self._driver_name} are ignored')

    def resume(self) -> ServiceAnswer:
        """Follow the driver again from its next sample, the motion started afresh."""
        host = self._host
        answer, _ = host.control.resume()
        if not answer.success:
            return answer
        # What the mechanism did meanwhile is unknown: its next sample starts the motion afresh.
        self._follower.restart()
        host.set_activity(f'waiting for {self._driver_name} on measured_joint_states')
        host.publish_diagnostics()
        return ServiceAnswer(True, f'following {self._driver_name} again from its next sample')

    def reset(self) -> ServiceAnswer:
        """Start the motion afresh at the next valid sample."""
        self._follower.restart()
        paused = self._host.control.paused
        return ServiceAnswer(True, 'the motion starts afresh at the next valid sample' + (
            '; paused: ~/resume follows it' if paused else ''))

    def _on_message(self, data: bytes) -> None:
        if self._host.control.paused:
            return  # ~/pause: not followed, not counted
        try:
            fields = self._decoder.decode(data)
        except ValueError:
            self.health.drop(DropReason.MALFORMED)
            return
        followed = self._follower.follow(*fields)
        if followed is None:
            return  # this node's own joint states, heard back
        if isinstance(followed, DropReason):
            self.health.drop(followed)
            return
        self.health.accept(self._host.now_ns(), followed.velocity)
        if self.stale:
            self.stale = False
            self._host.forget_state()  # publish the scene and the status with the next state
        self._host.set_activity(f'following {self._driver_name}')
        self._host.publish_state(followed.state, followed.stamp_ns, followed.motion_time,
                                 followed.joints)

    def _check_freshness(self) -> None:
        """Report at once when the measured data goes stale."""
        host = self._host
        if not self.stale and self.health.is_stale(host.now_ns(), host.config.measured_timeout):
            self.stale = True
            self._follower.restart()  # a long gap: the next valid sample starts afresh
            host.publish_diagnostics()
