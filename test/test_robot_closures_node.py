# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
linkage_node closing models others wrote, and the package's humanoid ankle and biped, over DDS.

A real node (``loops:=robot_description``) is fed measured joints from this process; every
``joint_states`` it publishes must close the model's loops by the URDF's own forward kinematics,
urchin's, not the package's: each closure's two frames put where urchin puts their links, their
origins within 1e-12 m (and a weld's frames within 1e-12 rad). The models come in each of the
three encodings: the ankle's ``<constraint>`` balls (and the biped's, with its knees' pins),
Gepetto/example-parallel-robots' closure files, and the same closures written as
``<constraint>`` or ``<loop_joint>`` elements (test/example_parallel_robots.py). Battobot's
closure file reads eight of its joints as universal and spherical joints, whose coordinates the
node solves but does not publish (they are no URDF joints, so urchin cannot pose them): its
answers are closed by the 50-digit reference's kinematics instead (test/closure_reference.py),
which solves those coordinates itself with every published joint held. The samples start at
the model's assembly the package takes at the zero pose (a closed pose: the measured joints
there) and move every measured joint by up to a hundredth of a radian (or metre).
"""

from __future__ import annotations

from collections.abc import Sequence
import math
from pathlib import Path
import re
import tempfile
from typing import Any
import xml.etree.ElementTree as ElementTree

from closure_reference import Reference
import example_parallel_robots as models
from linkage_kinematics.loops.plan import find_loops, LoopPlan
from linkage_kinematics.loops.solver import LoopSolver
from linkage_kinematics.model.urdf_reader import read_urdf
from mpmath import mp, mpf
from node_process import ros_context, stamp_ns
import numpy as np
import pytest
from rosbags.rosbag2 import Reader
from rosbags.typesys import get_typestore, Stores
from test_robot_loops import loop_node, LoopNode, matrix, values
import urchin
import yaml

REPOSITORY = Path(__file__).resolve().parent.parent
ANKLE = REPOSITORY / 'urdf' / 'humanoid_ankle.urdf'
BIPED = REPOSITORY / 'urdf' / 'biped.urdf'
TOLERANCE = 1e-12
TYPESTORE = get_typestore(Stores.ROS2_JAZZY)
START_NS = 1_000_000_000
PERIOD_NS = 10_000_000
SAMPLES = 6
AMPLITUDE = 0.01  # rad or m, about the zero-pose assembly
# of the estimated distance to the nearest singular configuration there, at most: WL16's
# assembly at the zero pose is 0.01 rad from one
REACH = 0.3
RATE = 0.2  # each measured joint's velocity in the input (rad/s or m/s)


@pytest.fixture(scope='module')
def context(domain_id):
    with ros_context(domain_id) as ros:
        yield ros


def model(name: str, encoding: str) -> tuple[str, str | None, list[str]]:
    """
    Return a model's URDF and closure file in ``encoding``, and its measured joints.

    With the closure file the node measures its actuated joints (``name_mot``); with the
    closures written as elements, the same joints are given as ``loops.measured_joints``.
    """
    if name == 'humanoid_ankle':
        return ANKLE.read_text(encoding='utf-8'), None, ['motor_left', 'motor_right']
    if name == 'biped':  # its motors; the hips, outside the loops, stay at 0
        return BIPED.read_text(encoding='utf-8'), None, [
            f'{side}_{motor}' for side in ('left', 'right')
            for motor in ('knee_motor', 'ankle_motor_lateral', 'ankle_motor_medial')]
    if encoding == 'closure file':
        return models.urdf(name), models.closure_file(name), []
    urdf = (models.with_constraints(name) if encoding == '<constraint>'
            else models.with_loop_joints(name))
    return urdf, None, list(models.closure_file_content(name)['name_mot'])


def planned(urdf: str, closures: str | None, measured: list[str]) -> LoopPlan:
    """Return the package's plan, from which the samples start (the measured joints' values)."""
    loops = find_loops(read_urdf(urdf), closures)
    return loops.plan(measured or loops.actuated)


def samples(plan: LoopPlan) -> list[dict[str, float]]:
    """
    Return the measured joints moving about their values at the zero-pose assembly.

    A measured joint outside every loop (a hip's motor in name_mot) moves about 0. The motion
    keeps well inside the distance to the nearest singular configuration.
    """
    start = dict.fromkeys(plan.measured, 0.0)
    amplitude = AMPLITUDE
    for group in plan.general:
        assembled = dict(zip(plan.tree.names, group.zero.assembly.values))
        start.update({name: assembled[name] for name in group.known})
        solver = group.zero.solver
        solver.solve([assembled[name] for name in group.known], [0.0] * len(group.known))
        amplitude = min(amplitude,
                        REACH * solver.derivatives.singular_distance([0.0] * len(group.known)))
    # the first sample at the assembly itself, then each joint on its own phase
    return [{name: value + amplitude * (math.sin(0.9 * index + 1.3 * place)
                                        - math.sin(1.3 * place))
             for place, (name, value) in enumerate(start.items())}
            for index in range(SAMPLES)]


def block_scalar(text: str) -> str:
    """Return ``text`` as a YAML literal block: how -p hands rcl a text of several lines."""
    return '|\n' + ''.join(f'  {line}\n' for line in text.splitlines())


def run_node(context, nodes, tmp_path: Path, urdf: str, closures: str | None,
             measured: list[str], fed: list[dict[str, float]]) -> tuple[LoopNode, list[int]]:
    """Run a node on the model, feed ``fed``; return it (stopped) and the stamps it answered."""
    arguments = ([] if closures is None
                 else ['-p', f'robot_description_closures:={block_scalar(closures)}'])
    parameters: dict[str, Any] = {'robot_description': urdf}
    if measured:
        parameters['loops.measured_joints'] = measured
    with loop_node(context, nodes, tmp_path, parameters, arguments) as node:
        stamps = []
        for index, measured in enumerate(fed):
            stamp = START_NS + index * PERIOD_NS
            node.send(stamp, list(measured), list(measured.values()), [RATE] * len(measured))
            stamps.append(stamp)
        node.status('robot loops', lambda status: values(status).get(
            'valid samples') == str(len(fed)))
        assert nodes.interrupt(node.process) == 0
        node.listener.drain()
    return node, stamps


def answers(node: LoopNode, fed: list[dict[str, float]],
            stamps: list[int]) -> list[dict[str, float]]:
    """Return each input's measured joints with the joint state published at its stamp."""
    outputs = {stamp_ns(message): dict(zip(message.name, message.position))
               for message in node.outputs}
    assert sorted(outputs) == stamps  # one answer per input, at its stamp
    return [{**measured, **outputs[stamp]} for measured, stamp in zip(fed, stamps)]


def urchin_robot(urdf: str) -> urchin.URDF:
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / 'robot.urdf'
        path.write_text(urdf, encoding='utf-8')
        return urchin.URDF.load(str(path), lazy_load_meshes=True)


def rpy(values: Sequence[float]) -> np.ndarray:
    """Return URDF roll–pitch–yaw as a 4×4 rotation, written here (Rz·Ry·Rx)."""
    roll, pitch, yaw = values
    x = np.array([[1, 0, 0], [0, math.cos(roll), -math.sin(roll)],
                  [0, math.sin(roll), math.cos(roll)]])
    y = np.array([[math.cos(pitch), 0, math.sin(pitch)], [0, 1, 0],
                  [-math.sin(pitch), 0, math.cos(pitch)]])
    z = np.array([[math.cos(yaw), -math.sin(yaw), 0], [math.sin(yaw), math.cos(yaw), 0],
                  [0, 0, 1]])
    matrix = np.eye(4)
    matrix[:3, :3] = z @ y @ x
    return matrix


def side_frames(urdf: str) -> list[tuple[str, str, tuple, tuple]]:
    """
    Return each closure written in the URDF: its kind and two frames (link, xyz, rpy).

    Read here with ElementTree from the <constraint> and <loop_joint> elements.
    """
    closures = []
    for element in ElementTree.fromstring(urdf):
        if element.tag == 'constraint':
            ends = [(element.find(side).get('link'), element.find(f'{side}_origin'))
                    for side in ('parent', 'child')]
            ends = [(link, (origin.get('xyz', '0 0 0'), origin.get('rpy', '0 0 0'))
                     if origin is not None else ('0 0 0', '0 0 0')) for link, origin in ends]
        elif element.tag == 'loop_joint':
            ends = [(element.find(tag).get('link'), (element.find(tag).get('xyz', '0 0 0'),
                                                     element.find(tag).get('rpy', '0 0 0')))
                    for tag in ('link1', 'link2')]
        else:
            continue
        closures.append((element.get('type'), *[
            (link, tuple(map(float, xyz.split())), tuple(map(float, turn.split())))
            for link, (xyz, turn) in ends]))
    return closures


def file_frames(name: str) -> list[tuple[str, tuple, tuple]]:
    """Return each closure of a model's closure file: its kind and two link frames."""
    kinds = {'3d': 'spherical', '6d': 'fixed'}
    return [(kinds[kind], (parent, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)),
             (child, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)))
            for _, kind, parent, child in models.closures(name)]


