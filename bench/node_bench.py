# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Section 3: the node: cost per tick, sustained rate, jitter, latency, log size, memory.

Nodes run as the tests run them (``python -m linkage_kinematics.ros.node --ros-args ...`` in their
own process, real Fast DDS over loopback, real MCAP logs); the cost split runs the node's own
objects in this process so each part can be timed alone, next to a bare rclpy publisher.
"""

from __future__ import annotations

from collections.abc import Callable
import json
import math
import os
import pathlib
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from typing import Any

from linkage_kinematics.run.diagnostics import NOT_MEASURED
from timing import format_seconds, interleaved_medians, markdown_table

ROOT = pathlib.Path(__file__).resolve().parent.parent
LISTENER = pathlib.Path(__file__).resolve().parent / 'listener.py'
# Each kind of run has its own ROS_DOMAIN_ID (the base given to run() plus this offset), so that
# none sees another's nodes.
DOMAIN_SPLIT, DOMAIN_RATE, DOMAIN_TIMING, DOMAIN_LOG, DOMAIN_MEMORY = range(5)
STARTUP_S = 4.0  # time for a node process to start, discover and settle before measuring


def ros_environment(domain: int) -> dict[str, str]:
    environment = dict(os.environ)
    environment.update({
        'ROS_DOMAIN_ID': str(domain),
        'ROS_AUTOMATIC_DISCOVERY_RANGE': 'LOCALHOST',
        'AMENT_PREFIX_PATH': os.environ.get('AMENT_PREFIX_PATH', sys.prefix),
    })
    return environment


def start_node(parameters: dict[str, str], domain: int) -> subprocess.Popen:
    arguments = [sys.executable, '-m', 'linkage_kinematics.ros.node', '--ros-args']
    for name, value in parameters.items():
        arguments += ['-p', f'{name}:={value}']
    return subprocess.Popen(arguments, cwd=ROOT, env=ros_environment(domain),
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)


def stop(process: subprocess.Popen) -> None:
    """SIGINT (the node finalizes its log), then wait; kill only if it hangs."""
    if process.poll() is None:
        process.send_signal(signal.SIGINT)
    try:
        process.wait(timeout=30)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()


def listen(seconds: float, topics: list[str], domain: int) -> tuple[subprocess.Popen, str]:
    output = tempfile.mktemp(suffix='.json', prefix='linkage_bench_')
    process = subprocess.Popen([sys.executable, str(LISTENER), output, str(seconds), *topics],
                               cwd=ROOT, env=ros_environment(domain),
                               stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    process.stdout.readline()  # "listening"
    return process, output


def collect(process: subprocess.Popen, output: str) -> dict[str, Any]:
    process.wait(timeout=120)
    with open(output, encoding='utf-8') as file:
        data = json.load(file)
    os.unlink(output)
    return data


def with_children(pid: int) -> list[int]:
    """``pid`` and its child processes (a logging node's is its bag writer)."""
    children = []
    for stat in pathlib.Path('/proc').glob('[0-9]*/stat'):
        try:
            parent = int(stat.read_text(encoding='ascii').rsplit(')', 1)[1].split()[1])
        except (OSError, ValueError):
            continue  # a process that ended meanwhile
        if parent == pid:
            children.append(int(stat.parent.name))
    return [pid, *children]


def rss_mib(pid: int) -> float:
    """Resident memory of ``pid`` and its children."""
    total = 0.0
    for process in with_children(pid):
        with open(f'/proc/{process}/status', encoding='utf-8') as status:
            total += next(int(line.split()[1]) for line in status
                          if line.startswith('VmRSS:')) / 1024.0
    return total


def bag_figures(folder: pathlib.Path) -> tuple[int, int]:
    """(bytes of every file of the one bag in ``folder``, messages it holds)."""
    from mcap.reader import make_reader

    bags = [path for path in folder.iterdir() if path.is_dir()]
    if len(bags) != 1:
        raise RuntimeError(f'expected one bag in {folder}, found {len(bags)}')
    size = sum(path.stat().st_size for path in bags[0].iterdir())
    messages = 0
    for path in bags[0].glob('*.mcap'):
        with open(path, 'rb') as file:
            summary = make_reader(file).get_summary()
            messages += summary.statistics.message_count
    return size, messages


# --- memory ---------------------------------------------------------------------------------

def memory_run(minutes: float, domain_base: int) -> str:
    """
    Resident memory of a 1 kHz node, logging on, with its bag writer.

    From start to ``minutes`` later.
    """
    with tempfile.TemporaryDirectory(prefix='linkage_bench_memory_') as folder:
        node = start_node({'rate_hz': '1000.0', 'end_behavior': 'loop',
                           'log.folder': folder}, domain_base + DOMAIN_MEMORY)
        try:
            time.sleep(STARTUP_S)
            start = time.monotonic()
            samples = [(0.0, rss_mib(node.pid))]
            interval = min(30.0, minutes * 60.0 / 10.0)
            while time.monotonic() - start < minutes * 60.0:
                time.sleep(interval)
                if node.poll() is not None:
                    raise RuntimeError(f'the node exited early: {node.stderr.read()}')
                samples.append((time.monotonic() - start, rss_mib(node.pid)))
        finally:
            stop(node)
        size, messages = bag_figures(pathlib.Path(folder))
    elapsed = samples[-1][0]
    half = [rss for seconds, rss in samples if seconds >= elapsed / 2.0]
    rows = [[f'{seconds:.0f} s', f'{rss:.1f} MiB'] for seconds, rss in samples]
    table = markdown_table(['time since start (after {:.0f} s warm-up)'.format(STARTUP_S),
                            'resident memory (node + bag writer)'], rows)
    return (
        f'{table}\n\nResident memory: {samples[0][1]:.1f} MiB at start, {samples[-1][1]:.1f} MiB '
        f'after {elapsed / 60.0:.1f} min (growth {samples[-1][1] - samples[0][1]:+.1f} MiB; '
        f"{max(half) - min(half):.1f} MiB spread over the second half). The run's log: "
        f'{size / 1e6:.1f} MB, {messages} messages, {size / (elapsed + STARTUP_S) / 1e3:.0f} kB/s.'
    )


# --- cost per tick, in this process ---------------------------------------------------------

def _tick_parts(logging_node: Any, quiet_node: Any, bare_publisher: Any,
                count: int) -> dict[str, Callable[[], int]]:
    """
    Return ``tick_split``'s parts: each does its part of a tick ``count`` times.

    With the logging node's configuration, encoders, publishers and recorder, both nodes' whole
    ticks and the bare publisher.
    """
    from linkage_kinematics.kinematics.solver import solve
    from linkage_kinematics.model.joints import DEFAULT_JOINT_NAMES, Driver, tree_values
    from linkage_kinematics.ros import messages
    from linkage_kinematics.run.motion import sample_at_time, solve_sample
    from rclpy.serialization import deserialize_message
    from sensor_msgs.msg import JointState

    config = logging_node.config
    recorder = logging_node.outputs.log.recorder
    publishers = logging_node.outputs._publishers
    clock = logging_node.get_clock()
    elapsed = [i * 1e-3 for i in range(count)]
    samples = [sample_at_time(config, t % config.motion.segment_duration) for t in elapsed]
    state = solve_sample(config, samples[0])
    stamp = clock.now()
    names = list(DEFAULT_JOINT_NAMES.values())
    positions, velocities = tree_values(state, Driver.CRANK)
    joint_state_encoder = messages.JointStateEncoder(names)
    state_encoder = messages.LinkageStateEncoder(config.geometry.linkage, config.outputs.frame_id)
    joint_state_data = joint_state_encoder.encode(stamp.nanoseconds, positions, velocities)
    trajectory_data = state_encoder.encode(state, stamp.nanoseconds, 0.0)
    # the node's own JointState, as a subscriber's rclpy decodes it
    bare_message = deserialize_message(joint_state_data, JointState)

    def compute() -> int:
        for sample in samples:
            solve_sample(config, sample)
        return count

    def solve_only() -> int:
        for sample in samples:
            solve(config.geometry.linkage, sample.alpha, config.motion.drive, config.motion.branch)
        return count

    def encode() -> int:
        for _ in range(count):
            nanoseconds = clock.now().nanoseconds
            joint_state_encoder.encode(nanoseconds, positions, velocities)
            state_encoder.encode(state, nanoseconds, 0.0)
        return count

    def publish() -> int:
        for _ in range(count):
            publishers.joint_states.publish(joint_state_data)
            publishers.state.publish(trajectory_data)
        return count

    def record() -> int:
        for index in range(count):
            recorder.record('/joint_states', joint_state_data, index)
            recorder.record('/linkage/state', trajectory_data, index)
        return count

    def tick(node: Any) -> int:
        for _ in range(count):
            node._source.tick()
        return count

    def bare() -> int:
        for _ in range(count):
            bare_publisher.publish(bare_message)
        return count

    return {
        'compute: sample_at_time + solve_sample (kinematics.solve)': compute,
        '  of which kinematics.solve alone': solve_only,
        "encode: the node's encoders of both messages, with clock.now()": encode,
        'publish: both encoded messages': publish,
        'log: Recorder.record of both encoded messages': record,
        'whole tick, logging on (DriveLawTimer.tick)': lambda: tick(logging_node),
        'whole tick, logging off (DriveLawTimer.tick)': lambda: tick(quiet_node),
        'bare rclpy publish of the same JointState': bare,
    }


# --- logging one message: CPU of the node's side and of its bag writer's ------------------

def _logged_messages(logging_node: Any) -> list[tuple[str, str, bytes]]:
    """Return what a tick of the 1 kHz timer node logs: joint_states, /tf, linkage/state."""
    from linkage_kinematics.kinematics.solver import solve
    from linkage_kinematics.model.joints import DEFAULT_JOINT_NAMES, Driver, tree_values
    from linkage_kinematics.ros import messages

    config, outputs = logging_node.config, logging_node.outputs
    state = solve(config.geometry.linkage, 0.3, config.motion.drive, config.motion.branch)
    positions, velocities = tree_values(state, Driver.CRANK)
    names = list(DEFAULT_JOINT_NAMES.values())
    stamp_ns = logging_node.get_clock().now().nanoseconds
    transforms = outputs._robot_transforms.message(dict(zip(names, positions)), stamp_ns)
    return [
        ('/joint_states', 'sensor_msgs/msg/JointState',
         messages.JointStateEncoder(names).encode(stamp_ns, positions, velocities)),
        ('/tf', 'tf2_msgs/msg/TFMessage', transforms),
        ('/linkage/state', 'trajectory_msgs/msg/JointTrajectory',
         messages.LinkageStateEncoder(config.geometry.linkage, config.outputs.frame_id).encode(
             state, stamp_ns, 0.0)),
    ]


def _cpu_per_message(workloads: dict[str, Callable[[], int]],
                     repetitions: int) -> dict[str, float]:
    """Median CPU seconds (this process's) per message of each workload, timed in turn."""
    samples: dict[str, list[float]] = {name: [] for name in workloads}
    for _ in range(repetitions):
        for name, workload in workloads.items():
            start = time.process_time()
            count = workload()
            samples[name].append((time.process_time() - start) / count)
    return {name: statistics.median(values) for name, values in samples.items()}


def logging_cost(logging_node: Any, ticks: int, repetitions: int) -> str:
    """
    CPU per logged message: ``Recorder.record`` in the node, and its bag writer's work.

    The writer's side in this process: ``_Child._write_messages`` of the batches the node
    hands over (``BATCH_SIZE`` bytes of MCAP Message records), with the chunk flush and the size
    report the child makes once a second at 1 kHz; beside it the same messages through mcap's
    own ``Writer.add_message``, the per-message path the child ran before ``mcap_chunk``.
    """
    import io
    from linkage_kinematics.bag.definitions import message_definition
    from linkage_kinematics.bag.mcap_chunk import message_record
    from linkage_kinematics.bag.writer_process import _Child, BATCH_SIZE
    from mcap.writer import Writer

    logged = _logged_messages(logging_node)
    recorder = logging_node.outputs.log.recorder
    per_second = 1000  # ticks: the child flushes its chunk and reports the size once a second

    def record() -> int:
        for tick in range(ticks):
            for topic, _, data in logged:
                recorder.record(topic, data, tick)
        return ticks * len(logged)

    with tempfile.TemporaryDirectory(prefix='linkage_bench_log_') as folder:
        replies = io.BytesIO()
        child = _Child(io.BytesIO(), replies)
        child._start({'folder': folder, 'metadata': {}, 'split': {'max_bag_size': 0,
                                                                  'max_bag_duration_ns': 0}})
        for topic, type_name, _ in logged:
            child._add_topic({'topic': topic, 'type_name': type_name,
                              'message_definition': message_definition(type_name),
                              'offered_qos_profiles': [], 'repeat_latest': False})
        channels = [json.loads(line)['channel'] for line in replies.getvalue().splitlines()
                    if 'channel' in json.loads(line)]
        records = [message_record(channel, tick, tick, data)
                   for tick in range(ticks) for channel, (_, _, data) in zip(channels, logged)]
        batches, batch = [], b''
        for start in range(0, len(records), per_second * len(logged)):
            for message in records[start:start + per_second * len(logged)]:
                batch += message
                if len(batch) >= BATCH_SIZE:
                    batches.append(batch)
                    batch = b''
            batches += [batch, None] if batch else [None]  # None: a second has passed
            batch = b''
        reference_file = open(os.path.join(folder, 'add_message.mcap'), 'wb')
        reference = Writer(reference_file)
        reference.start()
        schema = reference.register_schema('s', 'ros2msg', b'')
        for topic, _, _ in logged:
            reference.register_channel(topic, 'cdr', schema)

        def write_batches() -> int:
            for frame in batches:
                if frame is None:
                    child._writer.flush()
                    child._writer.finished_size()
                else:
                    child._write_messages(frame)
            return len(records)

        def add_message() -> int:
            for tick in range(ticks):
                for channel, (_, _, data) in zip(channels, logged):
                    reference.add_message(channel, tick, data, tick)
                if tick % per_second == per_second - 1:
                    reference.flush()
            return len(records)

        times = _cpu_per_message({
            "node: Recorder.record (the pipe's os.write once per batch)": record,
            "bag writer: _Child._write_messages of the node's batches": write_batches,
            "  the same messages through mcap's Writer.add_message": add_message,
        }, repetitions)
        child._close()
        reference.finish()
        reference_file.close()
    rows = [[name, format_seconds(seconds)] for name, seconds in times.items()]
    sizes = ', '.join(f'{topic} {len(data)} B' for topic, _, data in logged)
    return (f"Logging one message, CPU per message ({sizes}; the node's three per tick, "
            f'{ticks} ticks; `time.process_time`, median of {repetitions}):\n\n'
            + markdown_table(['part', 'CPU per message'], rows))


def tick_split(quick: bool, repetitions: int,
               domain_base: int) -> tuple[str, dict[str, float], str]:
    """
    Median time of each part of the node's tick and of a bare rclpy publish, side by side.

    A listener in another process subscribes to /joint_states and to the bare publisher's
    topic, so both publishes really send over loopback. Then ``logging_cost``.
    """
    os.environ.update(ros_environment(domain_base + DOMAIN_SPLIT))
    from linkage_kinematics.ros.node import LinkageNode
    import rclpy
    from rclpy.parameter import Parameter
    from sensor_msgs.msg import JointState

    count = 300 if quick else 1500
    listener, output = listen(60.0, ['/joint_states', '/bench/joint_states'],
                              domain_base + DOMAIN_SPLIT)
    with tempfile.TemporaryDirectory(prefix='linkage_bench_split_') as folder:
        rclpy.init()
        nodes = []
        try:
            logging_node = LinkageNode(parameter_overrides=[
                Parameter('rate_hz', value=1000.0), Parameter('end_behavior', value='loop'),
                Parameter('log.folder', value=folder)])
            nodes.append(logging_node)
            quiet_node = LinkageNode(parameter_overrides=[
                Parameter('rate_hz', value=1000.0), Parameter('end_behavior', value='loop'),
                Parameter('log.enabled', value=False)])
            nodes.append(quiet_node)
            bare_node = rclpy.create_node('bench_bare_publisher')
            nodes.append(bare_node)
            bare_publisher = bare_node.create_publisher(JointState, '/bench/joint_states', 10)
            parts = _tick_parts(logging_node, quiet_node, bare_publisher, count)
            time.sleep(STARTUP_S)  # let the listener match both publishers
            times = interleaved_medians(parts, repetitions)
            logging = logging_cost(logging_node, count * 10, repetitions)
        finally:
            for node in nodes:
                if isinstance(node, LinkageNode):
                    node.outputs.log.close()
                node.destroy_node()
            rclpy.try_shutdown()
    stop(listener)
    if os.path.exists(output):
        os.unlink(output)
    bare_time = times['bare rclpy publish of the same JointState']
    rows = [[name, format_seconds(seconds), f'{seconds / bare_time:.2f}×']
            for name, seconds in times.items()]
    table = markdown_table(['part of a tick', 'time (median)', '× bare publish'], rows)
    return table, times, logging


# --- rates, jitter, latency and log size from node processes --------------------------------

def _percentile(values: list[float], fraction: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(fraction * len(ordered)))]


