# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The closure equations of a set of loops: residuals, their exact Jacobian and its rate.

Each closure's residual is written in its loop's base frame (``tree.Loop``), where no joint
above the loop enters, between its parent side's frame a and its child side's frame b:

* BALL: p_a − p_b (3 rows, m);
* PIN: p_a − p_b, then u₁·n_a and u₂·n_a (2 rows), n_a the pin axis on side a and u₁, u₂ two
  unit vectors perpendicular to side b's axis, fixed on side b: zero where the axes are aligned;
* WELD: p_a − p_b, then e = log(R_aᵀ·R_b) (3 rows, rad), the rotation error by the log map of
  SO(3), not the skew part of R_aᵀ·R_b, which also vanishes where the frames are turned by π;
* DISTANCE (a ball closure whose rod is reduced, ``rods.Rod``, or any ``rods.Distance``):
  (|x − P|² − L²)/(2L) (1 row, m), x the ball on the other side, P the rod's universal-joint
  centre, L the rod's length from P to its ball.

Columns: the coordinates that move the loops. A turn about the unit world axis ω through the
point o moves a point p at ω × (p − o) per unit of its value, a slide along ω at ω; the frames
turn at ω. The rows' derivatives follow exactly: for a pin ∂(u·n_a)/∂q = ±ω·(n_a × u), for a
weld ∂e/∂q = J⁻¹(e)·R_aᵀ·(±ω) (``spatial.log_rate_matrix``). ``jacobian_rate`` is J̇ for joint
rates q̇, the derivative of each column along the motion (J̇·q̇ is the rows' acceleration at
q̈ = 0); for a weld's rotation rows it is J⁻¹(e)·d(R_aᵀ·ω)/dt, exact where e and ė vanish (an
assembled pose moving as the loops allow), which is where it is used.

