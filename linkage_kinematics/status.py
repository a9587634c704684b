# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
What ``/diagnostics`` says: the status level, its message and its key values.

Pure functions of the configuration and the latest state, and ``MeasuredHealth``, the
measured source's record of dropped samples and of the time since the last valid one. The node
turns them into a ``diagnostic_msgs/DiagnosticArray`` (``messages.diagnostic_array``). README.md,
section Diagnostics, documents every level and value. No ROS.
"""

from __future__ import annotations

from enum import IntEnum
import math

from linkage_kinematics.joints import Driver, Link
from linkage_kinematics.kinematics import LinkageState, loop_closure_residual
from linkage_kinematics.measured import Estimate, Rejection
from linkage_kinematics.motion import blocked_note
from linkage_kinematics.parameters import RunConfiguration, Source


class Level(IntEnum):
    """diagnostic_msgs/DiagnosticStatus levels."""

    OK = 0
    WARN = 1
    ERROR = 2
    STALE = 3


def driver_angle(config: RunConfiguration, state: LinkageState) -> float:
    """Return the driver's angle in ``state``: α for the crank, θ_BC = π − β for the rocker."""
    return state.alpha if config.driver is Driver.CRANK else math.pi - state.beta


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
    if problem is not None:
        return Level.ERROR, problem
    warnings = list(warnings)
    if state is not None:
        deviation = min(state.transmission_angle, math.pi - state.transmission_angle)
        if deviation < config.min_transmission_angle:
            warnings.append(
                f'transmission angle {math.degrees(state.transmission_angle):.2f}° is within '
                f'{math.degrees(config.min_transmission_angle):.2f}° of a straight line'
            )
        reachability = config.driven_linkage.reachability
        angle = driver_angle(config, state)
        distance = reachability.dead_point_distance(angle)
        if distance is not None and distance < config.dead_point_warning:
            warnings.append(f'{math.degrees(distance):.3f}° from a dead point')
        distance = reachability.change_point_distance(angle)
        if distance is not None and distance < config.dead_point_warning:
            warnings.append(
                f'{math.degrees(distance):.3f}° from a change point (the assemblies meet; the '
                'motion continues smoothly on its branch)'
            )
    note = blocked_note(config) if config.source is Source.DRIVE_LAW else None
    if note is not None:
        warnings.append(note)
    if warnings:
        return Level.WARN, '; '.join(warnings)
    return Level.OK, activity


def report(
    config: RunConfiguration,
    state: LinkageState | None,
    problem: str | None,
    activity: str,
    health: MeasuredHealth | None,
    now_ns: int,
    achieved_rate: float,
    missed_deadlines: int,
) -> tuple[Level, str, dict[str, str]]:
    """
    Return the level, message and key values of one status (README, Diagnostics).

    ``health`` is the measured source's (None under the drive law); its drops since the last
    status make it WARN and its staleness ERROR. ``achieved_rate`` counts states per second.
    """
    values = {'achieved rate (Hz)': f'{achieved_rate:.1f}'}
    warnings: tuple[str, ...] = ()
    if health is not None:
        values.update(health.values(now_ns, config))
        warnings = health.take_warnings()
        driver_name = config.joints[Link(config.driver.value)].name
        problem = problem or health.problem(now_ns, config.measured_timeout, driver_name)
    else:
        values.update({
            'end behavior': config.end_behavior.value,
            'mode': config.mode.value,
            'rate_hz': f'{config.rate_hz:g}',
            'missed deadlines': str(missed_deadlines),
        })
    values.update(state_values(config, state))
    level, text = assess(config, state, problem, activity, warnings)
    return level, text, values