def observe(parameters: dict[str, str], seconds: float, domain: int,
            topics: tuple[str, ...] | list[str] = ('/joint_states',)) -> dict[str, Any]:
    """
    Run a node with ``parameters`` and a listener for ``seconds``.

    The listener hears /diagnostics and ``topics``.
    """
    node = start_node({'end_behavior': 'loop', **parameters}, domain)
    try:
        time.sleep(STARTUP_S)
        listener, output = listen(seconds, list(topics), domain)
        data = collect(listener, output)
    finally:
        stop(node)
    return data


def achieved_rates(data: dict[str, Any]) -> list[float]:
    """
    Return the achieved rates the node's statuses report, after the first one measured.

    The first may still hold the listener's start-up; a status before any measurement says
    ``not measured yet``.
    """
    return [float(d['achieved rate (Hz)']) for d in data['diagnostics']
            if d.get('achieved rate (Hz)', NOT_MEASURED) != NOT_MEASURED][1:]


def sustained_rate(
    rate: float, logging: bool, seconds: float, domain_base: int
) -> tuple[float, int]:
    """
    Return the fraction of ticks missed and the node's missed-deadline count.

    The fraction is 1 − achieved/requested over the node's diagnostics windows after the first.
    """
    with tempfile.TemporaryDirectory(prefix='linkage_bench_rate_') as folder:
        data = observe({'rate_hz': f'{rate:.1f}', 'log.enabled': str(logging).lower(),
                        'log.folder': folder}, seconds, domain_base + DOMAIN_RATE)
    windows = achieved_rates(data)
    missed = max((int(d['missed deadlines']) for d in data['diagnostics']
                  if 'missed deadlines' in d), default=-1)
    if not windows:
        return math.nan, missed
    return max(0.0, 1.0 - statistics.mean(windows) / rate), missed