Plain floats throughout (``spatial``): this is the per-sample path. Pure: no ROS.
"""

from __future__ import annotations

from collections.abc import Collection, Iterator, Mapping, Sequence
from dataclasses import dataclass
import enum
import math

from linkage_kinematics.loops.closures import Closure, ClosureKind
from linkage_kinematics.loops.frames import Frames, Motion, Program
from linkage_kinematics.loops.rods import Distance, Rod, rod_distance
from linkage_kinematics.loops.spatial import (
    add,
    apply,
    apply_transposed,
    cross,
    dot,
    IDENTITY,
    log_rate_matrix,
    log_rotation,
    multiply,
    norm,
    perpendicular_pair,
    Rotation,
    scale,
    subtract,
    transpose,
    Vector,
)
from linkage_kinematics.loops.tree import KinematicTree, Loop, MotionKind, Pose, unit_axis

# What a closure's Jacobian rows need (LoopEquations._modes): none, its positions', all.
_SKIP = 0
_POSITIONS = 1
_ALL = 2


class RowKind(enum.Enum):
    """The unit of a residual row: a length (m) or an angle (rad)."""

    LENGTH = 'm'
    ANGLE = 'rad'


class _Form(enum.Enum):
    BALL = 3
    PIN = 5
    WELD = 6
    DISTANCE = 1


@dataclass
class Evaluation:
    """The frames of every loop program at one configuration, and the residual there."""

    values: list[float]
    frames: list[Frames]
    residual: list[float]
    # each closure's two points (a distance's: x, then P), as the residual found them
    points: list[tuple[Vector, Vector]]


class LoopEquations:
    """
    The residuals of a set of closures and their exact Jacobian (module docstring).

    Values are given per coordinate in ``coordinates`` order (indices of the tree's
    coordinates). ``rods`` names the closures written as a distance (a ``Rod``'s ball closure,
    or any ``Distance``).
    """

    def __init__(self, tree: KinematicTree, closures: Sequence[Closure],
                 rods: Mapping[str, Rod | Distance] | None = None) -> None:
        distances = {name: rod_distance(rod) if isinstance(rod, Rod) else rod
                     for name, rod in (rods or {}).items()}
        loops = [tree.loop(closure) for closure in closures]
        paths = []
        for loop in loops:
            distance = distances.get(loop.closure.name)
            trimmed = list(loop.paths)
            if distance is not None:
                trimmed = [tuple(step for step in path if step not in distance.trimmed)
                           for path in trimmed]
            paths.append(trimmed)
        self.coordinates: tuple[int, ...] = tuple(sorted(
            {tree.steps[step].coordinate for sides in paths for path in sides for step in path}
            | {slide[0] for distance in distances.values() for slide in distance.stretch}))
        self.names = tuple(tree.coordinates[i].name for i in self.coordinates)
        column = {coordinate: i for i, coordinate in enumerate(self.coordinates)}
        bases = sorted({loop.base for loop in loops})
        # per base frame, one program: the steps below it that the loops need, in tree order
        # (a rod's socket is on its side's path, which keeps the steps above the rod)
        self._programs: list[Program] = []
        # tree step → (program, place in it)
        self.places: dict[int, tuple[int, int]] = {}
        slots = []
        for base in bases:
            needed = sorted({step for loop, sides in zip(loops, paths) if loop.base == base
                             for path in sides for step in path})
            slot = {base: 0} | {step + 1: place + 1 for place, step in enumerate(needed)}
            self.places |= {step: (len(self._programs), place)
                            for place, step in enumerate(needed)}
            self._programs.append(Program([tree.steps[step] for step in needed], slot, column))
            slots.append(slot)
        self._closures = []
        kinds: list[RowKind] = []
        self.closure_rows: list[tuple[str, int, int]] = []
        for loop, sides in zip(loops, paths):
            program = bases.index(loop.base)
            record = _closure_record(tree, loop, sides, distances.get(loop.closure.name),
                                     slots[program], column, program)
            self.closure_rows.append((loop.closure.name, len(kinds), record[0].value))
            kinds += _row_kinds(record[0])
            self._closures.append(record)
        self.row_kinds = tuple(kinds)
        self.rows = len(kinds)
        # per set of columns and of rows asked for: what ``jacobian`` computes (its caches)
        self._prepared: dict[frozenset[int] | None, list[tuple]] = {}
        self._row_modes: dict[frozenset[int] | None, list[int]] = {}

    def evaluate(self, values: Sequence[float], previous: Evaluation | None = None,
                 changed: Collection[int] | None = None) -> Evaluation:
        """
        Return the frames and the residual at coordinate ``values``.

        Given the ``previous`` evaluation and the columns ``changed`` since, only the frames
        those move are posed again.
        """
        if previous is None:
            frames = [program.run(values) for program in self._programs]
        else:
            frames = [program.run(values, old, changed) if program.columns & changed else old
                      for program, old in zip(self._programs, previous.frames)]
        evaluation = Evaluation(list(values), frames, [], [])
        residual, points = evaluation.residual, evaluation.points
        for record in self._closures:
            pair = (_side_point(record[2], evaluation), _side_point(record[3], evaluation))
            points.append(pair)
            residual += _residual(record, evaluation, pair)
        return evaluation

    def residual(self, values: Sequence[float]) -> list[float]:
        """Return the residual rows at coordinate ``values``."""
        return self.evaluate(values).residual

    def jacobian(self, evaluation: Evaluation, columns: Collection[int] | None = None,
                 rows: Collection[int] | None = None) -> list[list[float]]:
        """
        Return ∂(residual)/∂(coordinates) at an evaluation, one list per row.

        Only the ``columns`` asked for are computed (the others left 0), and with ``rows``
        only those rows are sure to be (a closure none of whose rows is asked for gives zero
        rows; a pin's or weld's angle rows are left 0 unless one of them is asked for); all
        by default. The per-sample solver asks for the same sets every time: give them as
        frozensets, whose steps are then sorted out once.
        """
        width = len(self.coordinates)
        result: list[list[float]] = []
        steps = self._steps(columns)
        modes = self._modes(rows)
        for record, pair, prepared, mode, (_, _, count) in zip(
                self._closures, evaluation.points, steps, modes, self.closure_rows):
            if mode == _SKIP:
                result += [[0.0] * width for _ in range(count)]
            else:
                result += _jacobian_rows(record, evaluation, pair, width, prepared,
                                         mode == _ALL)
        return result

    def _steps(self, columns: Collection[int] | None) -> list[tuple]:
        """Return per closure its sides' steps that move ``columns`` (and its known slides)."""
        key = columns if columns is None or isinstance(columns, frozenset) else frozenset(
            columns)
        prepared = self._prepared.get(key)
        if prepared is None:
            prepared = []
            for record in self._closures:
                sides = tuple(tuple((place, col, sign * multiplier, turn)
                                    for place, col, multiplier, turn in side[4]
                                    if key is None or col in key)
                              for side, sign in ((record[2], 1.0), (record[3], -1.0)))
                stretch = () if record[0] is not _Form.DISTANCE else tuple(
                    slide for slide in record[6] if key is None or slide[0] in key)
                prepared.append(sides + (stretch,))
            self._prepared[key] = prepared
        return prepared

    def _modes(self, rows: Collection[int] | None) -> list[int]:
        """Return per closure which of its rows ``rows`` needs: none, positions, all."""
        key = rows if rows is None or isinstance(rows, frozenset) else frozenset(rows)
        modes = self._row_modes.get(key)
        if modes is None:
            modes = []
            for _, start, count in self.closure_rows:
                if key is None or any(row in key for row in range(start + 3, start + count)):
                    modes.append(_ALL)
                elif any(row in key for row in range(start, start + count)):
                    modes.append(_POSITIONS)
                else:
                    modes.append(_SKIP)
            self._row_modes[key] = modes
        return modes

    def jacobian_rate(self, evaluation: Evaluation,
                      rates: Sequence[float]) -> list[list[float]]:
        """Return J̇ for coordinate ``rates`` at an evaluation (module docstring), per row."""
        motion = Motion(self._programs, evaluation.frames, evaluation.values, rates)
        width = len(self.coordinates)
        rows: list[list[float]] = []
        for record in self._closures:
            rows += _rate_rows(record, evaluation, motion, width)
        return rows

    def gaps(self, evaluation: Evaluation) -> list[tuple[float, float | None]]:
        """
        Return per closure how far it is open: its frames' origins (m) and angle (rad).

        The angle is a pin's axes', a weld's frames'; None for a ball.
        """
        gaps = []
        for record in self._closures:
            form = record[0]
            gap = norm(subtract(_side_point(record[2], evaluation),
                                _side_point(record[3], evaluation)))
            angle = None
            if form is _Form.DISTANCE:
                gap = abs(gap - _length(record, evaluation.values))
            elif form is _Form.PIN:
                n_a = apply(_frame_rotation(record[2], evaluation), record[4])
                n_b = apply(_frame_rotation(record[3], evaluation), record[5])
                angle = math.atan2(norm(cross(n_a, n_b)), dot(n_a, n_b))
            elif form is _Form.WELD:
                turn = multiply(transpose(_side_rotation(record[2], evaluation)),
                                _side_rotation(record[3], evaluation))
                angle = norm(log_rotation(turn))
            gaps.append((gap, angle))
        return gaps

    def point(self, closure: int, side: int, evaluation: Evaluation) -> Vector:
        """
        Return a closure side's point in its loop's base frame.

        For a closure reduced to a distance, side 0 is the ball x on the other side and side 1
        the rod's centre P.
        """
        return evaluation.points[closure][side]

    def relative_motion(self, closure: int, evaluation: Evaluation,
                        rates: Sequence[float]) -> tuple[Vector, Vector]:
        """
        Return how fast a closure's side-0 point moves from its side-1 point, and how fast.

        The second: how fast side 1's moving frame turns (both in the base frame), for
        coordinate ``rates``; a rod's socket's spin.
        """
        record = self._closures[closure]
        vx = vy = vz = sx = sy = sz = 0.0
        for side, point, sign in ((record[2], evaluation.points[closure][0], 1.0),
                                  (record[3], evaluation.points[closure][1], -1.0)):
            px, py, pz = point
            _, _, axes, origins = evaluation.frames[side[0]]
            for place, col, multiplier, turn in side[4]:
                rate = sign * multiplier * rates[col]
                if rate == 0.0:
                    continue
                wx, wy, wz = axes[place]
                if not turn:
                    vx, vy, vz = vx + rate * wx, vy + rate * wy, vz + rate * wz
                    continue
                ox, oy, oz = origins[place]
                rx, ry, rz = px - ox, py - oy, pz - oz
                vx += rate * (wy * rz - wz * ry)
                vy += rate * (wz * rx - wx * rz)
                vz += rate * (wx * ry - wy * rx)
                if sign < 0.0:
                    sx, sy, sz = sx - rate * wx, sy - rate * wy, sz - rate * wz
        return (vx, vy, vz), (sx, sy, sz)

    def frame(self, closure: int, side: int, evaluation: Evaluation) -> tuple[Rotation, Vector]:
        """Return the rotation and origin of a closure side's moving frame, in the base frame."""
        program, slot = self._closures[closure][2 + side][:2]
        rotations, positions = evaluation.frames[program][:2]
        return rotations[slot], positions[slot]

    def spin(self, closure: int, side: int, evaluation: Evaluation,
             rates: Sequence[float]) -> Vector:
        """Return how fast a closure side's moving frame turns in the base frame, for ``rates``."""
        record = self._closures[closure][2 + side]
        axes = evaluation.frames[record[0]][2]
        sx = sy = sz = 0.0
        for place, col, multiplier, turn in record[4]:
            rate = multiplier * rates[col]
            if turn and rate != 0.0:
                wx, wy, wz = axes[place]
                sx, sy, sz = sx + rate * wx, sy + rate * wy, sz + rate * wz
        return (sx, sy, sz)

    def socket(self, closure: int) -> tuple[int, int]:
        """Return the program and slot of a closure's side-1 moving frame (a rod's socket)."""
        return self._closures[closure][3][0], self._closures[closure][3][1]

    def step_axis(self, step: int, evaluation: Evaluation) -> tuple[Vector, Vector]:
        """Return a tree step's world axis and joint origin (its loop's base frame)."""
        program, place = self.places[step]
        frames = evaluation.frames[program]
        return frames[2][place], frames[3][place]


