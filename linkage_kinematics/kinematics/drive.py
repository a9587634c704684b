# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The crank's drive law ω = ω0 + k·α and its exact flow in time.

With ω = dα/dt = ω0 + k·α the crank angle follows, from α_s at t = 0,

    α(t) = α_s + ω_s·(e^{k t} − 1)/k        (α_s + ω_s·t when k = 0)

where ω_s = ω0 + k·α_s, and α̈ = k·ω exactly. ``expm1``/``log1p`` keep both directions of the
flow exact as k → 0, so a timer computes α from elapsed time and never accumulates drift.
ω keeps the sign of ω_s for ever: the crank moves one way, toward α* = −ω0/k when k·ω_s < 0
(reached only as t → ∞), away from it when k·ω_s > 0.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

# Below this |k·t| (or |k·Δα/ω_s|) e^{k t} − 1 equals k·t to double precision: the linear law
# is then exact, and it avoids dividing a subnormal k·t, whose few bits would spoil the result.
_LINEAR_LIMIT = 1e-17


class DriveError(ValueError):
    """The drive law cannot take the crank where it was asked to go."""


@dataclass(frozen=True)
class DriveLaw:
    """ω = omega0 + k·α, with α in rad, omega0 in rad/s and k in 1/s."""

    omega0: float
    k: float = 0.0

    def __post_init__(self) -> None:
        for name in ('omega0', 'k'):
            value = getattr(self, name)
            if not isinstance(value, (int, float)) or not math.isfinite(value):
                raise DriveError(f'{name} must be a finite number, got {value!r}')

    def angular_velocity(self, alpha: float) -> float:
        """ω at crank angle α (rad/s)."""
        return self.omega0 + self.k * alpha

    def angular_acceleration(self, alpha: float) -> float:
        """α̈ = k·ω at crank angle α (rad/s²)."""
        return self.k * (self.omega0 + self.k * alpha)

    def alpha_at(self, alpha_start: float, elapsed: float) -> float:
        """Crank angle (rad) ``elapsed`` seconds after it was at ``alpha_start``."""
        omega_start = self.angular_velocity(alpha_start)
        if self.k == 0.0 or abs(self.k * elapsed) < _LINEAR_LIMIT:
            return alpha_start + omega_start * elapsed
        try:
            growth = math.expm1(self.k * elapsed)
        except OverflowError:
            raise DriveError(
                f'under ω = {self.omega0} + {self.k}·α the crank angle overflows {elapsed} s '
                f'after α = {alpha_start} rad'
            ) from None
        alpha = alpha_start + omega_start * growth / self.k
        if not math.isfinite(alpha):
            raise DriveError(
                f'under ω = {self.omega0} + {self.k}·α the crank angle overflows {elapsed} s '
                f'after α = {alpha_start} rad'
            )
        return alpha

    def time_to(self, alpha_start: float, alpha: float) -> float:
        """Seconds the crank takes from ``alpha_start`` to ``alpha``; DriveError if never."""
        omega_start = self.angular_velocity(alpha_start)
        travel = alpha - alpha_start
        if travel == 0.0:
            return 0.0
        if omega_start == 0.0:
            raise DriveError(
                f'the crank is at rest at α = {math.degrees(alpha_start):.6g}° (ω0 + k·α = 0) '
                'and never moves'
            )
        scaled = self.k * travel / omega_start
        if abs(scaled) < _LINEAR_LIMIT:
            elapsed = travel / omega_start
        else:
            elapsed = math.log1p(scaled) / self.k if scaled > -1.0 else -1.0
        if elapsed < 0.0:
            direction = 'counterclockwise' if omega_start > 0.0 else 'clockwise'
            limit = (
                ''
                if self.k * omega_start >= 0.0
                else f' and only approaches α* = {math.degrees(-self.omega0 / self.k):.6g}°'
            )
            raise DriveError(
                f'the crank turns {direction} from α = {math.degrees(alpha_start):.6g}°{limit}; '
                f'it never reaches α = {math.degrees(alpha):.6g}°'
            )
        return elapsed