def worst_gap(urdf: str, closures: list, answered: list[dict[str, float]]) -> float:
    """Return the largest gap (m, or rad for a weld's frames) of any closure, by urchin."""
    robot = urchin_robot(urdf)
    worst = 0.0
    for joints in answered:
        poses = robot.link_fk(cfg=joints, use_names=True)
        for kind, *ends in closures:
            frames = []
            for link, xyz, turn in ends:
                frame = poses[link] @ rpy(turn)
                frame[:3, 3] = poses[link][:3, :3] @ np.array(xyz) + poses[link][:3, 3]
                frames.append(frame)
            worst = max(worst, float(np.linalg.norm(frames[0][:3, 3] - frames[1][:3, 3])))
            if kind == 'fixed':
                turn = frames[0][:3, :3].T @ frames[1][:3, :3]
                worst = max(worst, float(np.max(np.abs(turn - np.eye(3)))))
    return worst


@pytest.mark.parametrize(('name', 'encoding'), [
    ('humanoid_ankle', '<constraint>'),
    ('biped', '<constraint>'),
    ('5bar_linkage', '<loop_joint>'),
    ('cassie_like', 'closure file'),
    ('digit_like', '<constraint>'),
    ('robot_delta', 'closure file'),
    ('wl16_like', '<loop_joint>'),
])
def test_every_answer_closes_the_loops_by_urchins_forward_kinematics(
        context, nodes, tmp_path, name, encoding):
    urdf, closures, measured = model(name, encoding)
    plan = planned(urdf, closures, measured)
    fed = samples(plan)
    node, stamps = run_node(context, nodes, tmp_path, urdf, closures, measured, fed)
    answered = answers(node, fed, stamps)
    assert set(answered[0]) == set(plan.measured) | set(plan.passive)
    frames = file_frames(name) if encoding == 'closure file' else side_frames(urdf)
    assert worst_gap(urdf, frames, answered) < TOLERANCE
    (bag,) = (tmp_path / 'bags').iterdir()
    assert_tf_poses_the_whole_robot(bag, urdf, answered)
    recorded = recorded_texts(bag)
    # -p folds the URDF's line breaks into spaces (a YAML single-quoted scalar); a literal
    # block keeps the closure file's
    assert [' '.join(text.split()) for text in recorded['/robot_description']] == [
        ' '.join(urdf.split())]
    assert recorded.get('/robot_description_closures', [None]) == [closures]