def _closure_record(tree: KinematicTree, loop: Loop, paths: Sequence[Sequence[int]],
                    distance: Distance | None, slot: Mapping[int, int],
                    column: Mapping[int, int], program: int) -> tuple:
    """
    Return what the rows of one closure need: (form, steps, side a, side b, extra…).

    A side is (program, slot, offset rotation, offset position, its steps as (step slot − 1,
    column, multiplier, turn)); steps lists both sides' with their sign (+1 side a, −1 side b).
    """
    def side(index: int) -> tuple:
        frame, offset = loop.sides[index]
        if distance is not None and distance.points[index] is not None:
            frame, point = distance.points[index]
            offset = Pose(IDENTITY, point)
        steps = tuple((slot[step + 1] - 1, column[tree.steps[step].coordinate],
                       tree.steps[step].multiplier, tree.steps[step].kind is MotionKind.TURN)
                      for step in paths[index])
        return (program, slot[frame], offset.rotation, offset.position, steps)

    a, b = side(0), side(1)
    closure = loop.closure
    if distance is not None:
        x, center = (b, a) if distance.center == 0 else (a, b)
        stretch = tuple((column[c], m, o, u) for c, m, o, u in distance.stretch)
        return (_Form.DISTANCE, None, x, center, distance.length, distance.span, stretch)
    if closure.kind is ClosureKind.BALL:
        return (_Form.BALL, None, a, b)
    if closure.kind is ClosureKind.WELD:
        return (_Form.WELD, None, a, b)
    n_a = unit_axis(closure.parent)
    n_b = unit_axis(closure.child)
    # the axes in their moving frames; u₁, u₂ perpendicular to side b's, fixed on side b
    n_a = apply(a[2], n_a)
    n_b = apply(b[2], n_b)
    u1, u2 = perpendicular_pair(n_b)
    return (_Form.PIN, None, a, b, n_a, n_b, u1, u2)


