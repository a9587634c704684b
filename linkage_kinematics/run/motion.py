# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The drive_law source: the motion under the drive law, from node-clock time to states.

Pure functions from node-clock time or a step index to the crank angle to solve at, and
``DriveLawRun``, which turns the node's timer ticks into the states that are due.

A RunConfiguration fixes one pass of the crank (alpha_start to ``segment_end``); these functions
say where the crank is in it, how passes follow each other under each end behaviour, and what the
node reports when the crank meets a dead point on its way. No ROS.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
import math

from linkage_kinematics.kinematics.geometry import TWO_PI, UnreachableError
from linkage_kinematics.kinematics.solver import (
    continued_branch,
    DeadPointError,
    LinkageState,
    solve,
)
from linkage_kinematics.run.configuration import EndBehavior, MotionMode, RunConfiguration


@dataclass(frozen=True)
class MotionSample:
    """
    Where the motion is.

    The crank angle of the first pass to solve at, whether that pass plays backwards (bounce), the
    whole turns to add to the published α (loop over whole turns), the drive-law time since the
    motion left alpha_start (s), whether this is the final state of a 'stop' motion, and how many
    passes have ended before this one (for bounce the forward passes are the even ones).
    """

    alpha: float
    is_reversed: bool = False
    turn_offset: float = 0.0
    motion_time: float = 0.0
    final: bool = False
    pass_index: int = 0


def _clamp_to_segment(config: RunConfiguration, alpha: float) -> float:
    # alpha_at near the end of a pass may overshoot the end by a rounding error.
    motion = config.motion
    if motion.direction * (alpha - motion.segment_end) > 0.0:
        return motion.segment_end
    return alpha


def sample_at_time(config: RunConfiguration, elapsed: float) -> MotionSample | None:
    """
    Return the motion ``elapsed`` seconds after it started (real_time mode).

    None when a 'stop' motion has reached a dead point before alpha_end: the crank cannot go on.
    """
    motion = config.motion
    duration = motion.segment_duration
    if motion.end_behavior == EndBehavior.STOP:
        if elapsed >= duration:
            if motion.blocked_at is not None:
                return None
            return MotionSample(motion.alpha_end, motion_time=duration, final=True)
        return MotionSample(
            _clamp_to_segment(config, motion.drive.alpha_at(motion.alpha_start, elapsed)),
            motion_time=elapsed,
        )
    if motion.end_behavior == EndBehavior.LOOP:
        passes = math.floor(elapsed / duration)
        in_pass = elapsed - passes * duration
        return MotionSample(
            _clamp_to_segment(config, motion.drive.alpha_at(motion.alpha_start, in_pass)),
            turn_offset=passes * (motion.alpha_end - motion.alpha_start) if motion.whole_turns
            else 0.0,
            motion_time=elapsed,
            pass_index=passes,
        )
    # EndBehavior.BOUNCE
    cycles = math.floor(elapsed / (2.0 * duration))
    in_cycle = elapsed - cycles * 2.0 * duration
    backwards = in_cycle > duration
    in_pass = 2.0 * duration - in_cycle if backwards else in_cycle
    return MotionSample(
        _clamp_to_segment(config, motion.drive.alpha_at(motion.alpha_start, in_pass)),
        is_reversed=backwards,
        motion_time=elapsed,
        pass_index=2 * cycles + backwards,
    )


def _step_alpha(config: RunConfiguration, index: int) -> float:
    motion = config.motion
    if index >= motion.step_count:
        return motion.segment_end
    return motion.alpha_start + motion.direction * index * motion.alpha_step


