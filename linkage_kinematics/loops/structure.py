# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Closure groups, their degrees of freedom, idle freedoms, and whether known joints determine them.

* **Groups.** Closures that share an unknown coordinate (one not known: not measured, or in
  issue 30's direction not an output joint) are solved together: the union of such closures is
  a group (``closure_groups``). Its coordinates are every coordinate that moves its loops.
* **Degrees of freedom** come from the rank of the group's constraint Jacobian at an assembled
  pose, not from counting rows: a planar loop welded in 3D has 6 rows per closure of which 3
  are independent, a delta's parallelograms are redundant too. DOF = coordinates − rank(J).
  The rank is the number of singular values above ``RANK_TOLERANCE`` times the largest, J
  scaled to be dimensionless (length rows divided by the group's size L, slide columns times
  L): rounding leaves an exactly dependent row at ~1e-16 of the largest and an exporter's
  printed digits at ~1e-7; a mechanism assembled away from its singular configurations has
  no singular value near 1e-9 of the largest (that would put it within ~1e-9 of one).
* **Idle freedoms**: the motions of the unknown coordinates that keep the loops closed (null
  space of J_U, the known coordinates held) and move no joint origin, closure-frame origin or
  link origin of the robot: a rod with a ball at each end spinning about itself, a link between
  two collinear pins. They are no reason to refuse; Newton holds them with the linear equations
  N_refᵀ·(q_U − q_U,ref) = 0 (square_system.py). A null motion that moves anything else leaves the
  group under-determined.
* **Determinacy.** The known coordinates determine the group when they are independent
  (rank J_U = rank J: every motion of them can be followed) and every null motion of J_U is
  idle. Then the number of known coordinates is DOF − (idle freedoms). Otherwise one line names
  the group, its joints, DOF and known ones.
* **How it is solved** (``GroupKind``): recognised from the tree, not from names (``classify``).

Plan time: numpy (SVD) is fine here. Pure: no ROS.
"""

from __future__ import annotations

from collections.abc import Collection, Sequence
from dataclasses import dataclass
import enum

from linkage_kinematics.loops.closures import Closure, ClosureKind
from linkage_kinematics.loops.equations import LoopEquations, RowKind
from linkage_kinematics.loops.rods import Rod, universal_rod
from linkage_kinematics.loops.spatial import apply, cross, norm, subtract
from linkage_kinematics.loops.tree import KinematicTree, MotionKind, unit_axis
import numpy as np

RANK_TOLERANCE = 1e-9
# An idle direction's component counts as moving a coordinate above this (of a unit vector).
COMPONENT_TOLERANCE = 1e-9
# How far (the sine of the angle) a planar loop's axes may lean from its pin's: exporters'
# rounding of π/2 tilts frames by some 1e-16 rad.
PARALLEL_TOLERANCE = 1e-9


class StructureError(ValueError):
    """Closures or known joints that cannot be grouped; the message names them."""


class Determinacy(enum.Enum):
    """Whether a group's known coordinates determine its other coordinates."""

    DETERMINED = 'determined'
    UNDER = 'under-determined'
    OVER = 'over-determined'


class GroupKind(enum.Enum):
    """How a group's positions are solved (velocities always from its exact Jacobian)."""

    NEWTON = 'Newton on the closure equations'
    PLANAR_LOOPS = 'planar one-degree-of-freedom loops in closed form'
    FIVE_BAR = 'planar five-bar in closed form'
    LEG_INVERSE = 'crank-rod-ball leg in closed form'


@dataclass(frozen=True)
class ClosureGroup:
    """Closures solved together, their coordinates (tree indices) and which of those are known."""

    closures: tuple[Closure, ...]
    coordinates: tuple[int, ...]
    known: tuple[int, ...]

    @property
    def name(self) -> str:
        """Return the group's name: its closures' names joined by '+'."""
        return '+'.join(closure.name for closure in self.closures)

    @property
    def unknown(self) -> tuple[int, ...]:
        """Return the coordinates the group solves, in the tree's order."""
        return tuple(i for i in self.coordinates if i not in self.known)


@dataclass(frozen=True)
class IdleFreedom:
    """A motion of unknown coordinates that moves nothing else: its unit direction over them."""

    joints: tuple[str, ...]
    direction: tuple[float, ...]


@dataclass(frozen=True)
class GroupStructure:
    """A group's structure at an assembled pose (module docstring); names are coordinates'."""

    name: str
    closures: tuple[str, ...]
    joints: tuple[str, ...]
    known: tuple[str, ...]
    solved: tuple[str, ...]
    rows: int
    rank: int
    dof: int
    # over the group's unknown coordinates, in ``solved`` order
    idle: tuple[IdleFreedom, ...]
    determinacy: Determinacy
    # one line for a group the known joints do not determine, else None
    problem: str | None
    # the group's size L (m): length rows are divided by it to compare with angle rows
    size: float


def closure_groups(tree: KinematicTree, closures: Sequence[Closure],
                   known: Collection[str]) -> tuple[ClosureGroup, ...]:
    """
    Return the closures' groups for the ``known`` coordinates, in the closures' order.

    StructureError for a known name that is no coordinate of the tree; TreeError (tree.py) for
    a closure the tree cannot hold.
    """
    missing = sorted(set(known) - set(tree.index))
    if missing:
        raise StructureError(f'known joints {missing} are not joints (coordinates) of the robot')
    known_indices = {tree.index[name] for name in known}
    moving = [tree.loop_coordinates(tree.loop(closure)) for closure in closures]
    group_of = list(range(len(closures)))

    def root(i: int) -> int:
        while group_of[i] != i:
            i = group_of[i]
        return i

    owner: dict[int, int] = {}
    for i, coordinates in enumerate(moving):
        for coordinate in coordinates:
            if coordinate in known_indices:
                continue
            if coordinate in owner:
                group_of[root(i)] = root(owner[coordinate])
            else:
                owner[coordinate] = i
    members: dict[int, list[int]] = {}
    for i in range(len(closures)):
        members.setdefault(root(i), []).append(i)
    groups = []
    for indices in sorted(members.values()):
        coordinates = tuple(sorted({c for i in indices for c in moving[i]}))
        groups.append(ClosureGroup(tuple(closures[i] for i in indices), coordinates,
                                   tuple(c for c in coordinates if c in known_indices)))
    return tuple(groups)


def scaled_jacobian(equations: LoopEquations, tree: KinematicTree, values: Sequence[float],
                    size: float) -> np.ndarray:
    """Return the Jacobian at ``values`` made dimensionless (length rows / L, slides × L)."""
    jacobian = np.array(equations.jacobian(equations.evaluate(values)), dtype=float)
    rows = np.array([1.0 / size if kind is RowKind.LENGTH else 1.0
                     for kind in equations.row_kinds])
    columns = np.array([size if tree.coordinates[i].kind is MotionKind.SLIDE else 1.0
                        for i in equations.coordinates])
    return jacobian * rows[:, None] * columns[None, :]


def group_size(equations: LoopEquations, values: Sequence[float]) -> float:
    """Return the group's size L (m): its farthest joint origin or closure point from a base."""
    evaluation = equations.evaluate(values)
    size = 0.0
    for frames in evaluation.frames:
        for origin in frames[3]:
            size = max(size, norm(origin))
    for closure in range(len(equations.closure_rows)):
        for side in (0, 1):
            size = max(size, norm(equations.point(closure, side, evaluation)))
    return size if size > 0.0 else 1.0


def rank(singular_values: np.ndarray) -> int:
    """Return how many singular values are above ``RANK_TOLERANCE`` times the largest."""
    if singular_values.size == 0 or singular_values[0] == 0.0:
        return 0
    return int(np.sum(singular_values > RANK_TOLERANCE * singular_values[0]))


def analyse(tree: KinematicTree, group: ClosureGroup, values: Sequence[float]) -> GroupStructure:
    """
    Return a group's structure at the assembled ``values`` (over all the tree's coordinates).

    The caller has found ``values`` closing the group (assembly.py); ranks there are the
    mechanism's, not an open drawing's.
    """
    equations = LoopEquations(tree, group.closures)
    local = [values[i] for i in equations.coordinates]
    size = group_size(equations, local)
    jacobian = scaled_jacobian(equations, tree, local, size)
    unknown = [equations.coordinates.index(i) for i in group.unknown]
    full_rank = rank(np.linalg.svd(jacobian, compute_uv=False)) if jacobian.size else 0
    unknown_jacobian = jacobian[:, unknown]
    if unknown:
        _, singular, right = np.linalg.svd(unknown_jacobian)
        unknown_rank = rank(singular)
        null = right[unknown_rank:].T  # columns: a basis of null(J_U)
    else:
        unknown_rank, null = 0, np.zeros((0, 0))
    names = [tree.coordinates[i].name for i in group.unknown]
    idle, moving = _idle_split(tree, group, values, null, size)
    dof = len(group.coordinates) - full_rank
    known = tuple(tree.coordinates[i].name for i in group.known)
    problem, determinacy = None, Determinacy.DETERMINED
    head = (f'group {group.name} (joints {[tree.coordinates[i].name for i in group.coordinates]}'
            f'): {dof} degrees of freedom ({len(idle)} idle), known {list(known)}')
    if unknown_rank < full_rank:
        determinacy = Determinacy.OVER
        problem = (f'{head}: over-determined, {len(known)} known joints for '
                   f'{dof - len(idle)} determining freedoms' if len(known) > dof - len(idle)
                   else f'{head}: over-determined, the known joints are not independent')
    elif moving.shape[1]:
        determinacy = Determinacy.UNDER
        moved = [names[i] for i in range(len(names))
                 if np.max(np.abs(moving[i])) > COMPONENT_TOLERANCE]
        problem = (f'{head}: under-determined, a free motion moves {moved}; '
                   f'{dof - len(idle)} known joints are needed')
    return GroupStructure(
        group.name, tuple(closure.name for closure in group.closures),
        tuple(tree.coordinates[i].name for i in group.coordinates), known, tuple(names),
        equations.rows, full_rank, dof,
        tuple(IdleFreedom(tuple(names[i] for i in range(len(names))
                                if abs(vector[i]) > COMPONENT_TOLERANCE),
                          tuple(float(x) for x in vector)) for vector in idle),
        determinacy, problem, size)


def _idle_split(tree: KinematicTree, group: ClosureGroup, values: Sequence[float],
                null: np.ndarray, size: float) -> tuple[list[np.ndarray], np.ndarray]:
    """
    Split null(J_U) into idle directions (moving no point of the robot) and the rest.

    Returns the idle directions as unit vectors, each moving as few coordinates as the subspace
    allows (reduced echelon form, so two rods' spins come out as one each), and a basis of the
    null motions that move points (columns; none when the group is not under-determined).
    """
    if null.shape[1] == 0:
        return [], null
    velocities = _point_velocities(tree, group, values) / size
    moved = velocities @ null
    _, singular, right = np.linalg.svd(moved)
    largest = float(singular[0]) if singular.size else 0.0
    still = int(np.sum(singular > RANK_TOLERANCE * max(1.0, largest)))
    idle_basis = null @ right[still:].T
    moving = null @ right[:still].T
    return _echelon(idle_basis), moving


def _echelon(basis: np.ndarray) -> list[np.ndarray]:
    """Return unit vectors spanning ``basis``'s columns, in reduced row echelon form."""
    if basis.shape[1] == 0:
        return []
    rows = basis.T.copy()
    pivot_row = 0
    for column in range(rows.shape[1]):
        if pivot_row == rows.shape[0]:
            break
        pivot = pivot_row + int(np.argmax(np.abs(rows[pivot_row:, column])))
        if abs(rows[pivot, column]) <= COMPONENT_TOLERANCE:
            continue
        rows[[pivot_row, pivot]] = rows[[pivot, pivot_row]]
        rows[pivot_row] /= rows[pivot_row, column]
        for other in range(rows.shape[0]):
            if other != pivot_row:
                rows[other] -= rows[other, column] * rows[pivot_row]
        pivot_row += 1
    rows[np.abs(rows) <= COMPONENT_TOLERANCE] = 0.0
    return [row / np.linalg.norm(row) for row in rows[:pivot_row]]


def _point_velocities(tree: KinematicTree, group: ClosureGroup,
                      values: Sequence[float]) -> np.ndarray:
    """
    Return how every link origin and closure point moves per unit of each unknown coordinate.

    Rows: three per point (root frame); columns: the group's unknown coordinates. Only points
    below a step of the group can move.
    """
    frames = tree.frames(values)
    unknown = {coordinate: column for column, coordinate in enumerate(group.unknown)}
    screws = {}  # step → (world axis, origin, turn)
    for index, step in enumerate(tree.steps):
        if step.coordinate in unknown:
            parent = frames[step.parent]
            joint = parent.then(step.origin)
            screws[index] = (apply(joint.rotation, step.axis), joint.position,
                             step.kind is MotionKind.TURN)
    points = [(frame, frames[frame].then(offset).position)
              for frame, offset in tree.links.values()]
    for closure in group.closures:
        for side in (closure.parent, closure.child):
            frame, offset = tree.side_frame(side)
            points.append((frame, frames[frame].then(offset).position))
    rows = []
    for frame, point in points:
        block = np.zeros((3, len(group.unknown)))
        for step in tree.path(frame):
            if step in screws:
                axis, origin, turn = screws[step]
                motion = cross(axis, subtract(point, origin)) if turn else axis
                block[:, unknown[tree.steps[step].coordinate]] += (
                    tree.steps[step].multiplier * np.array(motion))
        rows.append(block)
    return np.vstack(rows) if rows else np.zeros((0, len(group.unknown)))


def reducible_rods(tree: KinematicTree, group: ClosureGroup,
                   structure: GroupStructure) -> dict[str, Rod]:
    """
    Return the group's ball closures whose rod a distance can replace, by closure name.

    A rod qualifies when its universal joint's two coordinates are unknown, move no other
    closure of the group and take part in no idle freedom: then its closure's three rows and
    two unknowns become one row (|x − P| = L) and its angles follow in closed form.
    """
    loops = [tree.loop(closure) for closure in group.closures]
    rods = {}
    for index, loop in enumerate(loops):
        for side in (0, 1):
            rod = universal_rod(tree, loop, side)
            if rod is None or any(c in group.known for c in rod.coordinates):
                continue
            names = {tree.coordinates[c].name for c in rod.coordinates}
            shared = any(set(rod.coordinates) & set(tree.loop_coordinates(other))
                         for place, other in enumerate(loops) if place != index)
            if shared or any(names & set(idle.joints) for idle in structure.idle):
                continue
            rods[loop.closure.name] = rod
            break
    return rods


def classify(tree: KinematicTree, group: ClosureGroup, structure: GroupStructure,
             values: Sequence[float]) -> GroupKind:
    """
    Return how a determined group's positions are solved, recognised from the tree.

    LEG_INVERSE: one ball closure with a reducible rod, one unknown step (a crank's turn or a
    slide) above the rod and every coordinate of the other side known. FIVE_BAR: one pin
    closure, four turns about parallel axes, two of them known and adjacent around the loop
    with the base link among the three links they hold rigid (newton.py places the other
    pins). PLANAR_LOOPS: pins whose loops are planar with four joints each (the planar closed
    forms' groups, loops/solver.py). Otherwise NEWTON.
    """
    if structure.determinacy is not Determinacy.DETERMINED:
        return GroupKind.NEWTON
    if len(group.closures) == 1:
        closure = group.closures[0]
        loop = tree.loop(closure)
        rods = reducible_rods(tree, group, structure)
        if closure.name in rods:
            rod = rods[closure.name]
            above = [step for step in loop.paths[rod.side] if step not in rod.steps]
            unknown_above = [step for step in above
                             if tree.steps[step].coordinate not in group.known]
            other = loop.paths[1 - rod.side]
            if len(unknown_above) == 1 and all(tree.steps[step].coordinate in group.known
                                               for step in other):
                return GroupKind.LEG_INVERSE
        if five_bar_pair(tree, group, values) is not None:
            return GroupKind.FIVE_BAR
    if all(closure.kind is ClosureKind.PIN and planar(tree, closure, values)
           and len(tree.loop_coordinates(tree.loop(closure))) == 3
           for closure in group.closures):
        return GroupKind.PLANAR_LOOPS
    return GroupKind.NEWTON


def five_bar_cycle(tree: KinematicTree, closure: Closure) -> list[int | None]:
    """Return a loop's pins in cyclic order: its steps, None for the closure's pin."""
    loop = tree.loop(closure)
    return list(loop.paths[0]) + [None] + list(loop.paths[1])[::-1]


def five_bar_pair(tree: KinematicTree, group: ClosureGroup,
                  values: Sequence[float]) -> int | None:
    """
    Return where the known pair starts in ``five_bar_cycle`` if the closed form solves the group.

    That is i with pins i, i + 1 known; None when the group is not such a planar five-bar.
    """
    closure = group.closures[0]
    if closure.kind is not ClosureKind.PIN or not planar(tree, closure, values):
        return None
    cycle = five_bar_cycle(tree, closure)
    if len(cycle) != 5 or len(group.known) != 2 or any(
            step is not None and (tree.steps[step].kind is not MotionKind.TURN
                                  or tree.steps[step].multiplier == 0.0) for step in cycle):
        return None
    known = [place for place, step in enumerate(cycle)
             if step is not None and tree.steps[step].coordinate in group.known]
    coordinates = [tree.steps[step].coordinate for step in cycle if step is not None]
    if len(known) != 2 or len(set(coordinates)) != 4:
        return None
    # the base link joins the last pin to the first: it must be among the three rigid links
    for first in (3, 4, 0):
        if {first, (first + 1) % 5} == set(known):
            return first
    return None


def planar(tree: KinematicTree, closure: Closure, values: Sequence[float]) -> bool:
    """Return whether a pin closure's loop turns about axes parallel to its pin only."""
    loop = tree.loop(closure)
    frames = tree.frames(values)
    frame, offset = loop.sides[0]
    normal = apply(frames[frame].then(offset).rotation, unit_axis(closure.parent))
    for path in loop.paths:
        for index in path:
            step = tree.steps[index]
            axis = apply(frames[step.parent].then(step.origin).rotation, step.axis)
            off = (norm(cross(axis, normal)) if step.kind is MotionKind.TURN
                   else abs(axis[0] * normal[0] + axis[1] * normal[1] + axis[2] * normal[2]))
            if off > PARALLEL_TOLERANCE:
                return False
    return True
