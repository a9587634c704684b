# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
What the node's diagnostics say and when, without ROS.

``assess`` gives the status's level and message and ``report`` its whole content, from the
``StatusInputs`` the node has at that moment;
``MeasuredHealth`` is the measured source's record of dropped samples and of the time since
the last valid one. ``key_values`` formats the status's key values (docs/parameters.md,
"Diagnostics") so that a viewer shows them as they are: counts as integers, small residuals
in scientific notation, and in each mode only the rate it uses. ``StatusSchedule`` says which
states a status goes out with: one at least every ``STATUS_PERIOD`` of mechanism time, so that
a replayed bag's diagnostics move with the mechanism. ``RateMeter`` measures the achieved
state rate over the last ``RATE_WINDOW``, so that statuses that close together do not report
the jitter of a few ticks.
"""

from __future__ import annotations

import collections
from dataclasses import dataclass
from enum import IntEnum
import math

from linkage_kinematics.kinematics.solver import LinkageState, loop_closure_residual
from linkage_kinematics.loops.intake import DropReason, Estimate, FOUR_BAR_DROPS
from linkage_kinematics.model.joints import Driver, Link
from linkage_kinematics.run.configuration import MotionMode, RunConfiguration, SourceKind
from linkage_kinematics.run.control import RunState
from linkage_kinematics.run.motion import blocked_note

STATUS_PERIOD = 0.1  # s of mechanism time between statuses sent with the states
RATE_WINDOW = 1.0  # s of node-clock time over which the achieved rate is measured
LOG_DISABLED = 'disabled'
NOT_MEASURED = 'not measured yet'


class StatusSchedule:
    """
    Decide which states a status goes out with, so that statuses are at most STATUS_PERIOD apart.

    A state carries one when the next state, as far after it as it came after the one before,
    would be more than STATUS_PERIOD after the last status; where the states themselves are
    further apart, every state carries one.
    """

    def __init__(self) -> None:
        self._period_ns = round(STATUS_PERIOD * 1e9)
        self._last_status_ns: int | None = None
        self._last_state_ns: int | None = None

    def sent(self, stamp_ns: int) -> None:
        """Note a status stamped ``stamp_ns`` (sent with a state or for any other reason)."""
        self._last_status_ns = stamp_ns

    def due(self, stamp_ns: int) -> bool:
        """Whether the state stamped ``stamp_ns`` (states in the order published) carries one."""
        previous, self._last_state_ns = self._last_state_ns, stamp_ns
        if (self._last_status_ns is None or stamp_ns < self._last_status_ns
                or (previous is not None and stamp_ns < previous)):
            return True  # no status yet, or the clock went back
        # The first state of a motion comes with its own status (sent just before it).
        spacing = 0 if previous is None else stamp_ns - previous
        return stamp_ns + spacing - self._last_status_ns > self._period_ns


class RateMeter:
    """Ticks per second over the last RATE_WINDOW, measured at each status (None before)."""

    def __init__(self) -> None:
        self.rate: float | None = None
        self._ticks = 0
        self._samples: collections.deque[tuple[int, int]] = collections.deque()

    def tick(self) -> None:
        self._ticks += 1

    def update(self, now_ns: int) -> float | None:
        """Return the rate since the latest status at least RATE_WINDOW before ``now_ns``."""
        samples = self._samples
        if samples and now_ns < samples[-1][0]:
            samples.clear()  # the clock went back
        samples.append((now_ns, self._ticks))
        # Keep the last sample at least RATE_WINDOW old, so statuses further apart than that
        # still measure over the time between them.
        while len(samples) > 2 and now_ns - samples[1][0] >= round(RATE_WINDOW * 1e9):
            samples.popleft()
        (first_ns, first_ticks) = samples[0]
        if now_ns > first_ns:
            self.rate = (self._ticks - first_ticks) / ((now_ns - first_ns) * 1e-9)
        return self.rate


@dataclass(frozen=True, kw_only=True)
class StatusInputs:
    """
    What one status is made of, as the node has it when it sends one (docs/parameters.md).

    ``run_state`` says whether the motion runs or is paused and ``state`` is the latest state
    (None before the first). ``problem`` makes the status ERROR (the crank cannot go on, the
    log failed); ``activity`` is its message when all is well. ``health`` is the measured
    source's (None under the drive law), judged at ``now_ns``; its values replace the drive
    law's pace and settings. ``achieved_rate`` None means not measured yet (the first status);
    ``log_file`` None means logging is disabled; ``log_size`` is the bag's size in bytes.
    """

    config: RunConfiguration
    run_state: RunState
    state: LinkageState | None
    activity: str
    achieved_rate: float | None
    missed_deadlines: int
    log_file: str | None
    log_size: int | None
    problem: str | None = None
    health: MeasuredHealth | None = None
    now_ns: int = 0


def key_values(inputs: StatusInputs) -> dict[str, str]:
    """Return the status's key values (docs/parameters.md) as diagnostic_msgs/KeyValue texts."""
    config, state, health = inputs.config, inputs.state, inputs.health
    motion = config.motion
    log_file, log_size = inputs.log_file, inputs.log_size
    # The state first, then the pace, the log and the run's settings: a diagnostics panel shows
    # the values that change at the top.
    values = {}
    if state is not None:
        # Distances along the driver's travel: the rocker-driven chain's for the rocker.
        reachability = config.geometry.driven_linkage.reachability
        angle = driver_angle(config, state)
        distance = reachability.dead_point_distance(angle)
        change_distance = reachability.change_point_distance(angle)
        residual = float(loop_closure_residual(config.geometry.linkage, state))
        values.update({
            'alpha (deg)': f'{math.degrees(state.alpha):.6f}',
            'alpha (rad)': repr(state.alpha),
            **({'rocker angle (deg)': f'{math.degrees(angle):.6f}'}
               if config.joints.driver is Driver.ROCKER else {}),
            'transmission angle (deg)': f'{math.degrees(state.transmission_angle):.6f}',
            'dead point distance (deg)': (
                'none (full rotation)' if distance is None else f'{math.degrees(distance):.6f}'
            ),
            'change point distance (deg)': (
                'none' if change_distance is None else f'{math.degrees(change_distance):.6f}'
            ),
            'loop closure residual': f'{residual:.2e}',
        })
    values['achieved rate (Hz)'] = (
        NOT_MEASURED if inputs.achieved_rate is None else f'{inputs.achieved_rate:.1f}')
    if health is not None:
        values.update(health.values(inputs.now_ns, config))
        if log_file is not None and log_size is not None:
            values['log size (bytes)'] = str(int(log_size))
        values['log file'] = LOG_DISABLED if log_file is None else log_file
        values['run state'] = inputs.run_state.value
        return values
    # Each mode reports what paces it: rate_hz in real_time; in fixed_step the drive law sets
    # the pace, and rate_hz is not used.
    if motion.mode == MotionMode.REAL_TIME:
        values['rate_hz'] = f'{motion.rate_hz:g}'
    else:
        values['alpha_step (deg)'] = f'{math.degrees(motion.alpha_step):.6g}'
    values['missed deadlines'] = str(int(inputs.missed_deadlines))
    if log_file is not None and log_size is not None:
        values['log size (bytes)'] = str(int(log_size))
    values['log file'] = LOG_DISABLED if log_file is None else log_file
    values['run state'] = inputs.run_state.value
    values['mode'] = motion.mode.value
    values['end behavior'] = motion.end_behavior.value
    return values


