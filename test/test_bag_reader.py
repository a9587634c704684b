# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
bag.reader against bags written by an independent writer (mcap_ros2's), whole.

Cut and broken.
"""

from __future__ import annotations

import math
from pathlib import Path

from ament_index_python.packages import get_package_share_directory
from linkage_kinematics.bag.errors import BagError
from linkage_kinematics.bag.reader import bag_files, iter_messages, read_states
from linkage_kinematics.bag.state_layout import STATE_JOINT_NAMES, STATE_TOPIC
from linkage_kinematics.kinematics.drive import DriveLaw
from linkage_kinematics.kinematics.geometry import preset
from linkage_kinematics.kinematics.solver import LinkageState, solve_many
from mcap.writer import CompressionType
from mcap.writer import Writer as McapWriter
from mcap_ros2.decoder import DecoderFactory
from mcap_ros2.writer import Writer
import numpy as np
import pytest

STATE_TYPE = 'trajectory_msgs/msg/JointTrajectory'
STRING_TYPE = 'std_msgs/msg/String'
PAPER = preset('paper').geometry
START_NS = 1_700_000_000_000_000_000
PERIOD_NS = 50_000_000
_DEPENDENCIES = {
    STATE_TYPE: (
        'std_msgs/msg/Header',
        'builtin_interfaces/msg/Time',
        'trajectory_msgs/msg/JointTrajectoryPoint',
        'builtin_interfaces/msg/Duration',
    ),
    STRING_TYPE: (),
}


def message_definition(type_name: str) -> str:
    """Return the ros2msg schema text rosbag2 stores: the type, then each type it uses."""

    def text(name: str) -> str:
        package, _, message = name.split('/')
        return (Path(get_package_share_directory(package)) / 'msg' / f'{message}.msg').read_text()

    parts = [text(type_name)]
    for dependency in _DEPENDENCIES[type_name]:
        short_name = dependency.replace('/msg/', '/')
        parts.append('=' * 80 + f'\nMSG: {short_name}\n' + text(dependency))
    return '\n'.join(parts)


def state_message(
    state: LinkageState, index: int, stamp_ns: int, elapsed_s: float, seven: bool = False
) -> dict:
    """
    Build a /linkage/state JointTrajectory as docs/parameters.md (Topics) defines it.

    The geometry is the paper's; ``seven`` writes only the first seven coordinates, as bags logged
    before the rocker angle and the pin arcs were added hold.
    """
    row = state.at(index)
    crank, rocker = PAPER.crank_length, PAPER.rocker_length
    seconds, nanoseconds = divmod(stamp_ns, 1_000_000_000)
    elapsed_ns = round(elapsed_s * 1e9)
    count = 7 if seven else len(STATE_JOINT_NAMES)
    return {
        'header': {'stamp': {'sec': seconds, 'nanosec': nanoseconds}, 'frame_id': 'o'},
        'joint_names': list(STATE_JOINT_NAMES[:count]),
        'points': [{
            'positions': [row.alpha, row.beta, row.gamma,
                          row.pin_a_x, row.pin_a_y, row.pin_b_x, row.pin_b_y,
                          math.pi - row.beta, crank * row.alpha, rocker * row.beta][:count],
            'velocities': [row.omega, -row.omega_bc, row.omega_ab,
                           row.velocity_a_x, row.velocity_a_y,
                           row.velocity_b_x, row.velocity_b_y,
                           row.omega_bc, crank * row.omega, -rocker * row.omega_bc][:count],
            'accelerations': [row.omega_dot, -row.omega_dot_bc, row.omega_dot_ab,
                              row.acceleration_a_x, row.acceleration_a_y,
                              row.acceleration_b_x, row.acceleration_b_y,
                              row.omega_dot_bc, crank * row.omega_dot,
                              -rocker * row.omega_dot_bc][:count],
            'effort': [],
            'time_from_start': {'sec': elapsed_ns // 1_000_000_000,
                                'nanosec': elapsed_ns % 1_000_000_000},
        }],
    }


def paper_states(step_deg: float = 5.0, drive: DriveLaw = DriveLaw(2.0)) -> LinkageState:
    alpha = np.radians(np.arange(0.0, 90.0 + step_deg / 2, step_deg))
    return solve_many(PAPER, alpha, drive)


def write_mcap(
    path: Path,
    state: LinkageState | None,
    foreign: bool = True,
    chunk_size: int = 1024 * 1024,
    compression: CompressionType = CompressionType.ZSTD,
    finish: bool = True,
    seven: bool = False,
) -> list[int]:
    """
    Log ``state`` row by row on /linkage/state (with /chatter in between when ``foreign``).

    Returns the header stamps (ns). ``finish=False`` leaves the file as a killed recorder
    would: complete chunks only, no summary, no footer. ``seven``: as logged before the rocker
    angle and the pin arcs were added.
    """
    count = 0 if state is None else len(state.alpha)
    stamps = [START_NS + index * PERIOD_NS for index in range(count)]
    stream = open(path, 'wb')
    writer = Writer(stream, chunk_size=chunk_size, compression=compression)
    state_schema = writer.register_msgdef(STATE_TYPE, message_definition(STATE_TYPE))
    string_schema = writer.register_msgdef(STRING_TYPE, message_definition(STRING_TYPE))
    for index in range(max(count, 3 if foreign else 0)):
        log_time = START_NS + index * PERIOD_NS + 1_000_000
        if foreign:
            writer.write_message('/chatter', string_schema, {'data': f'hello {index}'},
                                 log_time=log_time - 500_000)
        if index < count:
            writer.write_message(
                STATE_TOPIC, state_schema,
                state_message(state, index, stamps[index], index * PERIOD_NS / 1e9, seven),
                log_time=log_time, publish_time=stamps[index],
            )
    if finish:
        writer.finish()
    stream.close()
    return stamps


def write_metadata(folder: Path, files: list[str], storage: str = 'mcap') -> None:
    listed = ''.join(f'\n    - {name}' for name in files)
    (folder / 'metadata.yaml').write_text(
        'rosbag2_bagfile_information:\n'
        '  version: 9\n'
        f'  storage_identifier: {storage}\n'
        f'  relative_file_paths:{listed}\n'
    )


def write_bag_folder(folder: Path, state: LinkageState, foreign: bool = True) -> list[int]:
    """Return a rosbag2 MCAP bag folder holding ``state``: metadata.yaml and one .mcap file."""
    folder.mkdir()
    stamps = write_mcap(folder / 'run_0.mcap', state, foreign=foreign)
    write_metadata(folder, ['run_0.mcap'])
    return stamps


def assert_states_equal(actual: LinkageState, expected: LinkageState, count: int) -> None:
    """
    Check every field but transmission_angle equal to the first ``count`` rows.

    transmission_angle is not on the wire.
    """
    for name in LinkageState.__dataclass_fields__:
        if name == 'transmission_angle':
            assert np.all(np.isnan(actual.transmission_angle))
            continue
        np.testing.assert_array_equal(getattr(actual, name), getattr(expected, name)[:count],
                                      err_msg=name)


def test_read_states_from_bag_folder_round_trips_every_field(tmp_path: Path) -> None:
    state = paper_states(drive=DriveLaw(0.1, 2.3))
    stamps = write_bag_folder(tmp_path / 'bag', state)
    times, logged = read_states(tmp_path / 'bag')
    assert times.dtype == np.int64
    assert times.tolist() == stamps
    assert_states_equal(logged, state, len(state.alpha))
    np.testing.assert_array_equal(logged.v_b, state.v_b)
    assert logged.omega_dot[-1] == pytest.approx(2.3 * (0.1 + 2.3 * math.pi / 2))


def test_read_states_from_a_bag_logged_with_seven_joint_names(tmp_path: Path) -> None:
    state = paper_states(drive=DriveLaw(0.1, 2.3))
    stamps = write_mcap(tmp_path / 'before.mcap', state, seven=True)
    [first, *_] = iter_messages(tmp_path / 'before.mcap', topics=[STATE_TOPIC])
    assert list(_decoder(STATE_TYPE)(first.data).joint_names) == list(STATE_JOINT_NAMES[:7])
    times, logged = read_states(tmp_path / 'before.mcap')
    assert times.tolist() == stamps
    assert_states_equal(logged, state, len(state.alpha))


def test_read_states_from_bare_mcap_file(tmp_path: Path) -> None:
    state = paper_states()
    stamps = write_mcap(tmp_path / 'run.mcap', state, foreign=False)
    times, logged = read_states(str(tmp_path / 'run.mcap'))
    assert times.tolist() == stamps
    assert_states_equal(logged, state, len(state.alpha))


def test_iter_messages_yields_every_message_raw_in_file_order(tmp_path: Path) -> None:
    state = paper_states(step_deg=30.0)  # 4 states
    write_bag_folder(tmp_path / 'bag', state)
    messages = list(iter_messages(tmp_path / 'bag'))
    assert [message.topic for message in messages] == ['/chatter', STATE_TOPIC] * 4
    assert {message.topic: message.schema_name for message in messages} == {
        '/chatter': STRING_TYPE, STATE_TOPIC: STATE_TYPE}
    states = [message for message in messages if message.topic == STATE_TOPIC]
    assert [message.publish_time_ns for message in states] == [
        START_NS + index * PERIOD_NS for index in range(4)]
    assert [message.log_time_ns for message in states] == [
        START_NS + index * PERIOD_NS + 1_000_000 for index in range(4)]
    topic, schema_name, data, log_time_ns, publish_time_ns = states[2]
    assert (topic, schema_name) == (STATE_TOPIC, STATE_TYPE)
    assert data[:4] == b'\x00\x01\x00\x00'  # CDR, little endian
    assert isinstance(data, bytes)
    chatter = [message for message in messages if message.topic == '/chatter']
    string_decoder = _decoder(STRING_TYPE)
    assert [string_decoder(message.data).data for message in chatter] == [
        f'hello {index}' for index in range(4)]
    only_states = list(iter_messages(tmp_path / 'bag', topics=[STATE_TOPIC]))
    assert only_states == states


def test_split_bag_reads_files_in_metadata_order(tmp_path: Path) -> None:
    state = paper_states(step_deg=10.0)  # 10 states
    folder = tmp_path / 'bag'
    folder.mkdir()
    first = solve_many(preset('paper').geometry, state.alpha[:6], DriveLaw(2.0))
    second = solve_many(preset('paper').geometry, state.alpha[6:], DriveLaw(2.0))
    # Names that sort the wrong way round: the order must come from metadata.yaml.
    write_mcap(folder / 'b_first.mcap', first, foreign=False)
    write_mcap(folder / 'a_second.mcap', second, foreign=False)
    write_metadata(folder, ['b_first.mcap', 'a_second.mcap'])
    _, logged = read_states(folder)
    assert_states_equal(logged, state, len(state.alpha))
    assert [file.path.name for file in bag_files(folder)] == ['b_first.mcap', 'a_second.mcap']


def test_folder_without_metadata_reads_its_mcap_files(tmp_path: Path) -> None:
    state = paper_states()
    folder = tmp_path / 'bag'
    folder.mkdir()
    write_mcap(folder / 'run_0.mcap', state)
    _, logged = read_states(folder)
    assert_states_equal(logged, state, len(state.alpha))


def test_killed_recorder_file_reads_its_complete_chunks(tmp_path: Path) -> None:
    state = paper_states(step_deg=1.0)  # 91 states, several chunks of about 2 kB
    path = tmp_path / 'killed.mcap'
    write_mcap(path, state, chunk_size=2000, finish=False)
    [scanned] = bag_files(path)
    assert scanned.truncated and scanned.readable_size == scanned.size
    times, logged = read_states(path)
    count = len(times)
    assert 10 < count < 91  # the open chunk was never written
    assert_states_equal(logged, state, count)


@pytest.mark.parametrize('compression', [CompressionType.ZSTD, CompressionType.NONE])
def test_file_cut_in_the_middle_reads_what_precedes_the_cut(
    tmp_path: Path, compression: CompressionType
) -> None:
    state = paper_states(step_deg=1.0)
    whole = tmp_path / 'whole.mcap'
    write_mcap(whole, state, chunk_size=2000, compression=compression)
    data = whole.read_bytes()
    cut = tmp_path / 'cut.mcap'
    cut.write_bytes(data[: len(data) // 2])
    [scanned] = bag_files(cut)
    assert scanned.truncated and scanned.readable_size < scanned.size == len(data) // 2
    times, logged = read_states(cut)
    assert 10 < len(times) < 91
    assert_states_equal(logged, state, len(times))
    assert not bag_files(whole)[0].truncated


def test_unchunked_file_cut_inside_a_message_never_yields_a_short_message(tmp_path: Path) -> None:
    source = tmp_path / 'source.mcap'
    write_mcap(source, paper_states(step_deg=30.0), foreign=False)
    originals = list(iter_messages(source))
    unchunked = tmp_path / 'unchunked.mcap'
    with open(unchunked, 'wb') as stream:
        writer = McapWriter(stream, use_chunking=False)
        writer.start(profile='ros2')
        schema_id = writer.register_schema(STATE_TYPE, 'ros2msg',
                                           message_definition(STATE_TYPE).encode())
        channel_id = writer.register_channel(STATE_TOPIC, 'cdr', schema_id)
        for message in originals:
            writer.add_message(channel_id, message.log_time_ns, message.data,
                               message.publish_time_ns)
        end_of_messages = stream.tell()
        writer.finish()
    data = unchunked.read_bytes()
    cut = tmp_path / 'cut.mcap'
    cut.write_bytes(data[: end_of_messages - 40])  # inside the last message's data
    assert list(iter_messages(cut)) == originals[:-1]


def test_file_with_only_the_start_written_has_no_states(tmp_path: Path) -> None:
    whole = tmp_path / 'whole.mcap'
    write_mcap(whole, paper_states(), foreign=False)
    cut = tmp_path / 'cut.mcap'
    cut.write_bytes(whole.read_bytes()[:30])
    assert list(iter_messages(cut)) == []
    with pytest.raises(BagError, match=r'holds no /linkage/state messages \(topics present: none'):
        read_states(cut)


def test_missing_path(tmp_path: Path) -> None:
    with pytest.raises(BagError, match='no bag at .*nothing_here: no such file or folder'):
        read_states(tmp_path / 'nothing_here')


def test_not_mcap_file(tmp_path: Path) -> None:
    text = tmp_path / 'notes.mcap'
    text.write_text('alpha,beta\n0,0\n')
    with pytest.raises(BagError, match=r"notes.mcap is not an MCAP file: it starts with b'alpha,"):
        read_states(text)
    empty = tmp_path / 'empty.mcap'
    empty.write_bytes(b'')
    with pytest.raises(BagError, match='empty.mcap is not an MCAP file: it is empty'):
        list(iter_messages(empty))


def test_folder_that_is_not_a_bag(tmp_path: Path) -> None:
    with pytest.raises(BagError, match='no metadata.yaml and no .mcap file'):
        read_states(tmp_path)


def test_bag_with_only_foreign_topics(tmp_path: Path) -> None:
    folder = tmp_path / 'bag'
    folder.mkdir()
    write_mcap(folder / 'run_0.mcap', None, foreign=True)
    write_metadata(folder, ['run_0.mcap'])
    assert len(list(iter_messages(folder))) == 3
    with pytest.raises(BagError, match=r'no /linkage/state messages \(topics present: /chatter\)'):
        read_states(folder)


def test_metadata_problems(tmp_path: Path) -> None:
    folder = tmp_path / 'bag'
    write_bag_folder(folder, paper_states())
    write_metadata(folder, ['run_0.db3'], storage='sqlite3')
    with pytest.raises(BagError, match="stores its messages in 'sqlite3'; only MCAP bags"):
        read_states(folder)
    write_metadata(folder, ['run_0.mcap', 'run_1.mcap'])
    with pytest.raises(BagError, match='lists files that are missing: .*run_1.mcap'):
        read_states(folder)
    (folder / 'metadata.yaml').write_text('just: [unclosed\n')
    with pytest.raises(BagError, match='metadata.yaml is not rosbag2 bag metadata'):
        read_states(folder)


def test_damaged_chunk_is_reported(tmp_path: Path) -> None:
    path = tmp_path / 'run.mcap'
    write_mcap(path, paper_states(), foreign=False)
    data = bytearray(path.read_bytes())
    middle = len(data) // 3  # inside the one compressed chunk
    data[middle:middle + 8] = bytes(byte ^ 0xFF for byte in data[middle:middle + 8])
    path.write_bytes(bytes(data))
    with pytest.raises(BagError, match='run.mcap is damaged'):
        read_states(path)


def test_state_messages_off_contract_are_rejected(tmp_path: Path) -> None:
    path = tmp_path / 'run.mcap'
    state = paper_states(step_deg=45.0)
    with open(path, 'wb') as stream:
        writer = Writer(stream)
        schema = writer.register_msgdef(STATE_TYPE, message_definition(STATE_TYPE))
        message = state_message(state, 0, START_NS, 0.0)
        message['joint_names'] = ['crank_joint'] * 7
        writer.write_message(STATE_TOPIC, schema, message, log_time=START_NS)
        writer.finish()
    with pytest.raises(BagError, match=r"message 0 .* has joint_names \['crank_joint'"):
        read_states(path)
    with open(path, 'wb') as stream:
        writer = Writer(stream)
        schema = writer.register_msgdef(STATE_TYPE, message_definition(STATE_TYPE))
        message = state_message(state, 0, START_NS, 0.0)
        message['points'][0]['velocities'] = message['points'][0]['velocities'][:7]
        writer.write_message(STATE_TOPIC, schema, message, log_time=START_NS)
        writer.finish()
    with pytest.raises(BagError, match=r'message 0 .* has 7 velocities; expected 10 \(one per'):
        read_states(path)
    with open(path, 'wb') as stream:
        writer = Writer(stream)
        schema = writer.register_msgdef(STRING_TYPE, message_definition(STRING_TYPE))
        writer.write_message(STATE_TOPIC, schema, {'data': '0.5'}, log_time=START_NS)
        writer.finish()
    with pytest.raises(BagError, match='has type std_msgs/msg/String; expected '
                                       'trajectory_msgs/msg/JointTrajectory'):
        read_states(path)


def _decoder(type_name: str):
    from mcap.records import Schema

    schema = Schema(id=1, name=type_name, encoding='ros2msg',
                    data=message_definition(type_name).encode())
    return DecoderFactory().decoder_for('cdr', schema)
