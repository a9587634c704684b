# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
urdf/biped.urdf: a biped's lower body, two four-bar knees and two parallel ankles, closed.

The file is installed (setup.py's urdf/*.urdf), reads as a URDF with a ``<limit>`` on every
revolute joint, and is safe to give to the node with ``-p robot_description:="$(cat …)"`` (no
comment holds a colon). ``linkage-check-loops`` finds its four closure groups: per leg a planar
one-degree-of-freedom knee known from its motor and a two-degree-of-freedom ankle of two balls
known from its two motors. Every answer of the follower, over a motion through the joints'
ranges, closes every loop by urchin's forward kinematics (not the package's): each knee's pin
and each ankle's ball within 1e-15 m, the pins' axes parallel. The follower's lists reach the
solver as the same floats as the joints by name (``LoopSolver.solve``), bit for bit.
"""

from __future__ import annotations

import contextlib
from glob import glob
import io
import math
from pathlib import Path
import re
import tempfile

from linkage_kinematics.cli import check_loops
from linkage_kinematics.loops.follower import LoopSample, RobotLoopsFollower
from linkage_kinematics.loops.intake import joint_velocity
from linkage_kinematics.loops.plan import read_loops
from linkage_kinematics.loops.solver import LoopSolver
from linkage_kinematics.loops.structure import GroupKind
from linkage_kinematics.model.urdf_reader import JointType, read_urdf
import numpy as np
import urchin

REPOSITORY = Path(__file__).resolve().parent.parent
URDF = REPOSITORY / 'urdf' / 'biped.urdf'
SIDES = ('left', 'right')
HIPS = tuple(f'{side}_hip_{axis}' for side in SIDES for axis in ('yaw', 'roll', 'pitch'))
MOTORS = tuple(f'{side}_{motor}' for side in SIDES
               for motor in ('knee_motor', 'ankle_motor_lateral', 'ankle_motor_medial'))
TOLERANCE = 1e-15  # m, and the sine of the angle between a pin's two axes
SAMPLES = 120


def test_the_urdf_is_installed_readable_limited_and_safe_to_pass_with_p() -> None:
    assert "glob('urdf/*.urdf')" in (REPOSITORY / 'setup.py').read_text(encoding='utf-8')
    assert str(URDF.relative_to(REPOSITORY)) in glob('urdf/*.urdf', root_dir=REPOSITORY)
    text = URDF.read_text(encoding='utf-8')
    tree = read_urdf(text)
    assert tree.name == 'biped' and tree.parser_messages == ()
    comments = re.findall(r'<!--(.*?)-->', text, re.DOTALL)
    assert comments and not any(':' in comment or '#' in comment for comment in comments)
    bounded = [joint for joint in tree.joints.values()
               if joint.joint_type in (JointType.REVOLUTE, JointType.PRISMATIC)]
    assert len(bounded) == 2 * 10 and all(joint.limit is not None for joint in bounded)
    assert [(c.get('name'), c.get('type')) for c in tree.element.findall('constraint')] == [
        (f'{side}_{name}', kind) for side in SIDES
        for name, kind in (('knee_rod_pin', 'revolute'), ('ankle_ball_lateral', 'spherical'),
                           ('ankle_ball_medial', 'spherical'))]


def test_the_checker_finds_two_planar_knees_and_two_ankles_known_from_the_motors() -> None:
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        assert check_loops.main([str(URDF), '--measured', *MOTORS]) == 0
    lines = printed.getvalue().splitlines()
    assert lines[0] == "robot 'biped': 6 loop(s) to close"
    for side in SIDES:
        knee = lines.index(f"constraint '{side}_knee_rod_pin': four-bar")
        assert lines[knee + 1] == (
            f'  joints from the cut pin: {side}_knee_rod (revolute, sign -1), {side}_knee_motor '
            f'(revolute, sign -1), {side}_knee (revolute, sign +1)')
        assert lines[knee + 5] == f'  known (measured): {side}_knee_motor'
        ankle = lines.index(f"group '{side}_ankle_ball_lateral+{side}_ankle_ball_medial': "
                            '2 balls, 2 degree(s) of freedom (0 idle)')
        assert lines[ankle + 4] == (f'  known (measured): {side}_ankle_motor_lateral, '
                                    f'{side}_ankle_motor_medial')
    plan = read_loops(read_urdf(URDF.read_text(encoding='utf-8'))).plan(MOTORS)
    groups = [(group.kind, group.known, group.zero.structure.dof if group.zero else 1)
              for group in plan.groups]
    assert groups == [(GroupKind.PLANAR_LOOPS, (f'{side}_knee_motor',), 1) for side in SIDES] + [
        (GroupKind.NEWTON, (f'{side}_ankle_motor_lateral', f'{side}_ankle_motor_medial'), 2)
        for side in SIDES]
    assert set(plan.passive) == {f'{side}_{joint}' for side in SIDES for joint in (
        'knee_rod', 'knee', 'ankle_pitch', 'ankle_roll', *(
            f'ankle_rod_{place}_{u}' for place in ('lateral', 'medial') for u in ('u1', 'u2')))}
    # drawn assembled: the zero pose closes every loop to rounding
    assert all(loop.loop.closure_residual < 1e-15 for loop in plan.loops)
    assert all(gap.position < 1e-15 for group in plan.general
               for gap in group.zero.assembly.start_gaps)


def motion(count: int) -> list[dict[str, float]]:
    """
    Return the measured joints through their ranges: hips, knees bending, ankles both ways.

    Each joint on its own frequency, so that the samples meet many combinations, the right leg
    half a period behind the left: the knee motors from straight to 1.2 rad (the knees to 1.5
    rad); each ankle's motors turning alike by up to ±0.35 rad (pitch) and apart by up to ±0.2
    rad (roll).
    """
    ranges = {'hip_yaw': (-0.3, 0.3), 'hip_roll': (-0.3, 0.3), 'hip_pitch': (-1.2, 0.4),
              'knee_motor': (-0.05, 1.2), 'ankle_pitch': (-0.35, 0.35),
              'ankle_roll': (-0.2, 0.2)}
    samples = []
    for index in range(count):
        values = {}
        for side, phase in (('left', 0.0), ('right', math.pi)):
            swing = {joint: low + (high - low) * (0.5 + 0.5 * math.sin(
                2.0 * math.pi * index / count * (1 + place) + phase))
                for place, (joint, (low, high)) in enumerate(ranges.items())}
            for joint in ('hip_yaw', 'hip_roll', 'hip_pitch', 'knee_motor'):
                values[f'{side}_{joint}'] = swing[joint]
            values[f'{side}_ankle_motor_lateral'] = swing['ankle_pitch'] + swing['ankle_roll']
            values[f'{side}_ankle_motor_medial'] = swing['ankle_pitch'] - swing['ankle_roll']
        samples.append(values)
    return samples


def urchin_robot(text: str) -> urchin.URDF:
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / 'biped.urdf'
        path.write_text(text, encoding='utf-8')
        return urchin.URDF.load(str(path), lazy_load_meshes=True)


def point(pose: np.ndarray, xyz: tuple[float, float, float]) -> np.ndarray:
    return pose[:3, :3] @ np.array(xyz) + pose[:3, 3]


def test_every_answer_closes_the_loops_by_urchins_forward_kinematics() -> None:
    text = URDF.read_text(encoding='utf-8')
    tree = read_urdf(text)
    follower = RobotLoopsFollower(read_loops(tree), MOTORS, {}, math.pi / 2)
    robot = urchin_robot(text)
    worst = 0.0
    reached: dict[str, float] = {}
    for index, measured in enumerate(motion(SAMPLES)):
        names = [*HIPS, *MOTORS]
        sample = follower.follow((index + 1) * 10_000_000, names,
                                 [measured[name] for name in names], [])
        assert isinstance(sample, LoopSample), sample
        # every joint within its limits (the universal joints' are continuous)
        for name, value in {**measured, **sample.joints}.items():
            limits = tree.joints[name].position_limits
            assert limits is None or limits[0] <= value <= limits[1], (name, value)
        poses = robot.link_fk(cfg={**measured, **sample.joints}, use_names=True)
        for side in SIDES:
            rod, shank = poses[f'{side}_knee_rod'], poses[f'{side}_shank']
            pins = point(rod, (0.008, 0.0, -0.324)), point(shank, (-0.04, 0.0, -0.03))
            worst = max(worst, float(np.linalg.norm(pins[0] - pins[1])),
                        float(np.linalg.norm(np.cross(rod[:3, 1], shank[:3, 1]))))
            for place, y in (('lateral', 0.035), ('medial', -0.035)):
                lateral = y if side == 'left' else -y
                ball = point(poses[f'{side}_ankle_rod_{place}'], (0.0, 0.0, -0.28))
                foot = point(poses[f'{side}_foot'], (-0.065, lateral, 0.02))
                worst = max(worst, float(np.linalg.norm(ball - foot)))
        for joint in ('knee', 'ankle_pitch', 'ankle_roll'):
            reached[joint] = max(reached.get(joint, 0.0),
                                 *(abs(sample.joints[f'{side}_{joint}']) for side in SIDES))
    assert worst <= TOLERANCE
    # the motion bends the knees and tilts the feet as far as it means to
    assert reached['knee'] > 1.4 and reached['ankle_pitch'] > 0.2 and reached['ankle_roll'] > 0.2


def test_the_followers_samples_are_the_solvers_by_name_bit_for_bit() -> None:
    """
    The follower hands the solver the intake's lists: the same floats as by joint name.

    A second solver of the same plan, given each sample's measured joints by name
    (``LoopSolver.solve``), gives the same positions and velocities to the bit: every other
    message carries velocities, the others none (the intake's backward difference).
    """
    follower = RobotLoopsFollower(read_loops(read_urdf(URDF.read_text(encoding='utf-8'))),
                                  MOTORS, {}, math.pi / 2)
    by_name = LoopSolver(follower.plan)
    names = [*HIPS, *MOTORS]
    last = None
    for index, measured in enumerate(motion(SAMPLES)):
        stamp_ns = (index + 1) * 10_000_000
        positions = [measured[name] for name in names]
        given = [0.01 * index - 0.1 * place for place in range(len(names))]
        sample = follower.follow(stamp_ns, names, positions, given if index % 2 else [])
        assert isinstance(sample, LoopSample)
        rates = {name: joint_velocity(
            stamp_ns, measured[name], given[names.index(name)] if index % 2 else None,
            None if last is None else (last[0], last[1][name]))[0] for name in MOTORS}
        last = stamp_ns, measured
        solved, solved_rates = by_name.solve({name: measured[name] for name in MOTORS}, rates)
        assert sample.names == tuple(solved)
        assert [value.hex() for value in sample.positions] == [
            value.hex() for value in solved.values()]
        assert [value.hex() for value in sample.velocities] == [
            value.hex() for value in solved_rates.values()]
        assert list(sample.joints.items()) == [*((name, measured[name]) for name in MOTORS),
                                               *solved.items()]
