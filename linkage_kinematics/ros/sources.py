# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The node's two sources wired to ROS: the drive law on a timer, the measured joint on a topic.

Each wraps a pure module (``motion.DriveLawRun``, ``measured.MeasuredFollower``) with the timer
or the subscription that feeds it, and hands the states it gives to the node, which publishes
them (``LinkageNode.publish_state``). One of them runs per node (parameter ``source``).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from linkage_kinematics.model.joints import Link
from linkage_kinematics.ros.exit_codes import ExitCode
from linkage_kinematics.run.configuration import EndBehavior, RunConfiguration
from linkage_kinematics.run.control import ServiceAnswer
from linkage_kinematics.run.diagnostics import MeasuredHealth
from linkage_kinematics.run.measured import MeasuredFollower, Rejection
from linkage_kinematics.run.motion import (
    dead_point_problem,
    DriveLawRun,
    MotionSample,
    solve_sample,
)
from rclpy.qos import QoSProfile
from sensor_msgs.msg import JointState

if TYPE_CHECKING:
    from linkage_kinematics.ros.node import LinkageNode

# Deep enough that a burst of encoder samples waiting for one slow callback is never lost.
MEASURED_QOS = QoSProfile(depth=100)


class DriveLawTimer:
    """The drive_law source: a timer at rate_hz (or re-armed per step) over ``DriveLawRun``."""

    health = None  # diagnostics: no measured data
    stale = False

    def __init__(self, node: LinkageNode) -> None:
        self._node = node
        self.run = DriveLawRun(node.config)
        self._timer = node.create_timer(self.run.timer_period, self.tick)

    def start(self) -> None:
        """
        Start the motion now: its first state, scene first, is published at once.

        Unless the clock does not run yet (use_sim_time before the first /clock).
        """
        self.tick()

    @property
    def missed_deadlines(self) -> int:
        return self.run.missed_deadlines

    def reconfigure(self, old: RunConfiguration, new: RunConfiguration) -> None:
        self.run.config = new

    def restart(self) -> None:
        """Start the motion again from alpha_start, now (a paused one waits there)."""
        self._back_to_start()
        self._node.destroy_timer(self._timer)
        self._timer = self._node.create_timer(self.run.timer_period, self.tick)
        self.tick()

    def _back_to_start(self) -> None:
        self.run.restart()
        self._node.forget_state()
        self._node.control.back_to_start()

    # ~/pause, ~/resume, ~/reset

    def pause(self) -> ServiceAnswer:
        node = self._node
        started = node.motion_started and self.run.start_ns is not None
        alpha = node.state.alpha if started else None
        answer = node.control.pause(
            node.now_ns() - self.run.start_ns if started else None, alpha)
        if answer.success:
            node.activity = node.control.activity(alpha)
            node.publish_diagnostics()
        return answer

    def resume(self) -> ServiceAnswer:
        node = self._node
        answer, held_ns = node.control.resume()
        if not answer.success:
            return answer
        if held_ns is None:
            self._back_to_start()  # from alpha_start
        else:
            # The motion goes on where it stopped: its time origin moves by the pause.
            self.run.start_ns = node.now_ns() - held_ns
            node.activity = 'moving'
            node.publish_diagnostics()
        self._timer.reset()
        self.tick()
        return answer

    def reset(self) -> ServiceAnswer:
        answer = self._node.control.reset(self._node.config.alpha_start)
        self._back_to_start()
        self._timer.reset()
        self.tick()
        return answer

    def tick(self) -> None:
        node = self._node
        now_ns = node.now_ns()
        if node.exit_code is not None or now_ns == 0:
            return  # finished, or use_sim_time and no /clock yet: no time to start at
        if node.control.paused:
            if node.state is None:
                # Waiting at alpha_start (autostart false, or reset while paused): its scene.
                node.activity = node.control.activity(None)
                node.show_waiting(
                    solve_sample(node.config, MotionSample(node.config.alpha_start)), now_ns)
            self._timer.cancel()  # ~/resume or a restart re-arms it
            return
        if self.run.start_ns is None or now_ns < self.run.start_ns:
            node.forget_state()  # the motion starts (again): its scene and status come first
        due_states, next_ns, blocked = self.run.advance(now_ns)
        for due in due_states:
            if due.met_dead_point:
                node.publish_diagnostics(dead_point_problem(node.config), due.at_ns)
            if due.state is None:
                if node.config.end_behavior is EndBehavior.STOP:
                    self._cannot_go_on(due.refusal)
                    return
                continue  # loop and bounce turn round at the dead point, which has no state
            node.publish_state(due.state, due.at_ns, due.sample.motion_time)
            if due.sample.final:
                node.activity = (
                    f'reached alpha_end = {math.degrees(node.config.alpha_end):.6f}°; stopped')
                self._node.get_logger().info(node.activity)
                node.publish_markers()
                node.outputs.flush_log()
                node.publish_diagnostics()
                node.exit_code = ExitCode.OK
                return
        if blocked:
            self._cannot_go_on(None)
        elif next_ns is not None:
            self._timer.timer_period_ns = next_ns - now_ns
            self._timer.reset()

    def _cannot_go_on(self, detail: str | None) -> None:
        node = self._node
        if node.config.blocked_at is not None:
            node.problem = dead_point_problem(node.config)
        else:
            node.problem = f'the crank cannot go on: {detail}'
        self._node.get_logger().error(node.problem)
        node.outputs.flush_log()
        node.publish_diagnostics()
        node.exit_code = ExitCode.FAILED


