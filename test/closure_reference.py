# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Independent 50-digit reference for closing a URDF's loops: pins, balls and welds.

Nothing of ``linkage_kinematics.loops`` is used; only the ``Closure`` data it is given.

* The URDF is read here with ``xml.etree.ElementTree``; every number is the float64 a URDF
  reader gets, converted to mpf exactly, so a difference from the package is the package's.
* Forward kinematics in mpmath at 50 digits: rpy as Rz·Ry·Rx, a turn by Rodrigues' matrix, an
  override as turns about its joint frame's x, y, z in the override's order (each about the
  axis as the previous turned it), a mimic as multiplier·value + offset.
* The closure equations are written differently from the package's, with the same zeros:
  a ball p_a − p_b; a pin p_a − p_b and n_a × n_b (three rows, zero when the axes are
  parallel); a weld p_a − p_b and the nine entries of R_aᵀ·R_b − I. All in the root frame.
* Their Jacobian by central differences at h = 1e-20 in 50 digits (truncation ~1e-40,
  rounding ~1e-30): no analytic derivative is shared with the package.
* Newton by Gauss–Newton on all rows at once (normal equations at 50 digits: squaring a
  condition number of 1e6 still leaves 1e-38), with idle freedoms held as the package holds
  them by convention: N_refᵀ·(q_U − q_ref) = 0, N_ref the null space of J_U at q_ref, which
  the reference computes itself (mpmath's SVD of its own Jacobian).
* Velocities from [J_U; N_refᵀ]·q̇_U = [−J_K·q̇_K; 0]; accelerations from central differences
  of the velocity along the motion.
* A model written by an exporter (bench/parallel_bench.py's: Gepetto/example-parallel-robots)
  is exact only to its printed digits: a planar loop welded in 3D, whose rows are redundant
  when drawn exactly, closes in 50 digits only to about 1e-16, and its idle freedoms' singular
  values are about 1e-16, not 0. For those, ``idle_basis`` takes a ``tolerance`` at that level
  and ``solve`` a ``tolerance`` for the residual: Gauss–Newton then ends at the least-squares
  closure (its steps still at 50 digits' rounding), which differs from any exact closure of
  the rounded drawing by that residual times the conditioning. The defaults are for drawings
  that close exactly.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
import xml.etree.ElementTree as ElementTree

from mpmath import mp, mpf

DIGITS = 50
STEP = mpf('1e-20')
CONVERGED = mpf('1e-40')
# singular values of J_U below this are null (idle) directions, for drawings that close exactly
NULL = mpf('1e-25')


@dataclass(frozen=True)
class _Joint:
    name: str
    kind: str
    parent: str
    child: str
    xyz: tuple[float, float, float]
    rpy: tuple[float, float, float]
    axis: tuple[float, float, float]
    mimic: tuple[str, float, float] | None


def _floats(text: str | None, default: str) -> tuple[float, float, float]:
    x, y, z = (float(word) for word in (text or default).split())
    return (x, y, z)


def _matrix(rows) -> mp.matrix:
    return mp.matrix([[mpf(value) for value in row] for row in rows])


def _rpy(rpy: Sequence[float]) -> mp.matrix:
    roll, pitch, yaw = (mpf(value) for value in rpy)
    cr, sr, cp, sp, cy, sy = (mp.cos(roll), mp.sin(roll), mp.cos(pitch), mp.sin(pitch),
                              mp.cos(yaw), mp.sin(yaw))
    return mp.matrix([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                      [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                      [-sp, cp * sr, cp * cr]])


def _turn(axis: Sequence, angle) -> mp.matrix:
    length = mp.sqrt(sum(mpf(a) ** 2 for a in axis))
    x, y, z = (mpf(a) / length for a in axis)
    c, s = mp.cos(angle), mp.sin(angle)
    t = 1 - c
    return mp.matrix([[c + t * x * x, t * x * y - s * z, t * x * z + s * y],
                      [t * x * y + s * z, c + t * y * y, t * y * z - s * x],
                      [t * x * z - s * y, t * y * z + s * x, c + t * z * z]])


def _column(values) -> mp.matrix:
    return mp.matrix([mpf(value) for value in values])


class Reference:
    """A URDF's loops closed at 50 digits (module docstring)."""

    def __init__(self, urdf: str, closures: Sequence, overrides: Mapping[str, str] | None = None):
        """Read the URDF; ``overrides``: joint → its axes ('xyz' spherical, 'zy' universal)."""
        root = ElementTree.fromstring(urdf)
        self.joints: dict[str, _Joint] = {}
        for element in root.findall('joint'):
            origin = element.find('origin')
            axis = element.find('axis')
            mimic = element.find('mimic')
            self.joints[element.get('name')] = _Joint(
                element.get('name'), element.get('type'), element.find('parent').get('link'),
                element.find('child').get('link'),
                _floats(origin.get('xyz') if origin is not None else None, '0 0 0'),
                _floats(origin.get('rpy') if origin is not None else None, '0 0 0'),
                _floats(axis.get('xyz') if axis is not None else None, '1 0 0'),
                None if mimic is None else (mimic.get('joint'),
                                            float(mimic.get('multiplier', '1')),
                                            float(mimic.get('offset', '0'))))
        self.above = {joint.child: joint for joint in self.joints.values()}
        self.closures = list(closures)
        self.overrides = dict(overrides or {})

    def _value(self, values: Mapping, name: str):
        joint = self.joints[name]
        if joint.mimic is not None:
            target, multiplier, offset = joint.mimic
            return mpf(multiplier) * self._value(values, target) + mpf(offset)
        return mpf(values.get(name, 0))

    def link(self, values: Mapping, link: str) -> tuple[mp.matrix, mp.matrix]:
        """Return a link's rotation and position in the root frame at joint ``values``."""
        if link not in self.above:
            return mp.eye(3), mp.matrix(3, 1)
        joint = self.above[link]
        rotation, position = self.link(values, joint.parent)
        position = position + rotation * _column(joint.xyz)
        rotation = rotation * _rpy(joint.rpy)
        if joint.name in self.overrides:
            for axis in self.overrides[joint.name]:
                unit = {'x': (1, 0, 0), 'y': (0, 1, 0), 'z': (0, 0, 1)}[axis]
                # named as the closure file's loader names a universal joint's turns
                angle = mpf(values.get(f'{joint.name}_{axis.upper()}', 0))
                rotation = rotation * _turn(unit, angle)
        elif joint.kind in ('revolute', 'continuous'):
            rotation = rotation * _turn(joint.axis, self._value(values, joint.name))
        elif joint.kind == 'prismatic':
            length = mp.sqrt(sum(mpf(a) ** 2 for a in joint.axis))
            position = position + rotation * _column(joint.axis) * (
                self._value(values, joint.name) / length)
        return rotation, position

    def _side(self, values: Mapping, side) -> tuple[mp.matrix, mp.matrix]:
        rotation, position = self.link(values, side.link)
        return rotation * _rpy(side.rpy), position + rotation * _column(side.xyz)

    def residual(self, values: Mapping) -> list:
        """Return every closure's rows (module docstring) at joint ``values``."""
        rows = []
        for closure in self.closures:
            r_a, p_a = self._side(values, closure.parent)
            r_b, p_b = self._side(values, closure.child)
            rows += list(p_a - p_b)
            if closure.kind.value == 'pin':
                n_a = r_a * _column(closure.parent.axis or (1.0, 0.0, 0.0))
                n_b = r_b * _column(closure.child.axis or (1.0, 0.0, 0.0))
                rows += [n_a[1] * n_b[2] - n_a[2] * n_b[1], n_a[2] * n_b[0] - n_a[0] * n_b[2],
                         n_a[0] * n_b[1] - n_a[1] * n_b[0]]
            elif closure.kind.value == 'weld':
                difference = r_a.T * r_b - mp.eye(3)
                rows += [difference[i, j] for i in range(3) for j in range(3)]
        return rows

    def jacobian(self, values: Mapping, names: Sequence[str]) -> mp.matrix:
        """Return ∂(residual)/∂(``names``) by central differences at 50 digits."""
        columns = []
        for name in names:
            plus, minus = dict(values), dict(values)
            plus[name] = mpf(values.get(name, 0)) + STEP
            minus[name] = mpf(values.get(name, 0)) - STEP
            columns.append([(a - b) / (2 * STEP) for a, b in
                            zip(self.residual(plus), self.residual(minus))])
        return mp.matrix([[column[i] for column in columns] for i in range(len(columns[0]))])

    def idle_basis(self, values: Mapping, unknown: Sequence[str],
                   tolerance: mpf = NULL) -> mp.matrix:
        """Return a basis of null(J_U) at ``values`` (columns): singular values < ``tolerance``."""
        with mp.workdps(DIGITS):
            jacobian = self.jacobian(values, unknown)
            _, singular, right = mp.svd_r(jacobian, full_matrices=True)
            null = [k for k in range(len(unknown))
                    if k >= len(singular) or abs(singular[k]) < tolerance]
            return mp.matrix([[right[k, i] for k in null] for i in range(len(unknown))]) \
                if null else mp.matrix(len(unknown), 0)

    def solve(self, known: Mapping, guess: Mapping, unknown: Sequence[str],
              idle: tuple[mp.matrix, Mapping] | None = None,
              tolerance: mpf = CONVERGED) -> dict:
        """
        Return the unknown joints closing every loop, by Gauss–Newton from ``guess``.

        ``idle``: (N_ref, q_ref) to hold the idle freedoms at. Raises RuntimeError unless the
        residual falls below ``tolerance`` (module docstring: a drawing that closes only to its
        printed digits).
        """
        with mp.workdps(DIGITS):
            values = {name: mpf(value) for name, value in known.items()}
            values |= {name: mpf(guess[name]) for name in unknown}
            for _ in range(40):
                rows = self._rows(values, unknown, idle)
                jacobian = self._augmented(values, unknown, idle)
                step = mp.lu_solve(jacobian.T * jacobian, jacobian.T * rows)
                for i, name in enumerate(unknown):
                    values[name] -= step[i]
                if mp.norm(step) < CONVERGED * 1e-3:
                    break
            if mp.norm(self._rows(values, unknown, idle)) > tolerance:
                raise RuntimeError(f'no closure from {dict(guess)} with {dict(known)}')
            return {name: values[name] for name in unknown}

    def _rows(self, values: Mapping, unknown: Sequence[str], idle) -> mp.matrix:
        rows = self.residual(values)
        if idle is not None and idle[0].cols:
            basis, reference = idle
            offsets = _column([values[name] - mpf(reference[name]) for name in unknown])
            rows += list(basis.T * offsets)
        return _column(rows)

    def _augmented(self, values: Mapping, unknown: Sequence[str], idle) -> mp.matrix:
        jacobian = self.jacobian(values, unknown)
        if idle is None or not idle[0].cols:
            return jacobian
        basis = idle[0].T
        return mp.matrix([[jacobian[i, j] for j in range(jacobian.cols)]
                          for i in range(jacobian.rows)]
                         + [[basis[i, j] for j in range(basis.cols)] for i in range(basis.rows)])

    def velocities(self, positions: Mapping, known_rates: Mapping, unknown: Sequence[str],
                   idle: mp.matrix | None = None) -> dict:
        """Return the unknown joints' rates: [J_U; N_refᵀ]·q̇_U = [−J_K·q̇_K; 0]."""
        with mp.workdps(DIGITS):
            values = {name: mpf(value) for name, value in positions.items()}
            known = list(known_rates)
            jacobian = self._augmented(values, unknown, None if idle is None else (idle, {}))
            known_jacobian = self.jacobian(values, known)
            rhs = -(known_jacobian * _column([known_rates[name] for name in known]))
            extra = jacobian.rows - rhs.rows
            rhs = _column(list(rhs) + [0] * extra)
            rates = mp.lu_solve(jacobian.T * jacobian, jacobian.T * rhs)
            return {name: rates[i] for i, name in enumerate(unknown)}
