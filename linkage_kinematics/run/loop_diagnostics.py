# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
What the node's diagnostics say with ``loops:=robot_description``, without ROS.

``LoopsHealth`` is the source's record: dropped messages by reason, overall and per loop or
group, the time since the last valid one, and how each measured joint's velocity was obtained.
``loop_statuses`` turns it, with the ``StatusInputs`` the node has at that moment, into the
node's status (waiting for the description or the input, following, problems), one status per
planar loop (its kind, its known joint, what is estimated, its drops, the distance of its known
joint to its nearest dead point) and one per closure group of the general closure (its
closures, degrees of freedom, known and solved joints, how it is solved, its idle freedoms and
unpublished coordinates, its assembly, the conditioning and the distance to the nearest
singular configuration at the last sample, its drops), and with output joints one per group
that has them (``transmission <group>``: its actuators and output joints, its mechanical
advantage at the last sample, whether that sample's efforts were published, and how many
samples' efforts were withheld near a singular configuration of the transmission), in
``diagnostics``' style.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

from linkage_kinematics.kinematics.planar_loop import JointKind
from linkage_kinematics.loops.follower import dead_point_distances, LoopSample
from linkage_kinematics.loops.intake import DropReason, Estimate, LOOPS_DROPS
from linkage_kinematics.loops.plan import LoopPlan, PlannedLoop
from linkage_kinematics.loops.robot_transmission import GroupTransmission, OutputEfforts
from linkage_kinematics.loops.solver import GroupStep
from linkage_kinematics.loops.structure import GroupKind
from linkage_kinematics.loops.transmission import MechanicalAdvantage, TransmissionSingular
from linkage_kinematics.run.diagnostics import (
    Freshness,
    Level,
    LOG_DISABLED,
    NOT_MEASURED,
    Status,
    StatusInputs,
)

NODE_TASK = 'robot loops'


def _counts() -> dict[DropReason, int]:
    return dict.fromkeys(LOOPS_DROPS, 0)


def _dropped(count: int, reason: DropReason) -> str:
    return f'dropped {count} message{"s" if count > 1 else ""} {reason.value}'


class LoopsHealth(Freshness):
    """
    Dropped messages by reason (overall and per loop), and how fresh the data is.

    Drops since the previous status make the node's status (and the loops they concern) WARN;
    stale data (``Freshness``) makes the node's status ERROR. ``withheld``: per group, the
    samples whose efforts its transmission withheld (too near a singular configuration).
    """

    def __init__(self, start_ns: int) -> None:
        super().__init__(start_ns, LOOPS_DROPS)
        self.per_loop: dict[str, dict[DropReason, int]] = {}
        self._loop_window: dict[str, dict[DropReason, int]] = {}
        self.last: LoopSample | None = None
        self.withheld: dict[str, int] = {}

    def drop(self, reason: DropReason, constraints: tuple[str, ...] = ()) -> None:
        """Count a dropped message, for the node and for each loop it concerned."""
        super().drop(reason)
        for constraint in constraints:
            for counts in (self.per_loop, self._loop_window):
                counts.setdefault(constraint, _counts())[reason] += 1

    def accept(self, now_ns: int, sample: LoopSample) -> None:
        """Note a message followed at node-clock time ``now_ns``."""
        self._accepted_at(now_ns)
        self.last = sample
        if sample.withheld is not None:
            self.withheld[sample.withheld] = self.withheld.get(sample.withheld, 0) + 1

    def problem(self, now_ns: int, timeout: float) -> str | None:
        """Return the ERROR message when the data is stale, else None."""
        return self._stale_problem(now_ns, timeout, 'measured sample')

    def take_warnings(self) -> tuple[tuple[str, ...], dict[str, tuple[str, ...]]]:
        """Return the drops since the last call (the node's, each loop's) and start anew."""
        node = tuple(_dropped(count, reason)
                     for reason, count in self._take_window().items() if count)
        loops = {constraint: tuple(_dropped(count, reason)
                                   for reason, count in counts.items() if count)
                 for constraint, counts in self._loop_window.items()}
        self._loop_window = {}
        return node, loops


@dataclass(frozen=True, kw_only=True)
class LoopsView:
    """What the source knows beyond ``StatusInputs``: its robot, plan and health."""

    robot_name: str | None  # None: no description closed yet
    description_from: str  # 'parameter robot_description' or the topic's resolved name
    plan: LoopPlan | None
    health: LoopsHealth
    # the plan's groups of the general closure as followed (solver.LoopSolver.groups)
    groups: tuple[GroupStep, ...] = ()
    # with output joints: the groups' transmissions (follower.RobotLoopsFollower.output_efforts)
    transmissions: OutputEfforts | None = None


def _estimated_joints(plan: LoopPlan, sample: LoopSample | None) -> set[str]:
    """Return the joints whose velocity is an estimate: unmeasured ones, and what they drive."""
    if sample is None:
        return set()
    estimated = {name for name, how in sample.estimates.items() if how is not Estimate.MEASURED}
    for planned in plan.loops:  # in solve order, so a loop's known joint is settled before it
        if planned.known.name in estimated:
            estimated.update(joint.name for joint in planned.passive)
    return estimated


def _value_text(planned: PlannedLoop, value: float | None) -> str:
    if value is None:
        return 'none (no dead point)'
    if planned.known.kind is JointKind.REVOLUTE:
        return f'{math.degrees(value):.6f} deg'
    return f'{value:.9f} m'


def _loop_status(inputs: StatusInputs, view: LoopsView, planned: PlannedLoop,
                 solver_of: dict[str, str], warnings: tuple[str, ...]) -> Status:
    """Return one loop's status."""
    constraint, known = planned.loop.constraint, planned.known
    health, sample = view.health, view.health.last
    prismatic = planned.loop.prismatic
    estimated = _estimated_joints(view.plan, sample)
    distance = None
    if sample is not None:
        distance = dead_point_distances(view.plan, sample.known_values).get(constraint)
    values = {
        'kind': ('four-bar' if prismatic is None
                 else f'one prismatic joint ({prismatic.name})'),
        'known joint': (f'{known.name} (measured)' if planned.measured
                        else f'{known.name} (solved by loop {solver_of[known.name]})'),
        'solves': ', '.join(joint.name for joint in planned.passive),
        'branch': f'{planned.branch:+d}',
        'estimated': (
            'none' if sample is None or known.name not in estimated
            else 'velocities of ' + ', '.join(joint.name for joint in planned.passive)
            + f' (from an estimated velocity of {known.name})'),
        'dead point distance': ('not followed yet' if sample is None
                                else _value_text(planned, distance)),
    }
    counts = health.per_loop.get(constraint, _counts())
    values['dropped samples'] = str(sum(counts.values()))
    values.update({f'dropped {reason.value}': str(count) for reason, count in counts.items()
                   if reason is not DropReason.NO_DESCRIPTION})
    notes = list(warnings)
    if (distance is not None and known.kind is JointKind.REVOLUTE
            and distance < inputs.config.outputs.dead_point_warning):
        notes.append(f'{known.name} is {math.degrees(distance):.3f}° from a dead point')
    if notes:
        level, message = Level.WARN, '; '.join(notes)
    elif sample is None:
        level, message = Level.OK, f'waiting for {known.name}'
    else:
        level, message = Level.OK, f'closed from {known.name}'
    return Status(f'loop {constraint}', f'robot {view.robot_name}', level, message, values)


def _counts_text(counts: dict[str, int]) -> str:
    """Return how many of each closure kind a group has: '2 balls', '1 pin and 1 weld'."""
    parts = [f'{count} {kind}{"s" if count > 1 else ""}' for kind, count in counts.items()]
    return ', '.join(parts[:-1]) + ' and ' + parts[-1] if len(parts) > 1 else parts[0]


def _how(kind: GroupKind) -> str:
    """Return how a group's positions are solved, for people."""
    if kind is GroupKind.NEWTON:
        return 'Newton on the closure equations with their exact Jacobian, to rounding'
    return kind.value


def _group_status(inputs: StatusInputs, view: LoopsView, step: GroupStep,
                  warnings: tuple[str, ...]) -> Status:
    """Return one closure group's status (general closure)."""
    plan, sample = step.plan, view.health.last
    structure = plan.zero.structure
    kinds: dict[str, int] = {}
    for closure in plan.group.closures:
        kinds[closure.kind.value] = kinds.get(closure.kind.value, 0) + 1
    followed = sample is not None and step.state is not None
    estimated = [] if sample is None else [
        name for name in plan.known if sample.estimates[name] is not Estimate.MEASURED]
    tree = view.plan.tree
    hidden_joints = sorted({tree.coordinates[tree.index[name]].joint for name in plan.hidden})
    values = {
        'kind': 'closure group of ' + _counts_text(kinds),
        'closures': ', '.join(f'{closure.name} ({closure.kind.value}, '
                              f'{closure.encoding.value})' for closure in plan.group.closures),
        'degrees of freedom': f'{structure.dof} ({len(structure.idle)} idle)',
        'known joints': ', '.join(plan.known) + ' (measured)',
        'solves': ', '.join(plan.solved),
        'solved by': _how(plan.kind),
        'idle freedoms': ('none' if not structure.idle else '; '.join(
            ', '.join(idle.joints) for idle in structure.idle)
            + ' (each held at its assembled value)'),
        'not published': ('none' if not plan.hidden else ', '.join(plan.hidden)
                          + f" (the closure file's coordinates of {', '.join(hidden_joints)}"
                          ': no URDF joints)'),
        'assembly': ("at the first sample, nearest the zero pose's"
                     if step.solver is None
                     else f'orientation {step.solver.orientation:+d} (the sign of det A), '
                          'assembled at the first sample'),
        'estimated': ('none' if not estimated else 'velocities of ' + ', '.join(plan.solved)
                      + f' (from an estimated velocity of {", ".join(estimated)})'),
    }
    distance = None
    if followed:
        state = step.state
        distance = step.solver.derivatives.singular_distance([0.0] * len(plan.known))
        values['conditioning'] = f'{state.conditioning:.3g}'
        values['Newton iterations'] = str(state.iterations)
        values['singular configuration distance'] = (
            f'{distance:.6g} (in the known joints, rad or m; an estimate)')
    else:
        for key in ('conditioning', 'Newton iterations', 'singular configuration distance'):
            values[key] = 'not followed yet'
    counts = view.health.per_loop.get(plan.name, _counts())
    values['dropped samples'] = str(sum(counts.values()))
    values.update({f'dropped {reason.value}': str(count) for reason, count in counts.items()
                   if reason is not DropReason.NO_DESCRIPTION})
    notes = list(warnings)
    if hidden_joints:
        notes.append('robot_state_publisher cannot pose the links below '
                     f'{", ".join(hidden_joints)} (the closure file overrides them): model them '
                     'as revolute joints in the URDF')
    if distance is not None and distance < inputs.config.outputs.dead_point_warning:
        notes.append(f'{distance:.3g} from a singular configuration')
    known = ', '.join(plan.known)
    if notes:
        level, message = Level.WARN, '; '.join(notes)
    elif not followed:
        level, message = Level.OK, f'waiting for {known}'
    else:
        level, message = Level.OK, f'closed from {known}'
    return Status(f'group {plan.name}', f'robot {view.robot_name}', level, message, values)


def _ratio_text(advantage: MechanicalAdvantage) -> str:
    """Return M = ∂m/∂o row by row: one row per actuator, one column per output joint."""
    return '; '.join(f'{actuator}: ' + ', '.join(f'{value:.6g}' for value in row)
                     for actuator, row in zip(advantage.actuators, advantage.ratio))


def _efforts_text(sample: LoopSample | None, found: GroupTransmission,
                  transmissions: OutputEfforts) -> str:
    """Return what became of the last sample's efforts, as this group's status says it."""
    if sample is None:
        return 'not followed yet'
    if sample.efforts:
        return ("published: each output joint Mᵀ·(the actuators' measured efforts), every other "
                'published joint 0')
    if sample.withheld == found.group.name:
        return 'withheld: the transmission is too near a singular configuration'
    if sample.withheld is not None:
        return (f'withheld: the transmission of group {sample.withheld} is too near a singular '
                'configuration')
    actuators = sorted({name for group in transmissions.groups
                        for name in group.transmission.actuators})
    return ('not published: the input does not carry a finite effort of each of '
            + ', '.join(actuators))


def _transmission_status(view: LoopsView, found: GroupTransmission,
                         advantage: MechanicalAdvantage | TransmissionSingular | None) -> Status:
    """Return one group's transmission status (with output joints)."""
    transmission, sample = found.transmission, view.health.last
    values = {
        'actuators': ', '.join(transmission.actuators),
        'output joints': ', '.join(transmission.outputs),
        'efforts': _efforts_text(sample, found, view.transmissions),
        'efforts withheld (samples)': str(view.health.withheld.get(found.group.name, 0)),
    }
    outputs = ', '.join(transmission.outputs)
    if isinstance(advantage, MechanicalAdvantage):
        values['mechanical advantage'] = advantage.describe()
        values['d(actuators)/d(outputs)'] = _ratio_text(advantage)
        level, message = Level.OK, f'{outputs} from {", ".join(transmission.actuators)}'
    else:
        text = 'not followed yet' if advantage is None else f'none: {advantage}'
        values['mechanical advantage'] = values['d(actuators)/d(outputs)'] = text
        level, message = ((Level.OK, f'waiting for {", ".join(transmission.actuators)}')
                          if advantage is None else (Level.WARN, str(advantage)))
    return Status(f'transmission {found.group.name}', f'robot {view.robot_name}', level, message,
                  values)


def _node_values(inputs: StatusInputs, view: LoopsView) -> dict[str, str]:
    """Return the node's status's key values."""
    health, plan = view.health, view.plan
    values = {
        'source': 'measured',
        'loops': 'robot_description',
        'robot': 'not received yet' if view.robot_name is None else view.robot_name,
        'description from': view.description_from,
        'measured joints': ('not known yet' if plan is None else ', '.join(plan.measured)),
        'passive joints': ('not known yet' if plan is None else ', '.join(plan.passive)),
        'closure groups': ('not known yet' if plan is None else ', '.join(
            f'{group.name} ({"planar loops" if group.zero is None else "general closure"})'
            for group in plan.groups)),
        **health.sample_values(inputs.now_ns),
    }
    sample = health.last
    estimated = [] if sample is None else [
        f'{name} velocity ({how.value})'
        for name, how in sample.estimates.items() if how is not Estimate.MEASURED]
    values['measured'] = ('every measured joint position' + (
        ', every measured joint velocity' if sample is not None and not estimated else ''))
    values['exact functions of the measured'] = 'every passive position, and velocities ' \
        'of measured velocities'
    values['estimated'] = ', '.join(estimated) + (
        ' and the velocities solved from them' if estimated else 'none')
    values['achieved rate (Hz)'] = (
        NOT_MEASURED if inputs.achieved_rate is None else f'{inputs.achieved_rate:.1f}')
    if inputs.log_file is not None and inputs.log_size is not None:
        values['log size (bytes)'] = str(int(inputs.log_size))
    values['log file'] = LOG_DISABLED if inputs.log_file is None else inputs.log_file
    values['run state'] = inputs.run_state.value
    return values


def loop_statuses(inputs: StatusInputs, view: LoopsView) -> tuple[Status, ...]:
    """
    Return the node's status and one per planar loop, group and transmission (parameters.md).

    The node's: ERROR for ``inputs.problem`` (a description that cannot be closed, the log
    failed) or stale data, WARN for drops since the last status, else OK with the activity.
    """
    health = view.health
    node_warnings, loop_warnings = health.take_warnings()
    stale = health.problem(inputs.now_ns, inputs.config.measured.timeout)
    if stale is not None and inputs.activity.startswith('waiting'):
        stale = f'{stale}; {inputs.activity}'  # say what the node still waits for
    problem = inputs.problem or stale
    if problem is not None:
        level, message = Level.ERROR, problem
    elif node_warnings:
        level, message = Level.WARN, '; '.join(node_warnings)
    else:
        level, message = Level.OK, inputs.activity
    hardware_id = ('robot description not received yet' if view.robot_name is None
                   else f'robot {view.robot_name}')
    statuses = [Status(NODE_TASK, hardware_id, level, message, _node_values(inputs, view))]
    if view.plan is not None:
        solver_of = {joint.name: planned.loop.constraint
                     for planned in view.plan.loops for joint in planned.passive}
        statuses += [_loop_status(inputs, view, planned, solver_of,
                                  loop_warnings.get(planned.loop.constraint, ()))
                     for planned in view.plan.loops]
        statuses += [_group_status(inputs, view, step, loop_warnings.get(step.plan.name, ()))
                     for step in view.groups]
    transmissions = view.transmissions
    if transmissions is not None:
        sample = health.last
        advantages = ((None,) * len(transmissions.groups) if sample is None
                      else transmissions.advantages(sample.joints, view.groups))
        statuses += [_transmission_status(view, found, advantage)
                     for found, advantage in zip(transmissions.groups, advantages)]
    return tuple(statuses)
