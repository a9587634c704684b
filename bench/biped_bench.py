# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Section "biped": issue 29's cost goal, a biped's loops closed at 1 kHz against the hand relay.

The robot is urdf/biped.urdf: per leg three hip joints outside the loops, a knee driven through
a planar four-bar from its motor and a parallel pitch–roll ankle on two motors; twelve measured
joints, four closure groups (two planar one-degree-of-freedom knees, two two-degree-of-freedom
ankles of two balls each). The encoder walks it (``motion``: each joint swinging at 0.5 Hz over
a walk's range, the right leg half a period behind the left, velocities included). Two parts:

* ``path_run``: the node's per-sample path in this process, part by part, in µs per sample over
  one period of that motion: the input's bytes read, the intake, each closure group, the
  follower in all, the joint_states bytes, the whole robot's /tf, the three messages handed to
  the bag writer, and all of it as the node's callback does it (without rclpy); beside them
  the hand relay's callback (rclpy's deserialisation, its message, rclpy's serialisation), the
  yardstick's own Python work. With valgrind on the machine, the same parts' instructions per
  sample (callgrind, counted inside each part only), which do not depend on the machine's
  load.
* ``run``: the measured section's side-by-side run (``measured_bench.follow_side_by_side``):
  ``linkage_node`` (``source:=measured``, ``loops:=robot_description``, the URDF as its
  ``robot_description`` parameter, logging on) and ``minimal_relay.py`` follow the encoder at
  once; CPU of each (the node's with its bag writer's), latency p50 and p99 from the encoder's
  stamp to a third process, samples lost by the listener and, from the node's own bag, by the
  node; then the goals of issue 29 item 9.

Other benchmarks (a command relay's) take the robot from here: ``URDF``, ``MEASURED`` (the
loops' motors, ``loops.measured_joints``), ``motion`` (the encoder's joints and ranges) and
``parameters`` (the node's).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
import functools
import math
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile
import time

from encoder import joint_names, sample, SWING_HZ, swings
from linkage_kinematics.bag.recorder import Recorder
from linkage_kinematics.loops.follower import LoopSample, RobotLoopsFollower
from linkage_kinematics.loops.intake import DropReason, Intake
from linkage_kinematics.loops.plan import LoopPlan, read_loops
from linkage_kinematics.loops.solver import GroupStep, LoopSolver
from linkage_kinematics.model.urdf_reader import read_urdf, ROTATING_TYPES
from linkage_kinematics.ros.loop_source import TreePositions
from linkage_kinematics.ros.messages import JointStateEncoder, RobotStateTransforms, TFMessage
from linkage_kinematics.ros.outputs import DATA_QOS, MEASURED_QOS, TF_QOS
from linkage_kinematics.run.diagnostics import RateMeter
from linkage_kinematics.run.loop_diagnostics import LoopsHealth
from linkage_kinematics.shared.cdr import JointStateDecoder
from loops_bench import input_bytes
import measured_bench
from minimal_relay import relayed
from rclpy.serialization import deserialize_message, serialize_message
from sensor_msgs.msg import JointState
from timing import interleaved_medians, markdown_table
import yaml

ROOT = pathlib.Path(__file__).resolve().parent.parent
URDF = ROOT / 'urdf' / 'biped.urdf'
SIDES = ('left', 'right')
# A walk's swing of each joint of a leg (rad): the hips a little in yaw and roll, more in pitch;
# the knee motor from nearly straight to about 1.1 rad of knee; the ankle motors ±0.35 rad, 30°
# apart in phase (the encoder's), so that the foot pitches by up to about 0.25 rad and rolls by
# up to about 0.12 rad. Every joint, measured and solved, stays within its URDF limits.
LEG = {'hip_yaw': (-0.1, 0.1), 'hip_roll': (-0.1, 0.1), 'hip_pitch': (-0.6, 0.3),
       'knee_motor': (0.05, 0.9), 'ankle_motor_lateral': (-0.35, 0.35),
       'ankle_motor_medial': (-0.35, 0.35)}
MEASURED = tuple(f'{side}_{joint}' for side in SIDES
                 for joint in ('knee_motor', 'ankle_motor_lateral', 'ankle_motor_medial'))
RATE_HZ = measured_bench.RATE_HZ
PERIOD_NS = round(1e9 / RATE_HZ)
STAMP_NS = 1_790_000_000_000_000_000
# One period of the walk at 1 kHz: the motion ends where it starts, so that a follower goes on
# from one run of the samples to the next as from one step to the next (no restart, whose
# assembly of each ankle at the first sample costs tens of milliseconds).
SAMPLES = round(RATE_HZ / SWING_HZ)


def motion() -> dict[str, tuple[float, float]]:
    """Return the encoder's joints and their ranges, the left leg's then the right leg's."""
    return {f'{side}_{joint}': swing for side in SIDES for joint, swing in LEG.items()}


def parameters(urdf: str) -> dict[str, object]:
    """Return the node's parameters for the biped described by ``urdf``."""
    return {'loops': 'robot_description', 'loops.measured_joints': list(MEASURED),
            'robot_description': urdf}


Message = tuple[int, list[str], list[float], list[float]]


def messages() -> list[Message]:
    """Return one period of the encoder's messages, as its ``sample`` makes them, 1 ms apart."""
    ranges = motion()
    added, names = swings(ranges), joint_names(ranges)
    return [(STAMP_NS + index * PERIOD_NS, names, *sample(added, index / RATE_HZ))
            for index in range(SAMPLES)]


def planar_only(plan: LoopPlan, group_index: int) -> LoopPlan:
    """Return ``plan`` with its planar group ``group_index`` alone: one knee's solver."""
    group = plan.groups[group_index]
    return replace(plan, loops=group.loops, groups=(group,))


class PerSamplePath:
    """
    The node's per-sample path on the biped, each part a workload over one period of the walk.

    Each workload returns how many samples it did. The followers are never restarted: each run
    goes on from the last (its stamps a period later), as the node follows a long walk.
    """

    def __init__(self, folder: pathlib.Path) -> None:
        urdf = URDF.read_text(encoding='utf-8')
        tree = read_urdf(urdf)
        self.follower = RobotLoopsFollower(read_loops(tree), MEASURED, {}, math.pi / 2)
        plan = self.follower.plan
        self.plan = plan
        self.inputs = messages()
        self.received = [input_bytes(message) for message in self.inputs]
        self.decoder = JointStateDecoder()
        self.fields = [self.decoder.decode(data) for data in self.received]
        # the follower's samples of the period, after a first period to assemble the ankles
        for stamp_ns, names, positions, velocities, _ in self.fields:
            self.follower.follow(stamp_ns, names, positions, velocities)
        self.runs = 1
        self.samples = [self._follow(fields) for fields in self.fields]
        self.runs = 2
        self.intake = Intake(plan.measured, [name for name in plan.measured
                                             if tree.joints[name].joint_type in ROTATING_TYPES],
                             math.pi / 2, DropReason.NO_JOINT)
        self.measured_values = [[sample.joints[name] for name in plan.measured]
                                for sample in self.samples]
        self.measured_rates = [[velocities[names.index(name)] for name in plan.measured]
                               for _, names, _, velocities, _ in self.fields]
        full = LoopSolver(plan)
        self.knees = {plan.groups[index].name: LoopSolver(planar_only(plan, index))
                      for index, group in enumerate(plan.groups) if group.zero is None}
        self.ankles = {step.plan.name: step for step in full.groups}
        for step in self.ankles.values():  # assembled at the period's last sample
            step.solve(self.measured_values[-1], self.measured_rates[-1])
        self.encoder = JointStateEncoder(self.samples[0].names)
        self.transforms = RobotStateTransforms(tree, '')
        self.tree = TreePositions(self.transforms.driven_joints, self.follower.loop_joints, {})
        self.health = LoopsHealth(0)
        self.rate = RateMeter()
        self.recorder = Recorder(folder, metadata={}, topics=[
            ('/biped/measured_joint_states', JointState, MEASURED_QOS, None),
            ('/biped/joint_states', JointState, DATA_QOS, None),
            ('/tf', TFMessage, TF_QOS, None)])
        self.outputs = [self.encoder.encode(s.stamp_ns, s.positions, s.velocities)
                        for s in self.samples]
        self.tfs = [self._tf(fields, s) for fields, s in zip(self.fields, self.samples)]

    def close(self) -> None:
        """Finish the bag the bag part wrote."""
        self.recorder.close()

    def _follow(self, fields: tuple) -> LoopSample:
        stamp_ns, names, positions, velocities, _ = fields
        followed = self.follower.follow(stamp_ns + self.runs * SAMPLES * PERIOD_NS, names,
                                        positions, velocities)
        if not isinstance(followed, LoopSample):
            raise RuntimeError(f'the biped refused a sample of its walk: {followed}')
        return followed

    def _tf(self, fields: tuple, followed: LoopSample) -> bytes:
        self.tree.note_input(fields[1], fields[2])
        return self.transforms.tree_message(self.tree.at_sample(followed.joints),
                                            followed.stamp_ns)

    def workloads(self) -> dict[str, Callable[[], int]]:
        """Return the parts' workloads, by the row each is reported in."""
        count = len(self.inputs)

        def decode() -> int:
            for data in self.received:
                self.decoder.decode(data)
            return count

        def intake() -> int:
            offset = self.runs * SAMPLES * PERIOD_NS
            self.runs += 1
            take, keep = self.intake.take, self.intake.keep
            for stamp_ns, names, positions, velocities, _ in self.fields:
                taken = take(stamp_ns + offset, names, positions, velocities)
                keep(stamp_ns + offset, taken[1])
            return count

        def planar(solver: LoopSolver) -> Callable[[], int]:
            measured = solver.plan.measured

            def run() -> int:
                for values, rates in zip(self.measured_values, self.measured_rates):
                    solver.solve(dict(zip(measured, values)), dict(zip(measured, rates)))
                return count
            return run

        def newton(step: GroupStep) -> Callable[[], int]:
            def run() -> int:
                for values, rates in zip(self.measured_values, self.measured_rates):
                    step.solve(values, rates)
                return count
            return run

        def follow() -> int:
            for fields in self.fields:
                self._follow(fields)
            self.runs += 1
            return count

        def encode() -> int:
            for followed in self.samples:
                self.encoder.encode(followed.stamp_ns, followed.positions, followed.velocities)
            return count

        def tf() -> int:
            for fields, followed in zip(self.fields, self.samples):
                self._tf(fields, followed)
            return count

        def record() -> int:
            record = self.recorder.record
            for data, output, transforms, (stamp_ns, *_) in zip(
                    self.received, self.outputs, self.tfs, self.fields):
                record('/biped/measured_joint_states', data, stamp_ns)
                record('/biped/joint_states', output, stamp_ns)
                record('/tf', transforms, stamp_ns)
            return count

        def node_callback() -> int:
            # RobotLoopsSubscription._on_message's work on a followed sample, without rclpy's
            # take and publish
            offset = self.runs * SAMPLES * PERIOD_NS
            self.runs += 1
            record = self.recorder.record
            for data in self.received:
                stamp_ns, names, positions, velocities, _ = self.decoder.decode(data)
                stamp_ns += offset
                followed = self.follower.follow(stamp_ns, names, positions, velocities)
                record('/biped/measured_joint_states', data, stamp_ns)
                self.tree.note_input(names, positions)
                self.health.accept(stamp_ns, followed)
                self.rate.tick()
                record('/biped/joint_states', self.encoder.encode(
                    stamp_ns, followed.positions, followed.velocities), stamp_ns)
                record('/tf', self.transforms.tree_message(self.tree.at_sample(followed.joints),
                                                           stamp_ns), stamp_ns)
            return count

        parts: dict[str, Callable[[], int]] = {
            'input bytes → stamp, names, positions, velocities (JointStateDecoder)': decode,
            'intake: the six motors found, checked, unwrapped (Intake.take, keep)': intake}
        for name, solver in self.knees.items():
            parts[f'knee {name}: planar four-bar in closed form (LoopSolver)'] = planar(solver)
        for name, step in self.ankles.items():
            parts[f'ankle {name}: Newton (GroupStep.solve)'] = newton(step)
        parts.update({
            'RobotLoopsFollower.follow (intake, the four groups, the sample)': follow,
            'joint_states bytes (JointStateEncoder)': encode,
            '/tf of the whole robot (TreePositions, tree_message)': tf,
            'bag: input, joint_states and /tf handed to the writer (Recorder.record ×3)': record,
            "all of it, as the node's callback (without rclpy's take and publish)":
                node_callback,
            "the hand relay's callback with rclpy's deserialisation and serialisation":
                lambda: hand_relay_callback(self.received),
        })
        return parts


def hand_relay_callback(received: list[bytes]) -> int:
    """
    Run minimal_relay.py's callback on each of ``received``; return how many.

    With rclpy's deserialisation before it (the take) and its serialisation after it (the
    publish).
    """
    for data in received:
        serialize_message(relayed(deserialize_message(data, JointState)))
    return len(received)


def instructions() -> dict[str, float] | None:
    """
    Return each part's instructions per sample (callgrind), None without valgrind.

    valgrind runs this module (``--count``) collecting only inside ``functools.reduce``, which
    nothing on the path calls but each part's one counted run goes through, and dumping the
    count after each such call: the dumps' counts in the parts' order.
    """
    valgrind = shutil.which('valgrind')
    if valgrind is None:
        return None
    with tempfile.TemporaryDirectory(prefix='linkage_bench_biped_') as folder:
        out = pathlib.Path(folder) / 'callgrind.out'
        environment = dict(os.environ, PYTHONPATH=os.pathsep.join(
            [str(ROOT), str(ROOT / 'test'), os.environ.get('PYTHONPATH', '')]))
        completed = subprocess.run(
            [valgrind, '--tool=callgrind', f'--callgrind-out-file={out}',
             '--collect-atstart=no', '--toggle-collect=functools_reduce',
             '--dump-after=functools_reduce', sys.executable, __file__, '--count', folder],
            capture_output=True, text=True, check=False, cwd=ROOT, env=environment)
        if completed.returncode != 0:
            raise RuntimeError(f'callgrind failed: {completed.stderr[-2000:]}')
        names = (pathlib.Path(folder) / 'parts.txt').read_text(encoding='utf-8').splitlines()
        dumps = sorted(pathlib.Path(folder).glob('callgrind.out.*'),
                       key=lambda path: int(path.name.rsplit('.', 1)[1]))
        if len(dumps) != len(names):
            raise RuntimeError(f'callgrind dumped {len(dumps)} counts for {len(names)} parts: '
                               'something else on the path calls functools.reduce')
        counts = [int(next(line for line in dump.read_text(encoding='utf-8').splitlines()
                           if line.startswith('totals:')).split()[1]) for dump in dumps]
    return {name: value / SAMPLES for name, value in zip(names, counts)}


def count(folder: str) -> None:
    """Under callgrind: run each part once inside ``functools.reduce`` (warm: see its init)."""
    path = PerSamplePath(pathlib.Path(folder) / 'bag')
    try:
        workloads = path.workloads()
        for workload in workloads.values():
            functools.reduce(lambda _, run: run(), [workload], 0)
        (pathlib.Path(folder) / 'parts.txt').write_text('\n'.join(workloads), encoding='utf-8')
    finally:
        path.close()


def path_run(quick: bool, repetitions: int) -> str:
    """Return the in-process table: µs per sample of each part, its share, its instructions."""
    with tempfile.TemporaryDirectory(prefix='linkage_bench_biped_') as folder:
        path = PerSamplePath(pathlib.Path(folder) / 'bag')
        try:
            workloads = path.workloads()
            medians = interleaved_medians(workloads, repetitions, time.process_time)
        finally:
            path.close()
    counted = None if quick else instructions()
    whole = medians["all of it, as the node's callback (without rclpy's take and publish)"]
    rows = [[part, f'{1e6 * seconds:.1f} µs', f'{100.0 * seconds / whole:.0f} %',
             '–' if counted is None else f'{counted[part] / 1e3:.0f} k']
            for part, seconds in medians.items()]
    note = ('' if counted is not None else
            '\n\nInstructions not counted (' + ('--quick' if quick else 'no valgrind') + ').')
    return (f'{SAMPLES} samples (one period of the walk) per run, CPU time per sample, medians '
            f'of {repetitions} interleaved runs\n\n'
            + markdown_table(['part of the per-sample path', 'CPU per sample', 'of all of it',
                              'instructions per sample (callgrind)'], rows) + note)


def run(quick: bool, ros_domain: int) -> str:
    """Return the side-by-side run as markdown (domain ``ros_domain`` + 4)."""
    seconds = 10.0 if quick else 30.0
    urdf = URDF.read_text(encoding='utf-8')
    loops = read_loops(read_urdf(urdf))
    node = ('linkage_node (biped, 4 closure groups, logging)', '/biped',
            ['--params-file', '{folder}/biped.yaml'])
    figures = measured_bench.follow_side_by_side(
        node, seconds, ros_domain + 4, motion(),
        {'biped.yaml': yaml.safe_dump({'/**': {'ros__parameters': parameters(urdf)}})},
        frozenset(loops.plan(MEASURED).passive))
    return (f'encoder at {RATE_HZ:g} Hz for {seconds:g} s walking the biped '
            f'({len(MEASURED)} loop motors and {len(motion()) - len(MEASURED)} hip joints '
            f'measured, {len(motion()) + 2} joints in each message), the node and the relay '
            'following it at once, latency to a third process\n\n'
            + measured_bench.report(figures))


if __name__ == '__main__':
    if sys.argv[1:2] == ['--count']:
        count(sys.argv[2])