def _row_kinds(form: _Form) -> list[RowKind]:
    if form is _Form.DISTANCE:
        return [RowKind.LENGTH]
    return [RowKind.LENGTH] * 3 + [RowKind.ANGLE] * (form.value - 3)


def _side_point(side: tuple, evaluation: Evaluation) -> Vector:
    program, slot, _, shift, _ = side
    rotations, positions = evaluation.frames[program][:2]
    r, p = rotations[slot], positions[slot]
    x, y, z = shift
    return (p[0] + r[0] * x + r[1] * y + r[2] * z, p[1] + r[3] * x + r[4] * y + r[5] * z,
            p[2] + r[6] * x + r[7] * y + r[8] * z)


def _frame_rotation(side: tuple, evaluation: Evaluation) -> Rotation:
    return evaluation.frames[side[0]][0][side[1]]


def _side_rotation(side: tuple, evaluation: Evaluation) -> Rotation:
    return multiply(_frame_rotation(side, evaluation), side[2])


def _point_rate(side: tuple, evaluation: Evaluation, motion: Motion) -> Vector:
    return motion.point(side[0], side[1], evaluation.frames[side[0]][1],
                        _side_point(side, evaluation))


def _span(record: tuple, values: Sequence[float]) -> Vector | None:
    """Return a distance's rod vector with its known slides at ``values`` (None: no slides)."""
    stretch = record[6]
    if not stretch:
        return None
    x, y, z = record[5]
    for col, multiplier, offset, (ux, uy, uz) in stretch:
        travel = multiplier * values[col] + offset
        x, y, z = x + travel * ux, y + travel * uy, z + travel * uz
    return (x, y, z)


