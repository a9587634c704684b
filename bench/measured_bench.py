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
import node_bench
from timing import markdown_table

HERE = pathlib.Path(__file__).resolve().parent
RATE_HZ = 1000.0
OUTPUTS = {'linkage_node (measured, logging)': '/completer/joint_states',
           'minimal rclpy relay': '/relay/joint_states'}
# The window's edges: samples published this close to its start or end may fall outside it.
EDGE_S = 0.5


def percentile(values: list[float], fraction: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(fraction * (len(ordered) - 1)))]


def one_run(seconds: float, domain: int) -> dict[str, dict[str, float]]:
    """Return per output: CPU share of one core, latency p50 and p99 (s), samples lost."""
    environment = node_bench.ros_environment(domain)
    with tempfile.TemporaryDirectory(prefix='linkage_bench_measured_') as folder:
        sent_file = pathlib.Path(folder) / 'sent.json'
        node = subprocess.Popen(
            [sys.executable, '-m', 'linkage_kinematics.ros.node', '--ros-args',
             '-r', '__ns:=/completer', '-r', 'measured_joint_states:=/encoder/joint_states',
             '-p', 'source:=measured', '-p', 'preset:=grashof_crank_rocker',
             '-p', f'log.folder:={folder}/bags'],
            cwd=node_bench.ROOT, env=environment, stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL)
        relay = subprocess.Popen([sys.executable, str(HERE / 'minimal_relay.py')],
                                 cwd=node_bench.ROOT, env=environment,
                                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        processes = {'linkage_node (measured, logging)': node, 'minimal rclpy relay': relay}
        try:
            time.sleep(node_bench.STARTUP_S)
            encoder = subprocess.Popen(
                [sys.executable, str(HERE / 'encoder.py'), str(sent_file), f'{RATE_HZ:g}',
                 f'{seconds + 2.0 * node_bench.STARTUP_S:g}'],
                cwd=node_bench.ROOT, env=environment, stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL)
            listener, output = node_bench.listen(seconds, list(OUTPUTS.values()), domain)
            # The listener records once it has heard both outputs: CPU within its window.
            time.sleep(1.0)
            started = time.monotonic()
            before = {name: cpu_seconds(process.pid) for name, process in processes.items()}
            time.sleep(seconds - 2.0)
            after = {name: cpu_seconds(process.pid) for name, process in processes.items()}
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
    figures = {}
    all_arrivals = [arrival for samples in data['received'].values()
                    for _, arrival in samples]
    window = (min(all_arrivals) + EDGE_S * 1e9, max(all_arrivals) - EDGE_S * 1e9)
    expected = {stamp for stamp in sent if window[0] <= stamp <= window[1]}
    for name, topic in OUTPUTS.items():
        samples = data['received'][topic]
        latencies = [(arrival - stamp) * 1e-9 for stamp, arrival in samples
                     if stamp in expected]
        figures[name] = {
            'cpu': (after[name] - before[name]) / elapsed,
            'p50': percentile(latencies, 0.5),
            'p99': percentile(latencies, 0.99),
            'missing': expected - {stamp for stamp, _ in samples},
            'expected': len(expected),
        }
    # A sample neither output delivered was lost before both (the encoder's writer, or the
    # listener falling behind both), not by one follower.
    common = set.intersection(*(value['missing'] for value in figures.values()))
    for value in figures.values():
        value['lost'] = len(value.pop('missing'))
        value['lost by both'] = len(common)
    return figures


def run(quick: bool, ros_domain: int) -> str:
    """Return the section as markdown (domain ``ros_domain`` + 4)."""
    seconds = 10.0 if quick else 30.0
    figures = one_run(seconds, ros_domain + 4)
    rows = [[name, f"{100.0 * value['cpu']:.1f} %", f"{1e3 * value['p50']:.3f} ms",
             f"{1e3 * value['p99']:.3f} ms",
             f"{value['lost']} of {value['expected']} ({value['lost by both']} by both)"]
            for name, value in figures.items()]
    node, relay = figures.values()
    table = markdown_table(['process', 'CPU (one core)', 'latency p50', 'latency p99',
                            'samples lost'], rows)
    goals = (
        f"\nCPU ratio node ÷ relay: {node['cpu'] / relay['cpu']:.2f} (goal ≤ 1.0); p99 "
        f"latency node − relay: {1e3 * (node['p99'] - relay['p99']):+.3f} ms (goal ≤ +0.5 ms); "
        f"samples lost by the node: {node['lost']} (goal 0)."
    )
    return (f'encoder at {RATE_HZ:g} Hz for {seconds:g} s, both followers at once, '
            'latency to a third process\n\n' + table + '\n' + goals)
