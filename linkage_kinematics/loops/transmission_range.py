# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A group's mechanical advantage over the reachable range of its output joints, for the checker.

A lab sizes an actuator from the worst transmission ratio the mechanism passes through, so the
output joints are swept over where they can go and M = ∂m/∂o (``transmission``) is taken at
every sample, by the command direction's own solver (``command.CommandGroup``), continuing
from the assembled pose:

* **one output joint**: from the assembled value up, then down, in steps of 1/``SAMPLES`` of
  its span, until its URDF limit (a continuous joint: half a turn each way, so a full turn in
  all) or the first point the command direction refuses (no assembly reaches it, a singular
  configuration of either direction is near, an actuator would leave its URDF ``<limit>``):
  the range is the one a command can reach, and its ends say why they are there;
* **two output joints**: slices. Output 0 is swept as above with output 1 at its assembled
  value (the spine); from each point of the spine output 1 is swept both ways. A grid that
  the continuation fills from the assembled pose, so every sample lies on the assembly the
  node follows; a region reachable only around a hole or by another assembly is not sampled.
* more output joints: not swept (``advantage_range`` returns None): a grid in three or more
  dimensions costs what a checker should not, and the labs' mechanisms with a transmission of
  three degrees of freedom (deltas) are not recognised from a URDF yet.

A range end inside the span is found to 2⁻²⁰ of a step by halving the last step (the reason
reported is the nearest refusal's). Near a dead point of the actuators M tends to 0 (the
actuators need unbounded effort for a given output effort), near one of the outputs to
infinity (a toggle): the extremes reported are those of the samples, which stop where the
conditioning rule or the reach does. Pure: no ROS.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

from linkage_kinematics.loops.command import CommandGroup, CommandRefused
from linkage_kinematics.loops.transmission import mechanical_advantage
from linkage_kinematics.loops.tree import MotionKind
from linkage_kinematics.model.urdf_reader import JointType

SAMPLES = 200
# samples per slice for two output joints (a 41 × 41 grid at most)
SLICE_SAMPLES = 40
REFINE = 20
FULL_TURN = 'half a turn each way (a continuous joint)'
LIMIT = 'its URDF <limit>'


@dataclass(frozen=True)
class OutputSweep:
    """How far an output joint went (rad or m) and why each end is where it is."""

    joint: str
    low: float
    high: float
    low_end: str
    high_end: str


@dataclass(frozen=True)
class AdvantageRange:
    """
    The mechanical advantage over the sampled range (module docstring).

    ``ratio``: with one output joint, the smallest and largest dm/do (signed); with two, None.
    ``singular_values``: the smallest σ_min and the largest σ_max of M over the samples, and
    ``weakest_at`` the output joints' values where σ_min is smallest. ``actuator_load``: per
    actuator the largest effort it gives per unit effort of every output joint.
    """

    group: str
    actuators: tuple[str, ...]
    outputs: tuple[str, ...]
    method: str
    sweeps: tuple[OutputSweep, ...]
    samples: int
    ratio: tuple[float, float] | None
    singular_values: tuple[float, float]
    weakest_at: tuple[float, ...]
    actuator_load: tuple[float, ...]

    def describe(self) -> list[str]:
        """Return the checker's lines for it."""
        lines = [f'  output joints {list(self.outputs)} -> actuators {list(self.actuators)} '
                 f'({self.method}, {self.samples} samples)']
        for sweep in self.sweeps:
            lines.append(f'    {sweep.joint}: [{sweep.low:.6g}, {sweep.high:.6g}] (low end: '
                         f'{sweep.low_end}; high end: {sweep.high_end})')
        if self.ratio is not None:
            lines.append(f'    transmission ratio d({self.actuators[0]})/d({self.outputs[0]}) '
                         f'from {self.ratio[0]:.6g} to {self.ratio[1]:.6g} (output effort per '
                         'actuator effort)')
        else:
            at = ', '.join(f'{name} = {value:.6g}'
                           for name, value in zip(self.outputs, self.weakest_at))
            lines.append(f'    singular values of d(actuators)/d(outputs) from '
                         f'{self.singular_values[0]:.6g} (at {at}) to '
                         f'{self.singular_values[1]:.6g}')
        loads = ', '.join(f'{name} {load:.6g}'
                          for name, load in zip(self.actuators, self.actuator_load))
        lines.append(f'    actuator effort per unit output effort, at worst: {loads}')
        return lines


def _bounds(command: CommandGroup, place: int, start: float) -> tuple[float, float, str, str]:
    """Return an output joint's sweep bounds and what they are."""
    name = command.outputs[place]
    tree = command.tree
    coordinate = tree.coordinates[tree.index[name]]
    joint = {joint.name: joint for joint in tree.joint_above.values()}.get(coordinate.joint)
    if joint is not None and coordinate.joint == name and joint.position_limits is not None:
        low, high = joint.position_limits
        return low, high, LIMIT, LIMIT
    if coordinate.kind is MotionKind.TURN and (joint is None or joint.joint_type
                                               is not JointType.PRISMATIC):
        return start - math.pi, start + math.pi, FULL_TURN, FULL_TURN
    size = command.transmission.size
    return start - size, start + size, "the group's size", "the group's size"


