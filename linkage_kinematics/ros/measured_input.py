# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
What both measured sources do alike with their input, ``measured_joint_states``.

``MeasuredInput`` is the base of ``measured_source.MeasuredSubscription`` (the four-bar's driver)
and ``loop_source.RobotLoopsSubscription`` (a lab's loops): it subscribes to the input as CDR
bytes (``JointStateDecoder`` reads them in a sixth of ``deserialize_message``'s time), acts on
~/pause, ~/resume and ~/reset, and reports at once when the data goes stale (no valid sample
within ``measured.timeout``), forgetting the motion so that the next valid sample starts it
afresh. A source says what it follows (``_show_activity`` and the answers' words), what
forgetting its motion means (``_forget_motion``) and takes each message (``_on_message``).
"""

from __future__ import annotations

from abc import ABC, abstractmethod

from linkage_kinematics.ros.outputs import MEASURED_QOS, MEASURED_TOPIC
from linkage_kinematics.ros.source import SourceHost
from linkage_kinematics.run.configuration import RunConfiguration
from linkage_kinematics.run.control import ServiceAnswer
from linkage_kinematics.run.diagnostics import Freshness
from linkage_kinematics.shared.cdr import JointStateDecoder
from sensor_msgs.msg import JointState


class MeasuredInput(ABC):
    """
    The measured input of one source; ``health`` counts its samples and says when it is stale.

    ``paused_answer`` and ``resumed_answer`` are the source's words for ~/pause and ~/resume.
    """

    missed_deadlines = 0  # no deadlines: the input sets the pace
    paused_answer: str
    resumed_answer: str

    def __init__(self, host: SourceHost, health: Freshness, efforts: bool = False) -> None:
        """``efforts``: whether the source reads the input's efforts (``JointStateDecoder``)."""
        self._host = host
        self._health = health
        self.stale = False  # no valid sample within measured.timeout
        self._decoder = JointStateDecoder(efforts)
        host.create_subscription(JointState, MEASURED_TOPIC, self._on_message, MEASURED_QOS,
                                 raw=True)
        self._timeout = host.config.measured.timeout
        self._freshness_timer = host.create_timer(0.25 * self._timeout, self._check_freshness)

    @abstractmethod
    def _on_message(self, data: bytes) -> None:
        """Take one message's CDR bytes."""

    @abstractmethod
    def _show_activity(self) -> None:
        """Say what the source does now (the status's message while all is well)."""

    @abstractmethod
    def _forget_motion(self) -> None:
        """Forget the motion: the next valid sample starts it afresh."""

    def _retime(self, new: RunConfiguration) -> None:
        """Check freshness four times per ``measured.timeout`` of ``new``, if it changed."""
        if new.measured.timeout != self._timeout:
            self._timeout = new.measured.timeout
            self._host.destroy_timer(self._freshness_timer)
            self._freshness_timer = self._host.create_timer(0.25 * self._timeout,
                                                            self._check_freshness)

    # ~/pause, ~/resume, ~/reset

    def pause(self) -> ServiceAnswer:
        """Ignore the input until ~/resume."""
        host = self._host
        if not host.control.pause(None, None).success:
            return ServiceAnswer(False, 'already paused; ~/resume goes on')
        self._show_activity()
        host.publish_diagnostics()
        return ServiceAnswer(True, self.paused_answer)

    def resume(self) -> ServiceAnswer:
        """Follow the input again from its next sample, the motion started afresh."""
        host = self._host
        answer, _ = host.control.resume()
        if not answer.success:
            return answer
        # What the mechanism did meanwhile is unknown: its next sample starts the motion afresh.
        self._forget_motion()
        self._show_activity()
        host.publish_diagnostics()
        return ServiceAnswer(True, self.resumed_answer)

    def reset(self) -> ServiceAnswer:
        """Start the motion afresh at the next valid sample."""
        self._forget_motion()
        paused = self._host.control.paused
        return ServiceAnswer(True, 'the motion starts afresh at the next valid sample' + (
            '; paused: ~/resume follows it' if paused else ''))

    def _check_freshness(self) -> None:
        """Report at once when the measured data goes stale."""
        host = self._host
        if not self.stale and self._health.is_stale(host.now_ns(), host.config.measured.timeout):
            self.stale = True
            self._forget_motion()  # a long gap: the next valid sample starts afresh
            host.publish_diagnostics()