def assert_tf_poses_the_whole_robot(bag: Path, urdf: str, answered: list[dict[str, float]]
                                    ) -> None:
    """One /tf per answer; /tf_static and the last /tf put every link where urchin does."""
    static, tf = [], []
    with Reader(bag) as reader:
        for connection, _, raw in reader.messages():
            if connection.topic in ('/tf', '/tf_static'):
                message = TYPESTORE.deserialize_cdr(raw, connection.msgtype)
                (tf if connection.topic == '/tf' else static).append(message)
    assert len(tf) == len(answered) and len(static) == 1
    transforms = {item.child_frame_id: item
                  for item in static[0].transforms + tf[-1].transforms}
    poses: dict[str, np.ndarray] = {}

    def pose(link: str) -> np.ndarray:
        if link not in transforms:
            return np.eye(4)  # the root
        if link not in poses:
            item = transforms[link]
            poses[link] = pose(item.header.frame_id) @ matrix(item.transform)
        return poses[link]

    expected = urchin_robot(urdf).link_fk(cfg=answered[-1], use_names=True)
    assert max(float(np.max(np.abs(pose(link) - world))) for link, world in expected.items()
               ) < TOLERANCE


def recorded_texts(bag: Path) -> dict[str, list[str]]:
    """Return the texts the bag holds on its latched String topics."""
    texts: dict[str, list[str]] = {}
    with Reader(bag) as reader:
        for connection, _, raw in reader.messages():
            if connection.msgtype == 'std_msgs/msg/String':
                texts.setdefault(connection.topic, []).append(
                    TYPESTORE.deserialize_cdr(raw, connection.msgtype).data)
    return texts


