# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The motion.

Pure functions from node-clock time or a step index to the crank angle to solve at.

A RunConfiguration fixes one pass of the crank (alpha_start to ``segment_end``); these functions
say where the crank is in it, how passes follow each other under each end behaviour, and what the
node reports when the crank meets a dead point on its way. No ROS.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
import math

from linkage_kinematics.geometry import TWO_PI
from linkage_kinematics.kinematics import continued_branch, LinkageState, solve
from linkage_kinematics.parameters import EndBehavior, RunConfiguration


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
    if config.direction * (alpha - config.segment_end) > 0.0:
        return config.segment_end
    return alpha


def sample_at_time(config: RunConfiguration, elapsed: float) -> MotionSample | None:
    """
    Return the motion ``elapsed`` seconds after it started (real_time mode).

    None when a 'stop' motion has reached a dead point before alpha_end: the crank cannot go on.
    """
    duration = config.segment_duration
    if config.end_behavior == EndBehavior.STOP:
        if elapsed >= duration:
            if config.blocked_at is not None:
                return None
            return MotionSample(config.alpha_end, motion_time=duration, final=True)
        return MotionSample(
            _clamp_to_segment(config, config.drive.alpha_at(config.alpha_start, elapsed)),
            motion_time=elapsed,
        )
    if config.end_behavior == EndBehavior.LOOP:
        passes = math.floor(elapsed / duration)
        in_pass = elapsed - passes * duration
        return MotionSample(
            _clamp_to_segment(config, config.drive.alpha_at(config.alpha_start, in_pass)),
            turn_offset=passes * (config.alpha_end - config.alpha_start) if config.whole_turns
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
        _clamp_to_segment(config, config.drive.alpha_at(config.alpha_start, in_pass)),
        is_reversed=backwards,
        motion_time=elapsed,
        pass_index=2 * cycles + backwards,
    )


def _step_alpha(config: RunConfiguration, index: int) -> float:
    if index >= config.step_count:
        return config.segment_end
    return config.alpha_start + config.direction * index * config.alpha_step


def sample_at_step(config: RunConfiguration, step: int) -> MotionSample | None:
    """
    Return the motion at tick ``step`` (fixed_step mode): α = alpha_start + n·alpha_step exactly.

    One pass visits the ``step_count`` steps before its end and then alpha_end itself (not a
    dead point, which has no state). None as in ``sample_at_time``.
    """
    points = config.step_count + (0 if config.blocked_at is not None else 1)
    duration = config.segment_duration

    def time_of(alpha: float) -> float:
        return config.drive.time_to(config.alpha_start, alpha)

    if config.end_behavior == EndBehavior.STOP:
        if step >= points:
            return None
        alpha = _step_alpha(config, step)
        return MotionSample(alpha, motion_time=time_of(alpha), final=(
            config.blocked_at is None and step == points - 1))
    if config.end_behavior == EndBehavior.LOOP:
        # Over whole turns the end of one pass is the start of the next: visit it once.
        per_pass = config.step_count if config.whole_turns else points
        passes, index = divmod(step, per_pass)
        alpha = _step_alpha(config, index)
        return MotionSample(
            alpha,
            turn_offset=passes * (config.alpha_end - config.alpha_start) if config.whole_turns
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
    drive = config.reverse_drive if sample.is_reversed else config.drive
    # `branch` names the assembly at alpha_start; through change points the mechanism goes on
    # on its smooth branch, which after an odd number of them is the other side.
    branch = continued_branch(
        config.linkage, config.alpha_start, config.branch, sample.alpha,
        turns=round(sample.turn_offset / TWO_PI),
    )
    state = solve(config.linkage, sample.alpha, drive, branch)
    if sample.turn_offset:
        state = replace(state, alpha=state.alpha + sample.turn_offset)
    return state


def blocked_note(config: RunConfiguration) -> str | None:
    """Return what happens at a dead point that lies before alpha_end; None if there is none."""
    if config.blocked_at is None:
        return None
    outcome = {
        EndBehavior.STOP: 'the run will end there with an error',
        EndBehavior.LOOP: 'the crank restarts from alpha_start there',
        EndBehavior.BOUNCE: 'the crank reverses there',
    }[config.end_behavior]
    return (
        f'dead point at {math.degrees(config.blocked_at):.6f}° before alpha_end = '
        f'{math.degrees(config.alpha_end):.6f}°: {outcome}'
    )


def met_dead_point(config: RunConfiguration, previous_pass: int, current_pass: int) -> bool:
    """
    Whether the crank met the dead point that cuts a pass short.

    (``blocked_at``) between a sample of pass ``previous_pass`` and one of pass ``current_pass``:
    'loop' meets it at the end of every pass, 'bounce' at the end of every forward (even) pass.
    """
    if config.blocked_at is None or current_pass <= previous_pass:
        return False
    if config.end_behavior == EndBehavior.BOUNCE:
        return previous_pass % 2 == 0 or current_pass - previous_pass >= 2
    return True


def dead_point_problem(config: RunConfiguration) -> str:
    """Return the ERROR message for the crank meeting ``blocked_at``: where, and what it does."""
    outcome = {
        EndBehavior.STOP: 'stops; the run cannot go on',
        EndBehavior.LOOP: 'restarts from alpha_start',
        EndBehavior.BOUNCE: 'reverses',
    }[config.end_behavior]
    return (
        f'the crank cannot go past the dead point at {math.degrees(config.blocked_at):.6f}° '
        f'before alpha_end = {math.degrees(config.alpha_end):.6f}°: it {outcome}'
    )