class MeasuredSubscription:
    """The measured source: ``measured_joint_states`` into a ``MeasuredFollower``."""

    missed_deadlines = 0  # no deadlines: the input sets the pace

    def __init__(self, node: LinkageNode) -> None:
        self._node = node
        config = node.config
        self._follower = MeasuredFollower(config)
        self.health = MeasuredHealth(node.now_ns())
        self.stale = False  # no valid sample within measured.timeout
        self._driver_name = config.joints[Link(config.driver.value)].name
        node.activity = (
            f'paused: {self._driver_name} is not followed until ~/resume' if node.control.paused
            else f'waiting for {self._driver_name} on measured_joint_states')
        node.create_subscription(
            JointState, 'measured_joint_states', self._on_message, MEASURED_QOS)
        self._freshness_timer = node.create_timer(0.25 * config.measured_timeout,
                                                  self._check_freshness)

    def start(self) -> None:
        """Publish the URDF (before the first sample, for robot_state_publisher) and status."""
        self._node.publish_description()
        self._node.publish_diagnostics()

    def reconfigure(self, old: RunConfiguration, new: RunConfiguration) -> None:
        self._follower.config = new
        if new.joints != old.joints:
            # The lab's names and mapping: the driver is read anew under them.
            self._follower = MeasuredFollower(new)
            self._driver_name = new.joints[Link(new.driver.value)].name
        if new.measured_timeout != old.measured_timeout:
            self._node.destroy_timer(self._freshness_timer)
            self._freshness_timer = self._node.create_timer(0.25 * new.measured_timeout,
                                                            self._check_freshness)

    def restart(self) -> None:
        """Forget the motion: the next valid sample starts it afresh on ``branch``."""
        self._follower.restart()
        self._node.publish_description()

    # ~/pause, ~/resume, ~/reset

    def pause(self) -> ServiceAnswer:
        node = self._node
        if not node.control.pause(None, None).success:
            return ServiceAnswer(False, 'already paused; ~/resume goes on')
        node.activity = f'paused: {self._driver_name} is not followed until ~/resume'
        node.publish_diagnostics()
        return ServiceAnswer(True, f'paused: samples of {self._driver_name} are ignored')

    def resume(self) -> ServiceAnswer:
        node = self._node
        answer, _ = node.control.resume()
        if not answer.success:
            return answer
        # What the mechanism did meanwhile is unknown: its next sample starts the motion afresh.
        self._follower.restart()
        node.activity = f'waiting for {self._driver_name} on measured_joint_states'
        node.publish_diagnostics()
        return ServiceAnswer(True, f'following {self._driver_name} again from its next sample')

    def reset(self) -> ServiceAnswer:
        self._follower.restart()
        paused = self._node.control.paused
        return ServiceAnswer(True, 'the motion starts afresh at the next valid sample' + (
            '; paused: ~/resume follows it' if paused else ''))

    def _on_message(self, message: JointState) -> None:
        if self._node.control.paused:
            return  # ~/pause: not followed, not counted
        stamp = message.header.stamp
        followed = self._follower.follow(stamp.sec * 1_000_000_000 + stamp.nanosec,
                                         message.name, message.position, message.velocity)
        if followed is None:
            return  # this node's own joint states, heard back
        if isinstance(followed, Rejection):
            self.health.drop(followed)
            return
        self.health.accept(self._node.now_ns(), followed.velocity)
        if self.stale:
            self.stale = False
            self._node.forget_state()  # publish the scene and the status with the next state
        self._node.activity = f'following {self._driver_name}'
        self._node.publish_state(followed.state, followed.stamp_ns, followed.motion_time)

    def _check_freshness(self) -> None:
        """Report at once when the measured data goes stale."""
        node = self._node
        if not self.stale and self.health.is_stale(node.now_ns(), node.config.measured_timeout):
            self.stale = True
            self._follower.restart()  # a long gap: the next valid sample starts afresh
            node.publish_diagnostics()