class Level(IntEnum):
    """diagnostic_msgs/DiagnosticStatus levels."""

    OK = 0
    WARN = 1
    ERROR = 2
    STALE = 3


@dataclass(frozen=True)
class Status:
    """One diagnostic_msgs/DiagnosticStatus: its task (after the node's name) and content."""

    task: str
    hardware_id: str
    level: Level
    message: str
    values: dict[str, str]


def driver_angle(config: RunConfiguration, state: LinkageState) -> float:
    """Return the driver's angle in ``state``: α for the crank, θ_BC = π − β for the rocker."""
    return state.alpha if config.joints.driver is Driver.CRANK else math.pi - state.beta


def assess(
    config: RunConfiguration,
    state: LinkageState | None,
    problem: str | None,
    activity: str,
    warnings: tuple[str, ...] = (),
) -> tuple[Level, str]:
    """
    Return the status level and message.

    ERROR for ``problem`` (the crank cannot go on, the log failed, no valid measured sample),
    WARN for ``warnings`` (e.g. dropped samples), near a dead point or a change point or at a
    poor transmission angle, else OK with ``activity``.
    """
    outputs = config.outputs
    if problem is not None:
        return Level.ERROR, problem
    warnings = list(warnings)
    if state is not None:
        deviation = min(state.transmission_angle, math.pi - state.transmission_angle)
        if deviation < outputs.min_transmission_angle:
            warnings.append(
                f'transmission angle {math.degrees(state.transmission_angle):.2f}° is within '
                f'{math.degrees(outputs.min_transmission_angle):.2f}° of a straight line'
            )
        reachability = config.geometry.driven_linkage.reachability
        angle = driver_angle(config, state)
        distance = reachability.dead_point_distance(angle)
        if distance is not None and distance < outputs.dead_point_warning:
            warnings.append(f'{math.degrees(distance):.3f}° from a dead point')
        distance = reachability.change_point_distance(angle)
        if distance is not None and distance < outputs.dead_point_warning:
            warnings.append(
                f'{math.degrees(distance):.3f}° from a change point (the assemblies meet; the '
                'motion continues smoothly on its branch)'
            )
    note = blocked_note(config) if config.joints.source is SourceKind.DRIVE_LAW else None
    if note is not None:
        warnings.append(note)
    if warnings:
        return Level.WARN, '; '.join(warnings)
    return Level.OK, activity