class _Samples:
    """The advantage at the samples taken so far."""

    def __init__(self, command: CommandGroup) -> None:
        self.command = command
        self.count = 0
        self.ratio = [math.inf, -math.inf]
        self.smallest = (math.inf, ())
        self.largest = 0.0
        self.load = [0.0] * len(command.actuators)
        self.reached = [[math.inf, -math.inf] for _ in command.outputs]

    def take(self, positions: list[float]) -> CommandRefused | None:
        """Solve at ``positions`` and add its advantage; return the refusal if refused."""
        try:
            found = self.command.solve(positions)
        except CommandRefused as refusal:
            return refusal
        ratio = found.linearization.ratio
        advantage = mechanical_advantage(self.command.actuators, self.command.outputs, ratio)
        self.count += 1
        if len(ratio) == 1:
            self.ratio = [min(self.ratio[0], ratio[0][0]), max(self.ratio[1], ratio[0][0])]
        smallest = advantage.singular_values[-1]
        if smallest < self.smallest[0]:
            self.smallest = (smallest, tuple(positions))
        self.largest = max(self.largest, advantage.singular_values[0])
        self.load = [max(a, b) for a, b in zip(self.load, advantage.actuator_load)]
        for reached, value in zip(self.reached, positions):
            reached[0], reached[1] = min(reached[0], value), max(reached[1], value)
        return None


def _sweep(samples: _Samples, base: list[float], place: int, low: float, high: float,
           count: int, ends: tuple[str, str]) -> tuple[str, str, list]:
    """
    Sweep output ``place`` from ``base`` up to ``high``, then down to ``low``.

    A refused step is halved ``REFINE`` times towards the last point reached, so that an end
    within the span lies within 2⁻²⁰ of a step of where commands stop. Returns why each end is
    where it is, and (value, state) of every point reached, the start included, in increasing
    order.
    """
    command = samples.command
    start_state = command.state()
    step = (high - low) / count
    reached = [(base[place], start_state)]
    found_ends = []
    for direction, bound, end in ((1.0, high, ends[1]), (-1.0, low, ends[0])):
        command.restore(start_state)
        k, why, good = 1, end, base[place]
        while True:
            value = base[place] + direction * k * step
            if direction * (value - bound) > 0.0:
                value = bound
            if direction * (value - good) <= 0.0:
                break
            point = list(base)
            point[place] = value
            refusal = samples.take(point)
            if refusal is not None:
                why = _refine(samples, point, place, good, value, refusal, reached)
                break
            reached.append((value, command.state()))
            good = value
            k += 1
        found_ends.append(why)
    command.restore(start_state)
    reached.sort(key=lambda pair: pair[0])
    return found_ends[1], found_ends[0], reached


def _refine(samples: _Samples, point: list[float], place: int, good: float, bad: float,
            refusal: CommandRefused, reached: list) -> str:
    """Halve the interval between the last point reached and a refused one; return why."""
    for _ in range(REFINE):
        middle = 0.5 * (good + bad)
        point[place] = middle
        found = samples.take(point)
        if found is None:
            good = middle
            reached.append((middle, samples.command.state()))
        else:
            bad, refusal = middle, found
    return refusal.reason.value


def advantage_range(command: CommandGroup) -> AdvantageRange | None:
    """
    Return the mechanical advantage over the output joints' reachable range, sampled.

    None for a group of more than two output joints. The command group is left at its
    assembled pose (``reset``).
    """
    outputs = command.outputs
    if len(outputs) > 2:
        return None
    command.reset()
    samples = _Samples(command)
    base = [command.position(name) for name in outputs]
    samples.take(list(base))
    low, high, low_end, high_end = _bounds(command, 0, base[0])
    count = SAMPLES if len(outputs) == 1 else SLICE_SAMPLES
    first = _sweep(samples, base, 0, low, high, count, (low_end, high_end))
    sweeps = [OutputSweep(outputs[0], samples.reached[0][0], samples.reached[0][1],
                          first[0], first[1])]
    method = f'swept by continuation in {count} steps of its span'
    if len(outputs) == 2:
        low, high, low_end, high_end = _bounds(command, 1, base[1])
        ends: set[tuple[str, str]] = set()
        for value, state in first[2]:
            command.restore(state)
            point = [value, base[1]]
            found = _sweep(samples, point, 1, low, high, SLICE_SAMPLES, (low_end, high_end))
            ends.add(found[:2])
        sweeps.append(OutputSweep(outputs[1], samples.reached[1][0], samples.reached[1][1],
                                  ' / '.join(sorted({end[0] for end in ends})),
                                  ' / '.join(sorted({end[1] for end in ends}))))
        method = (f'slices: {outputs[0]} swept by continuation in {count} steps of its span, '
                  f'{outputs[1]} from each of its points likewise')
    command.reset()
    return AdvantageRange(
        command.name, command.actuators, outputs, method, tuple(sweeps), samples.count,
        tuple(samples.ratio) if len(outputs) == 1 else None,
        (samples.smallest[0], samples.largest), samples.smallest[1], tuple(samples.load))
