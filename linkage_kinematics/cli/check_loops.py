# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
``linkage-check-loops``: what the package finds in a URDF's ``<constraint>`` loops.

As urdfdom's ``check_urdf`` does for the tree: ``linkage-check-loops robot.urdf`` (``-`` reads
standard input, so that ``xacro robot.urdf.xacro | linkage-check-loops -`` works) prints, for
each constraint, its loop's joints and kind, the dimensions found at the zero pose, which joint
is known (with ``--measured``) or could be, that joint's reachable range, dead points and change
points, the assembly branch, and the closure residual at the zero pose. Angles are printed in
degrees. Each problem is one line on standard error; the exit status is 0 without problems, 1
for problems in the URDF (or with the measured joints), 2 for a usage error such as an
unreadable file.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
import math
import sys

from linkage_kinematics.kinematics.geometry import GeometryError
from linkage_kinematics.kinematics.planar_loop import JointKind, known_joint_range
from linkage_kinematics.loops.description import LoopError
from linkage_kinematics.loops.plan import (
    find_loops,
    LoopPlan,
    mimic_warnings,
    RobotLoops,
    zero_pose_branch,
    zero_pose_warnings,
)
from linkage_kinematics.loops.planar import Loop, LoopJoint
from linkage_kinematics.model.urdf_reader import read_urdf, UrdfError

PROGRAM = 'linkage-check-loops'
EXIT_PROBLEMS = 1
EXIT_USAGE = 2


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=PROGRAM,
        description="Check a URDF's <constraint> loops: the planar four-bar or slider loops "
                    'the package can close, their dimensions, ranges and branches.')
    parser.add_argument('urdf', help="the URDF file, or '-' for standard input")
    parser.add_argument('--measured', nargs='+', metavar='JOINT',
                        help='the measured joints: each loop is then solved from one of them '
                             'or from a joint an earlier loop solves')
    return parser


def _read(path: str) -> str:
    if path == '-':
        return sys.stdin.read()
    with open(path, encoding='utf-8') as file:
        return file.read()


def _value(joint: LoopJoint, value: float) -> str:
    """Return a joint value (rad or m) for people: degrees or metres."""
    if joint.kind is JointKind.REVOLUTE:
        return f'{math.degrees(value):.3f}°'
    return f'{value:.6f} m'


def _vector(vector: Sequence[float]) -> str:
    # a direction's rounding residue (a frame tilted by a rounded π/2) shows as 0, and −0 as 0
    return '(' + ', '.join(f'{round(component, 12) + 0.0:.6g}' for component in vector) + ')'


def _range_lines(loop: Loop, joint: LoopJoint, branch: int) -> list[str]:
    """Return the known joint's reachable range, dead and change points (URDF values)."""
    reach = known_joint_range(loop.planar, joint.index)
    # URDF value = sign · loop coordinate: a sign of −1 mirrors every interval
    intervals = sorted(tuple(sorted((joint.sign * low, joint.sign * high)))
                       for low, high in reach.intervals)
    if reach.full_rotation:
        reachable = 'a full turn'
    else:
        reachable = ', '.join(f'[{_value(joint, low)}, {_value(joint, high)}]'
                              for low, high in intervals)
        if reach.periodic:
            reachable += ' (modulo 360°)'

    def points(values: Sequence[float]) -> str:
        shown = sorted(joint.sign * value for value in values)
        return ', '.join(_value(joint, value) for value in shown) or 'none'

    return [f'    reachable: {reachable}',
            f'    dead points: {points(reach.dead_points)}',
            f'    change points: {points(reach.change_points)}',
            f'    branch at the zero pose: {branch:+d}']


def _known_lines(loop: Loop, joint: LoopJoint, note: str, branch: int | None) -> list[str]:
    try:
        if branch is None:
            branch = zero_pose_branch(loop, joint)
        return [f'  {note}: {joint.name}'] + _range_lines(loop, joint, branch)
    except (LoopError, GeometryError) as error:
        return [f'  {note}: {joint.name}', f'    {error}']


