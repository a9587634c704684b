# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The shipped Foxglove/Lichtblick layout against a real node bag.

Read with independent readers (mcap, mcap-ros2-support, rosbags' message-definition parser), and
the paper quantities it plots as plain fields of /linkage/state.

The node runs once (the seed's variable-law turn) and logs a bag; every message path of the
layout is then parsed, walked through the ``ros2msg`` schema stored in that bag and evaluated on
every logged message, and the values it reads are compared with the library and the seed's table.
The efforts tab's paths are those of a loops node's bag (``loops:=robot_description`` with
``loops.output_joints``): the humanoid ankle's motors' efforts as measured, beside pitch's and
roll's as published, whose power balances the motors'.
"""
from __future__ import annotations

from collections.abc import Iterator
import json
import math
import re
from typing import Any

from linkage_kinematics.kinematics.drive import DriveLaw
from linkage_kinematics.kinematics.geometry import preset
from linkage_kinematics.kinematics.solver import solve
from linkage_kinematics.ros import messages
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from node_process import decode, NodeProcesses, REPOSITORY, ros_context
import pytest
from rosbags.interfaces import Nodetype
from rosbags.typesys import get_types_from_msg
from sensor_msgs.msg import JointState
from test_robot_loops import loop_node

NODE_EXIT_TIMEOUT = 60.0  # s; the stop run ends by itself after 1.57 s of motion
LAYOUT_FILE = REPOSITORY / 'foxglove' / 'linkage_layout.json'
TITLE_KEYS = ('foxglovePanelTitle', 'lichtblickPanelTitle')
PAPER = preset('paper').geometry
SEED_VARIABLE = DriveLaw(0.1, 2.3)
ALPHA_PATH = '/linkage/state.points[0].positions[0]'
# The α tab's x axis: crank_joint's position, α, in /joint_states, one message per state with the
# state's stamp. Lichtblick's Plot takes every message of the x axis's topic for x values only,
# so x must come from another topic than the plotted y values (docs/logging.md).
X_ALPHA_PATH = '/joint_states.position[0]'
# The least width per height of the 3D panel the framing is checked for: the layout's is about
# 2 on a 16:10 screen (42 % of the width, 40 % of the height less the toolbars), and wider
# panels see more.
SCENE_ASPECT = 1.2
# A message path without filters, slices or math modifiers: a topic, then fields with at most
# one constant index each, e.g. /linkage/state.points[0].velocities[7].
MESSAGE_PATH = re.compile(r'(?P<topic>/[A-Za-z0-9_/]+)(?P<fields>(?:\.[A-Za-z_]\w*(?:\[\d+\])?)+)')
FIELD = re.compile(r'\.([A-Za-z_]\w*)(?:\[(\d+)\])?')
NUMERIC_TYPES = {'float32', 'float64', 'int8', 'uint8', 'int16', 'uint16', 'int32', 'uint32',
                 'int64', 'uint64'}
# The efforts tab: the plots of a loops node's bag (the others: the four-bar's), read against
# the humanoid ankle's, its motors measured and its pitch and roll the output joints.
EFFORTS_TAB = 'Efforts'
ANKLE_URDF = REPOSITORY / 'urdf' / 'humanoid_ankle.urdf'
MOTORS = ['motor_left', 'motor_right']
ANKLE_OUTPUTS = ['ankle_pitch', 'ankle_roll']
EFFORT_SAMPLES = 50


def load_layout() -> dict[str, Any]:
    return json.loads(LAYOUT_FILE.read_text(encoding='utf-8'))


def plots(layout: dict[str, Any]) -> dict[str, dict[str, Any]]:
    return {key: config for key, config in layout['configById'].items()
            if key.startswith('Plot!')}


def effort_plots(layout: dict[str, Any]) -> dict[str, dict[str, Any]]:
    """Return the efforts tab's plots, which read a loops node's bag."""
    [tab_panel] = [config for key, config in layout['configById'].items()
                   if key.startswith('Tab!')]
    [tab] = [tab for tab in tab_panel['tabs'] if tab['title'] == EFFORTS_TAB]
    return {key: layout['configById'][key] for key in layout_tree_panels(tab['layout'])}


def plotted_paths(layout: dict[str, Any], four_bar: bool | None = None) -> list[str]:
    """
    Every message path the plots read: their series and their custom x axes.

    ``four_bar``: True, the plots of the four-bar's bag only; False, of a loops node's bag only.
    """
    efforts = effort_plots(layout)
    paths = []
    for key, config in plots(layout).items():
        if four_bar is not None and four_bar == (key in efforts):
            continue
        paths += [series['value'] for series in config['paths']]
        if config['xAxisVal'] == 'custom':
            paths.append(config['xAxisPath']['value'])
    return paths


def series_by_label(layout: dict[str, Any]) -> dict[str, str]:
    """Legend label -> message path; a label means the same path in every plot."""
    by_label: dict[str, str] = {}
    for config in plots(layout).values():
        for series in config['paths']:
            assert by_label.setdefault(series['label'], series['value']) == series['value']
    return by_label


def split_path(path: str) -> tuple[str, list[tuple[str, int | None]]]:
    """(topic, [(field, index or None)]) of a plain message path; fails on anything else."""
    match = MESSAGE_PATH.fullmatch(path)
    assert match, f'{path!r} is not a plain message path (topic, fields, [index])'
    fields = [(name, None if index == '' else int(index))
              for name, index in FIELD.findall(match['fields'])]
    return match['topic'], fields


def evaluate(message: Any, fields: list[tuple[str, int | None]], path: str) -> Any:
    value = message
    for name, index in fields:
        value = getattr(value, name)
        if index is not None:
            assert index < len(value), f'{path}: index {index} beyond the {len(value)} logged'
            value = value[index]
    return value


def strings(node: Any) -> Iterator[str]:
    """Every string (keys and values) in a JSON document."""
    if isinstance(node, str):
        yield node
    elif isinstance(node, dict):
        for key, value in node.items():
            yield key
            yield from strings(value)
    elif isinstance(node, list):
        for item in node:
            yield from strings(item)


def layout_tree_panels(node: Any) -> list[str]:
    if isinstance(node, str):
        return [node]
    return layout_tree_panels(node['first']) + layout_tree_panels(node['second'])


@pytest.fixture(scope='module')
def node_bag(
    tmp_path_factory: pytest.TempPathFactory, module_nodes: NodeProcesses
) -> dict[str, Any]:
    """
    Return the seed's variable-law turn, logged by the real node.

    The bag's schemas, channels and decoded messages per topic.
    """
    run_folder = tmp_path_factory.mktemp('layout_run')
    folder = run_folder / 'bags'
    process = module_nodes.start(
        {'omega0': SEED_VARIABLE.omega0, 'k': SEED_VARIABLE.k, 'alpha_start': 0.0,
         'alpha_end': math.pi / 2, 'end_behavior': 'stop', 'log.folder': str(folder)},
        run_folder / 'node.log',
    )
    status = process.wait(timeout=NODE_EXIT_TIMEOUT)
    assert status == 0, (run_folder / 'node.log').read_text()
    [mcap_file] = folder.glob('*/*.mcap')
    with open(mcap_file, 'rb') as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        summary = reader.get_summary()
        assert summary is not None
        schema_of_topic = {channel.topic: summary.schemas[channel.schema_id]
                           for channel in summary.channels.values()}
        decoded: dict[str, list[Any]] = {topic: [] for topic in schema_of_topic}
        log_times: dict[str, list[int]] = {topic: [] for topic in schema_of_topic}
        for _, channel, record, message in reader.iter_decoded_messages():
            decoded[channel.topic].append(message)
            log_times[channel.topic].append(record.log_time)
    return {'schemas': schema_of_topic, 'messages': decoded, 'log_times': log_times}


def read_bag(folder: Any) -> dict[str, Any]:
    """Return a node's bag in ``folder``: its schemas, channels and decoded messages per topic."""
    [mcap_file] = folder.glob('*/*.mcap')
    with open(mcap_file, 'rb') as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        summary = reader.get_summary()
        assert summary is not None
        schema_of_topic = {channel.topic: summary.schemas[channel.schema_id]
                           for channel in summary.channels.values()}
        decoded: dict[str, list[Any]] = {topic: [] for topic in schema_of_topic}
        for _, channel, _, message in reader.iter_decoded_messages():
            decoded[channel.topic].append(message)
    return {'schemas': schema_of_topic, 'messages': decoded}


@pytest.fixture(scope='module')
def efforts_bag(tmp_path_factory: pytest.TempPathFactory, module_nodes: NodeProcesses,
                domain_id: int) -> dict[str, Any]:
    """
    Return a loops node's bag of the humanoid ankle with efforts in and out.

    Its motors measured with their efforts, pitch and roll its output joints.
    """
    run_folder = tmp_path_factory.mktemp('efforts_run')
    parameters = {'robot_description': ANKLE_URDF.read_text(encoding='utf-8'),
                  'loops.measured_joints': MOTORS, 'loops.output_joints': ANKLE_OUTPUTS}
    with ros_context(domain_id) as context, loop_node(context, module_nodes, run_folder,
                                                      parameters) as node:
        for index in range(EFFORT_SAMPLES):
            phase = 2.0 * math.pi * index / EFFORT_SAMPLES
            message = JointState(name=MOTORS, position=[0.3 * math.sin(phase),
                                                        0.2 * math.sin(2.0 * phase)],
                                 velocity=[0.3 * math.cos(phase), 0.4 * math.cos(2.0 * phase)],
                                 effort=[2.0 + math.cos(phase), -1.5 * math.sin(phase)])
            stamp = 1_000_000_000 + index * 10_000_000
            message.header.stamp.sec, message.header.stamp.nanosec = divmod(stamp,
                                                                            1_000_000_000)
            node.inputs.publish(message)
            assert node.listener.spin_until(lambda: len(node.outputs) == index + 1)
        assert module_nodes.interrupt(node.process) == 0
    return read_bag(run_folder / 'bags')


# --- the layout on its own -----------------------------------------------------------------------


def test_every_panel_has_one_title_under_both_keys() -> None:
    layout = load_layout()
    for key, config in layout['configById'].items():
        titles = {config.get(title_key) for title_key in TITLE_KEYS}
        assert len(titles) == 1 and None not in titles and '' not in titles, key
        assert 'title' not in config, f"{key}: neither viewer reads the key 'title'"


def test_every_panel_is_placed_once_in_the_layout_or_a_tab() -> None:
    layout = load_layout()
    placed = layout_tree_panels(layout['layout'])
    for key, config in layout['configById'].items():
        if key.startswith('Tab!'):
            for tab in config['tabs']:
                placed += layout_tree_panels(tab['layout'])
    assert sorted(placed) == sorted(layout['configById'])


def test_no_math_modifiers_anywhere() -> None:
    layout = load_layout()
    assert not [text for text in strings(layout) if '.@' in text]
    for path in plotted_paths(layout):
        split_path(path)


def test_plots_carry_their_units_in_title_and_y_axis_label() -> None:
    for key, config in plots(load_layout()).items():
        [unit] = re.findall(r'\(([^)]+)\)', config['yAxisLabel'])
        assert f'({unit})' in config['foxglovePanelTitle'], key
        assert config['xAxisLabel'] == ('α (rad)' if config['xAxisVal'] == 'custom'
                                        else 'time (s)'), key


def test_first_tab_plots_over_time_second_reproduces_the_seeds_figures_against_alpha() -> None:
    layout = load_layout()
    [tab_panel] = [config for key, config in layout['configById'].items()
                   if key.startswith('Tab!')]
    assert tab_panel['activeTabIdx'] == 0
    over_time, against_alpha, efforts = (
        [layout['configById'][key] for key in layout_tree_panels(tab['layout'])]
        for tab in tab_panel['tabs']
    )

    def labels(configs: list[dict[str, Any]]) -> set[str]:
        return {series['label'] for config in configs for series in config['paths']}

    assert all(config['xAxisVal'] == 'timestamp' for config in over_time)
    # The node stamps each state with its time in the motion; plot against that.
    assert {series['timestampMethod'] for config in over_time
            for series in config['paths']} == {'headerStamp'}
    assert labels(over_time) == {'α', 'β', 'γ', 'ω', 'ω_AB', 'ω_BC', 'ω̇', 'ω̇_AB', 'ω̇_BC',
                                 'V_A', 'V_B'}
    assert all(config['xAxisVal'] == 'custom' and config['xAxisPath']
               == {'value': X_ALPHA_PATH, 'enabled': True} for config in against_alpha)
    assert labels(against_alpha) == {'β', 'γ', 'ω_AB', 'ω_BC', 'ω̇_AB', 'ω̇_BC', 'V_A', 'V_B'}
    # the third: a loops node's actuator efforts (its input) beside its output joints' (its
    # joint_states), over time at the input's stamps, which the answers carry
    assert [config['foxglovePanelTitle'] for config in efforts] == [
        'Actuator efforts, measured (N·m or N)', 'Output efforts, published (N·m or N)']
    assert all(config['xAxisVal'] == 'timestamp' for config in efforts)
    assert {series['timestampMethod'] for config in efforts
            for series in config['paths']} == {'headerStamp'}
    assert [[series['value'] for series in config['paths']] for config in efforts] == [
        ['/measured_joint_states.effort[0]', '/measured_joint_states.effort[1]'],
        ['/joint_states.effort[0]', '/joint_states.effort[1]']]


def test_scene_frames_the_whole_paper_mechanism_with_margin() -> None:
    """
    Check that the disk and every place pin B can reach lie inside the grid and the view.

    The disk has radius OA about O, pin B's places radius BC about C; the view is the 2D
    camera's of the layout's panel (SCENE_ASPECT; wider panels see more).
    """
    [three_d] = [config for key, config in load_layout()['configById'].items()
                 if key.startswith('3D!')]
    margin = 0.1  # m
    low_x = min(-PAPER.crank_length, PAPER.ground_x - PAPER.rocker_length)
    high_x = max(PAPER.crank_length, PAPER.ground_x + PAPER.rocker_length)
    high_y = max(PAPER.crank_length, abs(PAPER.ground_y) + PAPER.rocker_length)
    assert (low_x, high_x, high_y) == pytest.approx((-0.3, 1.6, 0.3))

    camera = three_d['cameraState']
    # 2D mode: an orthographic camera looking down z, x to the right, centred on targetOffset,
    # whose view is ``distance`` high and distance × (width/height) wide.
    assert (camera['perspective'], camera['phi'], camera['thetaOffset']) == (False, 0, 0)
    centre_x, centre_y, _ = camera['targetOffset']
    half_height = camera['distance'] / 2
    half_width = half_height * SCENE_ASPECT
    assert centre_x - half_width <= low_x - margin and high_x + margin <= centre_x + half_width
    assert centre_y - half_height <= -high_y - margin and high_y + margin <= centre_y + half_height

    grid = three_d['layers']['grid']
    grid_x, grid_y, grid_z = grid['position']
    half_grid = grid['size'] / 2
    assert grid_x - half_grid <= low_x - margin and high_x + margin <= grid_x + half_grid
    assert grid_y - half_grid <= -high_y - margin and high_y + margin <= grid_y + half_grid
    assert grid_z < 0.0  # below the disk and the bars
    # The grid fills a panel twice as wide as the layout's, around the mechanism.
    assert half_grid >= 2 * SCENE_ASPECT * half_height
    # Frame labels off, the frames' axes a quarter of their 0.2 m, TF preloaded so that a seek
    # finds every frame.
    assert three_d['scene']['transforms'] == {
        'showLabel': False, 'labelSize': 0.05, 'axisScale': 0.25, 'lineWidth': 1,
        'enablePreloading': True}
    # The URDF is posed by the bag's /tf (robot_state_publisher on a live system), under the
    # markers, which coincide with it.
    assert three_d['topics'] == {'/linkage/markers': {'visible': True},
                                 '/robot_description': {'visible': True}}


def test_legends_sit_beside_the_plots_and_tab_names_fit_their_tabs() -> None:
    layout = load_layout()
    for key, config in plots(layout).items():
        assert (config['showLegend'], config['legendDisplay']) == (True, 'left'), key
    [tab_panel] = [config for key, config in layout['configById'].items()
                   if key.startswith('Tab!')]
    # Lichtblick's tabs are at most 120 px wide (panels/Tab/ToolbarTab.tsx): about 14 letters.
    assert [tab['title'] for tab in tab_panel['tabs']] == ['Over time', 'Against α', EFFORTS_TAB]


# --- the layout against a real node bag ----------------------------------------------------------


@pytest.mark.parametrize('four_bar', [True, False])
def test_every_message_path_resolves_against_the_logged_definitions(
    node_bag: dict[str, Any], efforts_bag: dict[str, Any], four_bar: bool,
) -> None:
    """The four-bar's plots against its bag, the efforts tab's against a loops node's."""
    bag = node_bag if four_bar else efforts_bag
    for path in plotted_paths(load_layout(), four_bar):
        topic, fields = split_path(path)
        assert topic in bag['schemas'], f'{path}: the bag has no topic {topic}'
        schema = bag['schemas'][topic]
        assert schema.encoding == 'ros2msg'
        types = get_types_from_msg(schema.data.decode(), schema.name)
        type_name = schema.name
        leaf = None
        for name, index in fields:
            assert leaf is None, f'{path}: {name} follows the plain field before it'
            definition = dict(types[type_name][1])
            assert name in definition, f'{path}: {type_name} has no field {name}'
            node_type, detail = definition[name]
            if index is not None:
                assert node_type in (Nodetype.ARRAY, Nodetype.SEQUENCE), f'{path}: {name}'
                (node_type, detail), _ = detail
            if node_type == Nodetype.NAME:
                type_name = detail
            else:
                assert node_type == Nodetype.BASE, f'{path}: {name} is an array'
                leaf = detail[0]
        assert leaf in NUMERIC_TYPES, f'{path} ends in {leaf or type_name}, not a number'
        logged = bag['messages'][topic]
        assert logged
        for message in logged:
            assert isinstance(evaluate(message, fields, path), float | int)


def test_layout_names_only_topics_and_frames_the_node_logs(node_bag: dict[str, Any],
                                                           efforts_bag: dict[str, Any]) -> None:
    layout = load_layout()
    panels = layout['configById']
    assert {split_path(path)[0] for path in plotted_paths(layout, False)} == {
        '/measured_joint_states', '/joint_states'} <= set(efforts_bag['schemas'])
    named = {split_path(path)[0] for path in plotted_paths(layout, True)}
    [three_d] = [config for key, config in panels.items() if key.startswith('3D!')]
    named |= set(three_d['topics'])
    diagnostics = [config for key, config in panels.items() if key.startswith('Diagnostic')]
    assert len(diagnostics) == 2
    named |= {config['topicToRender'] for config in diagnostics}
    assert named == {'/linkage/state', '/joint_states', '/linkage/markers', '/robot_description',
                     '/diagnostics'}
    assert named <= set(node_bag['schemas'])

    frames = {marker.header.frame_id for array in node_bag['messages']['/linkage/markers']
              for marker in array.markers}
    assert frames == {three_d['followTf']} == {three_d['layers']['grid']['frameId']}


def test_custom_x_and_y_come_from_other_topics_with_equal_counts_and_stamps(
    node_bag: dict[str, Any],
) -> None:
    """
    Pair x and y values by index (Lichtblick's and Foxglove's custom x axis).

    So each plotted y stream and its x stream have one message per state with the same stamps;
    and x comes from another topic than y: Lichtblick reads the x topic's messages for x only.
    """
    custom = [config for config in plots(load_layout()).values()
              if config['xAxisVal'] == 'custom']
    assert len(custom) == 4
    for config in custom:
        x_topic, _ = split_path(config['xAxisPath']['value'])
        for series in config['paths']:
            y_topic, _ = split_path(series['value'])
            assert y_topic != x_topic, series['value']
            x_times, y_times = node_bag['log_times'][x_topic], node_bag['log_times'][y_topic]
            assert len(x_times) == len(y_times) > 100
            assert x_times == y_times
            stamps = [[message.header.stamp.sec * 10**9 + message.header.stamp.nanosec
                       for message in node_bag['messages'][topic]] for topic in (x_topic, y_topic)]
            assert stamps[0] == stamps[1] == x_times


def test_diagnostics_detail_panel_shows_the_status_the_node_logs(node_bag: dict[str, Any]) -> None:
    [detail] = [config for key, config in load_layout()['configById'].items()
                if key.startswith('DiagnosticStatusPanel!')]
    logged = {(status.hardware_id, status.name)
              for array in node_bag['messages']['/diagnostics'] for status in array.status}
    assert (detail['selectedHardwareId'], detail['selectedName']) in logged


def test_plotted_quantities_have_the_papers_signs_and_the_librarys_values(
    node_bag: dict[str, Any],
) -> None:
    by_label = series_by_label(load_layout())
    states = node_bag['messages']['/linkage/state']
    assert len(states) > 100

    def read(label_or_path: str) -> list[float]:
        path = by_label.get(label_or_path, label_or_path)
        topic, fields = split_path(path)
        return [evaluate(message, fields, path) for message in node_bag['messages'][topic]]

    alphas = read(ALPHA_PATH)
    assert alphas[0] == 0.0 and alphas[-1] == math.pi / 2
    assert read(X_ALPHA_PATH) == alphas  # the α tab's x values are the states' α
    library = [solve(PAPER, alpha, SEED_VARIABLE) for alpha in alphas]
    omega_bc = read('ω_BC')
    assert max(omega_bc) < 0.0  # clockwise over the whole turn, as in the seed's Table 3
    assert omega_bc == pytest.approx([state.omega_bc for state in library], rel=1e-12)
    assert read('ω̇_BC') == pytest.approx([state.omega_dot_bc for state in library], rel=1e-12)
    assert round(read('ω̇_BC')[-1], 2) == 15.36  # rad/s² at α = 90°, the seed's Table 4
    assert read('ω_AB') == pytest.approx([state.omega_ab for state in library], rel=1e-12)
    assert read('ω̇_AB') == pytest.approx([state.omega_dot_ab for state in library], rel=1e-12)
    # Both pins move forwards along their circles over the turn, so the signed V_A and V_B
    # equal the library's speeds.
    assert read('V_A') == pytest.approx([state.v_a for state in library], rel=1e-12)
    assert read('V_B') == pytest.approx([state.v_b for state in library], rel=1e-12)
    assert read('β') == pytest.approx([state.beta for state in library], rel=1e-12)
    assert read('γ') == pytest.approx([state.gamma for state in library], rel=1e-12)


def test_the_efforts_tab_shows_the_motors_measured_and_pitch_and_roll_published(
    efforts_bag: dict[str, Any],
) -> None:
    """What the efforts plots read: as sent, and as published, the power balanced."""
    layout = load_layout()
    actuator, output = effort_plots(layout).values()
    messages = efforts_bag['messages']
    inputs, answers = messages['/measured_joint_states'], messages['/joint_states']
    assert len(inputs) == len(answers) == EFFORT_SAMPLES
    assert [list(message.name) for message in inputs] == [MOTORS] * EFFORT_SAMPLES
    assert {tuple(message.name[:2]) for message in answers} == {tuple(ANKLE_OUTPUTS)}

    def read(config: dict[str, Any], topic_messages: list[Any]) -> list[list[float]]:
        found = []
        for series in config['paths']:
            _, fields = split_path(series['value'])
            found.append([evaluate(message, fields, series['value'])
                          for message in topic_messages])
        return found

    measured, published = read(actuator, inputs), read(output, answers)
    assert measured == [[message.effort[k] for message in inputs] for k in range(2)]
    for index, (given, answer) in enumerate(zip(inputs, answers)):
        assert stamp_of(given) == stamp_of(answer)
        motor_power = math.fsum(t * v for t, v in zip(given.effort, given.velocity))
        output_power = math.fsum(published[k][index] * answer.velocity[k] for k in range(2))
        assert output_power == pytest.approx(motor_power, rel=1e-12, abs=1e-12)


def stamp_of(message: Any) -> int:
    return message.header.stamp.sec * 10**9 + message.header.stamp.nanosec


# --- the paper's quantities as plain fields of /linkage/state ------------------------------------


def published_point(state: Any) -> Any:
    """Return the point of the node's linkage/state message of ``state``, as rosbags decodes it."""
    data = messages.LinkageStateEncoder(PAPER, 'o').encode(state, 0, 0.0)
    return decode(data, 'trajectory_msgs/msg/JointTrajectory').points[0]


@pytest.mark.parametrize('drive', [DriveLaw(2.0), SEED_VARIABLE, DriveLaw(-1.5, 0.4)])
@pytest.mark.parametrize('alpha_deg', [0.0, 17.0, 45.0, 90.0, 150.0])
def test_rocker_angle_and_pin_arcs_are_the_papers_coordinates(
    drive: DriveLaw, alpha_deg: float
) -> None:
    """
    θ_BC = π − β places B as C + BC·(cos θ, sin θ).

    V_A and V_B are the pins' velocities along (cos α, sin α) and (sin β, cos β) (the paper's Eqs.
    8a and 8b–9), their rates the tangential accelerations.
    """
    state = solve(PAPER, math.radians(alpha_deg), drive)
    point = published_point(state)
    rocker_angle, pin_a_arc, pin_b_arc = point.positions[7:]
    assert (PAPER.ground_x + PAPER.rocker_length * math.cos(rocker_angle),
            PAPER.ground_y + PAPER.rocker_length * math.sin(rocker_angle)) == pytest.approx(
        (state.pin_b_x, state.pin_b_y), abs=1e-15)
    assert (pin_a_arc, pin_b_arc) == pytest.approx(
        (PAPER.crank_length * state.alpha, PAPER.rocker_length * state.beta), rel=1e-15)

    omega_bc, v_a, v_b = point.velocities[7:]
    assert omega_bc == state.omega_bc
    along_a = (math.cos(state.alpha), math.sin(state.alpha))
    along_b = (math.sin(state.beta), math.cos(state.beta))
    assert v_a == pytest.approx(
        state.velocity_a_x * along_a[0] + state.velocity_a_y * along_a[1], rel=1e-12)
    assert v_b == pytest.approx(
        state.velocity_b_x * along_b[0] + state.velocity_b_y * along_b[1], rel=1e-12)
    assert (abs(v_a), abs(v_b)) == pytest.approx((state.v_a, state.v_b), rel=1e-12)

    omega_dot_bc, a_a, a_b = point.accelerations[7:]
    assert omega_dot_bc == state.omega_dot_bc
    assert a_a == pytest.approx(
        state.acceleration_a_x * along_a[0] + state.acceleration_a_y * along_a[1],
        rel=1e-12, abs=1e-12)
    assert a_b == pytest.approx(
        state.acceleration_b_x * along_b[0] + state.acceleration_b_y * along_b[1],
        rel=1e-12, abs=1e-12)


def test_plain_fields_match_the_seeds_table_for_the_constant_law() -> None:
    """Table 1 and 2 rows the seed gets right (see shared/seed/README.md)."""
    def fields(alpha: float) -> tuple[Any, Any]:
        state = solve(PAPER, alpha, DriveLaw(2.0))
        point = published_point(state)
        return point.velocities, point.accelerations

    velocities, accelerations = fields(0.0)
    assert round(velocities[7], 3) == -6.667  # ω_BC, rad/s
    assert round(velocities[9], 2) == 2.0  # V_B, m/s
    assert round(velocities[8], 2) == 0.6  # V_A = OA·ω, m/s
    assert round(accelerations[7], 2) == 192.59  # ω̇_BC, rad/s²
    velocities, _ = fields(math.pi / 2)
    assert round(velocities[9], 2) == 0.18  # V_B, m/s
