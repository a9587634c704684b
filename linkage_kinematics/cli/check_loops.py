# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
``linkage-check-loops``: what the package finds in a URDF's loops, and how it closes them.

As urdfdom's ``check_urdf`` does for the tree: ``linkage-check-loops robot.urdf`` (``-`` reads
standard input, so that ``xacro robot.urdf.xacro | linkage-check-loops -`` works; ``--closures
robot.yaml`` adds a closure file) reads every closure as the node does (``loops.plan``) and
prints, for each planar loop, its joints and kind, the dimensions found at the zero pose, which
joint is known (with ``--measured``, else the closure file's actuated joints) or could be, that
joint's reachable range, dead points and change points, the assembly branch, and the closure
residual at the zero pose; for each other closure group (the general closure), its closures,
joints, degrees of freedom, known and solved joints, how it is solved, its residual at the zero
pose and at the pose it assembles nearest it, the conditioning and the distance to the nearest
singular configuration there, its idle freedoms and overridden joints, and for one or two known
joints each one's reachable interval with the other held (``loops.reach``). Angles are printed
in degrees. With ``--outputs`` (the node's ``loops.output_joints``), for each group they name
joints of: its output joints and actuators, its mechanical advantage at the assembled pose, and
the range of its transmission ratio (one output joint) or of its singular values (two) over
the output joints' reachable range, swept by the command direction's own solver, which stops
where no assembly reaches, at a singular configuration, or where an actuator would leave its
URDF ``<limit>`` (``loops.transmission_range``; rad, m, and efforts in N·m, N). Each problem
is one line on standard error; the exit status is 0 without problems, 1 for problems in the
description (or with the measured or output joints), 2 for a usage error or input that cannot
be read (a file, a text that is no URDF, a closure file that is not one).
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
import math
import sys

from linkage_kinematics.kinematics.geometry import GeometryError
from linkage_kinematics.kinematics.planar_loop import JointKind, known_joint_range
from linkage_kinematics.loops.assembly import ClosureGap
from linkage_kinematics.loops.closures import ClosureError, ClosureSide
from linkage_kinematics.loops.command import CommandGroup
from linkage_kinematics.loops.description import LoopError
from linkage_kinematics.loops.plan import (
    find_loops,
    GroupPlan,
    LoopPlan,
    RobotLoops,
    zero_pose_branch,
)
from linkage_kinematics.loops.planar import Loop, LoopJoint
from linkage_kinematics.loops.reach import reach
from linkage_kinematics.loops.refusals import PlanError, Refusal
from linkage_kinematics.loops.robot_transmission import GroupTransmission, plan_transmissions
from linkage_kinematics.loops.structure import GroupKind
from linkage_kinematics.loops.transmission import TransmissionError, TransmissionSingular
from linkage_kinematics.loops.transmission_range import advantage_range
from linkage_kinematics.loops.tree import KinematicTree, MotionKind
from linkage_kinematics.model.urdf_reader import read_urdf, UrdfError

PROGRAM = 'linkage-check-loops'
EXIT_PROBLEMS = 1
EXIT_USAGE = 2


# The reach of the known joints is printed for groups of this many known joints at most.
REACH_KNOWN = 2


def _assembly_seed(text: str) -> tuple[str, float]:
    """Return one ``--assemblies`` JOINT=VALUE."""
    name, _, value = text.rpartition('=')
    try:
        number = float(value)
    except ValueError:
        number = math.nan
    if not name or not math.isfinite(number):
        raise argparse.ArgumentTypeError(f'{text!r} is not JOINT=VALUE (rad or m)')
    return name, number


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=PROGRAM,
        description="Check a URDF's loop closures (<constraint>, <loop_joint>, a closure "
                    'file): how the package closes them, their dimensions, degrees of '
                    'freedom, assemblies and ranges.')
    parser.add_argument('urdf', help="the URDF file, or '-' for standard input")
    parser.add_argument('--closures', metavar='FILE',
                        help="the URDF's closure file (toolbox-parallel-robots' YAML), as the "
                             "node's robot_description_closures")
    parser.add_argument('--measured', nargs='+', metavar='JOINT',
                        help="the measured joints (default: the closure file's name_mot): "
                             'each planar loop is then solved from one of them or from a joint '
                             'an earlier loop solves, each other group from those it holds')
    parser.add_argument('--assemblies', nargs='+', metavar='JOINT=VALUE', type=_assembly_seed,
                        default=[],
                        help="start values of joints a closure group solves, as the node's "
                             'loops.assemblies')
    parser.add_argument('--outputs', nargs='+', metavar='JOINT', default=[],
                        help="each closure group's output joints, as the node's "
                             'loops.output_joints: its transmission ratio (mechanical '
                             "advantage) over their reachable range, within the actuators' "
                             'URDF limits')
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


def _angle_or_length(tree: KinematicTree, name: str, value: float) -> str:
    """Return a coordinate's value for people: degrees for a turn, metres for a slide."""
    if tree.coordinates[tree.index[name]].kind is MotionKind.TURN:
        text = f'{math.degrees(value):.3f}°'
    else:
        text = f'{value:.6f} m'
    # a value that rounds to zero from below (the rounding of a closed pose) is printed as 0
    return text[1:] if text.startswith('-') and not text.strip('-0.°m ') else text


def _gaps(gaps: Sequence[ClosureGap]) -> str:
    return ', '.join(f'{gap.closure} {gap.position:.3g} m'
                     + ('' if gap.angle is None else f' and {gap.angle:.3g} rad')
                     for gap in gaps)


def _side(side: ClosureSide) -> str:
    return f'{side.link} at {_vector(side.xyz)}'


# Why a known joint's reach ends, for people
ENDS = {Refusal.UNREACHABLE: 'no assembly reaches further',
        Refusal.SINGULAR: 'a singular configuration',
        Refusal.ASSEMBLY_CHANGE: 'it would change assembly'}


def _reach_lines(tree: KinematicTree, group: GroupPlan) -> list[str]:
    """Return each known joint's interval, the others held at the assembly (loops.reach)."""
    held = ('alone' if len(group.known) == 1
            else 'with the other known joint held at its assembled value')
    lines = [f'  reachable from the assembly, each known joint {held} (continued until '
             'refused):']
    for item in reach(tree, group.zero):
        if item.full_turn:
            lines.append(f'    {item.joint}: a full turn')
            continue
        ends = '; '.join(
            f'{where} end: ' + ('none found' if end is None
                                else f'{ENDS[end]} (conditioning {conditioning:.3g} there)')
            for where, end, conditioning in zip(('low', 'high'), item.ends, item.conditioning))
        lines.append(f'    {item.joint}: [{_angle_or_length(tree, item.joint, item.low)}, '
                     f'{_angle_or_length(tree, item.joint, item.high)}] ({ends})')
    return lines


def _group_lines(tree: KinematicTree, group: GroupPlan, overrides: dict,
                 known_given: bool) -> list[str]:
    """Return a group of the general closure: what it is, how it assembles and is solved."""
    zero = group.zero
    structure = zero.structure
    kinds: dict[str, int] = {}
    for closure in group.group.closures:
        kinds[closure.kind.value] = kinds.get(closure.kind.value, 0) + 1
    counts = ', '.join(f'{count} {kind}{"s" if count > 1 else ""}'
                       for kind, count in kinds.items())
    how = ('Newton on the closure equations with their exact Jacobian, to rounding'
           if group.kind is GroupKind.NEWTON else group.kind.value)
    lines = [f'group {group.name!r}: {counts}, {structure.dof} degree(s) of freedom '
             f'({len(structure.idle)} idle)']
    lines += [f'  closure {closure.name!r} ({closure.kind.value}, {closure.encoding.value}): '
              f'{_side(closure.parent)} with {_side(closure.child)}'
              for closure in group.group.closures]
    lines.append(f'  joints: {", ".join(structure.joints)}')
    if known_given:
        lines.append(f'  known (measured): {", ".join(group.known) or "none"}')
    else:
        lines.append(f'  known: none given ({structure.dof - len(structure.idle)} needed: '
                     "--measured, or the closure file's name_mot)")
    lines.append(f'  solved: {", ".join(group.solved)}')
    if known_given:
        lines.append(f'  solved by: {how}')
    lines.append(f'  residual at the zero pose: {_gaps(zero.assembly.start_gaps)}')
    values = dict(zip(tree.names, zero.assembly.values))
    taken = ('from the zero pose' if zero.assembly.restart == 0
             else f'from restart {zero.assembly.restart} about it')
    lines.append(f'  assembled nearest the zero pose ({taken}'
                 + (f', seeded {", ".join(f"{k} = {v:g}" for k, v in group.seed.items())}'
                    if group.seed else '') + '): '
                 + ', '.join(f'{name} {_angle_or_length(tree, name, values[name])}'
                             for name in structure.joints))
    lines.append(f'  residual at the assembled pose: {_gaps(zero.assembly.gaps)}')
    if zero.solver is not None:
        state = zero.solver.solve([values[name] for name in group.known],
                                  [0.0] * len(group.known))
        distance = zero.solver.derivatives.singular_distance([0.0] * len(group.known))
        lines.append(f'  conditioning at the assembled pose: {state.conditioning:.3g} '
                     f'(orientation {zero.solver.orientation:+d})')
        lines.append(f'  nearest singular configuration: about {distance:.3g} from the '
                     'assembled pose (in the known joints, rad or m)')
    lines.append('  idle freedoms: ' + ('none' if not structure.idle else '; '.join(
        ', '.join(idle.joints) for idle in structure.idle) + ' (each held at its assembled '
        'value)'))
    overridden = sorted({tree.coordinates[tree.index[name]].joint for name in group.hidden})
    lines.append('  overridden joints: ' + ('none' if not overridden else '; '.join(
        f'{joint} ({overrides[joint].name}: '
        f'{", ".join(overrides[joint].coordinates(joint))}, solved, not published)'
        for joint in overridden)))
    if zero.solver is not None and 1 <= len(group.known) <= REACH_KNOWN:
        lines += _reach_lines(tree, group)
    return lines


def _transmission_lines(loops: RobotLoops,
                        found: GroupTransmission) -> tuple[list[str], str | None]:
    """Return a group's transmission: its advantage now and over its range; or a problem."""
    transmission = found.transmission
    tree = loops.tree
    head = (f'transmission of group {found.group.name!r}: output joints '
            f'{", ".join(transmission.outputs)}; actuators {", ".join(transmission.actuators)}')
    values = found.values
    try:
        now = transmission.advantage([values[tree.index[name]] for name in transmission.actuators],
                                     [values[tree.index[name]] for name in transmission.solved])
        command = CommandGroup(tree, transmission, values, loops.loops)
    except (TransmissionSingular, PlanError) as error:
        return [head], str(error)
    lines = [head, f'  at the assembled pose: {now.describe()}']
    swept = advantage_range(command)
    if swept is None:
        lines.append(f'  not swept: {len(transmission.outputs)} output joints (a sweep is of '
                     'one or two)')
    else:
        lines += swept.describe()
    return lines, None


def transmission_report(loops: RobotLoops, plan: LoopPlan,
                        outputs: Sequence[str]) -> tuple[list[str], list[str]]:
    """Return the transmissions of the groups ``outputs`` names joints of, and the problems."""
    try:
        groups = plan_transmissions(plan, outputs)
    except TransmissionError as error:
        return [], [f'--outputs: {error}']
    lines, problems = [], []
    for found in groups:
        group_lines, problem = _transmission_lines(loops, found)
        lines += group_lines
        if problem is not None:
            problems.append(problem)
    return lines, problems


def report(loops: RobotLoops, plan: LoopPlan | None, survey: LoopPlan | None = None,
           known_given: bool = True) -> list[str]:
    """
    Return the printout for ``loops``, with each loop's known joint from ``plan`` if given.

    ``survey``: the plan as far as it goes (``RobotLoops.survey``), whose groups of the general
    closure are printed after the planar loops; ``known_given``: whether the measured joints
    are known (else the groups are described without them).
    """
    refused = f', {len(loops.problems)} constraint(s) refused' if loops.problems else ''
    lines = [f'robot {loops.robot_name!r}: {len(loops.closures) or len(loops.loops)} loop(s) to '
             f'close{refused}']
    planned = {item.loop.constraint: item for item in plan.loops} if plan is not None else {}
    solver_of = {joint.name: item.loop.constraint
                 for item in planned.values() for joint in item.passive}
    general = survey.general if survey is not None else ()
    in_general = {closure.name for group in general for closure in group.group.closures}
    for loop in loops.loops:
        if loop.constraint in in_general:
            continue  # closed with spatial closures: its group says so
        lines += _loop_lines(loop)
        item = planned.get(loop.constraint)
        if item is not None:
            source = ('measured' if item.measured
                      else f'solved by constraint {solver_of[item.known.name]!r}')
            lines += _known_lines(loop, item.known, f'known ({source})', item.branch)
        else:
            for joint in loop.joints:
                lines += _known_lines(loop, joint, 'could be known', None)
    for group in general:
        lines += _group_lines(survey.tree, group, dict(loops.overrides), known_given)
    return lines


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``linkage-check-loops``; return the exit status."""
    arguments = _parser().parse_args(argv)
    texts = []
    for path in (arguments.urdf, arguments.closures):
        if path is None:
            texts.append(None)
            continue
        try:
            texts.append(_read(path))
        except (OSError, UnicodeDecodeError) as error:
            print(f'{PROGRAM}: cannot read {path}: {error}', file=sys.stderr)
            return EXIT_USAGE
    try:
        loops = find_loops(read_urdf(texts[0]), texts[1])
    except (UrdfError, ClosureError) as error:
        print(f'{PROGRAM}: {error}', file=sys.stderr)
        return EXIT_USAGE
    problems = list(loops.problems)
    measured = arguments.measured if arguments.measured is not None else loops.actuated
    survey = loops.survey(measured or (), {}, dict(arguments.assemblies))
    # nothing known: the loops and groups are described, not refused for lack of known joints
    problems += survey.problems if measured else survey.unassembled
    plan = survey if measured and not survey.problems else None
    if not loops.closures and not loops.problems:
        print(f'robot {loops.robot_name!r}: no <constraint> elements, no loops to close')
    else:
        print('\n'.join(report(loops, plan, survey, bool(measured))))
    if arguments.outputs and plan is not None:
        lines, found = transmission_report(loops, plan, arguments.outputs)
        if lines:
            print('\n'.join(lines))
        problems += found
    elif arguments.outputs and not problems:
        problems.append('--outputs: the output joints are those of closure groups the measured '
                        "joints close (--measured, or the closure file's name_mot)")
    warnings = survey.warnings
    for message in loops.parser_messages:
        print(f'{PROGRAM}: note: urdf_parser_py: {message}', file=sys.stderr)
    for message in warnings:
        print(f'{PROGRAM}: warning: {message}', file=sys.stderr)
    for message in problems:
        print(f'{PROGRAM}: {message}', file=sys.stderr)
    return EXIT_PROBLEMS if problems else 0


if __name__ == '__main__':
    sys.exit(main())
