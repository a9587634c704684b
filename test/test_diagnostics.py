# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""The diagnostics' schedule, rate and key values (the pure module ``diagnostics``)."""

from __future__ import annotations

import math
import re

from linkage_kinematics.kinematics.drive import DriveLaw
from linkage_kinematics.kinematics.solver import solve
from linkage_kinematics.loops.intake import DropReason, FOUR_BAR_DROPS, LOOPS_DROPS
from linkage_kinematics.run.configuration import build_configuration
from linkage_kinematics.run.control import RunState
from linkage_kinematics.run.diagnostics import (
    key_values,
    MeasuredHealth,
    RATE_WINDOW,
    RateMeter,
    STATUS_PERIOD,
    StatusInputs,
    StatusSchedule,
)
from linkage_kinematics.run.parameter_specs import parameter_specs
import pytest

PERIOD_NS = round(STATUS_PERIOD * 1e9)


def drive_law_values(**inputs: object) -> dict[str, str]:
    """Return the key values of a drive-law status: no deadline missed, no log, unless given."""
    return key_values(StatusInputs(**{
        'activity': 'moving', 'missed_deadlines': 0, 'log_file': None, 'log_size': None,
        **inputs}))


def configuration(**changes: object):
    values = {spec.name: spec.default for spec in parameter_specs('paper')}
    values.update(changes)
    return build_configuration(values)


def statuses_with(stamps: list[int]) -> list[int]:
    """Return the stamps of the states that carry a status."""
    schedule = StatusSchedule()
    carried = []
    for stamp in stamps:
        if schedule.due(stamp):
            schedule.sent(stamp)
            carried.append(stamp)
    return carried


@pytest.mark.parametrize('spacing_ms', [0.2, 4.36, 10.0, 33.3, 99.0, 100.0, 250.0])
def test_statuses_are_at_most_a_period_apart_and_not_much_closer(spacing_ms: float) -> None:
    stamps = [round(i * spacing_ms * 1e6) for i in range(round(3000 / spacing_ms))]
    carried = statuses_with(stamps)
    gaps = [later - earlier for earlier, later in zip(carried, carried[1:])]
    assert carried[0] == stamps[0]
    assert max(gaps) <= max(PERIOD_NS, round(spacing_ms * 1e6))
    # as many as needed, not one with every state where the states are close together
    assert len(carried) <= len(stamps) * spacing_ms * 1e6 / PERIOD_NS * 1.6 + 2


def test_statuses_keep_within_the_period_as_the_crank_slows_and_speeds() -> None:
    # The seed's variable law (ω = 0.1 + 2.3·α) in 0.5° steps, forwards and back (bounce).
    drive = DriveLaw(0.1, 2.3)
    forwards = [round(drive.time_to(0.0, math.radians(0.5 * step)) * 1e9) for step in range(181)]
    end = forwards[-1]
    stamps = forwards + [2 * end - stamp for stamp in reversed(forwards[:-1])]
    carried = statuses_with(stamps)
    assert max(later - earlier for earlier, later in zip(carried, carried[1:])) <= PERIOD_NS


def test_the_first_state_after_its_motions_status_carries_none() -> None:
    schedule = StatusSchedule()
    schedule.sent(1_000)  # the status that says the crank moves, at the first state's time
    assert not schedule.due(1_000)
    assert not schedule.due(1_000 + PERIOD_NS // 3)
    assert schedule.due(1_000 + 3 * PERIOD_NS // 4)  # the next one would be too late


def test_a_clock_that_goes_back_starts_the_schedule_again() -> None:
    assert statuses_with([0, 10, 20, 5, 15]) == [0, 5]


def test_rate_is_measured_over_the_last_window() -> None:
    meter = RateMeter()
    assert meter.update(0) is None  # nothing to measure over yet
    for step in range(1, 31):  # 100 ticks per 0.1 s, then 10
        for _ in range(100 if step <= 20 else 10):
            meter.tick()
        rate = meter.update(step * PERIOD_NS)
    # the last RATE_WINDOW (1 s) holds only the slow phase
    assert RATE_WINDOW <= 1.0 and rate == pytest.approx(10 / STATUS_PERIOD)
    # statuses further apart than the window measure over the time between them
    for _ in range(30):
        meter.tick()
    assert meter.update(30 * PERIOD_NS + round(1.5 * RATE_WINDOW * 1e9)) == pytest.approx(
        30 / (1.5 * RATE_WINDOW))


def test_fixed_step_reports_its_step_and_no_rate_hz() -> None:
    config = configuration(mode='fixed_step', alpha_step=math.radians(0.25))
    state = solve(config.geometry.linkage, 0.3, DriveLaw(2.0))
    values = drive_law_values(config=config, run_state=RunState.RUNNING, state=state,
                              achieved_rate=231.26, missed_deadlines=3, log_file='bags/run',
                              log_size=101_588)
    assert 'rate_hz' not in values
    assert values['alpha_step (deg)'] == '0.25'
    assert (values['achieved rate (Hz)'], values['missed deadlines']) == ('231.3', '3')
    assert values['log size (bytes)'] == '101588'
    first = drive_law_values(config=config, run_state=RunState.PAUSED, state=None,
                             achieved_rate=None)
    assert (first['achieved rate (Hz)'], first['run state']) == ('not measured yet', 'paused')
    real_time = drive_law_values(config=configuration(), run_state=RunState.RUNNING,
                                 state=None, achieved_rate=99.95)
    assert (real_time['rate_hz'], real_time['log file']) == ('100', 'disabled')
    assert real_time['run state'] == 'running'
    assert 'alpha_step (deg)' not in real_time and 'log size (bytes)' not in real_time


def test_residual_reads_in_scientific_notation() -> None:
    config = configuration()
    values = drive_law_values(config=config, run_state=RunState.RUNNING,
                              state=solve(config.geometry.linkage, 0.7, DriveLaw(2.0)),
                              achieved_rate=0.0)
    residual = values['loop closure residual']
    assert re.fullmatch(r'\d\.\d\de[+-]\d\d', residual) and float(residual) < 1e-12


def test_each_measured_modes_drop_reasons_keep_their_texts_and_order() -> None:
    """Each mode's 'dropped <reason>' key values, as bags and readers have them, from one enum."""
    assert [reason.value for reason in FOUR_BAR_DROPS] == [
        'without the driver joint',
        'with a NaN or infinite position or velocity',
        'with a stamp not newer than the last one used',
        'at a driver angle the loop cannot reach (or at a dead point)',
        'jumping further than measured.max_jump',
        'whose bytes are not a well-formed JointState']
    assert [reason.value for reason in LOOPS_DROPS] == [
        'before the robot description was closed',
        'while the measured joints cannot close the loops',
        'without every measured joint',
        'with a NaN or infinite position or velocity',
        'with a stamp not newer than the last one used',
        'at joint values a loop cannot reach (or at a dead point)',
        'jumping further than measured.max_jump',
        'whose bytes are not a well-formed JointState',
        'at joint values no assembly of a closure group reaches',
        'that would jump a closure group to another assembly',
        'too near a singular configuration of a closure group']
    assert set(FOUR_BAR_DROPS) | set(LOOPS_DROPS) == set(DropReason)
    health = MeasuredHealth(0)
    health.drop(DropReason.JUMP)
    assert [key for key in health.sample_values(0) if key.startswith('dropped ')] == [
        'dropped samples', *(f'dropped {reason.value}' for reason in FOUR_BAR_DROPS)]
