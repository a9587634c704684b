# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Robots for issue 30's tests: each group planned as the node plans it, with its output joints.

* ``ankle``: urdf/humanoid_ankle.urdf, motors measured, ankle pitch and roll the outputs (each
  leg a crank–rod–ball closed form in the command direction); checked with
  test/closure_reference.py.
* ``knee``: urdf/lab_knee.urdf, the Grashof crank-rocker: knee_motor (the crank) measured,
  knee_output (the rocker) the output (the planar closed form from the output); checked with
  test/loop_reference.py.
* ``knee_reversed``: the same knee, the rocker measured and the crank the output: the
  actuator has dead points inside the output's full turn.
* ``excavator``: test/loop_robots.py's excavator, the three cylinders (prismatic actuators of
  ±0.5 m stroke) measured, boom, stick and bucket joints the outputs; loop_reference.py.
* ``five_bar``: test/closure_robots.py's planar five-bar, both cranks measured, the distal
  joints j2 and j4 the outputs (Newton in the command direction); closure_reference.py.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from closure_reference import Reference
import closure_robots
from linkage_kinematics.loops.closures import Closure, JointOverride
from linkage_kinematics.loops.command import CommandGroup
from linkage_kinematics.loops.encodings import read_closures
from linkage_kinematics.loops.newton import plan_group, PlannedGroup
from linkage_kinematics.loops.plan import find_loops
from linkage_kinematics.loops.robot_command import RobotCommand
from linkage_kinematics.loops.structure import closure_groups, ClosureGroup
from linkage_kinematics.loops.transmission import Transmission
from linkage_kinematics.loops.tree import KinematicTree
from linkage_kinematics.model.urdf_reader import read_urdf
import loop_reference
import loop_robots
from mpmath import mp, mpf

REPOSITORY = Path(__file__).resolve().parent.parent
KNEE = (REPOSITORY / 'urdf' / 'lab_knee.urdf').read_text(encoding='utf-8')
# how each robot is checked: its closures' reference, or the planar loops' one
CLOSURE, PLANAR = 'closure_reference', 'loop_reference'


@dataclass
class Robot:
    """A robot's groups planned for its measured joints, and their transmissions."""

    name: str
    urdf: str
    closures: tuple[Closure, ...]
    overrides: dict[str, JointOverride]
    measured: tuple[str, ...]
    outputs: tuple[str, ...]
    reference: str
    tree: KinematicTree
    groups: list[ClosureGroup]
    planned: list[PlannedGroup]
    transmissions: list[Transmission]
    commands: list[CommandGroup]
    robot: RobotCommand

    def group_of(self, output: str) -> int:
        """Return the place of the group that has output joint ``output``."""
        return next(place for place, transmission in enumerate(self.transmissions)
                    if output in transmission.outputs)

    def loop_joints(self) -> list[str]:
        """Return every joint of the loops but the output joints, group by group."""
        return [name for transmission in self.transmissions
                for name in (*transmission.actuators, *transmission.solved)
                if name not in transmission.outputs]


DEFINITIONS = {
    'ankle': (lambda: closure_robots.ankle().urdf, ('motor_left', 'motor_right'),
              ('ankle_pitch', 'ankle_roll'), CLOSURE),
    'knee': (lambda: KNEE, ('knee_motor',), ('knee_output',), PLANAR),
    'knee_reversed': (lambda: KNEE, ('knee_output',), ('knee_motor',), PLANAR),
    'excavator': (loop_robots.excavator, ('boom_cylinder', 'stick_cylinder', 'bucket_cylinder'),
                  ('boom_joint', 'stick_joint', 'bucket_joint'), PLANAR),
    'five_bar': (lambda: closure_robots.five_bar().urdf, ('j1', 'j3'), ('j2', 'j4'), CLOSURE),
}


def build(name: str) -> Robot:
    """Return robot ``name`` planned at its zero pose (every one is drawn assembled there)."""
    text_of, measured, outputs, reference = DEFINITIONS[name]
    text = text_of()
    urdf = read_urdf(text)
    if name == 'ankle':
        closures = closure_robots.ankle().closures
    elif name == 'five_bar':
        closures = closure_robots.five_bar().closures
    else:
        closures = read_closures(urdf).closures
    tree = KinematicTree(urdf)
    loops = find_loops(urdf).loops
    planned, transmissions, commands = [], [], []
    groups = list(closure_groups(tree, closures, measured))
    for group in groups:
        found = plan_group(tree, group, [0.0] * len(tree.names))
        assert found.solver is not None, found.problem
        mine = tuple(output for output in outputs if tree.index[output] in group.coordinates)
        transmission = Transmission(tree, group, found.structure, mine, found.assembly.values)
        planned.append(found)
        transmissions.append(transmission)
        commands.append(CommandGroup(tree, transmission, found.assembly.values, loops))
    return Robot(name, text, tuple(closures), {}, measured, outputs, reference, tree, groups,
                 planned, transmissions, commands, RobotCommand(commands, urdf.joints))


def reference_pose(robot: Robot, outputs: Mapping[str, object],
                   guess: Mapping[str, float]) -> dict[str, mpf]:
    """Return every loop joint but the outputs closing every loop (50 digits)."""
    unknown = robot.loop_joints()
    if robot.reference == CLOSURE:
        reference = Reference(robot.urdf, robot.closures, robot.overrides)
        return reference.solve(dict(outputs), {name: guess[name] for name in unknown}, unknown)
    return loop_reference.solve(robot.urdf, dict(outputs), dict(guess))


def reference_velocities(robot: Robot, positions: Mapping[str, object],
                         output_rates: Mapping[str, object]) -> dict[str, mpf]:
    """Return every loop joint's velocity but the outputs' at a closed pose (50 digits)."""
    if robot.reference == CLOSURE:
        reference = Reference(robot.urdf, robot.closures, robot.overrides)
        return reference.velocities(dict(positions), dict(output_rates), robot.loop_joints())
    return loop_reference.velocities(robot.urdf, dict(positions), dict(output_rates))


def reference_ratio(robot: Robot, place: int, positions: Mapping[str, object]) -> mp.matrix:
    """Return M = ∂m/∂o of group ``place`` at a closed pose, from the reference's velocities."""
    transmission = robot.transmissions[place]
    columns = []
    for output in transmission.outputs:
        rates = {name: (1 if name == output else 0) for name in robot.outputs}
        velocities = reference_velocities(robot, positions, rates)
        columns.append([velocities[name] for name in transmission.actuators])
    return mp.matrix([[column[i] for column in columns]
                      for i in range(len(transmission.actuators))])


def relative(found: Sequence[float], exact: Sequence[object]) -> float:
    """Return max |found − exact| ÷ max |exact| (normwise relative; 0 for an exact 0)."""
    size = max(abs(float(x)) for x in exact)
    error = max(abs(float(mpf(x) - mpf(y))) for x, y in zip(found, exact))
    return error / size if size else error
