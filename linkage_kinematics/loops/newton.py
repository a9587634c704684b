# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
One closure group closed per sample: its known joints in, every other joint of its loops out.

``GroupSolver`` takes any set of known coordinates the structure found determining (the
measured actuators now; output joints in issue 30's direction). Per sample:

1. **Positions** by a closed form where the structure found one (``GroupKind``: the planar
   five-bar, a crank–rod–ball leg's inverse; closed_forms.py), else by Newton continued from
   the last solution along the known joints' motion (continuation.py). A rod reduced to a
   distance (structure.reducible_rods) gets its angles in closed form, continued from the
   last; a closure rewritten smaller (reduction.py) its joints.
2. **Velocities** from the same Jacobian: q̇_U = −A⁻¹·J_K·q̇_K (square_system.py's S), added
   in order; the rods' and rewritten closures' from theirs.
3. **Refusals** (refusals.py), each by name with its own reason, never NaN: a row left open
   beyond its rounding; a conditioning κ above ``refusals.CONDITION_LIMIT`` (the continuation
   goes on through such samples); det A's sign changed from the assembly's; and what the
   continuation refuses.
4. **Derivatives** on request (``derivatives.Derivatives``, on the unreduced equations, from
   the last solution): the sensitivity, accelerations, the distance to a singular
   configuration.

``plan_group`` assembles, analyses and classifies a group and builds its solver (or says in
one line why not): the one call the node and the checker make per group. Pure: no ROS.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
import math

from linkage_kinematics.loops.assembly import assemble, Assembly
from linkage_kinematics.loops.closed_forms import (
    FiveBarPositions,
    LegPositions,
    OutOfReach,
    TurnChain,
)
from linkage_kinematics.loops.continuation import bend, Continuation
from linkage_kinematics.loops.derivatives import Derivatives
from linkage_kinematics.loops.equations import Evaluation, LoopEquations
from linkage_kinematics.loops.reduction import reduce_group, Reduction
from linkage_kinematics.loops.refusals import (
    CONDITION_LIMIT,
    PlanError,
    Refusal,
    SampleRefused,
)
from linkage_kinematics.loops.spatial import apply_transposed, cross, dot, subtract
from linkage_kinematics.loops.square_system import NewtonSystem, residual_bounds
from linkage_kinematics.loops.structure import (
    analyse,
    classify,
    ClosureGroup,
    GroupKind,
    GroupStructure,
    reducible_rods,
)
from linkage_kinematics.loops.tree import KinematicTree, MotionKind

# A rewritten closure's joints (reduction.py) must come out of its closed forms at the
# assembled pose within this (rad) of the pose's, else the closures are solved as written.
FOLLOWED = 1e-9


@dataclass
class GroupState:
    """A solved sample: ``solved`` joints' positions and velocities, κ and Newton's iterations."""

    positions: tuple[float, ...]
    velocities: tuple[float, ...]
    conditioning: float
    iterations: int


class _Rods:
    """The rods reduced to distances: their angles in closed form, continued from the last."""

    def __init__(self, equations: LoopEquations, unknown: Sequence[int], rods: dict) -> None:
        names = [name for name, _, _ in equations.closure_rows]
        self.equations = equations
        # (closure place, rod, outputs: the rod's coordinates' places in ``unknown``, its
        # universal joint's turns)
        self.rods = [(names.index(name), rod, [list(unknown).index(c)
                                               for c in rod.coordinates],
                      TurnChain(rod.origins, rod.axes))
                     for name, rod in rods.items()]
        self.coordinates = {c for rod in rods.values() for c in rod.coordinates}
        self.branches: list[int] = []
        self.angles: list[list[float]] = []

    def reset(self, evaluation: Evaluation, values: Sequence[float]) -> None:
        """Take each rod's branch and angles at an assembled pose (all the tree's values)."""
        self.branches = [min((1, -1), key=lambda branch: abs(math.remainder(
            chain.pointing(rod.rod, self.target(place, evaluation)[0], branch)[1]
            - values[rod.coordinates[1]], 2.0 * math.pi)))
            for place, rod, _, chain in self.rods]
        self.angles = [[values[c] for c in rod.coordinates] for _, rod, *_ in self.rods]

    def target(self, place: int, evaluation: Evaluation) -> tuple:
        """Return the ball relative to the rod's centre in the socket frame, d, the socket."""
        program, slot = self.equations.socket(place)
        socket = evaluation.frames[program][0][slot]
        ball, center = evaluation.points[place]
        d = (ball[0] - center[0], ball[1] - center[1], ball[2] - center[2])
        return apply_transposed(socket, d), d, socket

    def solve(self, evaluation: Evaluation, rates: Sequence[float],
              refuse: Callable[[Refusal, str], SampleRefused]
              ) -> list[tuple[list[float], tuple[float, float], float]]:
        """Return per rod its angles (continued), their rates and the rates' conditioning."""
        results = []
        for (place, rod, _, chain), branch, last in zip(self.rods, self.branches, self.angles):
            target, d, socket = self.target(place, evaluation)
            try:
                angles = chain.pointing(rod.rod, target, branch)
            except OutOfReach as error:
                raise refuse(Refusal.UNREACHABLE, f'rod of {rod.closure}: {error}') from None
            angles = [angle if abs(angle - previous) <= math.pi else angle - 2.0 * math.pi
                      * round((angle - previous) / (2.0 * math.pi))
                      for angle, previous in zip(angles, last)]
            # the joint's axes in the base frame: the first fixed on the socket, the second
            # turned with the first
            axis1, axis2 = chain.world_axes(socket, [(math.cos(angles[0]),
                                                      math.sin(angles[0]))])
            # ḋ = (Ω_socket + θ̇₁ω₁ + θ̇₂ω₂) × d: the rod turns with its socket too
            velocity, spin = self.equations.relative_motion(place, evaluation, rates)
            d_rate = subtract(velocity, cross(spin, d))
            # ω₁θ̇₁ × d + ω₂θ̇₂ × d = ḋ: three consistent equations, solved by their normal
            # equations; κ of [c₁ c₂] is the square root of its Gram matrix's
            c1, c2 = cross(axis1, d), cross(axis2, d)
            g11, g12, g22 = dot(c1, c1), dot(c1, c2), dot(c2, c2)
            det = g11 * g22 - g12 * g12
            if not det > 0.0:
                raise refuse(Refusal.SINGULAR, f"rod of {rod.closure} along its joint's axis")
            r1, r2 = dot(c1, d_rate), dot(c2, d_rate)
            trace = g11 + g22
            spread = math.sqrt(max(trace * trace - 4.0 * det, 0.0))
            results.append((angles, ((g22 * r1 - g12 * r2) / det, (g11 * r2 - g12 * r1) / det),
                            math.sqrt((trace + spread) / max(trace - spread, 1e-300))))
        return results


class GroupSolver:
    """
    Closes one group per sample from its known joints (module docstring).

    ``known`` and ``solved`` name the coordinates given and returned, in the tree's order;
    ``solve`` takes and returns values in those orders. Built from the group's structure and an
    assembled pose (its known joints at the first sample's values, or the checker's); ``kind``
    is how positions are solved (structure.classify).
    """

    def __init__(self, tree: KinematicTree, group: ClosureGroup, structure: GroupStructure,
                 assembly: Assembly, kind: GroupKind = GroupKind.NEWTON) -> None:
        self.name = group.name
        self.kind = kind
        self.known = structure.known
        self.solved = structure.solved
        values = assembly.values
        # closures rewritten smaller where their end joints allow (reduction.py); a planar
        # loops' group stays as the planar closed forms read it
        reduction = (reduce_group(tree, group, structure, values)
                     if kind is not GroupKind.PLANAR_LOOPS else Reduction(group, structure, ()))
        try:
            self._build(tree, group, reduction, kind, values)
        except PlanError:
            # a rewriting that does not hold at the assembled pose: the closures as written
            self._build(tree, group, Reduction(group, structure, ()), kind, values)
        self.derivatives = Derivatives(tree, group, structure, values)
        self.reset(values)

    def _build(self, tree: KinematicTree, group: ClosureGroup, reduction: Reduction,
               kind: GroupKind, values: Sequence[float]) -> None:
        """Build the per-sample equations, system and closed forms; PlanError if they fail."""
        work = reduction.group
        rods = (reducible_rods(tree, work, reduction.structure)
                if kind in (GroupKind.NEWTON, GroupKind.LEG_INVERSE) else {})
        self.equations = LoopEquations(tree, work.closures, {**rods, **reduction.distances})
        self._rods = _Rods(self.equations, group.unknown, rods)
        self._followers = reduction.followers
        local = [values[i] for i in self.equations.coordinates]
        newton = [i for i in work.unknown if i not in self._rods.coordinates]
        system = NewtonSystem(tree, self.equations, newton, reduction.structure, local)
        self._known_columns = [self.equations.coordinates.index(i) for i in group.known]
        self._known_turns = [tree.coordinates[i].kind is MotionKind.TURN for i in group.known]
        self._outputs = [self.equations.coordinates.index(i) if i in newton else None
                         for i in group.unknown]
        unknown = list(group.unknown)
        self._follower_outputs = [[unknown.index(c) for c in follower.coordinates]
                                  for follower in self._followers]
        self._continuation = Continuation(
            self.name, self.equations, system, self._known_columns,
            system.wrapped(tree, self.equations),
            residual_bounds(tree, work, self.equations, reduction.structure.size))
        if kind is GroupKind.LEG_INVERSE:
            self._closed_form = LegPositions(tree, work, self.equations,
                                             next(iter(rods.values())))
        elif kind is GroupKind.FIVE_BAR:
            self._closed_form = FiveBarPositions(tree, work, self.equations, values)
        else:
            self._closed_form = None
        evaluation = self.equations.evaluate(local)
        for follower in self._followers:
            if not follower.reset(self.equations, evaluation, values) <= FOLLOWED:
                raise PlanError(f'group {self.name}: closure {follower.closure} rewritten '
                                'does not hold at the assembled pose')

    def reset(self, values: Sequence[float]) -> None:
        """Start again at an assembled pose (``values`` over all the tree's coordinates)."""
        local = [float(values[i]) for i in self.equations.coordinates]
        evaluation = self.equations.evaluate(local)
        self._continuation.reset(evaluation)
        self._values = local
        self._rods.reset(evaluation, values)
        for follower in self._followers:
            follower.reset(self.equations, evaluation, values)
        if self._closed_form is not None:
            self._closed_form.reset(local)
        self.derivatives.last = None

    @property
    def orientation(self) -> int:
        """Return the sign of det A at the last solution (±1), which names the assembly."""
        return int(self._continuation.sign)

    @property
    def lost(self) -> bool:
        """Return whether a sample crossed a singular configuration: all refused until reset."""
        return self._continuation.lost is not None

    def solve(self, positions: Sequence[float], velocities: Sequence[float]) -> GroupState:
        """
        Return the ``solved`` joints' positions and velocities for the ``known`` joints'.

        SampleRefused (with its ``Refusal``) leaves the answer (``derivatives``) as it was; the
        continuation follows a sample refused as too near a singular configuration, and is
        lost at a sample that crossed one (module docstring).
        """
        if self._continuation.lost is not None:
            raise self._continuation.lost
        values = list(self._values)
        changes = []
        for column, value, turn in zip(self._known_columns, positions, self._known_turns):
            if not math.isfinite(value):
                raise self._refuse(Refusal.UNREACHABLE, f'a known joint is {value!r}')
            change = value - values[column]
            changes.append(math.remainder(change, 2.0 * math.pi) if turn else change)
        if self._closed_form is not None:
            for column, value in zip(self._known_columns, positions):
                values[column] = value
            try:
                iterations, evaluation, jacobian = self._closed_form(values)
            except OutOfReach as error:
                raise self._refuse(Refusal.UNREACHABLE, str(error)) from None
            found = self._continuation.closed(values, evaluation, jacobian)
        else:
            iterations, values, evaluation, jacobian, found = self._continuation.follow(
                values, changes, positions)
        return self._finish(values, evaluation, jacobian, found, velocities, iterations)

    def _refuse(self, reason: Refusal, detail: str) -> SampleRefused:
        return SampleRefused(self.name, reason, detail)

    def _finish(self, values: list[float], evaluation: Evaluation, jacobian: list,
                found: tuple[list, float, list] | None, velocities: Sequence[float],
                iterations: int) -> GroupState:
        continuation = self._continuation
        continuation.check_residual(evaluation, self._refuse)
        if found is None:
            raise self._refuse(Refusal.SINGULAR, 'the Newton matrix is singular')
        system = continuation.system
        inverse_matrix, det, sensitivity = found
        conditioning = (system.conditioning(system.matrix(jacobian), inverse_matrix)
                        if inverse_matrix else 1.0)
        known = self._known_columns
        rates = [0.0] * len(values)
        for column, rate in zip(known, velocities):
            rates[column] = rate
        for line, column in zip(sensitivity, system.columns):
            total = 0.0
            for s, v in zip(line, velocities):  # in order: the same bits on every Python
                total += s * v
            rates[column] = total
        rods = self._rods.solve(evaluation, rates, self._refuse)
        try:
            followed = [follower.solve(self.equations, evaluation, rates)
                        for follower in self._followers]
        except OutOfReach as error:
            raise self._refuse(Refusal.UNREACHABLE, str(error)) from None
        # the continuation goes on from here even where the answer is too inaccurate to give
        # (Newton's substeps have kept det A's sign; a closed form keeps its branch)
        if self._closed_form is None:
            continuation.bend = bend(values, self._values, known, self._known_turns,
                                     continuation.sensitivity)
        self._values, continuation.sensitivity = values, sensitivity
        self._rods.angles = [rod[0] for rod in rods]
        for follower, (angles, _, _) in zip(self._followers, followed):
            follower.angles = angles
        conditioning = max([conditioning] + [rod[2] for rod in rods]
                           + [result[2] for result in followed])
        if not conditioning <= CONDITION_LIMIT:
            raise self._refuse(Refusal.SINGULAR, f'conditioning {conditioning:.3g} above '
                               f'{CONDITION_LIMIT:.3g}')
        if (det > 0.0) != (continuation.sign > 0.0):
            raise self._refuse(Refusal.ASSEMBLY_CHANGE, 'the sign of det A changed')
        positions = [values[c] if c is not None else 0.0 for c in self._outputs]
        speeds = [rates[c] if c is not None else 0.0 for c in self._outputs]
        for (angles, angle_rates, _), (_, _, outputs, _) in zip(rods, self._rods.rods):
            for output, angle, rate in zip(outputs, angles, angle_rates):
                positions[output], speeds[output] = angle, rate
        for (angles, angle_rates, _), outputs in zip(followed, self._follower_outputs):
            for output, angle, rate in zip(outputs, angles, angle_rates):
                positions[output], speeds[output] = angle, rate
        self.derivatives.last = (positions, speeds, [values[c] for c in known])
        return GroupState(tuple(positions), tuple(speeds), conditioning, iterations)


@dataclass(frozen=True)
class PlannedGroup:
    """
    A group planned at a start: its assembly, structure and solver, or why it is refused.

    ``solver`` is None exactly when ``structure.problem`` says why (under- or over-determined)
    or ``problem`` does (a singular assembled pose).
    """

    assembly: Assembly
    structure: GroupStructure
    kind: GroupKind
    solver: GroupSolver | None
    problem: str | None


def plan_group(tree: KinematicTree, group: ClosureGroup, start: Sequence[float],
               seed: Mapping[str, float] | None = None, hold_known: bool = True) -> PlannedGroup:
    """
    Return a group assembled nearest ``start`` (all the tree's coordinates), analysed, solved.

    ``hold_known``: the known joints stay at the start's values (the node, at its first
    sample); False assembles the whole group freely (the checker, at the zero pose). ``seed``:
    start values of some unknown joints (assembly.assemble). Raises AssemblyError (one line)
    where no closed pose is found.
    """
    assembly = assemble(tree, group, start, None if hold_known else (), seed)
    structure = analyse(tree, group, assembly.values)
    kind = classify(tree, group, structure, assembly.values)
    if kind is GroupKind.NEWTON and structure.problem is None:
        # a closed form may solve the group once its closures are rewritten (reduction.py)
        reduction = reduce_group(tree, group, structure, assembly.values)
        reduced = classify(tree, reduction.group, reduction.structure, assembly.values)
        if reduced in (GroupKind.FIVE_BAR, GroupKind.LEG_INVERSE):
            kind = reduced
    if structure.problem is not None:
        return PlannedGroup(assembly, structure, kind, None, structure.problem)
    try:
        solver = GroupSolver(tree, group, structure, assembly, kind)
    except PlanError as error:
        return PlannedGroup(assembly, structure, kind, None, str(error))
    return PlannedGroup(assembly, structure, kind, solver, None)