def sample_at_step(config: RunConfiguration, step: int) -> MotionSample | None:
    """
    Return the motion at tick ``step`` (fixed_step mode): α = alpha_start + n·alpha_step exactly.

    One pass visits the ``step_count`` steps before its end and then alpha_end itself (not a
    dead point, which has no state). None as in ``sample_at_time``.
    """
    motion = config.motion
    points = motion.step_count + (0 if motion.blocked_at is not None else 1)
    duration = motion.segment_duration

    def time_of(alpha: float) -> float:
        return motion.drive.time_to(motion.alpha_start, alpha)

    if motion.end_behavior == EndBehavior.STOP:
        if step >= points:
            return None
        alpha = _step_alpha(config, step)
        return MotionSample(alpha, motion_time=time_of(alpha), final=(
            motion.blocked_at is None and step == points - 1))
    if motion.end_behavior == EndBehavior.LOOP:
        # Over whole turns the end of one pass is the start of the next: visit it once.
        per_pass = motion.step_count if motion.whole_turns else points
        passes, index = divmod(step, per_pass)
        alpha = _step_alpha(config, index)
        return MotionSample(
            alpha,
            turn_offset=passes * (motion.alpha_end - motion.alpha_start) if motion.whole_turns
            else 0.0,
            motion_time=passes * duration + time_of(alpha),
            pass_index=passes,
        )
    # EndBehavior.BOUNCE
    per_cycle = max(2 * (points - 1), 1)
    cycles, index = divmod(step, per_cycle)
    if index < points:
        alpha = _step_alpha(config, index)
        return MotionSample(alpha, motion_time=cycles * 2.0 * duration + time_of(alpha),
                            pass_index=2 * cycles)
    alpha = _step_alpha(config, per_cycle - index)
    return MotionSample(
        alpha, is_reversed=True, motion_time=(cycles + 1) * 2.0 * duration - time_of(alpha),
        pass_index=2 * cycles + 1,
    )


def solve_sample(config: RunConfiguration, sample: MotionSample) -> LinkageState:
    """Return the library's state for a motion sample (raises as ``kinematics.solve``)."""
    motion = config.motion
    drive = motion.reverse_drive if sample.is_reversed else motion.drive
    # `branch` names the assembly at alpha_start; through change points the mechanism goes on
    # on its smooth branch, which after an odd number of them is the other side.
    branch = continued_branch(
        config.geometry.linkage, motion.alpha_start, motion.branch, sample.alpha,
        turns=round(sample.turn_offset / TWO_PI),
    )
    state = solve(config.geometry.linkage, sample.alpha, drive, branch)
    if sample.turn_offset:
        state = replace(state, alpha=state.alpha + sample.turn_offset)
    return state


def blocked_note(config: RunConfiguration) -> str | None:
    """Return what happens at a dead point that lies before alpha_end; None if there is none."""
    motion = config.motion
    if motion.blocked_at is None:
        return None
    outcome = {
        EndBehavior.STOP: 'the run will end there with an error',
        EndBehavior.LOOP: 'the crank restarts from alpha_start there',
        EndBehavior.BOUNCE: 'the crank reverses there',
    }[motion.end_behavior]
    return (
        f'dead point at {math.degrees(motion.blocked_at):.6f}° before alpha_end = '
        f'{math.degrees(motion.alpha_end):.6f}°: {outcome}'
    )


def met_dead_point(config: RunConfiguration, previous_pass: int, current_pass: int) -> bool:
    """
    Tell whether the crank met the dead point that cuts a pass short (``blocked_at``).

    That is, between a sample of pass ``previous_pass`` and one of pass ``current_pass``: 'loop'
    meets it at the end of every pass, 'bounce' at the end of every forward (even) pass.
    """
    motion = config.motion
    if motion.blocked_at is None or current_pass <= previous_pass:
        return False
    if motion.end_behavior == EndBehavior.BOUNCE:
        return previous_pass % 2 == 0 or current_pass - previous_pass >= 2
    return True


def dead_point_problem(config: RunConfiguration) -> str:
    """Return the ERROR message for the crank meeting ``blocked_at``: where, and what it does."""
    motion = config.motion
    outcome = {
        EndBehavior.STOP: 'stops; the run cannot go on',
        EndBehavior.LOOP: 'restarts from alpha_start',
        EndBehavior.BOUNCE: 'reverses',
    }[motion.end_behavior]
    return (
        f'the crank cannot go past the dead point at {math.degrees(motion.blocked_at):.6f}° '
        f'before alpha_end = {math.degrees(motion.alpha_end):.6f}°: it {outcome}'
    )


