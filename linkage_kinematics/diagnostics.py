# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
What the node's diagnostics say and when, without ROS.

``key_values`` formats the status's key values (README, "Diagnostics") so that a viewer shows
them as they are: counts as integers, small residuals in scientific notation, and in each mode
only the rate it uses. ``StatusSchedule`` says which states a status goes out with: one at least
every ``STATUS_PERIOD`` of mechanism time, so that a replayed bag's diagnostics move with the
mechanism. ``RateMeter`` measures the achieved state rate over the last ``RATE_WINDOW``, so
that statuses that close together do not report the jitter of a few ticks.
"""

from __future__ import annotations

import collections
import math

from linkage_kinematics.kinematics import LinkageState, loop_closure_residual
from linkage_kinematics.parameters import MotionMode, RunConfiguration
from linkage_kinematics.run_control import RunState

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


def key_values(
    config: RunConfiguration,
    run_state: RunState,
    state: LinkageState | None,
    achieved_rate: float | None,
    missed_deadlines: int,
    log_file: str | None,
    log_size: int | None,
) -> dict[str, str]:
    """
    Return the status's key values (README, "Diagnostics") as diagnostic_msgs/KeyValue strings.

    ``run_state`` says whether the motion runs or is paused; ``achieved_rate`` None means not
    measured yet (the first status); ``log_file`` None means logging is disabled; ``log_size`` is
    the bag's size in bytes.
    """
    # The state first, then the pace, the log and the run's settings: a diagnostics panel shows
    # the values that change at the top.
    values = {}
    if state is not None:
        reachability = config.linkage.reachability
        distance = reachability.dead_point_distance(state.alpha)
        change_distance = reachability.change_point_distance(state.alpha)
        residual = float(loop_closure_residual(config.linkage, state))
        values.update({
            'alpha (deg)': f'{math.degrees(state.alpha):.6f}',
            'alpha (rad)': repr(state.alpha),
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
        NOT_MEASURED if achieved_rate is None else f'{achieved_rate:.1f}')
    # Each mode reports what paces it: rate_hz in real_time; in fixed_step the drive law sets
    # the pace, and rate_hz is not used.
    if config.mode == MotionMode.REAL_TIME:
        values['rate_hz'] = f'{config.rate_hz:g}'
    else:
        values['alpha_step (deg)'] = f'{math.degrees(config.alpha_step):.6g}'
    values['missed deadlines'] = str(int(missed_deadlines))
    if log_file is not None and log_size is not None:
        values['log size (bytes)'] = str(int(log_size))
    values['log file'] = LOG_DISABLED if log_file is None else log_file
    values['run state'] = run_state.value
    values['mode'] = config.mode.value
    values['end behavior'] = config.end_behavior.value
    return values
