# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Mechanisms for the general closure's tests, each a URDF drawn assembled at its zero pose.

Each is a ``Mechanism``: the URDF text, its closures (built here as the encodings' readers
would build them), the joints overridden as spherical or universal joints, and the joints
measured. Lengths in metres, angles in radians.

* ``ankle``: urdf/humanoid_ankle.urdf, its two spherical constraints (motors measured).
* ``five_bar``: a planar five-bar, cranks at (0, 0) and (0.15, 0) of 0.2 m, distal links of
  0.25 m meeting at a pin (both cranks measured); stretched where the cranks' ends are 0.5 m
  apart.
* ``planar_weld``: the lab knee's four-bar (0.3, 1.044, 0.6, ground 1.0) with all four pins in
  the tree and the rocker's end welded to the ground: 6 rows of rank 3.
* ``rod_two_balls``: a spatial crank–rod–rocker whose rod has a ball at each end (a spherical
  override at the crank, a ball closure at the rocker): the rod spins idle.
* ``collinear_pins``: a four-bar whose coupler hangs from the crank by two pins on one axis:
  the short link between them turns idle.
* ``delta_like``: three motors 120° apart, arms of 0.1 m, rods of 0.25 m with a spherical
  override at the elbow, meeting at a point of the platform: each rod spins idle.
"""

from __future__ import annotations

from dataclasses import dataclass, field
import math
from pathlib import Path
import xml.etree.ElementTree as ElementTree

from closure_reference import Reference
from linkage_kinematics.loops.assembly import assemble, Assembly
from linkage_kinematics.loops.closures import (
    Closure,
    ClosureKind,
    ClosureSide,
    Encoding,
    JointOverride,
)
from linkage_kinematics.loops.newton import GroupSolver
from linkage_kinematics.loops.structure import (
    analyse,
    classify,
    closure_groups,
    ClosureGroup,
    GroupKind,
    GroupStructure,
)
from linkage_kinematics.loops.tree import KinematicTree
from linkage_kinematics.model.urdf_reader import read_urdf

REPOSITORY = Path(__file__).resolve().parent.parent
ANKLE_URDF = REPOSITORY / 'urdf' / 'humanoid_ankle.urdf'


@dataclass(frozen=True)
class Mechanism:
    """A URDF, its closures, its overridden joints and its measured joints."""

    name: str
    urdf: str
    closures: tuple[Closure, ...]
    measured: tuple[str, ...]
    overrides: dict[str, JointOverride] = field(default_factory=dict)

    @property
    def reference_overrides(self) -> dict[str, str]:
        """Return the overrides as the reference takes them: joint → axes in order."""
        return {name: override.value for name, override in self.overrides.items()}


def _numbers(values) -> str:
    return ' '.join(repr(float(value)) for value in values)


def joint(name: str, kind: str, parent: str, child: str, xyz=(0.0, 0.0, 0.0),
          rpy=(0.0, 0.0, 0.0), axis=(0.0, 0.0, 1.0)) -> str:
    """Return a ``<joint>`` element's text (a revolute joint limited to ±π, as urchin asks)."""
    limit = ('<limit lower="-3.15" upper="3.15" effort="1" velocity="1"/>'
             if kind in ('revolute', 'prismatic') else '')
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/>'
            f'<child link="{child}"/><origin xyz="{_numbers(xyz)}" rpy="{_numbers(rpy)}"/>'
            f'<axis xyz="{_numbers(axis)}"/>{limit}</joint>')


def robot(name: str, joints: list[str]) -> str:
    """Return a URDF of ``joints`` (their links declared from their parents and children)."""
    links: list[str] = []
    for text in joints:
        element = ElementTree.fromstring(text)
        for end in ('parent', 'child'):
            link = element.find(end).get('link')
            if link not in links:
                links.append(link)
    body = ''.join(f'<link name="{link}"/>' for link in links) + ''.join(joints)
    return f'<?xml version="1.0"?><robot name="{name}">{body}</robot>'


def side(link: str, xyz=(0.0, 0.0, 0.0), rpy=(0.0, 0.0, 0.0), axis=None) -> ClosureSide:
    return ClosureSide(link, tuple(float(v) for v in xyz), tuple(float(v) for v in rpy),
                       None if axis is None else tuple(float(v) for v in axis))


def closure(name: str, kind: ClosureKind, parent: ClosureSide, child: ClosureSide) -> Closure:
    return Closure(name, kind, parent, child, Encoding.CONSTRAINT)


def ankle() -> Mechanism:
    """Return the package's humanoid ankle and its two spherical constraints."""
    text = ANKLE_URDF.read_text(encoding='utf-8')
    closures = []
    for element in ElementTree.fromstring(text).findall('constraint'):
        ends = [side(element.find(end).get('link'),
                     [float(v) for v in element.find(f'{end}_origin').get('xyz').split()])
                for end in ('parent', 'child')]
        closures.append(closure(element.get('name'), ClosureKind.BALL, *ends))
    return Mechanism('ankle', text, tuple(closures), ('motor_left', 'motor_right'))


