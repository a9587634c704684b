# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The drive-law source: ``motion.DriveLawRun`` on the node's timer (parameter ``source`` drive_law).

``DriveLawTimer`` is a ``source.Source``: a timer at rate_hz (or re-armed per fixed step) asks
the run which states are due and hands them to its host, the node, which publishes them; it
acts on ~/pause, ~/resume and ~/reset, and ends the run at alpha_end or a dead point.
"""

from __future__ import annotations

import math

from linkage_kinematics.ros.source import SourceHost
from linkage_kinematics.run.configuration import EndBehavior, RunConfiguration
from linkage_kinematics.run.control import ServiceAnswer
from linkage_kinematics.run.diagnostics import StatusInputs
from linkage_kinematics.run.motion import (
    dead_point_problem,
    DriveLawRun,
    MotionSample,
    solve_sample,
)


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
        answer = self._host.control.reset(self._host.config.motion.alpha_start)
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
                at_start = solve_sample(config, MotionSample(config.motion.alpha_start))
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
                if host.config.motion.end_behavior is EndBehavior.STOP:
                    self._cannot_go_on(due.refusal)
                    return
                continue  # loop and bounce turn round at the dead point, which has no state
            if not host.motion_started:
                host.set_activity('moving')
            host.publish_state(due.state, due.at_ns, due.sample.motion_time)
            if due.sample.final:
                alpha_end = host.config.motion.alpha_end
                host.finish(f'reached alpha_end = {math.degrees(alpha_end):.6f}°; stopped')
                return
        if blocked:
            self._cannot_go_on(None)
        elif next_ns is not None:
            self._timer.timer_period_ns = next_ns - now_ns
            self._timer.reset()

    def _cannot_go_on(self, detail: str | None) -> None:
        config = self._host.config
        self._host.fail(dead_point_problem(config) if config.motion.blocked_at is not None
                        else f'the crank cannot go on: {detail}')
