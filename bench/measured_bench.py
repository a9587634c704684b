# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Section "measured": linkage_node completing an encoder's joint states, against a hand relay.

One run, side by side on one ROS domain: ``encoder.py`` publishes the crank at 1 kHz on
/encoder/joint_states; ``linkage_node`` (``source:=measured``, logging on, in namespace
/completer, remapped to the encoder's topic) and ``minimal_relay.py`` (the subscribe-and-publish
node a lab would write, rclpy's default executor) both follow it; ``listener.py``, a third
process, receives both outputs. CPU is utime + stime from /proc/PID/stat over the listener's
window, the node's with its bag writer's; latency is the listener's receipt time minus the
stamp the encoder gave the sample just before publishing it (both carry the input's stamp);
samples lost are the encoder's samples within the window that did not arrive.

``follow_side_by_side`` is that run for any node command line (the "loops" section runs the
node closing a URDF's loops with it), ``report`` its table and the goals.
"""

from __future__ import annotations

import json
import pathlib
import signal
import subprocess
import sys
import tempfile
import time

from cost_bench import cpu_seconds
from linkage_kinematics.bag.reader import iter_messages
import node_bench
from timing import markdown_table

HERE = pathlib.Path(__file__).resolve().parent
RATE_HZ = 1000.0
RELAY = 'minimal rclpy relay'
RELAY_TOPIC = '/relay/joint_states'
INPUT_TOPIC = '/encoder/joint_states'  # the followers' input, as the node's bag names it
# The window's edges: samples published this close to its start or end may fall outside it.
EDGE_S = 0.5


def percentile(values: list[float], fraction: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(fraction * (len(ordered) - 1)))]


def node_command(namespace: str, folder: str, arguments: list[str]) -> list[str]:
    """Return linkage_node's command line following the encoder, logging into ``folder``."""
    return [sys.executable, '-m', 'linkage_kinematics.ros.node', '--ros-args',
            '-r', f'__ns:={namespace}', '-r', f'measured_joint_states:={INPUT_TOPIC}',
            '-p', 'source:=measured', '-p', f'log.folder:={folder}/bags', *arguments]


def follow_side_by_side(
    node: tuple[str, str, list[str]], seconds: float, domain: int,
    joints: dict[str, tuple[float, float]] | None = None,
    files: dict[str, str] | None = None,
    published: frozenset[str] | None = None,
) -> dict[str, dict[str, float]]:
    """
    Return per follower: CPU share of one core, latency p50 and p99 (s), samples lost.

    The node's also: its process's CPU share without its bag writer's (``cpu alone``), and what
    its bag says it did with the samples (``in the node``).

    ``node`` is (its name in the table, its namespace, its ``--ros-args`` after the measured
    source's and logging's); the relay follows the same encoder at the same time. ``files``
    (name → text) are written into the run's folder first, and ``{folder}`` in an argument is
    that folder. ``joints`` adds a robot's measured joints to the encoder's messages, each
    swinging over its range. With ``published``, the node's messages must carry exactly those
    joints: a node that took its parameters otherwise is not what was to be measured.
    """
    name, namespace, arguments = node
    outputs = {name: f'{namespace}/joint_states', RELAY: RELAY_TOPIC}
    environment = node_bench.ros_environment(domain)
    with tempfile.TemporaryDirectory(prefix='linkage_bench_measured_') as folder:
        sent_file = pathlib.Path(folder) / 'sent.json'
        joints_file = pathlib.Path(folder) / 'joints.json'
        joints_file.write_text(json.dumps(joints or {}), encoding='utf-8')
        for file_name, text in (files or {}).items():
            (pathlib.Path(folder) / file_name).write_text(text, encoding='utf-8')
        command = node_command(namespace, folder,
                               [argument.format(folder=folder) for argument in arguments])
        node_log = pathlib.Path(folder) / 'node.log'
        with node_log.open('w', encoding='utf-8') as log:
            node_process = subprocess.Popen(command, cwd=node_bench.ROOT, env=environment,
                                            stdout=subprocess.DEVNULL, stderr=log)
        processes = {
            name: node_process,
            RELAY: subprocess.Popen([sys.executable, str(HERE / 'minimal_relay.py')],
                                    cwd=node_bench.ROOT, env=environment,
                                    stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL),
        }
        try:
            time.sleep(node_bench.STARTUP_S)
            if processes[name].poll() is not None:
                # a node that refused its parameters: say why rather than time out listening
                raise RuntimeError(f'{name} exited early: '
                                   + node_log.read_text(encoding='utf-8')[-2000:])
            encoder = subprocess.Popen(
                [sys.executable, str(HERE / 'encoder.py'), str(sent_file), f'{RATE_HZ:g}',
                 f'{seconds + 2.0 * node_bench.STARTUP_S:g}', str(joints_file)],
                cwd=node_bench.ROOT, env=environment, stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL)
            listener, output = node_bench.listen(seconds, list(outputs.values()), domain)
            # The listener records once it has heard both outputs: CPU within its window.
            time.sleep(1.0)
            started = time.monotonic()
            before = {key: cpu_seconds(process.pid) for key, process in processes.items()}
            alone_before = cpu_seconds(node_process.pid, children=False)
            time.sleep(seconds - 2.0)
            after = {key: cpu_seconds(process.pid) for key, process in processes.items()}
            alone_after = cpu_seconds(node_process.pid, children=False)
            elapsed = time.monotonic() - started
            data = node_bench.collect(listener, output)
            encoder.wait(timeout=seconds + 60.0)
            sent = json.loads(sent_file.read_text())
        finally:
            for process in processes.values():
                if process.poll() is None:
                    process.send_signal(signal.SIGINT)
            for process in processes.values():
                node_bench.stop(process)
        # The node's bag holds every input it received and every joint state it published,
        # each at the input's stamp: what the node itself did with each sample.
        logged = {'received': set(), 'published': set()}
        output_topic = outputs[name]
        bag, = (pathlib.Path(folder) / 'bags').iterdir()  # the run's one bag folder
        for message in iter_messages(bag, (INPUT_TOPIC, output_topic)):
            kind = 'received' if message.topic == INPUT_TOPIC else 'published'
            logged[kind].add(message.log_time_ns)
    shown = data.get('names', {}).get(outputs[name])
    if published is not None and set(shown or ()) != published:
        raise RuntimeError(f'{name} published {shown}, not the joints {sorted(published)}')
    cpu = {key: (after[key] - before[key]) / elapsed for key in processes}
    figures = _figures(data['received'], sent, outputs, cpu)
    figures[name]['cpu alone'] = (alone_after - alone_before) / elapsed
    expected = figures[name].pop('expected stamps')
    figures[RELAY].pop('expected stamps')
    # Only the loops node logs its input; the four-bar node's bag has its outputs alone.
    received_by_node = logged['received'] & expected if logged['received'] else None
    figures[name]['in the node'] = {
        'published': len(logged['published'] & expected),
        'received': None if received_by_node is None else len(received_by_node),
        'dropped': None if received_by_node is None else len(
            received_by_node - logged['published']),
    }
    return figures


def _figures(received: dict[str, list[tuple[int, int]]], sent: list[int],
             outputs: dict[str, str], cpu: dict[str, float]) -> dict[str, dict[str, float]]:
    """
    Return each follower's CPU, latencies and samples lost within the listener's window.

    Lost: not received by the listener (before the follower, in it, or on the way out).
    """
    figures = {}
    all_arrivals = [arrival for samples in received.values() for _, arrival in samples]
    window = (min(all_arrivals) + EDGE_S * 1e9, max(all_arrivals) - EDGE_S * 1e9)
    expected = {stamp for stamp in sent if window[0] <= stamp <= window[1]}
    for name, topic in outputs.items():
        samples = received[topic]
        latencies = [(arrival - stamp) * 1e-9 for stamp, arrival in samples
                     if stamp in expected]
        figures[name] = {
            'cpu': cpu[name],
            'p50': percentile(latencies, 0.5),
            'p99': percentile(latencies, 0.99),
            'missing': expected - {stamp for stamp, _ in samples},
            'expected': len(expected),
            'expected stamps': expected,
        }
    # A sample neither output delivered was lost before both (the encoder's writer, or the
    # listener falling behind both), not by one follower.
    common = set.intersection(*(value['missing'] for value in figures.values()))
    for value in figures.values():
        value['lost'] = len(value.pop('missing'))
        value['lost by both'] = len(common)
    return figures


def report(figures: dict[str, dict[str, float]]) -> str:
    """Return the followers' table and the goals: the node's figures against the relay's."""
    rows = [[name, f"{100.0 * value['cpu']:.1f} %", f"{1e3 * value['p50']:.3f} ms",
             f"{1e3 * value['p99']:.3f} ms",
             f"{value['lost']} of {value['expected']} ({value['lost by both']} by both)"]
            for name, value in figures.items()]
    node, relay = figures.values()
    table = markdown_table(['process', 'CPU (one core)', 'latency p50', 'latency p99',
                            'samples lost'], rows)
    goals = (
        f"\nThe node's CPU without its bag writer's: {100.0 * node['cpu alone']:.1f} % (the "
        f"writer's {100.0 * (node['cpu'] - node['cpu alone']):.1f} %)."
        f"\nCPU ratio node ÷ relay: {node['cpu'] / relay['cpu']:.2f} (goal ≤ 1.0); p99 "
        f"latency node − relay: {1e3 * (node['p99'] - relay['p99']):+.3f} ms (goal ≤ +0.5 ms); "
        f"samples the listener missed from the node: {node['lost']}."
    )
    inside = node['in the node']
    goals += (f"\nThe node's bag: a joint state for {inside['published']} of the "
              f"{node['expected']} samples sent in the window")
    if inside['received'] is not None:
        goals += (f"; it received {inside['received']} of them and dropped "
                  f"{inside['dropped']} (goal 0: no sample lost by the node)")
    goals += '.'

    return table + '\n' + goals


def run(quick: bool, ros_domain: int) -> str:
    """Return the section as markdown (domain ``ros_domain`` + 4)."""
    seconds = 10.0 if quick else 30.0
    node = ('linkage_node (measured, logging)', '/completer',
            ['-p', 'preset:=grashof_crank_rocker'])
    figures = follow_side_by_side(node, seconds, ros_domain + 4)
    return (f'encoder at {RATE_HZ:g} Hz for {seconds:g} s, both followers at once, '
            'latency to a third process\n\n' + report(figures))