def timing_figures(
    rate: float, seconds: float, domain_base: int, parameters: dict[str, str] | None = None
) -> dict[str, float]:
    """
    Timer jitter (|stamp interval − period|) and node → listener latency, p50 and p99.

    Of a node with ``parameters`` besides the rate.
    """
    with tempfile.TemporaryDirectory(prefix='linkage_bench_timing_') as folder:
        data = observe({'rate_hz': f'{rate:.1f}', 'log.folder': folder, **(parameters or {})},
                       seconds, domain_base + DOMAIN_TIMING)
    samples = data['received']['/joint_states']
    stamps = [stamp for stamp, _ in samples]
    period_ns = 1e9 / rate
    jitter = [abs((later - earlier) - period_ns) * 1e-9
              for earlier, later in zip(stamps, stamps[1:])]
    latency = [(arrival - stamp) * 1e-9 for stamp, arrival in samples]
    expected = (stamps[-1] - stamps[0]) / period_ns + 1
    return {
        'received': len(samples), 'expected': expected,
        'jitter_p50': _percentile(jitter, 0.5), 'jitter_p99': _percentile(jitter, 0.99),
        'latency_p50': _percentile(latency, 0.5), 'latency_p99': _percentile(latency, 0.99),
    }


def log_size(seconds: float, domain_base: int) -> tuple[float, float, int]:
    """(bytes per second, bytes per message, messages) of a run at the default settings."""
    with tempfile.TemporaryDirectory(prefix='linkage_bench_log_') as folder:
        node = start_node({'end_behavior': 'loop', 'log.folder': folder},
                          domain_base + DOMAIN_LOG)
        started = time.monotonic()
        time.sleep(seconds)
        stop(node)
        elapsed = time.monotonic() - started
        size, messages = bag_figures(pathlib.Path(folder))
    return size / elapsed, size / messages, messages