@dataclass(frozen=True)
class DueState:
    """
    One state the drive law has made due, and what happened on the way to it.

    ``at_ns`` is its node-clock stamp; ``state`` None when the crank angle was refused
    (``refusal`` says why: at a dead point, which has no state to show); ``met_dead_point``
    when the crank met the dead point that cuts a pass short just before it.
    """

    sample: MotionSample
    at_ns: int
    state: LinkageState | None
    refusal: str | None
    met_dead_point: bool


class DriveLawRun:
    """
    The drive_law source: which states are due at a node-clock time (ns), in either mode.

    The node's timer calls ``advance`` with the clock's time; the run remembers where the
    motion started, which fixed step comes next, the ticks and the missed deadlines (in
    real_time, timer periods that passed without a tick; in fixed_step, steps published only
    after the next step's time had come; counted over the whole run, across restarts). No ROS.
    """

    def __init__(self, config: RunConfiguration) -> None:
        self.config = config
        self.missed_deadlines = 0
        self.restart()

    def restart(self) -> None:
        """Start the motion again from alpha_start at the next ``advance``."""
        self.start_ns: int | None = None
        self._step = 0
        self._ticks = 0
        self._pass_index = 0
        self._missed_before_restart = self.missed_deadlines

    @property
    def timer_period(self) -> float:
        """
        Return the state timer's period (s): 1/rate_hz in real_time mode.

        In fixed_step mode the timer is re-armed for each step's time (``advance``'s second
        value) and this first period only starts it.
        """
        motion = self.config.motion
        if motion.mode is MotionMode.REAL_TIME:
            return 1.0 / motion.rate_hz
        return 1e-3

    def advance(self, now_ns: int) -> tuple[list[DueState], int | None, bool]:
        """
        Return the states due by ``now_ns``, the next step's time, and whether it cannot go on.

        The next step's time (ns) only in fixed_step mode; a 'stop' motion cannot go on at a
        dead point before alpha_end. A time before the motion's start (ROS time jumped back,
        e.g. a simulation restarted) starts it over.
        """
        if self.start_ns is None or now_ns < self.start_ns:
            self.restart()
            self.start_ns = now_ns
        if self.config.motion.mode is MotionMode.REAL_TIME:
            return self._advance_in_real_time(now_ns)
        return self._advance_steps(now_ns)

    def _advance_in_real_time(self, now_ns: int) -> tuple[list[DueState], int | None, bool]:
        config = self.config
        elapsed = (now_ns - self.start_ns) * 1e-9
        # A period that passed without a tick is a missed deadline; rcl timers skip such
        # periods rather than firing twice, so the shortfall stays visible.
        self._ticks += 1
        due = math.floor(elapsed * config.motion.rate_hz + 1e-6) + 1
        self.missed_deadlines = max(
            self.missed_deadlines, self._missed_before_restart + due - self._ticks)
        sample = sample_at_time(config, elapsed)
        if sample is None:
            return [], None, True
        # The end of a 'stop' pass is stamped at the time the drive law reaches it.
        at_ns = self._motion_time(sample.motion_time) if sample.final else now_ns
        return [self._solve(sample, at_ns)], None, False

    def _advance_steps(self, now_ns: int) -> tuple[list[DueState], int | None, bool]:
        due_states: list[DueState] = []
        while True:
            sample = sample_at_step(self.config, self._step)
            if sample is None:
                return due_states, None, True
            at_ns = self._motion_time(sample.motion_time)
            if at_ns > now_ns:
                return due_states, at_ns, False
            if due_states:
                # The step before this one went out only once this one's time had come.
                self.missed_deadlines += 1
            self._step += 1
            self._ticks += 1
            due_states.append(self._solve(sample, at_ns))
            if sample.final:
                return due_states, None, False

    def _motion_time(self, seconds: float) -> int:
        """Return the node-clock time ``seconds`` of drive-law time after the start (ns)."""
        return self.start_ns + round(seconds * 1e9)

    def _solve(self, sample: MotionSample, at_ns: int) -> DueState:
        config = self.config
        met = met_dead_point(config, self._pass_index, sample.pass_index)
        self._pass_index = sample.pass_index
        try:
            return DueState(sample, at_ns, solve_sample(config, sample), None, met)
        except (DeadPointError, UnreachableError) as error:
            return DueState(sample, at_ns, None, str(error), met)
