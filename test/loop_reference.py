# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Independent high-precision reference for planar kinematic loops closed by URDF constraints.

A robot's loops are read from ``<constraint>`` elements (urdfdom PR #264 syntax); a revolute
constraint says that the frames ``parent_link·parent_origin`` and ``child_link·child_origin``
share their origin. This module answers what the package's closed forms answer, by other means:

* It reads the URDF itself (``xml.etree.ElementTree``), not through urdfdom_py or the package.
  Every number is the float64 a URDF reader gets from the text, converted to mpf exactly, so a
  difference from the package is the package's own error.
* Positions: forward kinematics in mpmath (50 digits) of the whole tree, and Newton's method
  (mpmath's multidimensional ``findroot``) on all constraint equations at once, from a guess.
  No triangle, circle intersection or loop classification is involved: the package solves each
  loop in closed form (intersecting circles and lines, loop by loop in a solve order), and
  nothing of that is shared here. The assembly branch is the one Newton converges to from the
  guess; the tests walk along a sweep from the zero pose, passing each answer as the next
  guess.
* Velocities: the linear system J_passive·q̇_passive = −J_known·q̇_known with the Jacobian of
  the same constraint equations, formed from the screw of each joint (ω × r for a revolute
  joint, its axis for a prismatic one), all loops at once.
* Closure: :func:`closure_residuals` measures the gap of each constraint with urchin's float64
  forward kinematics, an independent URDF library.

The equations. Each loop is planar: its revolute joints turn about axes parallel to the
constraint's axis n, its prismatic joints slide perpendicular to n. So the loop's joints move
its two constraint frames only within planes perpendicular to n, and the component of the gap
along n is a constant of the geometry (zero for an exactly planar drawing, a few 1e-17 m where a
frame is tilted by a rounded π/2) that no joint changes. The square system is therefore the
gap's two components in the plane, n × e and e for a unit e perpendicular to n, for each
constraint: two equations per constraint, and two unknowns per loop of three tree joints of
which one is known (measured, or solved by another loop). The plane (n, e) is the loop's plane
as drawn, at the all-zero pose, for every configuration: the equations are then one smooth
function, the same for :func:`solve`, :func:`velocities` and :func:`planar_residuals`, whose
exact Jacobian Newton gets. (Taking n from the current configuration instead would mix a
tilted frame's ~1e-17 m out-of-plane gap into the plane by its ~1e-17 rad turn, about 1e-34 m,
which is above the 1e-40 m the solve promises.)
"""

from __future__ import annotations

from dataclasses import dataclass
import functools
import itertools
import math
from pathlib import Path
import tempfile
from types import MappingProxyType
from typing import Mapping, Sequence
import xml.etree.ElementTree as ElementTree

from mpmath import mp, mpf
import numpy as np
import urchin

# Working precision: a converged answer (residual below CONVERGED) is good to about 40 digits,
# far below anything float64 can show.
DIGITS = 50
CONVERGED = mpf('1e-40')
# Newton stops a little below CONVERGED (the floor at 50 digits is about 1e-49 m for metre-sized
# robots) so that convergence is checked with margin rather than at the rounding floor.
NEWTON_TOLERANCE = mpf('1e-45')
NEWTON_STEPS = 30
# Converging from a neighbouring sample takes under 10 evaluations of the equations. When it
# cannot converge (no closure, a wrong branch, a dead point) findroot's step halving would go
# on to the last bit, about 170 evaluations per step; this budget ends it first.
NEWTON_EVALUATIONS = 60
# How far a loop's axes may be from parallel (rad) before the loop is not planar: the drawings'
# rounding of π/2 tilts a frame by about 6e-17 rad.
PLANAR_TOLERANCE = 1e-9

Vector = tuple[mpf, mpf, mpf]
Rotation = tuple[Vector, Vector, Vector]


class NotClosed(RuntimeError):
    """The loops did not close to :data:`CONVERGED` from the given guess."""


@dataclass(frozen=True)
class Frame:
    """A fixed transform: translation ``xyz`` (m) and URDF roll–pitch–yaw ``rpy`` (rad)."""

    xyz: tuple[float, float, float]
    rpy: tuple[float, float, float]


@dataclass(frozen=True)
class Joint:
    """A URDF joint as written: ``axis`` in the joint frame, ``mimic`` (joint, ×, +) or None."""

    name: str
    kind: str
    parent: str
    child: str
    origin: Frame
    axis: tuple[float, float, float]
    mimic: tuple[str, float, float] | None


@dataclass(frozen=True)
class Constraint:
    """A ``<constraint>``: a frame and an axis on each of two links."""

    name: str
    kind: str
    parent: str
    parent_origin: Frame
    parent_axis: tuple[float, float, float]
    child: str
    child_origin: Frame
    child_axis: tuple[float, float, float]


@dataclass(frozen=True)
class Robot:
    """A parsed URDF: its root link, joints in tree order (parents first) and constraints."""

    root: str
    joints: Mapping[str, Joint]
    constraints: Mapping[str, Constraint]
    # link → the joint whose child it is (none for the root)
    joint_above: Mapping[str, Joint]


# --- reading the URDF ----------------------------------------------------------------------------


def _floats(text: str | None, default: str) -> tuple[float, float, float]:
    """Read three floats of an attribute, as a float64 URDF reader reads them."""
    values = [float(value) for value in (text or default).split()]
    if len(values) != 3:
        raise ValueError(f'expected three numbers, got {text!r}')
    return (values[0], values[1], values[2])


def _frame(element: ElementTree.Element | None) -> Frame:
    """Read an ``origin``-like element (absent: identity)."""
    if element is None:
        return Frame((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    return Frame(_floats(element.get('xyz'), '0 0 0'), _floats(element.get('rpy'), '0 0 0'))


def _axis(element: ElementTree.Element | None) -> tuple[float, float, float]:
    """Read an ``axis``-like element (absent: URDF's default x)."""
    return _floats(None if element is None else element.get('xyz'), '1 0 0')


def _link_of(element: ElementTree.Element, tag: str) -> str:
    """Read the ``link`` attribute of the child element ``tag``."""
    child = element.find(tag)
    if child is None or child.get('link') is None:
        raise ValueError(f'{element.get("name")}: no <{tag} link="..."/>')
    return str(child.get('link'))


@functools.lru_cache(maxsize=32)
def parse(urdf_text: str) -> Robot:
    """Read links, joints (origin, axis, type, parent, child, mimic) and constraints."""
    root_element = ElementTree.fromstring(urdf_text)
    joints = {}
    for element in root_element.findall('joint'):
        mimic_element = element.find('mimic')
        mimic = None if mimic_element is None else (
            str(mimic_element.get('joint')), float(mimic_element.get('multiplier', '1')),
            float(mimic_element.get('offset', '0')))
        joint = Joint(str(element.get('name')), str(element.get('type')),
                      _link_of(element, 'parent'), _link_of(element, 'child'),
                      _frame(element.find('origin')), _axis(element.find('axis')), mimic)
        joints[joint.name] = joint
    constraints = {}
    for element in root_element.findall('constraint'):
        constraint = Constraint(
            str(element.get('name')), str(element.get('type')),
            _link_of(element, 'parent'), _frame(element.find('parent_origin')),
            _axis(element.find('parent_axis')),
            _link_of(element, 'child'), _frame(element.find('child_origin')),
            _axis(element.find('child_axis')))
        constraints[constraint.name] = constraint
    links = [str(link.get('name')) for link in root_element.findall('link')]
    joint_above = {joint.child: joint for joint in joints.values()}
    roots = [link for link in links if link not in joint_above]
    if len(roots) != 1:
        raise ValueError(f'expected one root link, found {roots}')
    # Parents before children, so forward kinematics is one pass.
    ordered: list[Joint] = []
    reached = {roots[0]}
    while len(ordered) < len(joints):
        ready = [joint for joint in joints.values()
                 if joint.parent in reached and joint.child not in reached]
        if not ready:
            raise ValueError('joints do not form a tree from the root link')
        ordered += ready
        reached |= {joint.child for joint in ready}
    return Robot(roots[0], MappingProxyType({joint.name: joint for joint in ordered}),
                 MappingProxyType(constraints), MappingProxyType(joint_above))


# --- forward kinematics in mpmath ----------------------------------------------------------------


def _rpy_rotation(rpy: tuple[float, float, float]) -> Rotation:
    """Return Rz(yaw)·Ry(pitch)·Rx(roll), URDF's convention, at the working precision."""
    return _rpy_rotation_at(rpy, mp.prec)


@functools.lru_cache(maxsize=1024)
def _rpy_rotation_at(rpy: tuple[float, float, float], precision: int) -> Rotation:
    """Return Rz(yaw)·Ry(pitch)·Rx(roll) at ``precision`` bits (cached: Newton repeats them)."""
    roll, pitch, yaw = (mpf(angle) for angle in rpy)
    cr, sr = mp.cos(roll), mp.sin(roll)
    cp, sp = mp.cos(pitch), mp.sin(pitch)
    cy, sy = mp.cos(yaw), mp.sin(yaw)
    return ((cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr),
            (sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr),
            (-sp, cp * sr, cp * cr))


def _unit(vector: Sequence[float | mpf]) -> Vector:
    """Scale ``vector`` to length 1 (URDF normalises axes)."""
    length = mp.sqrt(sum(mpf(component) ** 2 for component in vector))
    return (mpf(vector[0]) / length, mpf(vector[1]) / length, mpf(vector[2]) / length)


@functools.lru_cache(maxsize=1024)
def _unit_axis(axis: tuple[float, float, float], precision: int) -> Vector:
    """Return a written axis scaled to length 1 at ``precision`` bits (cached)."""
    return _unit(axis)


def _apply(rotation: Rotation, vector: Vector) -> Vector:
    """Return rotation · vector."""
    # fdot: one rounding per component, and twice as fast as three products and two sums.
    return tuple(mp.fdot(row, vector) for row in rotation)


def _times(left: Rotation, right: Rotation) -> Rotation:
    """Return left · right."""
    columns = [_apply(left, (right[0][k], right[1][k], right[2][k])) for k in range(3)]
    return tuple((columns[0][i], columns[1][i], columns[2][i]) for i in range(3))


def _axis_angle(axis: Vector, angle: mpf) -> Rotation:
    """Return the rotation by ``angle`` about unit ``axis`` (Rodrigues)."""
    c, s = mp.cos(angle), mp.sin(angle)
    x, y, z = axis
    t = 1 - c
    return ((c + t * x * x, t * x * y - s * z, t * x * z + s * y),
            (t * x * y + s * z, c + t * y * y, t * y * z - s * x),
            (t * x * z - s * y, t * y * z + s * x, c + t * z * z))


def _add(a: Vector, b: Vector) -> Vector:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def _subtract(a: Vector, b: Vector) -> Vector:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _scale(factor: mpf, a: Vector) -> Vector:
    return (factor * a[0], factor * a[1], factor * a[2])


def _dot(a: Vector, b: Vector) -> mpf:
    return mp.fdot(a, b)


def _cross(a: Vector, b: Vector) -> Vector:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@dataclass(frozen=True)
class _Pose:
    """World pose: rotation and position (m)."""

    rotation: Rotation
    position: Vector

    def then(self, frame: Frame) -> _Pose:
        """Return this pose followed by the fixed transform ``frame``."""
        xyz = (mpf(frame.xyz[0]), mpf(frame.xyz[1]), mpf(frame.xyz[2]))
        return _Pose(_times(self.rotation, _rpy_rotation(frame.rpy)),
                     _add(self.position, _apply(self.rotation, xyz)))


@dataclass(frozen=True)
class _Kinematics:
    """World poses of the links, and each joint's world axis and point, at one configuration."""

    links: dict[str, _Pose]
    axes: dict[str, Vector]
    points: dict[str, Vector]


def _joint_value(robot: Robot, values: Mapping[str, float | mpf], name: str) -> mpf:
    """Return a joint's position: a mimic follows its joint, others default to 0 (drawn pose)."""
    mimic = robot.joints[name].mimic
    if mimic is not None:
        return mpf(mimic[1]) * _joint_value(robot, values, mimic[0]) + mpf(mimic[2])
    return mpf(values.get(name, 0))


def _forward(robot: Robot, values: Mapping[str, float | mpf]) -> _Kinematics:
    """Compute the whole tree's forward kinematics in mpmath at the working precision."""
    identity = ((mpf(1), mpf(0), mpf(0)), (mpf(0), mpf(1), mpf(0)), (mpf(0), mpf(0), mpf(1)))
    links = {robot.root: _Pose(identity, (mpf(0), mpf(0), mpf(0)))}
    axes, points = {}, {}
    for joint in robot.joints.values():
        frame = links[joint.parent].then(joint.origin)
        unit_axis = _unit_axis(joint.axis, mp.prec)
        axis = _apply(frame.rotation, unit_axis)
        axes[joint.name], points[joint.name] = axis, frame.position
        value = _joint_value(robot, values, joint.name)
        if joint.kind in ('revolute', 'continuous'):
            links[joint.child] = _Pose(_times(frame.rotation,
                                              _axis_angle(unit_axis, value)),
                                       frame.position)
        elif joint.kind == 'prismatic':
            links[joint.child] = _Pose(frame.rotation,
                                       _add(frame.position, _scale(value, axis)))
        elif joint.kind == 'fixed':
            links[joint.child] = frame
        else:
            raise ValueError(f'{joint.name}: joint type {joint.kind!r} is not handled')
    return _Kinematics(links, axes, points)


# --- the loops -----------------------------------------------------------------------------------


def _path_to_root(robot: Robot, link: str) -> list[str]:
    """Return the joints from ``link`` up to the root, nearest first."""
    path = []
    while link in robot.joint_above:
        joint = robot.joint_above[link]
        path.append(joint.name)
        link = joint.parent
    return path


def _loop_sides(robot: Robot, constraint: Constraint) -> tuple[list[str], list[str]]:
    """Return the loop's tree joints above the constraint's parent link and its child link."""
    parent_side = _path_to_root(robot, constraint.parent)
    child_side = _path_to_root(robot, constraint.child)
    shared = set(parent_side) & set(child_side)
    return ([joint for joint in parent_side if joint not in shared],
            [joint for joint in child_side if joint not in shared])


def loop_joints(urdf_text: str, constraint: str) -> tuple[str, ...]:
    """Return the tree joints of a constraint's loop: from its parent link round to its child."""
    robot = parse(urdf_text)
    parent_side, child_side = _loop_sides(robot, robot.constraints[constraint])
    return tuple(parent_side + child_side[::-1])


@dataclass(frozen=True)
class _Plane:
    """A loop's plane: two unit vectors spanning it (the normal is their cross product)."""

    first: Vector
    second: Vector


def _pin_points(kinematics: _Kinematics, constraint: Constraint) -> tuple[Vector, Vector]:
    """Return the world positions of the constraint's two frame origins (parent, child)."""
    parent = kinematics.links[constraint.parent].then(constraint.parent_origin)
    child = kinematics.links[constraint.child].then(constraint.child_origin)
    return parent.position, child.position


@functools.lru_cache(maxsize=32)
def _drawn_planes(urdf_text: str) -> Mapping[str, _Plane]:
    """Return each loop's plane as drawn (all joints at 0), after checking it is planar."""
    robot = parse(urdf_text)
    with mp.workdps(DIGITS):
        kinematics = _forward(robot, {})
        return MappingProxyType({name: _plane(robot, kinematics, constraint)
                                 for name, constraint in robot.constraints.items()})


def _plane(robot: Robot, kinematics: _Kinematics, constraint: Constraint) -> _Plane:
    """Return the loop's plane at this configuration, after checking that it is planar."""
    parent = kinematics.links[constraint.parent].then(constraint.parent_origin)
    child = kinematics.links[constraint.child].then(constraint.child_origin)
    normal = _apply(parent.rotation, _unit(constraint.parent_axis))
    directions = {f'{constraint.name} child_axis':
                  (_apply(child.rotation, _unit(constraint.child_axis)), 'revolute')}
    for side in _loop_sides(robot, constraint):
        for name in side:
            directions[name] = (kinematics.axes[name], robot.joints[name].kind)
    for name, (direction, kind) in directions.items():
        # A revolute axis must be parallel to the normal (either sense); a slide perpendicular.
        off_plane = (mp.norm(_cross(direction, normal)) if kind != 'prismatic'
                     else abs(_dot(direction, normal)))
        if off_plane > PLANAR_TOLERANCE:
            raise ValueError(f'{constraint.name}: {name} is not in the loop plane '
                             f'({kind}, {float(off_plane):.3g} rad off)')
    # e: the world axis least along the normal, made perpendicular to it.
    helper = [(mpf(1), mpf(0), mpf(0)), (mpf(0), mpf(1), mpf(0)), (mpf(0), mpf(0), mpf(1))][
        min(range(3), key=lambda i: abs(normal[i]))]
    first = _unit(_subtract(helper, _scale(_dot(helper, normal), normal)))
    return _Plane(first, _cross(normal, first))


def _residuals(kinematics: _Kinematics, constraint: Constraint, plane: _Plane) -> list[mpf]:
    """Return the gap between the constraint's two frame origins in the plane (2 components)."""
    parent_point, child_point = _pin_points(kinematics, constraint)
    gap = _subtract(parent_point, child_point)
    return [_dot(plane.first, gap), _dot(plane.second, gap)]


def _gap_rate(robot: Robot, kinematics: _Kinematics, constraint: Constraint,
              joint: str) -> Vector:
    """Return ∂(parent point − child point)/∂(joint position): the joint's screw there."""
    parent_side, child_side = _loop_sides(robot, constraint)
    parent_point, child_point = _pin_points(kinematics, constraint)
    if joint in parent_side:
        point, sign = parent_point, mpf(1)
    elif joint in child_side:
        point, sign = child_point, mpf(-1)
    else:
        return (mpf(0), mpf(0), mpf(0))
    axis = kinematics.axes[joint]
    if robot.joints[joint].kind == 'prismatic':
        return _scale(sign, axis)
    return _scale(sign, _cross(axis, _subtract(point, kinematics.points[joint])))


def _jacobian(robot: Robot, kinematics: _Kinematics, names: Sequence[str],
              planes: Mapping[str, _Plane], joints: Sequence[str]) -> mp.matrix:
    """Return ∂(in-plane residuals of ``names``)/∂(``joints``), two rows per constraint."""
    jacobian = mp.matrix(2 * len(names), len(joints))
    for row, name in enumerate(names):
        constraint = robot.constraints[name]
        for column, joint in enumerate(joints):
            rate = _gap_rate(robot, kinematics, constraint, joint)
            jacobian[2 * row, column] = _dot(planes[name].first, rate)
            jacobian[2 * row + 1, column] = _dot(planes[name].second, rate)
    return jacobian


def _unknowns(robot: Robot, names: Sequence[str], known: Mapping[str, object]) -> list[str]:
    """Return the loops' tree joints not in ``known``, in the loops' order, each once."""
    unknowns: list[str] = []
    for name in names:
        for side in _loop_sides(robot, robot.constraints[name]):
            unknowns += [joint for joint in side if joint not in known and joint not in unknowns]
    mimics = [joint for joint in unknowns if robot.joints[joint].mimic is not None]
    if mimics:
        raise ValueError(f'loop joints {mimics} are mimic joints; give their joints as known')
    if len(unknowns) != 2 * len(names):
        raise ValueError(f'{len(unknowns)} unknown joints {unknowns} for the {2 * len(names)} '
                         f'equations of {list(names)}: each loop needs exactly one known joint')
    return unknowns


def solve(urdf_text: str, known: Mapping[str, float | mpf], guess: Mapping[str, float | mpf],
          constraints: Sequence[str] | None = None) -> dict[str, mpf]:
    """
    Return every passive loop joint's position (rad or m) closing the constraints.

    ``known``: the measured joints (and any others already solved); ``guess``: where Newton
    starts for the unknown joints (missing ones start at 0, the drawn pose), which picks the
    assembly branch. ``constraints`` restricts the solve to those loops (default: all, at
    once). Raises :class:`NotClosed` if the in-plane gaps do not fall below
    :data:`CONVERGED` and ``ValueError`` if the loops do not have one known joint each or
    are not planar.
    """
    robot = parse(urdf_text)
    names = list(robot.constraints if constraints is None else constraints)
    unknowns = _unknowns(robot, names, known)
    with mp.workdps(DIGITS):
        fixed = {joint: mpf(value) for joint, value in known.items()}
        start = [mpf(guess.get(joint, 0)) for joint in unknowns]
        planes = _drawn_planes(urdf_text)

        @functools.lru_cache(maxsize=4)
        def kinematics_at(*x: mpf) -> _Kinematics:
            # Newton evaluates the residuals and the Jacobian at the same points.
            return _forward(robot, {**fixed, **dict(zip(unknowns, x))})

        evaluations = itertools.count(1)

        def residuals(*x: mpf) -> list[mpf]:
            if next(evaluations) > NEWTON_EVALUATIONS:
                raise NotClosed(f'{names}: no convergence in {NEWTON_EVALUATIONS} evaluations '
                                f'from {dict(guess)} with {dict(known)}')
            kinematics = kinematics_at(*x)
            return [value for name in names
                    for value in _residuals(kinematics, robot.constraints[name], planes[name])]

        def jacobian(*x: mpf) -> mp.matrix:
            return _jacobian(robot, kinematics_at(*x), names, planes, unknowns)

        try:
            root = mp.findroot(residuals, start, J=jacobian, tol=NEWTON_TOLERANCE,
                               maxsteps=NEWTON_STEPS, verify=False)
        except ZeroDivisionError as error:  # lu_solve on a singular Jacobian (a dead point)
            raise NotClosed(f'{names}: singular Jacobian on the way from {guess}') from error
        solution = [root[i] for i in range(len(unknowns))]
        gap = max(abs(value) for value in residuals(*solution))
        if gap > CONVERGED:
            raise NotClosed(f'{names}: in-plane gap {mp.nstr(gap, 3)} m after Newton from '
                            f'{dict(guess)} with {dict(known)}')
        return dict(zip(unknowns, solution))


def planar_residuals(urdf_text: str,
                     joint_values: Mapping[str, float | mpf]) -> dict[str, mpf]:
    """Return each constraint's gap (m) in its loop's drawn plane: what :func:`solve` zeroes."""
    robot = parse(urdf_text)
    planes = _drawn_planes(urdf_text)
    with mp.workdps(DIGITS):
        kinematics = _forward(robot, joint_values)
        return {name: mp.norm(_residuals(kinematics, constraint, planes[name]))
                for name, constraint in robot.constraints.items()}


def velocities(urdf_text: str, positions: Mapping[str, float | mpf],
               known_velocities: Mapping[str, float | mpf]) -> dict[str, mpf]:
    """
    Return the passive loop joints' velocities at the closed ``positions`` (rad/s or m/s).

    Solves J_passive·q̇_passive = −J_known·q̇_known, the time derivative of the in-plane
    constraint equations, over all constraints at once; the passive joints are the loops'
    tree joints not in ``known_velocities``.
    """
    robot = parse(urdf_text)
    names = list(robot.constraints)
    unknowns = _unknowns(robot, names, known_velocities)
    with mp.workdps(DIGITS):
        kinematics = _forward(robot, positions)
        planes = _drawn_planes(urdf_text)
        known = list(known_velocities)
        passive_jacobian = _jacobian(robot, kinematics, names, planes, unknowns)
        known_jacobian = _jacobian(robot, kinematics, names, planes, known)
        known_rates = mp.matrix([mpf(known_velocities[joint]) for joint in known])
        rates = mp.lu_solve(passive_jacobian, -(known_jacobian * known_rates))
        return {joint: rates[i] for i, joint in enumerate(unknowns)}


# --- closure by an independent float64 library ---------------------------------------------------


@functools.lru_cache(maxsize=32)
def _urchin_robot(urdf_text: str) -> urchin.URDF:
    """Load urchin's model of the URDF text (urchin loads from a file)."""
    # urchin keeps elements it does not know, such as <constraint>, aside as extra XML and
    # builds its tree from the joints alone, so the text is handed over unchanged.
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / 'robot.urdf'
        path.write_text(urdf_text, encoding='utf-8')
        return urchin.URDF.load(str(path), lazy_load_meshes=True)


def link_poses(urdf_text: str,
               joint_values: Mapping[str, float | mpf]) -> dict[str, np.ndarray]:
    """
    Return every link's world pose (4×4) by urchin's float64 forward kinematics.

    Joints not given sit at 0. Mimic joints follow their joint when it is given: urchin
    computes them from the full configuration and ignores a value given for the mimic itself.
    """
    return _urchin_robot(urdf_text).link_fk(
        cfg={name: float(value) for name, value in joint_values.items()}, use_names=True)


def closure_residuals(urdf_text: str,
                      joint_values: Mapping[str, float | mpf]) -> dict[str, float]:
    """
    Return each constraint's gap (m): the distance between its two frame origins.

    Computed in float64 from :func:`link_poses` (urchin) and urchin's ``xyz_rpy_to_matrix``
    for the constraint frames, which urchin itself does not model.
    """
    robot = parse(urdf_text)
    poses = link_poses(urdf_text, joint_values)
    gaps = {}
    for name, constraint in robot.constraints.items():
        points = []
        for link, frame in ((constraint.parent, constraint.parent_origin),
                            (constraint.child, constraint.child_origin)):
            offset = urchin.utils.xyz_rpy_to_matrix(np.array(frame.xyz + frame.rpy))
            points.append((poses[link] @ offset)[:3, 3])
        gaps[name] = math.dist(points[0], points[1])
    return gaps
