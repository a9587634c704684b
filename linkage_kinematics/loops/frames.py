# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The moving frames below one base frame, per sample: the forward kinematics the closures run on.

A ``Program`` is the tree steps a set of loops needs below one base frame, renumbered (slot 0
is the base, slot k + 1 the frame step k makes). ``Program.run`` poses them at coordinate
values and gives each step's world axis ω and joint origin o, which the Jacobian needs; given
the previous run and the coordinates that changed since, it recomputes only the steps those
move (in a Newton iteration the known joints' frames stay as they were). ``Motion`` gives the
frames' angular velocities and origin velocities and the steps' axis and origin rates for
coordinate rates, which J̇ needs.

Written for CPython's speed, in plain floats: a turn about a principal axis of its joint frame
whose origin is not turned (the common URDF joint) mixes two columns of the parent's rotation
(12 products); any other turn composes R_parent·(R₀ + sin θ·R₀K + (1 − cos θ)·R₀K²). Pure:
no ROS.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping, Sequence
import math

from linkage_kinematics.loops.spatial import (
    add,
    apply,
    cross,
    IDENTITY,
    multiply,
    rodrigues_parts,
    Rotation,
    scale,
    subtract,
    Vector,
    ZERO,
)
from linkage_kinematics.loops.tree import MotionKind, Step

_PRINCIPAL = 0
_TURN = 1
_SLIDE = 2
# the other two columns (i, j) of a turn about principal axis k: e_i → c·e_i + s·e_j
_PLANES = ((1, 2), (2, 0), (0, 1))

Frames = tuple[list[Rotation], list[Vector], list[Vector], list[Vector]]


def _principal(step: Step) -> tuple[int, float] | None:
    """Return (k, ±1) if the step turns about ±e_k of an unturned joint frame, else None."""
    if step.kind is not MotionKind.TURN or step.origin.rotation != IDENTITY:
        return None
    for k in range(3):
        others = [step.axis[i] for i in range(3) if i != k]
        if others == [0.0, 0.0] and abs(step.axis[k]) == 1.0:
            return k, step.axis[k]
    return None


class Program:
    """The steps below one base frame, compiled for ``run`` (module docstring)."""

    def __init__(self, steps: Sequence[Step], slot: Mapping[int, int],
                 column: Mapping[int, int]) -> None:
        compiled = []
        for step in steps:
            rotation, shift = step.origin.rotation, step.origin.position
            principal = _principal(step)
            if principal is not None:
                k, sign = principal
                form, extra = _PRINCIPAL, (k, _PLANES[k][0], _PLANES[k][1], sign)
            elif step.kind is MotionKind.TURN:
                k1, k2 = rodrigues_parts(step.axis)
                form, extra = _TURN, (multiply(rotation, k1), multiply(rotation, k2))
            else:
                form, extra = _SLIDE, None
            compiled.append((slot[step.parent], form, rotation, shift,
                             apply(rotation, step.axis), extra, column[step.coordinate],
                             step.multiplier, step.offset))
        self.steps = tuple(compiled)
        self.columns = frozenset(column[step.coordinate] for step in steps)

    def run(self, values: Sequence[float], previous: Frames | None = None,
            changed: Collection[int] | None = None) -> Frames:
        """
        Return the frames' rotations and origins and the steps' world axes and joint origins.

        At coordinate ``values``; with ``previous`` and ``changed``, only what those move.
        """
        if previous is None:
            rotations, positions = [IDENTITY], [ZERO]
            axes: list[Vector] = []
            origins: list[Vector] = []
            dirty = None
        else:
            rotations, positions = list(previous[0]), list(previous[1])
            axes, origins = list(previous[2]), list(previous[3])
            dirty = [False] * (len(self.steps) + 1)
        for place, (parent, form, rotation, shift, axis, extra, col, multiplier,
                    offset) in enumerate(self.steps):
            if dirty is not None:
                if not (col in changed or dirty[parent]):
                    continue
                dirty[place + 1] = True
            rp, pp = rotations[parent], positions[parent]
            if parent == 0:
                o = shift
            else:
                x, y, z = shift
                o = (pp[0] + rp[0] * x + rp[1] * y + rp[2] * z,
                     pp[1] + rp[3] * x + rp[4] * y + rp[5] * z,
                     pp[2] + rp[6] * x + rp[7] * y + rp[8] * z)
            value = multiplier * values[col] + offset
            if form == _PRINCIPAL:
                k, i, j, sign = extra
                w = (sign * rp[k], sign * rp[3 + k], sign * rp[6 + k])
                c, s = math.cos(value), sign * math.sin(value)
                r = list(rp)
                ri0, ri1, ri2, rj0, rj1, rj2 = rp[i], rp[3 + i], rp[6 + i], rp[j], rp[3 + j], \
                    rp[6 + j]
                r[i], r[3 + i], r[6 + i] = c * ri0 + s * rj0, c * ri1 + s * rj1, c * ri2 + s * rj2
                r[j], r[3 + j], r[6 + j] = c * rj0 - s * ri0, c * rj1 - s * ri1, c * rj2 - s * ri2
                child = tuple(r)
                p = o
            elif form == _TURN:
                w = apply(rp, axis)
                b, d = extra
                s, t = math.sin(value), 1.0 - math.cos(value)
                r0, r1, r2, r3, r4, r5, r6, r7, r8 = rotation
                turned = (r0 + s * b[0] + t * d[0], r1 + s * b[1] + t * d[1],
                          r2 + s * b[2] + t * d[2], r3 + s * b[3] + t * d[3],
                          r4 + s * b[4] + t * d[4], r5 + s * b[5] + t * d[5],
                          r6 + s * b[6] + t * d[6], r7 + s * b[7] + t * d[7],
                          r8 + s * b[8] + t * d[8])
                child = turned if parent == 0 else multiply(rp, turned)
                p = o
            else:
                w = apply(rp, axis)
                child = multiply(rp, rotation)
                p = (o[0] + value * w[0], o[1] + value * w[1], o[2] + value * w[2])
            if previous is None:
                rotations.append(child)
                positions.append(p)
                axes.append(w)
                origins.append(o)
            else:
                rotations[place + 1], positions[place + 1] = child, p
                axes[place], origins[place] = w, o
        return rotations, positions, axes, origins


class Motion:
    """The frames' angular and origin velocities, and the steps' axis and origin rates."""

    def __init__(self, programs: Sequence[Program], frames: Sequence[Frames],
                 values: Sequence[float], rates: Sequence[float]) -> None:
        self.spins: list[list[Vector]] = []
        self.velocities: list[list[Vector]] = []
        self.axis_rates: list[list[Vector]] = []
        self.origin_rates: list[list[Vector]] = []
        for program, (_, positions, step_axes, step_origins) in zip(programs, frames):
            spins, velocities = [ZERO], [ZERO]
            axis_rates, origin_rates = [], []
            for place, (parent, form, _, _, _, _, col, multiplier,
                        offset) in enumerate(program.steps):
                spin, velocity = spins[parent], velocities[parent]
                w, o = step_axes[place], step_origins[place]
                w_rate = cross(spin, w)
                o_rate = add(velocity, cross(spin, subtract(o, positions[parent])))
                rate = multiplier * rates[col]
                if form != _SLIDE:
                    spins.append(add(spin, scale(rate, w)))
                    velocities.append(o_rate)
                else:
                    value = multiplier * values[col] + offset
                    spins.append(spin)
                    velocities.append(add(o_rate, add(scale(value, w_rate), scale(rate, w))))
                axis_rates.append(w_rate)
                origin_rates.append(o_rate)
            self.spins.append(spins)
            self.velocities.append(velocities)
            self.axis_rates.append(axis_rates)
            self.origin_rates.append(origin_rates)

    def point(self, program: int, slot: int, positions: Sequence[Vector],
              point: Vector) -> Vector:
        """Return the velocity of ``point``, fixed on frame ``slot`` (at ``positions[slot]``)."""
        return add(self.velocities[program][slot],
                   cross(self.spins[program][slot], subtract(point, positions[slot])))

    def screw_rate(self, program: int, step: int, turn: bool, axis: Vector, origin: Vector,
                   point: Vector, point_rate: Vector) -> Vector:
        """Return the rate of how a step moves ``point`` (ω × (p − o), or ω for a slide)."""
        w_rate = self.axis_rates[program][step]
        if not turn:
            return w_rate
        return add(cross(w_rate, subtract(point, origin)),
                   cross(axis, subtract(point_rate, self.origin_rates[program][step])))