def _loop_lines(loop: Loop) -> list[str]:
    """Return a loop's joints, kind and dimensions."""
    prismatic = loop.prismatic
    kind = ('four-bar' if prismatic is None
            else f'one prismatic joint ({prismatic.name})')
    joints = ', '.join(f'{joint.name} ({joint.kind}, sign {joint.sign:+d})'
                       for joint in loop.joints)
    lengths = ', '.join(f'{math.hypot(*link):.6f} m' for link in loop.planar.links)
    lines = [f'constraint {loop.constraint!r}: {kind}',
             f'  joints from the cut pin: {joints}',
             f'  plane normal in the world: {_vector(loop.normal)}',
             f'  link lengths (pin→{loop.names[0]}→{loop.names[1]}→{loop.names[2]}→pin): '
             f'{lengths}']
    if prismatic is not None and loop.slide_world is not None:
        slide = loop.planar.slide
        before, after = loop.planar.links[prismatic.index - 1], loop.planar.links[prismatic.index]
        # the distance from the joint before the slider to the line its far joint travels
        offset = (slide[0] * (before[1] + after[1]) - slide[1] * (before[0] + after[0]))
        lines.append(f'  slide: along {_vector(loop.slide_world)} in the world, offset '
                     f'{abs(offset):.6f} m')
    # the distance between the two constraint frames, and its part in the plane (Σ links): a
    # depth between them (the pin's two sides on links stacked in depth) moves nothing
    lines.append(f'  closure residual at the zero pose: {loop.closure_residual:.3g} m '
                 f'(in the plane {loop.planar.closure_gap:.3g} m)')
    return lines


def report(loops: RobotLoops, plan: LoopPlan | None) -> list[str]:
    """Return the printout for ``loops``, with each loop's known joint from ``plan`` if given."""
    refused = f', {len(loops.problems)} constraint(s) refused' if loops.problems else ''
    lines = [f'robot {loops.robot_name!r}: {len(loops.loops)} loop(s) to close{refused}']
    planned = {item.loop.constraint: item for item in plan.loops} if plan is not None else {}
    solver_of = {joint.name: item.loop.constraint
                 for item in planned.values() for joint in item.passive}
    for loop in loops.loops:
        lines += _loop_lines(loop)
        item = planned.get(loop.constraint)
        if item is not None:
            source = ('measured' if item.measured
                      else f'solved by constraint {solver_of[item.known.name]!r}')
            lines += _known_lines(loop, item.known, f'known ({source})', item.branch)
        else:
            for joint in loop.joints:
                lines += _known_lines(loop, joint, 'could be known', None)
    return lines


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``linkage-check-loops``; return the exit status."""
    arguments = _parser().parse_args(argv)
    try:
        text = _read(arguments.urdf)
    except (OSError, UnicodeDecodeError) as error:
        print(f'{PROGRAM}: cannot read {arguments.urdf}: {error}', file=sys.stderr)
        return EXIT_USAGE
    problems: list[str] = []
    try:
        loops = find_loops(read_urdf(text))
    except UrdfError as error:
        print(f'{PROGRAM}: {error}', file=sys.stderr)
        return EXIT_PROBLEMS
    problems += loops.problems
    plan = None
    if arguments.measured is not None:
        try:
            plan = loops.plan(arguments.measured)
        except LoopError as error:
            problems += str(error).split('\n')
    if not loops.loops and not loops.problems:
        print(f'robot {loops.robot_name!r}: no <constraint> elements, no loops to close')
    else:
        print('\n'.join(report(loops, plan)))
    warnings = (plan.warnings if plan is not None
                else zero_pose_warnings(loops.loops) + mimic_warnings(loops.loops, ()))
    for message in loops.parser_messages:
        print(f'{PROGRAM}: note: urdf_parser_py: {message}', file=sys.stderr)
    for message in warnings:
        print(f'{PROGRAM}: warning: {message}', file=sys.stderr)
    for message in problems:
        print(f'{PROGRAM}: {message}', file=sys.stderr)
    return EXIT_PROBLEMS if problems else 0


if __name__ == '__main__':
    sys.exit(main())
