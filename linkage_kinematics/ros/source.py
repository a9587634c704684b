# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
What a source of the node's states is, and what it may ask of the node that runs it.

One source runs per node: the drive law on a timer (``drive_law_source``), the four-bar's
measured joint on a topic (``measured_source``) or every loop of a lab's URDF
(``loop_source``). The node holds it as a ``Source``; a source asks its host only what
``SourceHost`` declares, so that it depends on no node and a test can host it in a fake of its
own. ``RunStatus`` is the status the host owns, which a source changes only through it.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Protocol

from linkage_kinematics.kinematics.solver import LinkageState
from linkage_kinematics.model.joints import TreeValues
from linkage_kinematics.ros.exit_codes import ExitCode
from linkage_kinematics.run.configuration import RunConfiguration
from linkage_kinematics.run.control import RunControl, ServiceAnswer
from linkage_kinematics.run.diagnostics import MeasuredHealth, Status, StatusInputs
from rclpy.qos import QoSProfile


class Source(Protocol):
    """What the node asks of its source, whichever it is (docs/parameters.md: Services)."""

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
