# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Small dense linear algebra in plain floats, for the per-sample closure.

A closure group's square system has one to a few unknowns per loop: in CPython a 2×2 solve in
floats costs well under a microsecond, a numpy call on a small array several. Gaussian
elimination with partial pivoting (backward stable), and Gauss–Jordan for the inverse and the
determinant (its sign is the assembly's orientation). Systems larger than ``NUMPY_FROM`` go to
LAPACK through numpy, where the float loops would cost more than its calls. Pure: no ROS.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

Matrix = Sequence[Sequence[float]]
NUMPY_FROM = 7


def solve(matrix: Matrix, rhs: Sequence[float]) -> list[float] | None:
    """Return x with matrix·x = rhs; None where a pivot is exactly zero (singular)."""
    n = len(rhs)
    if n == 1:
        return [rhs[0] / matrix[0][0]] if matrix[0][0] != 0.0 else None
    if n == 2:
        (a, b), (c, d) = matrix
        det = a * d - b * c
        if det == 0.0:
            return None
        return [(d * rhs[0] - b * rhs[1]) / det, (a * rhs[1] - c * rhs[0]) / det]
    if n >= NUMPY_FROM:
        try:
            return [float(x) for x in np.linalg.solve(np.array(matrix), np.array(rhs))]
        except np.linalg.LinAlgError:
            return None
    rows = [list(row) + [value] for row, value in zip(matrix, rhs)]
    for k in range(n):
        pivot = max(range(k, n), key=lambda i: abs(rows[i][k]))
        if rows[pivot][k] == 0.0:
            return None
        rows[k], rows[pivot] = rows[pivot], rows[k]
        head = rows[k]
        for i in range(k + 1, n):
            factor = rows[i][k] / head[k]
            if factor != 0.0:
                row = rows[i]
                for j in range(k + 1, n + 1):
                    row[j] -= factor * head[j]
    x = [0.0] * n
    for k in range(n - 1, -1, -1):
        row = rows[k]
        total = row[n]
        for j in range(k + 1, n):
            total -= row[j] * x[j]
        x[k] = total / row[k]
    return x


def inverse(matrix: Matrix) -> tuple[list[list[float]], float] | None:
    """Return (matrix⁻¹, det matrix); None where a pivot is exactly zero (singular)."""
    n = len(matrix)
    if n == 1:
        a = matrix[0][0]
        return ([[1.0 / a]], a) if a != 0.0 else None
    if n == 2:
        (a, b), (c, d) = matrix
        det = a * d - b * c
        if det == 0.0:
            return None
        return [[d / det, -b / det], [-c / det, a / det]], det
    if n >= NUMPY_FROM:
        array = np.array(matrix, dtype=float)
        sign, logarithm = np.linalg.slogdet(array)
        if sign == 0.0:
            return None
        return np.linalg.inv(array).tolist(), float(sign * np.exp(logarithm))
    rows = [list(row) + [1.0 if i == j else 0.0 for j in range(n)]
            for i, row in enumerate(matrix)]
    det = 1.0
    for k in range(n):
        pivot = max(range(k, n), key=lambda i: abs(rows[i][k]))
        if rows[pivot][k] == 0.0:
            return None
        if pivot != k:
            rows[k], rows[pivot] = rows[pivot], rows[k]
            det = -det
        head = rows[k]
        lead = head[k]
        det *= lead
        for j in range(2 * n):
            head[j] /= lead
        for i in range(n):
            if i != k and rows[i][k] != 0.0:
                factor = rows[i][k]
                row = rows[i]
                for j in range(2 * n):
                    row[j] -= factor * head[j]
    return [row[n:] for row in rows], det


def condition(matrix: Matrix, inverse_matrix: Matrix, row_scale: Sequence[float],
              column_scale: Sequence[float]) -> float:
    """Return ‖R·A·C‖₁·‖(R·A·C)⁻¹‖₁ for the diagonal scalings R and C."""
    n = len(matrix)
    scaled = max(sum(abs(matrix[i][j]) * row_scale[i] for i in range(n)) * column_scale[j]
                 for j in range(n))
    # (R·A·C)⁻¹ = C⁻¹·A⁻¹·R⁻¹
    inverted = max(sum(abs(inverse_matrix[i][j]) / column_scale[i] for i in range(n))
                   / row_scale[j] for j in range(n))
    return scaled * inverted