def _apex(p, q, rp, rq):
    """Return the point at rp from p and rq from q, left of p → q (floats, for drawing)."""
    dx, dy = q[0] - p[0], q[1] - p[1]
    d = math.hypot(dx, dy)
    along = (rp * rp - rq * rq + d * d) / (2 * d)
    height = math.sqrt(rp * rp - along * along)
    return (p[0] + (along * dx - height * dy) / d, p[1] + (along * dy + height * dx) / d)


def five_bar() -> Mechanism:
    """Return the planar five-bar, both cranks measured."""
    a2 = (0.15, 0.0)
    t1, t2 = math.radians(100.0), math.radians(80.0)
    b1 = (0.2 * math.cos(t1), 0.2 * math.sin(t1))
    b2 = (a2[0] + 0.2 * math.cos(t2), a2[1] + 0.2 * math.sin(t2))
    p = _apex(b2, b1, 0.25, 0.25)
    u1 = math.atan2(p[1] - b1[1], p[0] - b1[0]) - t1
    u2 = math.atan2(p[1] - b2[1], p[0] - b2[0]) - t2
    text = robot('five_bar', [
        joint('j1', 'revolute', 'base', 'crank1', rpy=(0, 0, t1)),
        joint('j2', 'revolute', 'crank1', 'distal1', xyz=(0.2, 0, 0), rpy=(0, 0, u1)),
        joint('j3', 'revolute', 'base', 'crank2', xyz=(a2[0], 0, 0), rpy=(0, 0, t2)),
        joint('j4', 'revolute', 'crank2', 'distal2', xyz=(0.2, 0, 0), rpy=(0, 0, u2))])
    pin = closure('tip', ClosureKind.PIN, side('distal1', (0.25, 0, 0), axis=(0, 0, 1)),
                  side('distal2', (0.25, 0, 0), axis=(0, 0, 1)))
    return Mechanism('five_bar', text, (pin,), ('j1', 'j3'))


def planar_weld() -> Mechanism:
    """Return the four-bar with its four pins in the tree, the rocker's end welded to ground."""
    crank, coupler, rocker, c = 0.3, math.sqrt(1.09), 0.6, (1.0, 0.0)
    angle = math.radians(60.0)
    a = (crank * math.cos(angle), crank * math.sin(angle))
    b = _apex(a, c, coupler, rocker)
    heading_ab = math.atan2(b[1] - a[1], b[0] - a[0])
    heading_bc = math.atan2(c[1] - b[1], c[0] - b[0])
    text = robot('planar_weld', [
        joint('k1', 'revolute', 'ground', 'crank', rpy=(0, 0, angle)),
        joint('k2', 'revolute', 'crank', 'coupler', xyz=(crank, 0, 0),
              rpy=(0, 0, heading_ab - angle)),
        joint('k3', 'revolute', 'coupler', 'rocker', xyz=(coupler, 0, 0),
              rpy=(0, 0, heading_bc - heading_ab)),
        joint('k4', 'revolute', 'rocker', 'end', xyz=(rocker, 0, 0), rpy=(0, 0, -heading_bc))])
    weld = closure('weld_c', ClosureKind.WELD, side('end'), side('ground', (c[0], c[1], 0)))
    return Mechanism('planar_weld', text, (weld,), ('k1',))


def _heading(vector) -> tuple[float, float, float]:
    """Return the rpy turning x onto ``vector`` (yaw, then pitch)."""
    x, y, z = vector
    return (0.0, -math.atan2(z, math.hypot(x, y)), math.atan2(y, x))


def rod_two_balls() -> Mechanism:
    """Return the spatial crank–rod–rocker whose rod has a ball at each end."""
    # the crank drawn at 0.5 rad, the lever at 0.6 rad about x, away from dead points
    crank_angle, lever_angle = 0.5, 0.6
    end = (0.1 * math.cos(crank_angle), 0.1 * math.sin(crank_angle), 0.0)
    rocker_pivot, rocker_arm = (0.35, 0.0, 0.15), 0.12
    tip = (rocker_pivot[0], rocker_pivot[1] - rocker_arm * math.sin(lever_angle),
           rocker_pivot[2] + rocker_arm * math.cos(lever_angle))
    rod = tuple(t - e for t, e in zip(tip, end))
    length = math.sqrt(sum(v * v for v in rod))
    heading = _heading(rod)
    text = robot('rod_two_balls', [
        joint('crank', 'revolute', 'ground', 'arm', rpy=(0, 0, crank_angle)),
        joint('ball', 'fixed', 'arm', 'rod', xyz=(0.1, 0, 0),
              rpy=(heading[0], heading[1], heading[2] - crank_angle)),
        joint('rocker', 'revolute', 'ground', 'lever', xyz=rocker_pivot, rpy=(lever_angle, 0, 0),
              axis=(1, 0, 0))])
    ball = closure('rod_end', ClosureKind.BALL, side('rod', (length, 0, 0)),
                   side('lever', (0, 0, rocker_arm)))
    return Mechanism('rod_two_balls', text, (ball,), ('crank',),
                     {'ball': JointOverride.SPHERICAL})


