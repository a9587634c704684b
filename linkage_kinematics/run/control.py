# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Start control: whether the motion runs, and what ``~/pause``, ``~/resume`` and ``~/reset`` do.

A pure state machine (no ROS): the node asks it, answers each std_srvs/srv/Trigger call with the
returned ServiceAnswer and moves the motion's time origin by the motion time it hands back, so
that a paused motion goes on where it stopped. docs/parameters.md documents the services.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
import math


class RunState(StrEnum):
    """Whether the crank moves; the value is what diagnostics show."""

    RUNNING = 'running'
    PAUSED = 'paused'


@dataclass(frozen=True)
class ServiceAnswer:
    """A Trigger service's response: whether the call acted, and what it did or why not."""

    success: bool
    message: str


def _degrees(alpha: float) -> str:
    return f'{math.degrees(alpha):.6f}°'


class RunControl:
    """
    The run state and the motion time held while paused.

    ``held_motion_time_ns`` is the drive-law time (ns) the motion had reached when it was paused;
    None while the motion has not left alpha_start (a node started with autostart false, or
    reset), so that resuming starts it from alpha_start.
    """

    def __init__(self, autostart: bool) -> None:
        self.state = RunState.RUNNING if autostart else RunState.PAUSED
        self.held_motion_time_ns: int | None = None

    @property
    def paused(self) -> bool:
        return self.state is RunState.PAUSED

    def activity(self, alpha: float | None) -> str:
        """Return the status message of a paused motion, with the crank angle ``alpha`` (rad)."""
        if self.held_motion_time_ns is None:
            return 'paused: waiting at alpha_start for ~/resume'
        return f'paused at α = {_degrees(alpha)}; ~/resume goes on'

    def pause(self, motion_time_ns: int | None, alpha: float | None) -> ServiceAnswer:
        """
        Pause a running motion that has reached ``motion_time_ns`` (None: not started yet).

        ``alpha`` (rad) is where the crank stands, for the answer.
        """
        if self.paused:
            return ServiceAnswer(False, 'already paused; ~/resume goes on')
        self.state = RunState.PAUSED
        self.held_motion_time_ns = motion_time_ns
        if motion_time_ns is None:
            return ServiceAnswer(True, 'paused before the motion started, at alpha_start')
        return ServiceAnswer(True, f'paused at α = {_degrees(alpha)}')

    def resume(self) -> tuple[ServiceAnswer, int | None]:
        """
        Let a paused motion run again.

        Also return the motion time to go on from (None: start from alpha_start).
        """
        if not self.paused:
            return ServiceAnswer(False, 'already running; ~/pause stops it'), None
        self.state = RunState.RUNNING
        held, self.held_motion_time_ns = self.held_motion_time_ns, None
        if held is None:
            return ServiceAnswer(True, 'started from alpha_start'), None
        return ServiceAnswer(True, 'resumed'), held

    def back_to_start(self) -> None:
        """Forget the held motion time: the motion starts again from alpha_start."""
        self.held_motion_time_ns = None

    def reset(self, alpha_start: float) -> ServiceAnswer:
        """Send the motion back to ``alpha_start`` (rad); a paused motion stays paused there."""
        self.back_to_start()
        where = f'back to alpha_start = {_degrees(alpha_start)}'
        if self.paused:
            return ServiceAnswer(True, f'{where}; paused: ~/resume starts the motion')
        return ServiceAnswer(True, f'{where}; the motion starts again')