def test_battobots_answers_close_its_loops_by_the_references_kinematics(
        context, nodes, tmp_path):
    """
    Its overridden joints' coordinates are solved, not published; the published joints close.

    For each answer and each group, the reference solves the overridden coordinates at 50
    digits (Gauss–Newton from the package's own values, which only start it) with every
    measured and published joint held: the residual left is what the published joints leave.
    """
    name = 'battobot_6d'
    urdf, closures, _ = model(name, 'closure file')
    loops = find_loops(read_urdf(urdf), closures)
    plan = loops.plan(loops.actuated)
    hidden = [coordinate for group in plan.general for coordinate in group.hidden]
    assert hidden and not set(hidden) & set(plan.passive)
    fed = samples(plan)
    node, stamps = run_node(context, nodes, tmp_path, urdf, closures, [], fed)
    answered = answers(node, fed, stamps)
    assert not set(hidden) & set(answered[0])
    # the package's own values of the hidden coordinates, at the same samples: starts only
    solver = LoopSolver(plan)
    overrides = {joint: override.value for joint, override in loops.overrides.items()}
    worst = mpf(0)
    for joints in answered:
        solver.solve({name: joints[name] for name in plan.measured},
                     dict.fromkeys(plan.measured, 0.0))
        for step in solver.groups:
            reference = Reference(urdf, step.plan.group.closures, overrides)
            unknown = list(step.plan.hidden)
            start = dict(zip(step.plan.solved, step.state.positions))
            worst = max(worst, closed_residual(reference, joints, unknown,
                                               {name: start[name] for name in unknown}))
    assert worst < TOLERANCE


def closed_residual(reference: Reference, known: dict[str, float], unknown: list[str],
                    start: dict[str, float]) -> Any:
    """Return the reference's residual after Gauss–Newton on ``unknown``, ``known`` held."""
    with mp.workdps(50):
        values: dict[str, Any] = {name: mpf(value) for name, value in known.items()}
        values |= {name: mpf(value) for name, value in start.items()}
        for _ in range(3):
            rows = mp.matrix(reference.residual(values))
            jacobian = reference.jacobian(values, unknown)
            step = mp.lu_solve(jacobian.T * jacobian, jacobian.T * rows)
            for index, name in enumerate(unknown):
                values[name] -= step[index]
        return max(abs(row) for row in reference.residual(values))


def documented_ankle_sample() -> tuple[dict[str, float], dict[str, float], dict, dict]:
    """
    Return the humanoid ankle's sample in docs/following_loops.md and the echo it shows.

    The motors' positions and velocities of its ``ros2 topic pub``, and the names, positions
    and velocities of the ``text`` block after it.
    """
    text = (REPOSITORY / 'docs' / 'following_loops.md').read_text(encoding='utf-8')
    start = text.index('### The humanoid ankle from its URDF')
    section = text[start:text.index('\n## ', start)]
    published = re.search(r'"\{name: \[(.*?)\], position: \[(.*?)\], velocity: \[(.*?)\]\}"',
                          section)
    names = [name.strip() for name in published.group(1).split(',')]
    positions = [float(value) for value in published.group(2).split(',')]
    velocities = [float(value) for value in published.group(3).split(',')]
    echo = yaml.safe_load(re.search(r'```text\n(.*?)```', section, re.DOTALL).group(1))
    return (dict(zip(names, positions)), dict(zip(names, velocities)),
            dict(zip(echo['name'], echo['position'])), dict(zip(echo['name'], echo['velocity'])))


def test_the_documented_ankle_sample_is_what_the_node_publishes(context, nodes, tmp_path):
    """The motors of the document's ros2 topic pub in, its echo's pitch, roll and rods out."""
    measured, rates, positions, velocities = documented_ankle_sample()
    assert list(positions)[:2] == ['ankle_pitch', 'ankle_roll']
    parameters = {'robot_description': ANKLE.read_text(encoding='utf-8'),
                  'loops.measured_joints': list(measured), 'log.enabled': False}
    with loop_node(context, nodes, tmp_path, parameters) as node:
        node.send(START_NS, list(measured), list(measured.values()), list(rates.values()))
        assert nodes.interrupt(node.process) == 0
        node.listener.drain()
    (message,) = node.outputs
    assert list(message.name) == list(positions)
    assert list(message.position) == pytest.approx(list(positions.values()), abs=TOLERANCE)
    assert list(message.velocity) == pytest.approx(list(velocities.values()), abs=TOLERANCE)
