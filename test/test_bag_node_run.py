# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A real node's bag, read back by two independent readers (rosbags and mcap-ros2-support).

And linkage-replay over it (the Foxglove layout's tests are in test_foxglove_layout.py). Nodes
run and are listened to through node_process; the bag helpers are in bag_files.py.
"""
from __future__ import annotations

from collections import defaultdict
import json
import math
from pathlib import Path
import subprocess
import sys
from typing import Any

from bag_files import (
    bag_information,
    listen_to_node_topics,
    LOGGED_TOPICS,
    message_stamp_ns,
    NODE_TOPICS,
    only_bag,
    read_with_rosbags,
    topic_counts,
)
from linkage_kinematics.bag import player
from linkage_kinematics.bag import reader as bag_reader
from linkage_kinematics.bag.metadata import package_version
from linkage_kinematics.bag.writer import BagWriter
from linkage_kinematics.cli.replay import main as replay_main
from linkage_kinematics.kinematics.drive import DriveLaw
from linkage_kinematics.kinematics.geometry import preset
from linkage_kinematics.kinematics.solver import solve
from linkage_kinematics.shared.cdr import encode_cdr, ros_type_name
from mcap.reader import make_reader
from mcap_ros2.reader import read_ros2_messages
from node_process import (
    expected_state_point,
    Listener,
    NodeProcesses,
    REPOSITORY,
    ros_context,
    ros_environment,
    stamp_ns,
    TYPESTORE,
)
import pytest
from rosbags.rosbag2 import Reader
from trajectory_msgs.msg import JointTrajectory

DATA_TOPICS = ('/joint_states', '/linkage/state', '/linkage/markers', '/diagnostics')
RATE_HZ = 200.0
# 90° at this constant ω takes 0.3 s: a short run.
SHORT_RUN_OMEGA = (math.pi / 2) / 0.3


# --- a real node run, read back by two independent readers ------------------------------------


@pytest.fixture(scope='module')
def node_run(
    tmp_path_factory: pytest.TempPathFactory, module_nodes: NodeProcesses
) -> dict[str, Any]:
    """
    Return a logging run that the listener has heard on every topic, ended by SIGINT.

    The node loops until the listener (whose discovery may take seconds on a busy machine) has
    received a few messages on every topic; the bag then holds everything the listener got.
    """
    run_folder = tmp_path_factory.mktemp('node_run')
    folder = run_folder / 'bags'
    with ros_context(module_nodes.domain_id) as context:
        listener = listen_to_node_topics(context, 'bag_test_listener')
        process = module_nodes.start(
            {'log.folder': str(folder), 'rate_hz': RATE_HZ, 'omega0': SHORT_RUN_OMEGA,
             'end_behavior': 'loop'},
            run_folder / 'node.log',
        )
        try:
            assert listener.wait_for_every_topic(count=2), (run_folder / 'node.log').read_text()
            assert module_nodes.interrupt(process) == 0, (
                (run_folder / 'node.log').read_text())
        finally:
            listener.destroy()
    return {'bag': only_bag(folder), 'received': listener.received}


def test_every_published_topic_is_logged_with_its_type(node_run: dict[str, Any]) -> None:
    logged = read_with_rosbags(node_run['bag'])
    assert set(logged) == set(LOGGED_TOPICS)
    with Reader(node_run['bag']) as reader:
        types = {connection.topic: connection.msgtype for connection in reader.connections}
    assert types == {topic: ros_type_name(msg_type) for topic, msg_type in LOGGED_TOPICS.items()}
    assert len(logged['/linkage/state']) == len(logged['/joint_states']) >= 2
    assert len(logged['/robot_description']) == 1


def test_logged_messages_equal_what_subscribers_received(node_run: dict[str, Any]) -> None:
    logged = read_with_rosbags(node_run['bag'])
    received = node_run['received']
    for topic in DATA_TOPICS:
        assert received.get(topic), f'the listener received nothing on {topic}'
        type_name = ros_type_name(NODE_TOPICS[topic])
        by_stamp = {message_stamp_ns(message): message for _, message, _ in logged[topic]}
        for message in received[topic]:
            logged_message = by_stamp[message_stamp_ns(message)]
            # every field equal, whatever the type
            assert encode_cdr(message) == bytes(
                TYPESTORE.serialize_cdr(logged_message, type_name)
            ), topic
            if topic == '/linkage/state':
                (point,) = message.points
                (logged_point,) = logged_message.points
                assert list(logged_message.joint_names) == list(message.joint_names)
                for field in ('positions', 'velocities', 'accelerations'):
                    assert list(getattr(logged_point, field)) == list(getattr(point, field))
            elif topic == '/joint_states':
                assert list(logged_message.position) == list(message.position)
                assert list(logged_message.velocity) == list(message.velocity)
            elif topic == '/linkage/markers':
                assert [m.id for m in logged_message.markers] == [m.id for m in message.markers]
                assert [(p.x, p.y) for m in logged_message.markers for p in m.points] == [
                    (p.x, p.y) for m in message.markers for p in m.points
                ]
            else:
                (status,) = message.status
                (logged_status,) = logged_message.status
                assert (logged_status.level, logged_status.message) == (
                    int.from_bytes(status.level, 'little'), status.message
                )
                assert {kv.key: kv.value for kv in logged_status.values} == {
                    kv.key: kv.value for kv in status.values
                }
    (description,) = received['/robot_description']
    assert logged['/robot_description'][0][1].data == description.data


def test_logged_states_are_the_library_solution_at_the_logged_alpha(
    node_run: dict[str, Any],
) -> None:
    paper = preset('paper')
    drive = DriveLaw(SHORT_RUN_OMEGA, 0.0)
    states = read_with_rosbags(node_run['bag'])['/linkage/state']
    for _, message, _ in states:
        (point,) = message.points
        state = solve(paper.geometry, point.positions[0], drive)
        positions, velocities, accelerations = expected_state_point(paper.geometry, state)
        assert tuple(point.positions) == positions
        assert tuple(point.velocities) == velocities
        assert tuple(point.accelerations) == accelerations


def test_log_times_are_monotonic_and_every_message_has_its_exact_cdr_length(
    node_run: dict[str, Any],
) -> None:
    bag = node_run['bag']
    log_times = [message.log_time_ns for message in bag_reader.iter_messages(bag)]
    assert log_times == sorted(log_times)
    for topic, entries in read_with_rosbags(bag).items():
        type_name = ros_type_name(LOGGED_TOPICS[topic])
        for _, decoded, raw in entries:
            assert len(raw) == len(TYPESTORE.serialize_cdr(decoded, type_name)), topic


def test_mcap_ros2_decodes_every_message_with_the_logged_schemas(node_run: dict[str, Any]) -> None:
    bag = node_run['bag']
    (mcap_path,) = bag.glob('*.mcap')
    counts: dict[str, int] = defaultdict(int)
    for decoded in read_ros2_messages(str(mcap_path)):
        counts[decoded.channel.topic] += 1
        assert decoded.schema.encoding == 'ros2msg'
        assert decoded.channel.message_encoding == 'cdr'
        assert decoded.schema.name == ros_type_name(LOGGED_TOPICS[decoded.channel.topic])
        assert 'offered_qos_profiles' in decoded.channel.metadata
    assert dict(counts) == topic_counts(bag_information(bag))


def test_run_metadata_holds_parameters_and_version(node_run: dict[str, Any]) -> None:
    bag = node_run['bag']
    (mcap_path,) = bag.glob('*.mcap')
    with open(mcap_path, 'rb') as stream:
        reader = make_reader(stream)
        assert reader.get_header().profile == 'ros2'
        records = {record.name: record.metadata for record in reader.iter_metadata()}
    run = records['linkage_kinematics']
    parameters = json.loads(run['parameters'])
    assert parameters['rate_hz'] == RATE_HZ
    assert parameters['omega0'] == SHORT_RUN_OMEGA
    assert run['package_version'] == package_version()
    assert bag_information(bag)['custom_data'] == run


def test_metadata_yaml_is_rosbag2_jazzy_format(node_run: dict[str, Any]) -> None:
    bag = node_run['bag']
    information = bag_information(bag)
    (mcap_path,) = bag.glob('*.mcap')
    assert information['version'] == 9
    assert information['storage_identifier'] == 'mcap'
    assert information['relative_file_paths'] == [mcap_path.name]
    assert information['compression_format'] == information['compression_mode'] == ''
    assert information['ros_distro'] == 'jazzy'
    logged = read_with_rosbags(bag)
    total = sum(len(entries) for entries in logged.values())
    assert information['message_count'] == total
    (file_entry,) = information['files']
    assert file_entry['path'] == mcap_path.name and file_entry['message_count'] == total
    log_times = sorted(t for entries in logged.values() for t, _, _ in entries)
    assert information['starting_time']['nanoseconds_since_epoch'] == log_times[0]
    assert information['duration']['nanoseconds'] == log_times[-1] - log_times[0]
    for entry in information['topics_with_message_count']:
        topic = entry['topic_metadata']
        assert topic['serialization_format'] == 'cdr'
        assert topic['type_description_hash'].startswith('RIHS01_')
        (profile,) = topic['offered_qos_profiles']
        assert set(profile) == {
            'history', 'depth', 'reliability', 'durability', 'deadline', 'lifespan',
            'liveliness', 'liveliness_lease_duration', 'avoid_ros_namespace_conventions',
        }
        expected_durability = (
            'transient_local' if topic['name'] in ('/robot_description', '/tf_static')
            else 'volatile'
        )
        assert (profile['reliability'], profile['durability']) == ('reliable', expected_durability)
        assert entry['message_count'] == len(logged[topic['name']])


# --- linkage-replay ---------------------------------------------------------------------------


def test_replay_republishes_the_logged_run(
    node_run: dict[str, Any], nodes: NodeProcesses, other_domain_id: int, tmp_path: Path
) -> None:
    bag = node_run['bag']
    logged = read_with_rosbags(bag)
    logged_states = {
        stamp_ns(m): (list(m.points[0].positions), list(m.points[0].accelerations))
        for _, m, _ in logged['/linkage/state']
    }
    logged_joints = {stamp_ns(m): list(m.position) for _, m, _ in logged['/joint_states']}
    with ros_context(other_domain_id) as context:
        listener = listen_to_node_topics(context, 'replay_test_listener')
        states = listener.received['/linkage/state']
        with open(tmp_path / 'replay.log', 'w') as output:
            # At the logged pace, looped until every logged state was heard: a listener that
            # discovers the replay late, or falls behind while the machine is busy (the logged
            # QoS keeps the last 10), hears the rest in a later round.
            replay = nodes.add(subprocess.Popen(
                [sys.executable, '-m', 'linkage_kinematics.cli.replay', str(bag), '--loop'],
                cwd=REPOSITORY, env=ros_environment(other_domain_id), stdout=output,
                stderr=subprocess.STDOUT,
            ), tmp_path / 'replay.log')
        try:
            assert listener.spin_until(
                lambda: listener.heard_every_topic()
                and len({stamp_ns(m) for m in states}) == len(logged_states)
            ), (tmp_path / 'replay.log').read_text()
            assert nodes.interrupt(replay) == 0, (tmp_path / 'replay.log').read_text()
        finally:
            listener.destroy()
    received = listener.received
    for message in states:
        assert (list(message.points[0].positions), list(message.points[0].accelerations)) == (
            logged_states[stamp_ns(message)]
        )
    for message in received['/joint_states']:
        assert list(message.position) == logged_joints[stamp_ns(message)]
    # Each round replays the run in its logged order.
    stamps = [stamp_ns(m) for m in states]
    rounds = [i for i in range(1, len(stamps)) if stamps[i] < stamps[i - 1]]
    for start, end in zip([0, *rounds], [*rounds, len(stamps)]):
        assert stamps[start:end] == sorted(stamps[start:end])
    assert received['/robot_description'][0].data == logged['/robot_description'][0][1].data


def test_replay_loops_until_interrupted(
    node_run: dict[str, Any], nodes: NodeProcesses, other_domain_id: int, tmp_path: Path
) -> None:
    bag = node_run['bag']
    logged_states = len(read_with_rosbags(bag)['/linkage/state'])
    with ros_context(other_domain_id) as context:
        listener = Listener('replay_loop_listener', context)
        listener.subscribe('/linkage/state', JointTrajectory)
        with open(tmp_path / 'replay.log', 'w') as output:
            replay = nodes.add(subprocess.Popen(
                [sys.executable, '-m', 'linkage_kinematics.cli.replay', str(bag), '--loop',
                 '--rate', '4', '--topics', '/linkage/state'],
                cwd=REPOSITORY, env=ros_environment(other_domain_id), stdout=output,
                stderr=subprocess.STDOUT,
            ), tmp_path / 'replay.log')
        try:
            assert listener.spin_until(
                lambda: len(listener.received['/linkage/state']) > 2 * logged_states
            )
            assert nodes.interrupt(replay) == 0
        finally:
            listener.destroy()
    output_text = (tmp_path / 'replay.log').read_text()
    assert 'Traceback' not in output_text and 'published' in output_text
    alphas = [message.points[0].positions[0] for message in listener.received['/linkage/state']]
    assert alphas.count(alphas[0]) >= 2  # the run started over


def test_replay_leaves_out_excluded_topics_such_as_the_bags_tf(
    node_run: dict[str, Any], capsys: pytest.CaptureFixture[str],
) -> None:
    bag = node_run['bag']
    everything = player.plan_topics(bag, None)
    # tf2_msgs is not installed here: its topics are skipped, with a warning
    assert {plan.topic for plan in everything} == set(NODE_TOPICS)
    assert 'skipping /tf' in capsys.readouterr().err
    # beside a robot_state_publisher the bag's TF is left out, and nothing is said about it
    without_tf = player.plan_topics(bag, None, ['/tf', '/tf_static'])
    assert [plan.topic for plan in without_tf] == [plan.topic for plan in everything]
    assert capsys.readouterr().err == ''
    only_states = player.plan_topics(bag, ['/linkage/state', '/joint_states'], ['/joint_states'])
    assert [plan.topic for plan in only_states] == ['/linkage/state']


def test_replay_rejects_bad_input_with_a_clear_message(
    tmp_path: Path, node_run: dict[str, Any], capsys: pytest.CaptureFixture[str]
) -> None:
    not_mcap = tmp_path / 'notes.mcap'
    not_mcap.write_text('just text')
    assert replay_main([str(tmp_path / 'missing')]) == 1
    assert 'no bag at' in capsys.readouterr().err
    assert replay_main([str(not_mcap)]) == 1
    assert 'not an MCAP file' in capsys.readouterr().err

    cut = tmp_path / 'cut'
    cut.mkdir()
    (source,) = node_run['bag'].glob('*.mcap')
    (cut / source.name).write_bytes(source.read_bytes()[: source.stat().st_size // 2])
    assert replay_main([str(cut / source.name)]) == 1
    assert '--recover' in capsys.readouterr().err

    foreign = tmp_path / 'foreign'
    writer = BagWriter(foreign, metadata={})
    channel = writer.add_topic('/thing', 'foreign_msgs/msg/Thing', 'int32 x\n', [])
    writer.write(channel, b'\x00\x01\x00\x00\x05\x00\x00\x00', 1, 1)
    writer.close()
    assert replay_main([str(foreign)]) == 1
    error = capsys.readouterr().err
    assert 'foreign_msgs/msg/Thing' in error and 'nothing to replay' in error

    assert replay_main([str(node_run['bag']), '--topics', '/nope']) == 1
    assert '/nope' in capsys.readouterr().err
    every_topic = list(LOGGED_TOPICS)
    assert replay_main([str(node_run['bag']), '--exclude-topics', *every_topic]) == 1
    assert 'every topic is excluded' in capsys.readouterr().err
    with pytest.raises(SystemExit) as exit_info:
        replay_main([str(node_run['bag']), '--rate', '-2'])
    assert exit_info.value.code == 2
    assert 'positive factor' in capsys.readouterr().err