def rate_text(rate: float | None) -> str:
    return 'none of the rates tried' if rate is None else f'{rate:g} Hz'


def run(quick: bool, repetitions: int, domain_base: int) -> str:
    """Return the node section as markdown."""
    split, times, logging_text = tick_split(quick, repetitions, domain_base)
    with_logging = times['whole tick, logging on (DriveLawTimer.tick)']
    ratio = with_logging / times['bare rclpy publish of the same JointState']
    logging_share = with_logging / times['whole tick, logging off (DriveLawTimer.tick)']
    lines = ['Cost per tick (one process; a listener in another process subscribes to '
             '/joint_states and the bare topic):', '', split, '',
             f'- whole tick with logging / bare publish = {ratio:.2f}× (goal ≤ 2×: '
             f"{'met' if ratio <= 2.0 else 'missed'})",
             f'- whole tick with logging / without = {logging_share:.2f}×', '',
             logging_text, '']
    seconds = 4.0 if quick else 8.0
    rates = (100.0, 500.0, 1000.0) if quick else (100.0, 200.0, 500.0, 1000.0, 2000.0, 5000.0)
    rows = []
    sustained: dict[bool, float | None] = {True: None, False: None}
    for logging in (True, False):
        for rate in rates:
            fraction, missed = sustained_rate(rate, logging, seconds, domain_base)
            rows.append([f'{rate:g} Hz', 'on' if logging else 'off',
                         f'{100.0 * fraction:.2f} %', str(missed)])
            if fraction < 0.01:
                sustained[logging] = max(sustained[logging] or 0.0, rate)
    lines += [f"Sustained rate ({seconds:g} s per run, missed share from the node's "
              '/diagnostics achieved rate):', '',
              markdown_table(['timer rate', 'logging', 'ticks missed', 'missed deadlines '
                              "(node's count)"], rows), '',
              f'- highest rate tried with < 1 % missed: {rate_text(sustained[True])} with '
              f'logging, {rate_text(sustained[False])} without', '']
    rows = []
    for rate in (100.0, 1000.0):
        figures = timing_figures(rate, seconds, domain_base)
        rows.append([f'{rate:g} Hz', format_seconds(figures['jitter_p50']),
                     format_seconds(figures['jitter_p99']), format_seconds(figures['latency_p50']),
                     format_seconds(figures['latency_p99']),
                     f"{figures['received']} of {figures['expected']:.0f}"])
    lines += ['Timer jitter (|interval between header stamps − period|) and latency (listener '
              'receive time − header stamp, another process), logging on:', '',
              markdown_table(['rate', 'jitter p50', 'jitter p99', 'latency p50', 'latency p99',
                              'messages received'], rows), '']
    per_second, per_message, messages = log_size(seconds + 2.0, domain_base)
    lines.append(f'Log at the default settings (100 Hz state, 30 Hz markers, 1 Hz '
                 f'diagnostics): {per_second / 1e3:.1f} kB/s, {per_message:.0f} B per message '
                 f'({messages} messages in {seconds + 2.0:g} s).')
    return '\n'.join(lines)
