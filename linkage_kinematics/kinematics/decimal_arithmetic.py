# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The decimal arithmetic of a loop's singular points, computed once per loop.

A loop's dead points and change points (``geometry.LoopClosure``, ``prismatic_loop``) are found
in DIGITS-digit decimals from the exact values of its float dimensions, and kept as
double-doubles (``split``): the per-sample closed forms then take a joint's offset from them
exactly to rounding (``singular_points``). Callers set the precision themselves (``with
localcontext() as context: context.prec = DIGITS``) around all their steps, so that their
intermediate results keep it too.
"""

from __future__ import annotations

from decimal import Decimal
import math

# Digits of the one-time computation of the singular points.
DIGITS = 60
PI = Decimal('3.14159265358979323846264338327950288419716939937510582097494459230781640629')


def _cos_sin(angle: Decimal) -> tuple[Decimal, Decimal]:
    """Cos and sin of a decimal angle of a few radians, by their Taylor series."""
    cosine = sine = Decimal(0)
    term = Decimal(1)
    tiny = Decimal(10) ** -(DIGITS + 5)
    order = 0
    while abs(term) > tiny or order < 4:
        if order % 4 == 0:
            cosine += term
        elif order % 4 == 1:
            sine += term
        elif order % 4 == 2:
            cosine -= term
        else:
            sine -= term
        order += 1
        term = term * angle / order
    return cosine, sine


def atan2(y: Decimal, x: Decimal) -> Decimal:
    """atan2 in decimal: the float's value refined by Newton's method on x·sin θ − y·cos θ."""
    if x == 0:
        # exact, so that a pivot C straight above or below O puts α₀ on an exact float
        return PI / 2 if y > 0 else -PI / 2
    angle = Decimal(math.atan2(float(y), float(x)))
    for _ in range(3):
        cosine, sine = _cos_sin(angle)
        angle += (y * cosine - x * sine) / (x * cosine + y * sine)
    return angle


def split(value: Decimal) -> tuple[float, float]:
    """Return the nearest float and the float nearest to what it leaves over (a double-double)."""
    high = float(value)
    return high, float(value - Decimal(high))
