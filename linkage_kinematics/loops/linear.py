# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Small dense linear algebra in plain floats, for the per-sample closure.

A closure group's square system has one to a few unknowns per loop: in CPython a 2×2 solve in
floats costs well under a microsecond, a numpy call on a small array several. Gaussian
elimination with partial pivoting (backward stable), kept as its LU factors (``factor``) so
that Newton's last step and the inverse at the same pose (the sensitivity, κ, the sign of the
determinant: the assembly's orientation) eliminate once. Systems of ``NUMPY_FROM`` unknowns
or more go to LAPACK through numpy, where the float loops would cost more than its calls.
Pure: no ROS.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

Matrix = Sequence[Sequence[float]]
NUMPY_FROM = 7


class Factors:
    """
    A square matrix factored for solving: P·A = L·U, and its determinant.

    ``rows`` holds L (below the diagonal, unit diagonal) and U; ``order`` the row each
    row of P·A came from. At ``NUMPY_FROM`` unknowns or more, the matrix itself for numpy.
    """

    def __init__(self, rows: list[list[float]], order: list[int], determinant: float) -> None:
        self.rows = rows
        self.order = order
        self.determinant = determinant

    def solve(self, rhs: Sequence[float]) -> list[float]:
        """Return x with A·x = rhs."""
        rows = self.rows
        n = len(rows)
        if n >= NUMPY_FROM:
            return [float(x) for x in np.linalg.solve(np.array(rows), np.array(rhs))]
        if n == 1:
            return [rhs[0] / rows[0][0]]
        if n == 2:
            (a, b), (c, d) = rows
            det = self.determinant
            return [(d * rhs[0] - b * rhs[1]) / det, (a * rhs[1] - c * rhs[0]) / det]
        x = [rhs[i] for i in self.order]
        for i in range(1, n):
            row = rows[i]
            total = x[i]
            for j in range(i):
                total -= row[j] * x[j]
            x[i] = total
        for i in range(n - 1, -1, -1):
            row = rows[i]
            total = x[i]
            for j in range(i + 1, n):
                total -= row[j] * x[j]
            x[i] = total / row[i]
        return x

    def inverse(self) -> list[list[float]]:
        """Return A⁻¹, one list per row."""
        rows = self.rows
        n = len(rows)
        if n >= NUMPY_FROM:
            return np.linalg.inv(np.array(rows)).tolist()
        if n == 1:
            return [[1.0 / rows[0][0]]]
        if n == 2:
            (a, b), (c, d) = rows
            det = self.determinant
            return [[d / det, -b / det], [-c / det, a / det]]
        columns = [self.solve([1.0 if i == j else 0.0 for i in range(n)]) for j in range(n)]
        return [[column[i] for column in columns] for i in range(n)]


def factor(matrix: Matrix) -> Factors | None:
    """Return the LU factors of ``matrix``; None where a pivot is exactly zero (singular)."""
    n = len(matrix)
    if n == 1:
        a = matrix[0][0]
        return Factors([[a]], [0], a) if a != 0.0 else None
    if n == 2:
        (a, b), (c, d) = matrix
        det = a * d - b * c
        return Factors([[a, b], [c, d]], [0, 1], det) if det != 0.0 else None
    if n >= NUMPY_FROM:
        array = np.array(matrix, dtype=float)
        sign, logarithm = np.linalg.slogdet(array)
        if sign == 0.0:
            return None
        return Factors(array.tolist(), list(range(n)), float(sign * np.exp(logarithm)))
    rows = [list(row) for row in matrix]
    order = list(range(n))
    det = 1.0
    for k in range(n):
        pivot, largest = k, abs(rows[k][k])
        for i in range(k + 1, n):
            size = abs(rows[i][k])
            if size > largest:
                pivot, largest = i, size
        if largest == 0.0:
            return None
        if pivot != k:
            rows[k], rows[pivot] = rows[pivot], rows[k]
            order[k], order[pivot] = order[pivot], order[k]
            det = -det
        head = rows[k]
        lead = head[k]
        det *= lead
        for i in range(k + 1, n):
            row = rows[i]
            multiplier = row[k] / lead
            row[k] = multiplier
            if multiplier != 0.0:
                for j in range(k + 1, n):
                    row[j] -= multiplier * head[j]
    return Factors(rows, order, det)


def condition(matrix: Matrix, inverse_matrix: Matrix, row_scale: Sequence[float],
              column_scale: Sequence[float]) -> float:
    """Return ‖R·A·C‖₁·‖(R·A·C)⁻¹‖₁ for the diagonal scalings R and C."""
    n = len(matrix)
    sums = [0.0] * n
    for row, scale in zip(matrix, row_scale):
        for j in range(n):
            sums[j] += abs(row[j]) * scale
    scaled = max([total * scale for total, scale in zip(sums, column_scale)])
    # (R·A·C)⁻¹ = C⁻¹·A⁻¹·R⁻¹
    sums = [0.0] * n
    for row, scale in zip(inverse_matrix, column_scale):
        for j in range(n):
            sums[j] += abs(row[j]) / scale
    inverted = max([total / scale for total, scale in zip(sums, row_scale)])
    return scaled * inverted