def state_values(config: RunConfiguration, state: LinkageState | None) -> dict[str, str]:
    """Return the key values of the latest state (none before the first)."""
    if state is None:
        return {}
    reachability = config.driven_linkage.reachability
    angle = driver_angle(config, state)
    distance = reachability.dead_point_distance(angle)
    change_distance = reachability.change_point_distance(angle)
    residual = float(loop_closure_residual(config.linkage, state))
    values = {
        'alpha (rad)': repr(state.alpha),
        'alpha (deg)': f'{math.degrees(state.alpha):.6f}',
    }
    if config.driver is Driver.ROCKER:
        values['rocker angle (deg)'] = f'{math.degrees(angle):.6f}'
    values.update({
        'dead point distance (deg)': (
            'none (full rotation)' if distance is None else f'{math.degrees(distance):.6f}'
        ),
        'change point distance (deg)': (
            'none' if change_distance is None else f'{math.degrees(change_distance):.6f}'
        ),
        'transmission angle (deg)': f'{math.degrees(state.transmission_angle):.6f}',
        'loop closure residual': f'{residual:.3g}',
    })
    return values


class MeasuredHealth:
    """
    The measured source's health: dropped samples by reason, and how fresh the data is.

    Drops since the previous status make it WARN, naming each reason and its count; no valid
    sample for ``measured.timeout`` (node clock) makes it ERROR, as diagnostic_updater's
    frequency status says ERROR when no event came in its window.
    """

    def __init__(self, start_ns: int) -> None:
        self.totals = dict.fromkeys(Rejection, 0)
        self._window = dict.fromkeys(Rejection, 0)
        self.accepted = 0
        self.last_valid_ns: int | None = None
        self._start_ns = start_ns
        self.velocity: Estimate | None = None

    def drop(self, rejection: Rejection) -> None:
        self.totals[rejection] += 1
        self._window[rejection] += 1

    def accept(self, now_ns: int, velocity: Estimate) -> None:
        self.accepted += 1
        self.last_valid_ns = now_ns
        self.velocity = velocity

    def is_stale(self, now_ns: int, timeout: float) -> bool:
        """Whether no valid sample came for ``timeout`` seconds (since the start, at first)."""
        since = self.last_valid_ns if self.last_valid_ns is not None else self._start_ns
        return (now_ns - since) * 1e-9 > timeout

    def problem(self, now_ns: int, timeout: float, driver_name: str) -> str | None:
        """Return the ERROR message when the data is stale, else None."""
        if not self.is_stale(now_ns, timeout):
            return None
        if self.last_valid_ns is None:
            return f'no valid sample of {driver_name} received yet (timeout {timeout:g} s)'
        age = (now_ns - self.last_valid_ns) * 1e-9
        return f'no valid sample of {driver_name} for {age:.3f} s (timeout {timeout:g} s)'

    def take_warnings(self) -> tuple[str, ...]:
        """Return the drops since the last call, one text per reason, and start a new window."""
        warnings = tuple(
            f'dropped {count} sample{"s" if count > 1 else ""} {rejection.value}'
            for rejection, count in self._window.items() if count
        )
        self._window = dict.fromkeys(Rejection, 0)
        return warnings

    def values(self, now_ns: int, config: RunConfiguration) -> dict[str, str]:
        """Return the key values: counts, freshness, and which quantities are estimates."""
        values = {
            'source': 'measured',
            'driver': config.driver.value,
            'valid samples': str(self.accepted),
            'dropped samples': str(sum(self.totals.values())),
        }
        values.update({f'dropped {rejection.value}': str(count)
                       for rejection, count in self.totals.items()})
        values['last valid sample age (s)'] = (
            'none yet' if self.last_valid_ns is None
            else f'{(now_ns - self.last_valid_ns) * 1e-9:.3f}')
        values['measured'] = f'{config.driver.value} angle' + (
            f', {config.driver.value} angular velocity'
            if self.velocity is Estimate.MEASURED else '')
        values['exact functions of the measured'] = (
            'every angle and position, passive joints' + (
                ', every velocity' if self.velocity is Estimate.MEASURED else ''))
        values['estimated'] = (
            ('' if self.velocity is Estimate.MEASURED
             else f'{config.driver.value} angular velocity '
             f'({(self.velocity or Estimate.BACKWARD_DIFFERENCE).value}) and every velocity; ')
            + f'{config.driver.value} angular acceleration (low-pass filtered difference, '
            f'τ = {config.acceleration_time_constant:g} s) and every acceleration'
        )
        return values