def collinear_pins() -> Mechanism:
    """Return the four-bar whose coupler hangs from the crank by two collinear pins."""
    crank, coupler, rocker, c = 0.3, math.sqrt(1.09), 0.6, (1.0, 0.0)
    angle = math.radians(60.0)
    a = (crank * math.cos(angle), crank * math.sin(angle))
    b = _apex(a, c, coupler, rocker)
    heading_ab = math.atan2(b[1] - a[1], b[0] - a[0])
    heading_bc = math.atan2(c[1] - b[1], c[0] - b[0])
    text = robot('collinear_pins', [
        joint('c1', 'revolute', 'ground', 'crank', rpy=(0, 0, angle)),
        joint('p1', 'revolute', 'crank', 'spacer', xyz=(crank, 0, 0)),
        joint('p2', 'revolute', 'spacer', 'coupler', xyz=(0, 0, 0.02),
              rpy=(0, 0, heading_ab - angle)),
        joint('p3', 'revolute', 'coupler', 'rocker', xyz=(coupler, 0, 0),
              rpy=(0, 0, heading_bc - heading_ab))])
    pin = closure('pin_c', ClosureKind.PIN, side('rocker', (rocker, 0, -0.02), axis=(0, 0, 1)),
                  side('ground', (c[0], c[1], 0), axis=(0, 0, 1)))
    return Mechanism('collinear_pins', text, (pin,), ('c1',))


def delta_like() -> Mechanism:
    """Return the three-legged delta-like mechanism; the motors are measured."""
    base, arm, rod = 0.1, 0.1, 0.25
    drop = math.sqrt(rod * rod - (base + arm) ** 2)
    joints, closures = [], []
    for leg in range(3):
        heading = 2.0 * math.pi * leg / 3.0
        elbow = ((base + arm) * math.cos(heading), (base + arm) * math.sin(heading), 0.0)
        forearm = (-elbow[0], -elbow[1], -drop)
        joints += [
            joint(f'motor{leg}', 'revolute', 'base', f'arm{leg}',
                  xyz=(base * math.cos(heading), base * math.sin(heading), 0.0),
                  rpy=(0, 0, heading), axis=(0, 1, 0)),
            joint(f'elbow{leg}', 'fixed', f'arm{leg}', f'rod{leg}', xyz=(arm, 0, 0),
                  rpy=(lambda r: (r[0], r[1], r[2] - heading))(_heading(forearm)))]
        if leg == 0:
            joints.append(joint('platform_mount', 'fixed', 'rod0', 'platform', xyz=(rod, 0, 0)))
        else:
            closures.append(closure(f'ball{leg}', ClosureKind.BALL, side(f'rod{leg}', (rod, 0, 0)),
                                    side('platform')))
    return Mechanism('delta_like', robot('delta_like', joints), tuple(closures),
                     ('motor0', 'motor1', 'motor2'),
                     {f'elbow{leg}': JointOverride.SPHERICAL for leg in range(3)})


@dataclass
class Planned:
    """A mechanism's one group planned as the node would: tree, structure, assembly, solver."""

    mechanism: Mechanism
    tree: KinematicTree
    group: ClosureGroup
    structure: GroupStructure
    assembly: Assembly
    solver: GroupSolver


def plan(mechanism: Mechanism, known: tuple[str, ...] | None = None,
         kind: GroupKind | None = None, start: dict[str, float] | None = None,
         place: int = 0) -> Planned:
    """Return the mechanism's group ``place`` planned for ``known`` (default: the measured)."""
    tree = KinematicTree(read_urdf(mechanism.urdf), mechanism.overrides)
    group = closure_groups(tree, mechanism.closures,
                           mechanism.measured if known is None else known)[place]
    values = [0.0] * len(tree.names)
    for name, value in (start or {}).items():
        values[tree.index[name]] = value
    assembly = assemble(tree, group, values)
    structure = analyse(tree, group, assembly.values)
    chosen = classify(tree, group, structure, assembly.values) if kind is None else kind
    return Planned(mechanism, tree, group, structure, assembly,
                   GroupSolver(tree, group, structure, assembly, chosen))


def reference_state(planned: Planned, known: list[float], rates: list[float],
                    guess: tuple[float, ...]) -> tuple[dict, dict]:
    """Return the reference's positions and velocities of the solved joints (mpf, by name)."""
    structure = planned.structure
    reference = Reference(planned.mechanism.urdf, planned.group.closures,
                          planned.mechanism.reference_overrides)
    unknown = list(structure.solved)
    anchor = dict(zip(planned.tree.names, planned.assembly.values))
    basis = reference.idle_basis(anchor, unknown)
    given = dict(zip(structure.known, known))
    positions = reference.solve(given, dict(zip(unknown, guess)), unknown, (basis, anchor))
    velocities = reference.velocities({**given, **positions}, dict(zip(structure.known, rates)),
                                      unknown, basis)
    return positions, velocities