def _length(record: tuple, values: Sequence[float]) -> float:
    """Return a distance's length L at ``values`` (its known slides moved)."""
    span = _span(record, values)
    return record[4] if span is None else norm(span)


def _residual(record: tuple, evaluation: Evaluation,
              points: tuple[Vector, Vector]) -> list[float]:
    form, _, a, b = record[:4]
    p_a, p_b = points
    dx, dy, dz = p_a[0] - p_b[0], p_a[1] - p_b[1], p_a[2] - p_b[2]
    if form is _Form.DISTANCE:
        length = _length(record, evaluation.values)
        return [(dx * dx + dy * dy + dz * dz - length * length) / (2.0 * length)]
    rows = [dx, dy, dz]
    if form is _Form.PIN:
        n_a = apply(_frame_rotation(a, evaluation), record[4])
        r_b = _frame_rotation(b, evaluation)
        rows += [dot(apply(r_b, record[6]), n_a), dot(apply(r_b, record[7]), n_a)]
    elif form is _Form.WELD:
        rows += log_rotation(multiply(transpose(_side_rotation(a, evaluation)),
                                      _side_rotation(b, evaluation)))
    return rows


def _jacobian_rows(record: tuple, evaluation: Evaluation, points: tuple[Vector, Vector],
                   width: int, prepared: tuple, angles: bool) -> list[list[float]]:
    """Return one closure's Jacobian rows over its ``prepared`` steps (LoopEquations._steps)."""
    form, _, a, b = record[:4]
    p_a, p_b = points
    steps_a, steps_b, stretch = prepared
    if form is _Form.DISTANCE:
        # ∂/∂q of (|d|² − L²)/(2L) = d·(screw at x − screw at P)/L, d·(ω × (p − o)) written as
        # ω·((p − o) × d)
        span = _span(record, evaluation.values)
        length = record[4] if span is None else norm(span)
        dx, dy, dz = ((p_a[0] - p_b[0]) / length, (p_a[1] - p_b[1]) / length,
                      (p_a[2] - p_b[2]) / length)
        row = [0.0] * width
        if span is not None:
            # a known slide stretches the rod: ∂r/∂L = −(|d|² + L²)/(2L²), ∂L/∂q = m·(u·ℓ)/L
            factor = -(dx * dx + dy * dy + dz * dz + 1.0) / (2.0 * length)
            for col, multiplier, _, direction in stretch:
                row[col] += factor * multiplier * dot(direction, span)
        for side, (px, py, pz), steps in ((a, p_a, steps_a), (b, p_b, steps_b)):
            _, _, axes, origins = evaluation.frames[side[0]]
            for place, col, factor, turn in steps:
                wx, wy, wz = axes[place]
                if turn:
                    ox, oy, oz = origins[place]
                    rx, ry, rz = px - ox, py - oy, pz - oz
                    row[col] += factor * (wx * (ry * dz - rz * dy) + wy * (rz * dx - rx * dz)
                                          + wz * (rx * dy - ry * dx))
                else:
                    row[col] += factor * (wx * dx + wy * dy + wz * dz)
        return [row]
    rows = [[0.0] * width for _ in range(form.value)]
    row_x, row_y, row_z = rows[0], rows[1], rows[2]
    if not angles:
        form = _Form.BALL
    elif form is _Form.PIN:
        n_a = apply(_frame_rotation(a, evaluation), record[4])
        r_b = _frame_rotation(b, evaluation)
        (n0x, n0y, n0z), (n1x, n1y, n1z) = (cross(n_a, apply(r_b, record[6])),
                                            cross(n_a, apply(r_b, record[7])))
        row_3, row_4 = rows[3], rows[4]
    elif form is _Form.WELD:
        r_a = _side_rotation(a, evaluation)
        e = log_rotation(multiply(transpose(r_a), _side_rotation(b, evaluation)))
        # ∂e/∂q = J⁻¹(e)·R_aᵀ·(−factor·ω)
        m0, m1, m2, m3, m4, m5, m6, m7, m8 = multiply(log_rate_matrix(e), transpose(r_a))
        row_3, row_4, row_5 = rows[3], rows[4], rows[5]
    for side, (px, py, pz), steps in ((a, p_a, steps_a), (b, p_b, steps_b)):
        _, _, axes, origins = evaluation.frames[side[0]]
        for place, col, factor, turn in steps:
            wx, wy, wz = axes[place]
            if not turn:
                row_x[col] += factor * wx
                row_y[col] += factor * wy
                row_z[col] += factor * wz
                continue
            ox, oy, oz = origins[place]
            rx, ry, rz = px - ox, py - oy, pz - oz
            row_x[col] += factor * (wy * rz - wz * ry)
            row_y[col] += factor * (wz * rx - wx * rz)
            row_z[col] += factor * (wx * ry - wy * rx)
            if form is _Form.PIN:
                row_3[col] += factor * (wx * n0x + wy * n0y + wz * n0z)
                row_4[col] += factor * (wx * n1x + wy * n1y + wz * n1z)
            elif form is _Form.WELD:
                row_3[col] -= factor * (m0 * wx + m1 * wy + m2 * wz)
                row_4[col] -= factor * (m3 * wx + m4 * wy + m5 * wz)
                row_5[col] -= factor * (m6 * wx + m7 * wy + m8 * wz)
    return rows


