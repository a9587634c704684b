# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Rigid motions in plain floats: the arithmetic the loops' kinematics runs on per sample.

A rotation is a 9-tuple, row-major (r00, r01, r02, r10, …, r22); a vector a 3-tuple. Plain
floats rather than numpy arrays because the loops are small: a 3×3 product of floats costs
about a microsecond in CPython, a numpy call on 3×3 arrays about as much each, and a loop's
closure makes hundreds of them per sample. Every function is exact arithmetic on floats (no
hidden rounding beyond each product and sum), adding in a fixed order so that the results are
the same bits on every Python.

The rotation error of a weld is the logarithm of SO(3), e = θ·n for the rotation by θ ∈ [0, π]
about the unit axis n, computed from the rotation's quaternion (Shepperd's choice of the largest
component), which is accurate from θ = 0 to θ = π. Its left Jacobian's inverse maps a rotation
rate to the rate of e (``log_rate_matrix``).
"""

from __future__ import annotations

import math

Rotation = tuple[float, float, float, float, float, float, float, float, float]
Vector = tuple[float, float, float]

IDENTITY: Rotation = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
ZERO: Vector = (0.0, 0.0, 0.0)
# Below this angle (rad) the log map's coefficient is taken from its series: the closed form
# 1 − (θ/2)·cot(θ/2) cancels, losing ε/(θ²/12) relative; at 0.05 rad the series' first dropped
# term is 7e-15 of the coefficient and the closed form's loss 1e-12 (of a term of size θ²).
SERIES_ANGLE = 0.05


def rpy_rotation(roll: float, pitch: float, yaw: float) -> Rotation:
    """Return URDF's roll–pitch–yaw rotation (about fixed x, then y, then z): Rz·Ry·Rx."""
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return (cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr,
            sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr,
            -sp, cp * sr, cp * cr)


def axis_rotation(axis: Vector, angle: float) -> Rotation:
    """Return the rotation by ``angle`` (rad) about the unit ``axis`` (Rodrigues)."""
    x, y, z = axis
    c, s = math.cos(angle), math.sin(angle)
    t = 1.0 - c
    return (c + t * x * x, t * x * y - s * z, t * x * z + s * y,
            t * x * y + s * z, c + t * y * y, t * y * z - s * x,
            t * x * z - s * y, t * y * z + s * x, c + t * z * z)


def turn_vector(axis: Vector, angle: float, v: Vector) -> Vector:
    """Return v turned by ``angle`` (rad) about the unit ``axis`` (Rodrigues, on the vector)."""
    c, s = math.cos(angle), math.sin(angle)
    ax, ay, az = axis
    x, y, z = v
    along = (1.0 - c) * (ax * x + ay * y + az * z)
    return (c * x + s * (ay * z - az * y) + along * ax, c * y + s * (az * x - ax * z) + along * ay,
            c * z + s * (ax * y - ay * x) + along * az)


def rodrigues_parts(axis: Vector) -> tuple[Rotation, Rotation]:
    """Return K = [axis]× and K² for the unit ``axis``: Rot(θ) = I + sin θ·K + (1 − cos θ)·K²."""
    x, y, z = axis
    k = (0.0, -z, y, z, 0.0, -x, -y, x, 0.0)
    return k, multiply(k, k)


def multiply(a: Rotation, b: Rotation) -> Rotation:
    """Return a·b."""
    a0, a1, a2, a3, a4, a5, a6, a7, a8 = a
    b0, b1, b2, b3, b4, b5, b6, b7, b8 = b
    return (a0 * b0 + a1 * b3 + a2 * b6, a0 * b1 + a1 * b4 + a2 * b7, a0 * b2 + a1 * b5 + a2 * b8,
            a3 * b0 + a4 * b3 + a5 * b6, a3 * b1 + a4 * b4 + a5 * b7, a3 * b2 + a4 * b5 + a5 * b8,
            a6 * b0 + a7 * b3 + a8 * b6, a6 * b1 + a7 * b4 + a8 * b7, a6 * b2 + a7 * b5 + a8 * b8)


def transpose(a: Rotation) -> Rotation:
    """Return aᵀ (the inverse of a rotation)."""
    return (a[0], a[3], a[6], a[1], a[4], a[7], a[2], a[5], a[8])


def apply(a: Rotation, v: Vector) -> Vector:
    """Return a·v."""
    x, y, z = v
    return (a[0] * x + a[1] * y + a[2] * z, a[3] * x + a[4] * y + a[5] * z,
            a[6] * x + a[7] * y + a[8] * z)


def apply_transposed(a: Rotation, v: Vector) -> Vector:
    """Return aᵀ·v."""
    x, y, z = v
    return (a[0] * x + a[3] * y + a[6] * z, a[1] * x + a[4] * y + a[7] * z,
            a[2] * x + a[5] * y + a[8] * z)


