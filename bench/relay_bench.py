# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Section "relay": linkage_command_node relaying a biped's commands, against a hand relay.

The robot is biped_bench's (urdf/biped.urdf: per leg three hip joints, a knee driven through
a planar four-bar from its motor and the parallel pitch–roll ankle on two motors: four closure
groups, its loop motors the loops' measured joints as there); the commands name per leg the
hips (passed through), the knee and the ankle's pitch and roll, twelve joints.

``path_run`` times the relay's work per message in this process, bytes in to bytes out as the
node does it: one forward command (``decode_float64_array``, ``Relay.forward``, the
``FixedShapeEncoder``) beside the hand relay's callback with rclpy's deserialisation and
serialisation (the yardstick's own Python work), and a 1000-point trajectory at 100 Hz
(``decode_joint_trajectory``, ``Relay.trajectory``, ``encode_joint_trajectory``), with
positions, velocities and accelerations as a planner sends them and with positions alone,
against issue 30's goal: the whole trajectory in less time than its first point's
time_from_start (10 ms).

``run`` is the side-by-side run: ``commander.py`` publishes the commands at 1 kHz;
``linkage_command_node`` (the URDF as its parameter, logging on, its ``~/commands`` remapped to
the commander's topic) and ``minimal_command_relay.py`` (what a lab writes by hand: each value
times a constant ratio, rclpy's default executor) both relay them; ``command_listener.py``, a
third process, receives both outputs. CPU is utime + stime over the listener's window (the
node's with its bag writer's), latency the listener's receipt time minus the commander's time
just before it published, a command lost when it was published within the window and its
answer never arrived; the node's bag says which of those it received and relayed.
"""

from __future__ import annotations

import json
import math
import pathlib
import signal
import subprocess
import sys
import tempfile
import time

import biped_bench
from commander import NUMBER
from cost_bench import cpu_seconds
from linkage_kinematics.bag.reader import iter_messages
from linkage_kinematics.loops.command import JointPoint
from linkage_kinematics.run.configuration import build_relay_configuration
from linkage_kinematics.run.parameter_specs import relay_parameter_specs
from linkage_kinematics.run.relay import read_relay, Relay
from linkage_kinematics.shared.cdr import encode_cdr, FixedShapeEncoder
from linkage_kinematics.shared.command_cdr import (
    decode_float64_array,
    decode_joint_trajectory,
    encode_joint_trajectory,
    TrajectoryPoint,
)
from measured_bench import percentile
import node_bench
from rclpy.serialization import deserialize_message, serialize_message
from std_msgs.msg import Float64MultiArray
from timing import markdown_table

HERE = pathlib.Path(__file__).resolve().parent
RATE_HZ = 1000.0
# per leg: the joint of the commands, its range (rad) and the minimal relay's constant ratio
# (1 for a joint passed through; the loops' at the zero pose, roughly)
JOINTS = {'hip_yaw': ((-0.3, 0.3), 1.0), 'hip_roll': ((-0.3, 0.3), 1.0),
          'hip_pitch': ((-0.3, 0.3), 1.0), 'knee': ((0.2, 1.3), 0.85),
          'ankle_pitch': ((-0.3, 0.3), 1.9), 'ankle_roll': ((-0.2, 0.2), 1.3)}
OUTPUTS = ('knee', 'ankle_pitch', 'ankle_roll')
TRAJECTORY_POINTS = 1000
TRAJECTORY_PERIOD_NS = 10_000_000  # 100 Hz: the first point at 10 ms
RELAY = 'minimal rclpy relay'
NODE = 'linkage_command_node (biped, logging)'
INPUT_TOPIC = '/planner/commands'
EDGE_S = 0.5  # commands this close to the window's edges may fall outside it


def parameters() -> dict[str, object]:
    """Return the relay's parameters for the biped (its description given as one)."""
    return {
        'robot_description': biped_bench.URDF.read_text(encoding='utf-8'),
        'loops.measured_joints': list(biped_bench.MEASURED),
        'loops.output_joints': [f'{side}_{joint}' for side in biped_bench.SIDES
                                for joint in OUTPUTS],
        'commands.joints': [f'{side}_{joint}' for side in biped_bench.SIDES for joint in JOINTS],
    }


def relay_for_biped() -> Relay:
    """Return the relay (``run.relay.Relay``) of the biped with the bench's parameters."""
    values = {spec.name: spec.default for spec in relay_parameter_specs()}
    values.update(parameters())
    return read_relay(values['robot_description'], build_relay_configuration(values))


def _swing(fraction: float, place: int) -> tuple[float, float, float]:
    """
    Return a command joint's value, rate and acceleration ``fraction`` into a 10 s swing.

    Each joint over its range in its own phase (rad, rad/s, rad/s²).
    """
    (low, high), _ = JOINTS[list(JOINTS)[place % len(JOINTS)]]
    centre, amplitude = (low + high) / 2.0, (high - low) / 2.0
    turn = 2.0 * math.pi / (TRAJECTORY_POINTS * TRAJECTORY_PERIOD_NS * 1e-9)
    angle = 2.0 * math.pi * fraction + place
    return (centre + amplitude * math.sin(angle), amplitude * turn * math.cos(angle),
            -amplitude * turn * turn * math.sin(angle))


def trajectory_points(velocities: bool, accelerations: bool
                      ) -> tuple[list[str], list[TrajectoryPoint]]:
    """Return a 1000-point trajectory at 100 Hz over one swing of every joint: names, points."""
    count = len(JOINTS) * len(biped_bench.SIDES)
    points = []
    for index in range(TRAJECTORY_POINTS):
        motion = [_swing((index + 1) / TRAJECTORY_POINTS, place) for place in range(count)]
        sec, nanosec = divmod((index + 1) * TRAJECTORY_PERIOD_NS, 1_000_000_000)
        points.append(TrajectoryPoint(
            tuple(value for value, _, _ in motion),
            tuple(rate for _, rate, _ in motion) if velocities else (),
            tuple(change for _, _, change in motion) if accelerations else (), (), sec,
            nanosec))
    return list(parameters()['commands.joints']), points


def _trajectory_bytes(velocities: bool, accelerations: bool) -> bytes:
    """Return ``trajectory_points`` as a JointTrajectory's bytes."""
    names, points = trajectory_points(velocities, accelerations)
    return encode_joint_trajectory(0, 0, '', names, points)


def path_run(quick: bool, repetitions: int) -> str:
    """Return the relay's work per message in this process, as markdown."""
    # a millisecond apart, as the commander sends them at 1 kHz
    commands = [encode_cdr(Float64MultiArray(data=[_swing(step * 1e-4, place)[0]
                                                   for place in range(12)]))
                for step in range(1000)]
    relay = relay_for_biped()
    encoder = FixedShapeEncoder(Float64MultiArray(data=[0.0] * 12), ['data'])
    ratios = [JOINTS[name.split('_', 1)[1]][1] for name in parameters()['commands.joints']]

    def forward() -> None:
        for data in commands:
            encoder.encode(relay.forward(decode_float64_array(data), 0))

    def hand_relay() -> None:
        # minimal_command_relay.py's callback, with rclpy's deserialisation before it (the
        # take) and its serialisation after it (the publish)
        for data in commands:
            command = deserialize_message(data, Float64MultiArray)
            serialize_message(Float64MultiArray(
                data=[value * ratio for value, ratio in zip(command.data, ratios)]))

    forward()  # from the assembled pose to the swing
    times: dict[str, list[float]] = {'forward': [], 'hand': []}
    for _ in range(repetitions):
        for key, workload in (('forward', forward), ('hand', hand_relay)):
            started = time.thread_time_ns()
            workload()
            times[key].append((time.thread_time_ns() - started) / len(commands))
    forward_ns, hand_ns = _median(times['forward']), _median(times['hand'])
    rows = [['one forward command (12 joints, 4 groups)', f'{forward_ns * 1e-3:.0f} µs',
             f"{forward_ns / hand_ns:.1f}× the hand relay's", ''],
            ["the hand relay's callback with rclpy's deserialisation and serialisation",
             f'{hand_ns * 1e-3:.0f} µs', '', '']]
    first_point_ms = TRAJECTORY_PERIOD_NS * 1e-6
    verdicts = []
    for label, rates in (('positions, velocities, accelerations', (True, True)),
                         ('positions, velocities', (True, False)), ('positions', (False, False))):
        data = _trajectory_bytes(*rates)
        totals = []
        for _ in range(max(1, repetitions // (2 if quick else 1))):
            relay.command.reset()
            started = time.thread_time_ns()
            message = decode_joint_trajectory(data)
            names, points = relay.trajectory(message.joint_names, [
                JointPoint(p.positions, p.velocities, p.accelerations, p.efforts)
                for p in message.points])
            encode_joint_trajectory(message.sec, message.nanosec, message.frame_id, names, [
                TrajectoryPoint(*point, before.sec, before.nanosec)
                for point, before in zip(points, message.points)])
            totals.append(time.thread_time_ns() - started)
        total_ms = _median(totals) * 1e-6
        rows.append([f'a {TRAJECTORY_POINTS}-point trajectory at 100 Hz: {label}',
                     f'{total_ms / TRAJECTORY_POINTS * 1e3:.0f} µs per point',
                     f'{total_ms:.1f} ms in all', f'{total_ms / first_point_ms:.1f}×'])
        verdicts.append(f'{label}: {total_ms:.0f} ms, '
                        + ('met' if total_ms < first_point_ms else
                           f'not met ({total_ms / first_point_ms:.1f}× the time; the goal '
                           f'needs under {first_point_ms / TRAJECTORY_POINTS * 1e3:.0f} µs '
                           'per point)'))
    return (f'CPU time per message, medians of {repetitions} runs of {len(commands)} forward '
            'commands (one swing of every joint over 0.1 s, as the commander sends them) '
            f"interleaved with the hand relay's, and of the trajectory converted whole\n\n"
            + markdown_table(['message, bytes in to bytes out', 'CPU time', 'compared',
                              "÷ its first point's time_from_start (goal < 1)"], rows)
            + f"\n\nThe trajectory's goal (converted whole in less than its first point's "
            f'time_from_start, {first_point_ms:g} ms at 100 Hz): ' + '; '.join(verdicts) + '.')


def _median(values: list[float]) -> float:
    ordered = sorted(values)
    return ordered[len(ordered) // 2]


def relay_side_by_side(seconds: float, domain: int) -> dict[str, dict[str, object]]:
    """Return per relay: CPU share of one core, latency p50 and p99 (s), commands lost."""
    environment = node_bench.ros_environment(domain)
    outputs = {NODE: '/relay/commands', RELAY: '/minimal/commands'}
    ranges = {name: JOINTS[name.split('_', 1)[1]][0] for name in parameters()['commands.joints']}
    ratios = [JOINTS[name.split('_', 1)[1]][1] for name in ranges]
    with tempfile.TemporaryDirectory(prefix='linkage_bench_relay_') as folder:
        base = pathlib.Path(folder)
        (base / 'joints.json').write_text(json.dumps(ranges), encoding='utf-8')
        (base / 'ratios.json').write_text(json.dumps(ratios), encoding='utf-8')
        (base / 'parameters.yaml').write_text(json.dumps({'/**': {'ros__parameters': {
            **parameters(), 'log.folder': str(base / 'bags')}}}), encoding='utf-8')
        node_log = base / 'node.log'
        with node_log.open('w', encoding='utf-8') as log:
            node = subprocess.Popen(
                [sys.executable, '-m', 'linkage_kinematics.ros.command_node', '--ros-args',
                 '--params-file', str(base / 'parameters.yaml'),
                 '-r', f'~/commands:={INPUT_TOPIC}', '-r', f'actuators/commands:={outputs[NODE]}'],
                cwd=node_bench.ROOT, env=environment, stdout=subprocess.DEVNULL, stderr=log)
        processes = {
            NODE: node,
            RELAY: subprocess.Popen([sys.executable, str(HERE / 'minimal_command_relay.py'),
                                     str(base / 'ratios.json')], cwd=node_bench.ROOT,
                                    env=environment, stdout=subprocess.DEVNULL,
                                    stderr=subprocess.DEVNULL),
        }
        try:
            time.sleep(node_bench.STARTUP_S)
            if node.poll() is not None:
                raise RuntimeError('the relay exited early: '
                                   + node_log.read_text(encoding='utf-8')[-2000:])
            commander = subprocess.Popen(
                [sys.executable, str(HERE / 'commander.py'), str(base / 'sent.json'),
                 f'{RATE_HZ:g}', f'{seconds + 2.0 * node_bench.STARTUP_S:g}',
                 str(base / 'joints.json')],
                cwd=node_bench.ROOT, env=environment, stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL)
            listened = str(base / 'listened.json')
            listener = subprocess.Popen(
                [sys.executable, str(HERE / 'command_listener.py'), listened, str(seconds),
                 *outputs.values()], cwd=node_bench.ROOT, env=environment,
                stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
            listener.stdout.readline()  # "listening"
            time.sleep(1.0)  # the listener records once it has heard both
            started = time.monotonic()
            before = {key: cpu_seconds(process.pid) for key, process in processes.items()}
            time.sleep(seconds - 2.0)
            after = {key: cpu_seconds(process.pid) for key, process in processes.items()}
            elapsed = time.monotonic() - started
            listener.wait(timeout=seconds + 60.0)
            received = json.loads(pathlib.Path(listened).read_text())['received']
            commander.wait(timeout=seconds + 60.0)
            sent = json.loads((base / 'sent.json').read_text())
        finally:
            for process in processes.values():
                if process.poll() is None:
                    process.send_signal(signal.SIGINT)
            for process in processes.values():
                node_bench.stop(process)
        # the node's bag: every command it received and every answer it published, each logged
        # at its receipt, in order
        (bag,) = (base / 'bags').iterdir()
        numbers: dict[str, set[int]] = {'received': set(), 'published': set()}
        for message in iter_messages(bag, (INPUT_TOPIC, outputs[NODE])):
            kind = 'received' if message.topic == INPUT_TOPIC else 'published'
            numbers[kind].add(round(decode_float64_array(message.data)[0] / NUMBER))
    cpu = {key: (after[key] - before[key]) / elapsed for key in processes}
    arrivals = [arrival for answers in received.values() for _, arrival in answers]
    window = (min(arrivals) + EDGE_S * 1e9, max(arrivals) - EDGE_S * 1e9)
    expected = {number for number, stamp in enumerate(sent) if window[0] <= stamp <= window[1]}
    figures = {}
    for name, topic in outputs.items():
        latencies = [(arrival - sent[number]) * 1e-9 for number, arrival in received[topic]
                     if number in expected]
        figures[name] = {'cpu': cpu[name], 'p50': percentile(latencies, 0.5),
                         'p99': percentile(latencies, 0.99),
                         'lost': len(expected - {number for number, _ in received[topic]}),
                         'expected': len(expected)}
    figures[NODE]['in the node'] = {
        'received': len(numbers['received'] & expected),
        'relayed': len(numbers['published'] & expected)}
    return figures


def run(quick: bool, ros_domain: int) -> str:
    """Return the side-by-side run as markdown (domain ``ros_domain`` + 4)."""
    seconds = 10.0 if quick else 30.0
    figures = relay_side_by_side(seconds, ros_domain + 4)
    rows = [[name, f"{100.0 * value['cpu']:.1f} %", f"{1e3 * value['p50']:.3f} ms",
             f"{1e3 * value['p99']:.3f} ms", f"{value['lost']} of {value['expected']}"]
            for name, value in figures.items()]
    node, relay = figures[NODE], figures[RELAY]
    inside = node['in the node']
    ratio = node['cpu'] / relay['cpu']
    extra = 1e3 * (node['p99'] - relay['p99'])
    return (
        f'commands at {RATE_HZ:g} Hz for {seconds:g} s, both relays at once, latency to a third '
        'process\n\n'
        + markdown_table(['process', 'CPU (one core)', 'latency p50', 'latency p99',
                          'commands lost'], rows)
        + f'\n\nCPU ratio relay node ÷ hand relay: {ratio:.2f} (goal ≤ 1.0: '
        f'{_verdict(ratio <= 1.0)}); p99 latency node − hand relay: {extra:+.3f} ms (goal ≤ '
        f'+0.5 ms: {_verdict(extra <= 0.5)}); commands the listener missed from the node: '
        f"{node['lost']} (goal none: {_verdict(node['lost'] == 0)}). The node's bag: it "
        f"received {inside['received']} of the {node['expected']} commands sent in the window "
        f"and relayed {inside['relayed']}.")


def _verdict(met: bool) -> str:
    return 'met' if met else 'not met'
