# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Section 2: the drive law in time: the exact flow against explicit Euler and classical RK4.

A node ticking at a timer rate needs α at each tick. The library computes it from the elapsed
time with the law's exact flow (DriveLaw.alpha_at); the alternative is to integrate
dα/dt = ω0 + k·α tick by tick. Errors are against the closed form α(t) in mpmath at the tick's
exact time t = n/rate.
"""

from __future__ import annotations

import math
from typing import Callable

from linkage_kinematics.kinematics.drive import DriveError, DriveLaw
from mpmath import mp, mpf
from timing import format_seconds, interleaved_medians, markdown_table

LAWS = {'ω = 0.10 + 2.3·α': DriveLaw(0.1, 2.3), 'constant ω = 2 rad/s': DriveLaw(2.0)}
RATES_HZ = (10, 100, 1000)
HOUR_S = 3600.0


def exact_alpha(law: DriveLaw, alpha_start: float, elapsed: mpf) -> mpf:
    """α(t) in 50 digits."""
    with mp.workdps(50):
        omega_start = mpf(law.omega0) + mpf(law.k) * mpf(alpha_start)
        if law.k == 0.0:
            return mpf(alpha_start) + omega_start * elapsed
        return mpf(alpha_start) + omega_start * mp.expm1(mpf(law.k) * elapsed) / mpf(law.k)


def euler_step(law: DriveLaw, alpha: float, period: float) -> float:
    return alpha + period * (law.omega0 + law.k * alpha)


def rk4_step(law: DriveLaw, alpha: float, period: float) -> float:
    omega0, k = law.omega0, law.k
    k1 = omega0 + k * alpha
    k2 = omega0 + k * (alpha + 0.5 * period * k1)
    k3 = omega0 + k * (alpha + 0.5 * period * k2)
    k4 = omega0 + k * (alpha + period * k3)
    return alpha + period / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


def integrate(
    step: Callable[[DriveLaw, float, float], float], law: DriveLaw, rate: int, ticks: int
) -> tuple[float, int | None]:
    """α after ``ticks`` steps from α = 0, and the first tick it stopped being finite."""
    period = 1.0 / rate
    alpha = 0.0
    for tick in range(1, ticks + 1):
        alpha = step(law, alpha, period)
        if not math.isfinite(alpha):
            return alpha, tick
    return alpha, None


def exact_flow(law: DriveLaw, rate: int, ticks: int) -> tuple[float | str, None]:
    """α from the elapsed time, as the node computes it (or the DriveError it raises)."""
    try:
        return law.alpha_at(0.0, ticks / rate), None
    except DriveError as error:
        return f'DriveError: {error}', None


def _cell(value: float | str, overflow_tick: int | None, rate: int, exact: mpf) -> str:
    if isinstance(value, str):
        return value.split(':')[0] + ' (overflow)'
    if overflow_tick is not None:
        return f'{value} from t = {overflow_tick / rate:.1f} s'
    with mp.workdps(50):
        error = abs(mpf(value) - exact)
        return f'{float(error):.1e} rad ({float(error / abs(exact)):.0e} rel.)'


def run(quick: bool, repetitions: int) -> str:
    """Accuracy at the 90° turn and after an hour, and the cost per tick; as markdown."""
    rows = []
    for law_name, law in LAWS.items():
        turn = law.time_to(0.0, math.pi / 2)
        for horizon_name, horizon in (('90° turn', turn), ('1 h', HOUR_S)):
            for rate in RATES_HZ:
                ticks = round(horizon * rate)
                with mp.workdps(50):
                    exact = exact_alpha(law, 0.0, mpf(ticks) / rate)
                flow = exact_flow(law, rate, ticks)
                euler = integrate(euler_step, law, rate, ticks)
                rk4 = integrate(rk4_step, law, rate, ticks)
                rows.append([
                    law_name, horizon_name, f'{rate} Hz', str(ticks),
                    mp.nstr(exact, 6),
                    _cell(*flow, rate, exact), _cell(*euler, rate, exact),
                    _cell(*rk4, rate, exact),
                ])
    accuracy = markdown_table(
        ['law', 'until', 'timer', 'ticks', 'exact α (rad)', 'exact flow (alpha_at)',
         'explicit Euler', 'classical RK4'], rows)
    law = LAWS['ω = 0.10 + 2.3·α']
    ticks = 2000 if quick else 20000
    rate = 1000
    times = interleaved_medians({
        'exact flow': lambda: _flow_ticks(law, rate, ticks),
        'explicit Euler': lambda: integrate(euler_step, law, rate, ticks) and ticks,
        'classical RK4': lambda: integrate(rk4_step, law, rate, ticks) and ticks,
    }, repetitions)
    cost = markdown_table(['method', 'time per tick (median)', 'relative to the exact flow'], [
        [name, format_seconds(seconds), f"{seconds / times['exact flow']:.2f}×"]
        for name, seconds in times.items()
    ])
    return accuracy + '\n\nCost per tick (variable law, 1 kHz ticks from α = 0):\n\n' + cost


def _flow_ticks(law: DriveLaw, rate: int, ticks: int) -> int:
    for tick in range(1, ticks + 1):
        law.alpha_at(0.0, tick / rate)
    return ticks