def _screw(frames: Frames, place: int, turn: bool, point: Vector) -> Vector:
    """Return how a step moves ``point`` per unit of its value."""
    w = frames[2][place]
    return cross(w, subtract(point, frames[3][place])) if turn else w


def _rate_rows(record: tuple, evaluation: Evaluation, motion: Motion,
               width: int) -> list[list[float]]:
    form, _, a, b = record[:4]
    p_a, p_b = _side_point(a, evaluation), _side_point(b, evaluation)
    v_a, v_b = _point_rate(a, evaluation, motion), _point_rate(b, evaluation, motion)

    def screw_rates(side: tuple, point: Vector, velocity: Vector) -> Iterator[tuple]:
        frames = evaluation.frames[side[0]]
        for place, col, multiplier, turn in side[4]:
            w, o = frames[2][place], frames[3][place]
            yield (place, col, multiplier, turn, w, _screw(frames, place, turn, point),
                   motion.screw_rate(side[0], place, turn, w, o, point, velocity))

    if form is _Form.DISTANCE:  # (of a rod without known slides: the unreduced equations')
        length = _length(record, evaluation.values)
        d, d_rate = subtract(p_a, p_b), subtract(v_a, v_b)
        row = [0.0] * width
        for side, point, velocity, sign in ((a, p_a, v_a, 1.0), (b, p_b, v_b, -1.0)):
            moves = screw_rates(side, point, velocity)
            for _, col, multiplier, _, _, screw, screw_rate in moves:
                row[col] += sign * multiplier * (dot(d_rate, screw)
                                                 + dot(d, screw_rate)) / length
        return [row]
    rows = [[0.0] * width for _ in range(form.value)]
    spin_a, spin_b = motion.spins[a[0]][a[1]], motion.spins[b[0]][b[1]]
    if form is _Form.PIN:
        n_a = apply(_frame_rotation(a, evaluation), record[4])
        r_b = _frame_rotation(b, evaluation)
        pairs = []
        for u_local in (record[6], record[7]):
            u = apply(r_b, u_local)
            pairs.append((cross(n_a, u), add(cross(cross(spin_a, n_a), u),
                                             cross(n_a, cross(spin_b, u)))))
    elif form is _Form.WELD:
        r_a = _side_rotation(a, evaluation)
        rate = log_rate_matrix(log_rotation(multiply(transpose(r_a),
                                                     _side_rotation(b, evaluation))))
    for side, point, velocity, sign in ((a, p_a, v_a, 1.0), (b, p_b, v_b, -1.0)):
        moves = screw_rates(side, point, velocity)
        for place, col, multiplier, turn, w, _, screw_rate in moves:
            factor = sign * multiplier
            for row, component in zip(rows, screw_rate):
                row[col] += factor * component
            if not turn:
                continue
            w_rate = motion.axis_rates[side[0]][place]
            if form is _Form.PIN:
                for row, (normal, normal_rate) in zip(rows[3:], pairs):
                    row[col] += factor * (dot(w_rate, normal) + dot(w, normal_rate))
            elif form is _Form.WELD:
                # d(R_aᵀ·v)/dt = R_aᵀ·(v̇ − Ω_a × v), v = −factor·ω
                v, v_rate = scale(-factor, w), scale(-factor, w_rate)
                ex, ey, ez = apply(rate, apply_transposed(r_a, subtract(v_rate,
                                                                        cross(spin_a, v))))
                rows[3][col] += ex
                rows[4][col] += ey
                rows[5][col] += ez
    return rows