def add(a: Vector, b: Vector) -> Vector:
    """Return a + b."""
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def subtract(a: Vector, b: Vector) -> Vector:
    """Return a − b."""
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def scale(factor: float, a: Vector) -> Vector:
    """Return factor·a."""
    return (factor * a[0], factor * a[1], factor * a[2])


def dot(a: Vector, b: Vector) -> float:
    """Return a·b."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a: Vector, b: Vector) -> Vector:
    """Return a × b."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def norm(a: Vector) -> float:
    """Return |a|."""
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


def unit(a: Vector) -> Vector:
    """Return ``a`` scaled to length 1 (ValueError for a zero vector)."""
    length = norm(a)
    if length == 0.0:
        raise ValueError('a zero vector has no direction')
    return (a[0] / length, a[1] / length, a[2] / length)


def perpendicular_pair(axis: Vector) -> tuple[Vector, Vector]:
    """Return two unit vectors u, v with (u, v, axis) right-handed and orthonormal."""
    # the coordinate axis least along ``axis``, made perpendicular to it
    helper = [(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)][
        min(range(3), key=lambda i: abs(axis[i]))]
    first = unit(subtract(helper, scale(dot(helper, axis), axis)))
    return first, cross(axis, first)


def log_rotation(r: Rotation) -> Vector:
    """Return e = θ·n, the rotation ``r`` as the angle θ ∈ [0, π] times its unit axis n."""
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = r
    trace = r00 + r11 + r22
    # Shepperd: the quaternion component of largest size is taken from the diagonal, the others
    # from sums or differences divided by it, so no component is found by a cancelling square root.
    largest = max(trace, r00, r11, r22)
    if largest == trace:
        w = 0.5 * math.sqrt(max(1.0 + trace, 0.0))
        x, y, z = (r21 - r12) / (4.0 * w), (r02 - r20) / (4.0 * w), (r10 - r01) / (4.0 * w)
    elif largest == r00:
        x = 0.5 * math.sqrt(max(1.0 + r00 - r11 - r22, 0.0))
        w, y, z = (r21 - r12) / (4.0 * x), (r01 + r10) / (4.0 * x), (r02 + r20) / (4.0 * x)
    elif largest == r11:
        y = 0.5 * math.sqrt(max(1.0 - r00 + r11 - r22, 0.0))
        w, x, z = (r02 - r20) / (4.0 * y), (r01 + r10) / (4.0 * y), (r12 + r21) / (4.0 * y)
    else:
        z = 0.5 * math.sqrt(max(1.0 - r00 - r11 + r22, 0.0))
        w, x, y = (r10 - r01) / (4.0 * z), (r02 + r20) / (4.0 * z), (r12 + r21) / (4.0 * z)
    if w < 0.0:  # q and −q are the same rotation; w ≥ 0 gives θ ≤ π
        w, x, y, z = -w, -x, -y, -z
    sine = math.sqrt(x * x + y * y + z * z)  # sin(θ/2)
    if sine == 0.0:
        return ZERO
    factor = 2.0 * math.atan2(sine, w) / sine
    return (factor * x, factor * y, factor * z)


def log_coefficient(angle: float) -> float:
    """Return c(θ) = (1 − (θ/2)·cot(θ/2))/θ², the [e]×² coefficient of ``log_rate_matrix``."""
    if angle < SERIES_ANGLE:
        square = angle * angle
        return 1.0 / 12.0 + square * (1.0 / 720.0 + square * (
            1.0 / 30240.0 + square / 1209600.0))
    half = 0.5 * angle
    return (1.0 - half * math.cos(half) / math.sin(half)) / (angle * angle)


def log_rate_matrix(e: Vector) -> Rotation:
    """
    Return J⁻¹(e) = I − ½[e]× + c(θ)·[e]×², the map from a rotation rate to the rate of e.

    For R(t) with Ṙ = [w]×·R (w the rate in the frame R maps into), ė = J⁻¹(log R)·w. It is the
    identity at e = 0 and finite up to θ = π (c(π) = 1/π²).
    """
    x, y, z = e
    c = log_coefficient(math.sqrt(x * x + y * y + z * z))
    xx, yy, zz, xy, xz, yz = x * x, y * y, z * z, x * y, x * z, y * z
    return (1.0 - c * (yy + zz), 0.5 * z + c * xy, -0.5 * y + c * xz,
            -0.5 * z + c * xy, 1.0 - c * (xx + zz), 0.5 * x + c * yz,
            0.5 * y + c * xz, -0.5 * x + c * yz, 1.0 - c * (xx + yy))