def report(inputs: StatusInputs) -> Status:
    """
    Return the four-bar's status, 'crank motion' (docs/parameters.md, Diagnostics).

    A measured source's drops since the last status make it WARN and its staleness ERROR.
    """
    config, health, problem = inputs.config, inputs.health, inputs.problem
    warnings: tuple[str, ...] = ()
    if health is not None:
        warnings = health.take_warnings()
        driver_name = config.joints.lab[Link(config.joints.driver.value)].name
        problem = problem or health.problem(inputs.now_ns, config.measured.timeout, driver_name)
    values = key_values(inputs)
    level, text = assess(config, inputs.state, problem, inputs.activity, warnings)
    hardware_id = f"four-bar linkage ({config.geometry.preset or 'explicit geometry'})"
    return Status('crank motion', hardware_id, level, text, values)


class Freshness:
    """
    A measured source's samples: the valid ones, when the last came, and those dropped, by reason.

    No valid sample for ``measured.timeout`` (node clock) makes the source's status ERROR, as
    diagnostic_updater's frequency status says ERROR when no event came in its window. Both
    measured sources' health records (``MeasuredHealth``, ``loop_diagnostics.LoopsHealth``),
    each with ``totals``, its dropped samples by reason (one of its mode's ``reasons``, in the
    order its key values list them), and those since its last status (``_take_window``).
    """

    def __init__(self, start_ns: int, reasons: tuple[DropReason, ...]) -> None:
        self.accepted = 0
        self.last_valid_ns: int | None = None
        self.totals = dict.fromkeys(reasons, 0)
        self._window = dict.fromkeys(reasons, 0)
        self._start_ns = start_ns

    def drop(self, reason: DropReason) -> None:
        """Count a dropped sample."""
        self.totals[reason] += 1
        self._window[reason] += 1

    def _take_window(self) -> dict[DropReason, int]:
        """Return the drops since the last call, by reason, and start a new window."""
        window, self._window = self._window, dict.fromkeys(self.totals, 0)
        return window

    def _accepted_at(self, now_ns: int) -> None:
        self.accepted += 1
        self.last_valid_ns = now_ns

    def is_stale(self, now_ns: int, timeout: float) -> bool:
        """Whether no valid sample came for ``timeout`` seconds (since the start, at first)."""
        since = self.last_valid_ns if self.last_valid_ns is not None else self._start_ns
        return (now_ns - since) * 1e-9 > timeout

    def sample_values(self, now_ns: int) -> dict[str, str]:
        """Return the key values of the samples: valid, dropped (by reason), the last's age."""
        values = {
            'valid samples': str(self.accepted),
            'dropped samples': str(sum(self.totals.values())),
        }
        values.update({f'dropped {reason.value}': str(count)
                       for reason, count in self.totals.items()})
        values['last valid sample age (s)'] = (
            'none yet' if self.last_valid_ns is None
            else f'{(now_ns - self.last_valid_ns) * 1e-9:.3f}')
        return values

    def _stale_problem(self, now_ns: int, timeout: float, sample: str) -> str | None:
        """Return the ERROR message naming ``sample`` when the data is stale, else None."""
        if not self.is_stale(now_ns, timeout):
            return None
        if self.last_valid_ns is None:
            return f'no valid {sample} received yet (timeout {timeout:g} s)'
        age = (now_ns - self.last_valid_ns) * 1e-9
        return f'no valid {sample} for {age:.3f} s (timeout {timeout:g} s)'


class MeasuredHealth(Freshness):
    """
    The measured source's health: dropped samples by reason, and how fresh the data is.

    Drops since the previous status make it WARN, naming each reason and its count; stale data
    (``Freshness``) makes it ERROR.
    """

    def __init__(self, start_ns: int) -> None:
        super().__init__(start_ns, FOUR_BAR_DROPS)
        self.velocity: Estimate | None = None

    def accept(self, now_ns: int, velocity: Estimate) -> None:
        self._accepted_at(now_ns)
        self.velocity = velocity

    def problem(self, now_ns: int, timeout: float, driver_name: str) -> str | None:
        """Return the ERROR message when the data is stale, else None."""
        return self._stale_problem(now_ns, timeout, f'sample of {driver_name}')

    def take_warnings(self) -> tuple[str, ...]:
        """Return the drops since the last call, one text per reason, and start a new window."""
        return tuple(
            f'dropped {count} sample{"s" if count > 1 else ""} {reason.value}'
            for reason, count in self._take_window().items() if count
        )

    def values(self, now_ns: int, config: RunConfiguration) -> dict[str, str]:
        """Return the key values: counts, freshness, and which quantities are estimates."""
        joints = config.joints
        values = {'source': 'measured', 'driver': joints.driver.value,
                  **self.sample_values(now_ns)}
        values['measured'] = f'{joints.driver.value} angle' + (
            f', {joints.driver.value} angular velocity'
            if self.velocity is Estimate.MEASURED else '')
        values['exact functions of the measured'] = (
            'every angle and position, passive joints' + (
                ', every velocity' if self.velocity is Estimate.MEASURED else ''))
        values['estimated'] = (
            ('' if self.velocity is Estimate.MEASURED
             else f'{joints.driver.value} angular velocity '
             f'({(self.velocity or Estimate.BACKWARD_DIFFERENCE).value}) and every velocity; ')
            + f'{joints.driver.value} angular acceleration (low-pass filtered difference, '
            f'τ = {config.measured.acceleration_time_constant:g} s) and every acceleration'
        )
        return values
