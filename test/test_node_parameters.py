# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
linkage_node's parameters.

Validation as pure functions, rejection at start-up (one line naming the parameter, exit status 2,
nothing written) and at run time over the parameter services; the lists of names of both nodes
string arrays, also when empty.
"""

from __future__ import annotations

import math
import re

from diagnostic_msgs.msg import DiagnosticArray
from linkage_kinematics.kinematics.drive import DriveLaw
from linkage_kinematics.kinematics.geometry import FourBar, preset
from linkage_kinematics.kinematics.solver import solve
from linkage_kinematics.model.joints import Link
from linkage_kinematics.model.urdf import urdf_text
from linkage_kinematics.ros.command_node import CommandNode
from linkage_kinematics.ros.messages import DISK_ID, PIN_A_ID
from linkage_kinematics.ros.node import LinkageNode
from linkage_kinematics.ros.parameters import parameter_descriptor
from linkage_kinematics.run.configuration import build_configuration
from linkage_kinematics.run.parameter_specs import (
    Kind,
    PARAMETER_NAMES,
    parameter_specs,
    ParameterSpec,
    RELAY_SPECS,
    unknown_parameters,
)
from linkage_kinematics.run.parameter_values import ConfigurationError, parameter_value
from node_process import (
    configuration_values,
    get_parameter,
    Listener,
    PROCESS_TIMEOUT,
    REPOSITORY,
    ros_context,
    set_parameter,
)
import pytest
import rclpy
from rclpy.parameter import Parameter, parameter_value_to_python
from rclpy.parameter_client import AsyncParameterClient
from sensor_msgs.msg import JointState
from std_msgs.msg import String
from trajectory_msgs.msg import JointTrajectory
from visualization_msgs.msg import MarkerArray

PAPER = preset('paper').geometry
DEAD_POINT = min(PAPER.reachability.dead_points, key=abs)  # ≈ −1.94°

# (parameter overrides, the parameter the error must name): one case per class of bad value.
BAD_VALUES = {
    'negative length': ({'crank_length': -1.0}, 'crank_length'),
    'zero length': ({'coupler_length': 0.0}, 'coupler_length'),
    'nan': ({'rocker_length': math.nan}, 'rocker_length'),
    'inf': ({'k': math.inf}, 'k'),
    'wrong type': ({'omega0': 'fast'}, 'omega0'),
    'wrong type int': ({'branch': 1.0}, 'branch'),
    'direction not an integer': ({'joints.crank.direction': 1.0}, 'joints.crank.direction'),
    'branch not ±1': ({'branch': 0}, 'branch'),
    'unknown preset': ({'preset': 'paper_v2'}, 'preset'),
    'no geometry without preset': ({'preset': ''}, 'crank_length'),
    'geometry cannot close': ({'ground_x': 5.0}, 'ground_x'),
    'unknown mode': ({'mode': 'warp'}, 'mode'),
    'unknown end_behavior': ({'end_behavior': 'explode'}, 'end_behavior'),
    'alpha_start unreachable': ({'alpha_start': 3.5}, 'alpha_start'),
    'alpha_start at a dead point': ({'alpha_start': DEAD_POINT}, 'alpha_start'),
    'alpha_end never reached': ({'alpha_end': -0.5}, 'alpha_end'),
    'alpha_end is alpha_start': ({'alpha_end': 0.0}, 'alpha_end'),
    'crank at rest': ({'omega0': 0.0}, 'omega0'),
    'rate zero': ({'rate_hz': 0.0}, 'rate_hz'),
    'rate too high': ({'rate_hz': 20000.0}, 'rate_hz'),
    'display rate negative': ({'display_rate_hz': -1.0}, 'display_rate_hz'),
    'alpha_step zero': ({'alpha_step': 0.0}, 'alpha_step'),
    'empty frame': ({'frame_id': ''}, 'frame_id'),
    'threshold out of range': ({'diagnostics.min_transmission_angle': 2.0},
                               'diagnostics.min_transmission_angle'),
}
# The classes checked in a node process too (each costs a process start).
PROCESS_CASES = [
    'negative length', 'nan', 'wrong type', 'branch not ±1', 'unknown preset',
    'no geometry without preset', 'unknown mode', 'alpha_start unreachable',
    'alpha_end never reached', 'rate too high',
]


@pytest.mark.parametrize('case', list(BAD_VALUES))
def test_build_configuration_names_the_bad_parameter(case):
    overrides, parameter = BAD_VALUES[case]
    values = configuration_values(**overrides)
    if case == 'no geometry without preset':
        values.update(dict.fromkeys(
            ('crank_length', 'coupler_length', 'rocker_length', 'ground_x', 'ground_y')))
    with pytest.raises(ConfigurationError) as raised:
        build_configuration(values)
    assert parameter in raised.value.parameter
    assert str(raised.value).startswith(raised.value.parameter + ': ')


NUMERIC_SPECS = [spec for spec in parameter_specs('paper')
                 if spec.kind in (Kind.REAL, Kind.INTEGER, Kind.SIGN)]


def refused(name: str, value: object) -> ConfigurationError:
    """Return the error build_configuration raises for the defaults with ``name`` = ``value``."""
    with pytest.raises(ConfigurationError) as raised:
        build_configuration(configuration_values(**{name: value}))
    assert raised.value.parameter == name
    return raised.value


@pytest.mark.parametrize('spec', NUMERIC_SPECS, ids=lambda spec: spec.name)
def test_the_descriptors_range_is_the_one_validated(spec):
    """Just outside the range ros2 param describe shows is refused, its ends are accepted."""
    descriptor = parameter_descriptor(spec)
    if spec.kind is Kind.REAL:
        (interval,) = descriptor.floating_point_range
        low, high = interval.from_value, interval.to_value
        # The descriptor cannot show an open end: its description says it (docs/parameters.md).
        open_low = 'greater than' in descriptor.description
        assert spec.interval.open_low == open_low
        bounds = (f'greater than {low:g} {spec.unit} and at most {high:g} {spec.unit}' if open_low
                  else f'in [{low:g}, {high:g}] {spec.unit}')
        assert bounds in str(refused(spec.name, math.nextafter(high, math.inf)))
        assert bounds in str(refused(spec.name, math.nextafter(low, -math.inf)))
        inside = [high, math.nextafter(low, math.inf) if open_low else low]
        if open_low:
            assert bounds in str(refused(spec.name, low))
    else:
        (interval,) = descriptor.integer_range
        low, high, step = interval.from_value, interval.to_value, interval.step
        assert f'{high}' in str(refused(spec.name, high + 1))
        assert f'{low}' in str(refused(spec.name, low - 1))
        if step > 1:
            refused(spec.name, low + 1)
        inside = [low, high]
    for value in inside:
        assert parameter_value({spec.name: value}, spec.name) == value


def test_an_integer_parameter_refuses_what_lies_between_its_off_value_and_its_range():
    (spec,) = [spec for spec in NUMERIC_SPECS if spec.name == 'log.max_bag_size']
    assert spec.off.value + 1 < spec.interval.low
    assert str(refused(spec.name, spec.interval.low - 1)) == (
        f'log.max_bag_size: must be 0 (no split) or a size in [1024, {2**63 - 1}] bytes, got '
        'int 1023')


SUPERSCRIPTS = str.maketrans('⁰¹²³⁴⁵⁶⁷⁸⁹', '0123456789')


def documented_number(text: str) -> float:
    """Return a bound as docs/parameters.md writes it: 0, 10000, −10⁶, π/2, 2π."""
    sign, text = (-1.0, text[1:]) if text.startswith('−') else (1.0, text)
    power = re.fullmatch(r'10([⁰-⁹]+)', text)
    if power:
        return sign * 10.0 ** int(power[1].translate(SUPERSCRIPTS))
    factor, pi, divisor = re.fullmatch(r'(\d*)(π?)(?:/(\d+))?', text).groups()
    value = float(factor or 1) * (math.pi if pi else 1.0) / float(divisor or 1)
    return sign * value


def test_the_parameter_reference_states_each_real_parameters_range_as_validated():
    """docs/parameters.md's table gives each real parameter's range as its spec has it."""
    reference = (REPOSITORY / 'docs' / 'parameters.md').read_text(encoding='utf-8')
    table = reference[reference.index('## Parameters'):reference.index('**Geometry.**')]
    stated = {}
    for row in table.splitlines():
        cells = row.split('|')
        interval = re.search(r'in ([\[(])([^,]+), ([^\]]+)\]', row)
        if len(cells) < 4 or interval is None:
            continue
        for name in re.findall(r'`([^`]+)`', cells[1]):
            for link in Link:
                stated[name.replace('<joint>', link.value)] = (
                    documented_number(interval[2]), documented_number(interval[3]),
                    interval[1] == '(')
    reals = {spec.name: spec for spec in parameter_specs('') if spec.kind is Kind.REAL}
    assert set(reals) <= set(stated)
    for name, spec in reals.items():
        low, high, open_low = stated[name]
        assert (low, high) == pytest.approx((spec.interval.low, spec.interval.high)), name
        assert open_low == spec.interval.open_low, name


@pytest.mark.parametrize('preset_name', ['', 'paper', 'paper_full_turn', 'grashof_crank_rocker'])
def test_every_default_passes_its_own_check(preset_name):
    for spec in parameter_specs(preset_name):
        if spec.default is not None:
            assert parameter_value({spec.name: spec.default}, spec.name) == spec.default


def test_a_spec_without_what_its_kind_needs_is_refused():
    with pytest.raises(TypeError, match='real parameter rate_hz needs interval'):
        ParameterSpec('rate_hz', 100.0, 'rate', Kind.REAL, unit='Hz')
    with pytest.raises(TypeError, match='choice parameter mode needs choices'):
        ParameterSpec('mode', 'real_time', 'mode', Kind.CHOICE)


def test_defaults_are_the_seed_run_swinging_until_stopped():
    config = build_configuration(configuration_values())
    assert config.geometry.linkage == PAPER
    assert config.motion.drive == DriveLaw(2.0, 0.0)
    motion = config.motion
    assert (motion.alpha_start, motion.alpha_end, motion.end_behavior, motion.mode) == (
        0.0, math.pi / 2.0, 'bounce', 'real_time')
    assert config.autostart
    assert config.motion.blocked_at is None
    assert config.motion.segment_duration == math.pi / 4.0
    assert set(configuration_values()) == set(PARAMETER_NAMES)


def test_explicit_geometry_overrides_the_preset_and_integers_are_accepted():
    config = build_configuration(configuration_values(crank_length=0.25, ground_x=1))
    assert config.geometry.linkage == FourBar(0.25, PAPER.coupler_length, PAPER.rocker_length,
                                              1.0, 0.0)
    explicit = build_configuration(configuration_values(preset=''))
    assert explicit.geometry.linkage == PAPER and explicit.geometry.preset == ''


def test_alpha_end_beyond_a_dead_point_runs_to_the_dead_point():
    config = build_configuration(configuration_values(omega0=-1.0, alpha_end=-1.0))
    assert config.motion.blocked_at == pytest.approx(DEAD_POINT, abs=1e-15)
    assert config.motion.segment_end == config.motion.blocked_at
    assert config.motion.segment_duration == DriveLaw(-1.0).time_to(0.0, config.motion.blocked_at)


# A lab's linkage whose crank can reach neither 0 nor 90° (only about 135°–315°): the drive
# law's defaults (alpha_start 0, alpha_end 90°) are outside its reach.
BEYOND_DEFAULTS = {'preset': '', 'crank_length': 0.3, 'coupler_length': 1.0,
                   'rocker_length': 0.3, 'ground_x': -0.9, 'ground_y': 0.9}


@pytest.mark.parametrize('overrides', [
    {'omega0': 0.0},  # a drive law that cannot move the crank
    {'alpha_end': 0.0},  # an empty pass
    {'omega0': -1.0, 'alpha_end': 2.0},  # a pass the drive law never ends
    BEYOND_DEFAULTS,
], ids=['crank at rest', 'empty pass', 'pass never ends', 'crank cannot reach 0-90°'])
def test_measured_mode_does_not_check_the_drive_law(overrides):
    values = configuration_values(source='measured', **overrides)
    config = build_configuration(values)
    assert config.joints.source == 'measured'
    motion = config.motion
    assert (motion.blocked_at, motion.segment_duration, motion.step_count) == (None, 0.0, 1)
    # The same values with the drive law are refused: the guard decides, not the values.
    with pytest.raises(ConfigurationError):
        build_configuration({**values, 'source': 'drive_law'})


def test_the_measured_node_starts_where_the_drive_laws_defaults_cannot(nodes, tmp_path):
    """A lab whose crank cannot reach alpha_start … alpha_end follows its encoder at once."""
    with ros_context(nodes.domain_id) as context:
        listener = Listener('measured_start_listener', context)
        listener.subscribe('/diagnostics', DiagnosticArray)
        process = nodes.start({'source': 'measured', 'omega0': 0.0, 'log.enabled': False,
                               **BEYOND_DEFAULTS}, tmp_path / 'node.log')
        try:
            statuses = listener.received['/diagnostics']
            assert listener.spin_until(lambda: any(
                status.message.startswith('no valid sample of crank_joint received yet')
                for array in statuses for status in array.status)), (
                tmp_path / 'node.log').read_text()
            assert process.poll() is None
        finally:
            listener.destroy()


def test_only_motion_changes_restart_the_motion():
    config = build_configuration(configuration_values())
    display = build_configuration(configuration_values(
        display_rate_hz=10.0, cpu_affinity=0, **{'diagnostics.dead_point_warning': 0.1}))
    faster = build_configuration(configuration_values(omega0=3.0))
    assert not display.restarts_motion(config)
    assert faster.restarts_motion(config)
    # The motion's fields are listed, not those that leave it alone: a field outside the list
    # (here a measured source's threshold) restarts nothing ...
    patient = build_configuration(configuration_values(**{'measured.timeout': 5.0}))
    assert patient != config
    assert not patient.restarts_motion(config)
    # ... and each kind of motion change restarts it.
    for change in ({'ground_x': 1.01}, {'branch': -1}, {'alpha_end': 1.0},
                   {'end_behavior': 'loop'}, {'rate_hz': 50.0}):
        assert build_configuration(configuration_values(**change)).restarts_motion(config), change


@pytest.mark.parametrize('case', PROCESS_CASES)
def test_bad_value_at_start_up_ends_the_node_with_one_clear_line(nodes, tmp_path, case):
    overrides, parameter = BAD_VALUES[case]
    bags = tmp_path / 'bags'
    status, output = nodes.run({**overrides, 'log.folder': str(bags)}, tmp_path / 'node.log')
    assert status == 2, output
    assert 'Traceback' not in output
    plain = [line for line in output.splitlines() if line.startswith('linkage_node: invalid')]
    assert len(plain) == 1, output
    assert plain[0].startswith(f'linkage_node: invalid parameter {parameter}'), output
    assert any('[FATAL]' in line and parameter in line for line in output.splitlines()), output
    assert not bags.exists()


def test_unwritable_log_folder_is_a_start_up_error(nodes, tmp_path):
    blocker = tmp_path / 'not_a_folder'
    blocker.write_text('')
    status, output = nodes.run({'log.folder': str(blocker / 'bags')}, tmp_path / 'node.log')
    assert status == 2, output
    assert 'invalid parameter log.folder' in output
    assert blocker.read_text() == ''


def test_unknown_parameters_are_named_with_the_closest_known_name():
    declared = [*PARAMETER_NAMES, 'use_sim_time']
    assert unknown_parameters(['rate', 'omega0', 'use_sim_time', 'log.enable', 'xyzzy'],
                              declared) == [
        "unknown parameter 'log.enable' ignored: linkage_node has no such parameter; did you "
        "mean 'log.enabled'?",
        "unknown parameter 'rate' ignored: linkage_node has no such parameter; did you mean "
        "'rate_hz'?",
        "unknown parameter 'xyzzy' ignored: linkage_node has no such parameter",
    ]
    assert unknown_parameters(declared, declared) == []


def test_an_unknown_parameter_gets_a_warning_and_the_node_runs_on(nodes, tmp_path):
    # A misspelt -p, and a wildcard entry of a parameters file shared with other nodes.
    shared = tmp_path / 'shared.yaml'
    shared.write_text('/**:\n  ros__parameters:\n    use_sim_time: false\n    gain: 0.5\n'
                      '/other_node:\n  ros__parameters:\n    rate: 7\n')
    status, output = nodes.run(
        {'rate': 50, 'end_behavior': 'stop', 'log.enabled': False},
        tmp_path / 'node.log', ros_arguments=['--params-file', str(shared)])
    assert status == 0, output
    warnings = [line for line in output.splitlines() if '[WARN]' in line]
    assert len(warnings) == 2, output
    assert warnings[0].endswith(
        "unknown parameter 'gain' ignored: linkage_node has no such parameter")
    assert warnings[1].endswith(
        "unknown parameter 'rate' ignored: linkage_node has no such parameter; did you mean "
        "'rate_hz'?")


def test_run_time_changes_are_validated_whole_and_applied_atomically(nodes, tmp_path):
    with ros_context(nodes.domain_id) as context:
        listener = Listener('parameter_tester', context)
        listener.subscribe('/joint_states', JointState)
        listener.subscribe('/linkage/state', JointTrajectory)
        process = nodes.start(
            {'end_behavior': 'bounce', 'rate_hz': 100.0, 'log.enabled': False},
            tmp_path / 'node.log')
        try:
            client = AsyncParameterClient(listener.node, 'linkage_node')
            assert client.wait_for_services(timeout_sec=PROCESS_TIMEOUT)
            assert listener.spin_until(lambda: listener.received['/joint_states'])

            rejected = {
                'crank_length': -1.0,       # bad on its own
                'omega0': 'fast',          # wrong type
                'alpha_start': 3.5,        # fine on its own, unreachable for this mechanism
                'rate_hz': 0.0,
                'log.folder': 'elsewhere',  # read-only
                'preset': '',              # read-only
            }
            for name, value in rejected.items():
                before = get_parameter(client, listener, name)
                successful, reason = set_parameter(client, listener, name, value)
                assert not successful
                assert name in reason
                assert get_parameter(client, listener, name) == before

            count = len(listener.received['/joint_states'])
            assert listener.spin_until(lambda: len(listener.received['/joint_states']) > count + 5)

            assert set_parameter(client, listener, 'omega0', 4.0) == (True, '')
            states = listener.received['/linkage/state']
            assert listener.spin_until(lambda: states[-1].points[0].velocities[0] == 4.0)
            changed_at = len(states)
            assert listener.spin_until(lambda: len(states) > changed_at + 5)
            speeds = {abs(message.points[0].velocities[0]) for message in states[changed_at:]}
            assert speeds == {4.0}

            listener.subscribe('/robot_description', String, transient_local=True)
            listener.subscribe('/linkage/markers', MarkerArray)
            assert set_parameter(client, listener, 'crank_length', 0.25) == (True, '')
            smaller = FourBar(0.25, PAPER.coupler_length, PAPER.rocker_length, PAPER.ground_x)
            descriptions = listener.received['/robot_description']
            assert listener.spin_until(
                lambda: descriptions and descriptions[-1].data == urdf_text(smaller))
            joint_states = listener.received['/joint_states']
            changed_at = len(joint_states)
            assert listener.spin_until(lambda: len(joint_states) > changed_at + 10)
            for message in joint_states[-5:]:
                state = solve(smaller, message.position[0], DriveLaw(
                    math.copysign(4.0, message.velocity[0])))
                assert tuple(message.velocity)[0] == state.omega
                assert message.velocity[1] == state.omega_ab - state.omega
            # The scene follows the new geometry: the disk's diameter and pin A's circle.
            scenes = listener.received['/linkage/markers']
            assert listener.spin_until(
                lambda: scenes and scenes[-1].markers[DISK_ID].scale.x == 0.5)
            changed_at = len(scenes) - 1
            assert listener.spin_until(lambda: len(scenes) > changed_at + 3)
            for scene in scenes[changed_at:]:
                pin_a = scene.markers[PIN_A_ID].pose.position
                assert math.hypot(pin_a.x, pin_a.y) == pytest.approx(0.25, abs=1e-12)
                assert scene.markers[DISK_ID].scale.x == 0.5
            assert process.poll() is None
        finally:
            listener.destroy()


def test_parameters_keep_their_types_show_their_ranges_and_unchanged_sets_change_nothing(
    nodes, tmp_path,
):
    output = tmp_path / 'node.log'
    with ros_context(nodes.domain_id) as context:
        listener = Listener('parameter_contract_tester', context)
        listener.subscribe('/linkage/state', JointTrajectory)
        states = listener.received['/linkage/state']
        process = nodes.start(
            {'preset': 'grashof_crank_rocker', 'alpha_end': 2.0 * math.pi,
             'end_behavior': 'loop', 'rate_hz': 50, 'log.enabled': False},
            output)
        try:
            client = AsyncParameterClient(listener.node, 'linkage_node')
            assert client.wait_for_services(timeout_sec=PROCESS_TIMEOUT)

            # Every numeric parameter's descriptor carries its range (/describe_parameters).
            numeric = [spec.name for spec in parameter_specs('paper')
                       if isinstance(spec.default, (int, float))
                       and not isinstance(spec.default, bool)]
            descriptors = listener.result_of(client.describe_parameters(numeric)).descriptors
            for name, descriptor in zip(numeric, descriptors):
                assert descriptor.name == name
                assert descriptor.floating_point_range or descriptor.integer_range, name
            (rate_range,) = descriptors[numeric.index('rate_hz')].floating_point_range
            assert (rate_range.from_value, rate_range.to_value) == (0.0, 10000.0)

            # A whole number for a real parameter, at start-up and at run time, stays a real.
            def rate() -> object:
                (value,) = listener.result_of(client.get_parameters(['rate_hz'])).values
                return parameter_value_to_python(value)

            assert rate() == 50.0 and isinstance(rate(), float)
            assert set_parameter(client, listener, 'rate_hz', 60) == (True, '')
            assert rate() == 60.0 and isinstance(rate(), float)
            successful, reason = set_parameter(client, listener, 'rate_hz', 0)
            assert not successful and reason == set_parameter(client, listener, 'rate_hz', 0.0)[1]

            # Setting every writable parameter to its current value (as `ros2 param load` of the
            # node's own dump does) restarts nothing: time_from_start keeps counting.
            assert listener.spin_until(lambda: len(states) >= 3)
            writable = [spec.name for spec in parameter_specs('grashof_crank_rocker')
                        if not spec.read_only]
            values = listener.result_of(client.get_parameters(writable)).values
            before = len(states)
            results = listener.result_of(client.set_parameters(
                [Parameter(name, value=parameter_value_to_python(value))
                 for name, value in zip(writable, values)])).results
            assert all(result.successful for result in results)
            assert listener.spin_until(lambda: len(states) > before + 10)
            times = [m.points[0].time_from_start.sec * 10**9 + m.points[0].time_from_start.nanosec
                     for m in states[before - 1:]]
            assert times == sorted(times)
            assert process.poll() is None
        finally:
            listener.destroy()
    log = output.read_text()
    assert log.count('parameters changed') == 1 and 'parameters changed: rate_hz=60.0' in log


@pytest.mark.parametrize(('node_type', 'specs', 'given'), [
    (LinkageNode, {spec.name: spec for spec in parameter_specs('paper')}, {}),
    # the relay needs its output joints: the description, from the topic, comes later
    (CommandNode, RELAY_SPECS, {'loops.output_joints': 'knee_output'})])
def test_an_empty_list_of_names_is_an_empty_string_array(
    domain_id, tmp_path, node_type, specs, given,
):
    """By default (rclpy: a byte array), from `-p NAME:=[]` and from a file (rcl: no value)."""
    lists = [name for name, spec in specs.items() if spec.kind is Kind.TEXTS and name not in given]
    # `[]` as `ros2 param dump` writes it, for each node's first list
    parameters = tmp_path / 'parameters.yaml'
    parameters.write_text(f'/**:\n  ros__parameters:\n    {lists[0]}: []\n')
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=domain_id, args=[
        '--ros-args', '--params-file', str(parameters), '-p', f'{lists[1]}:=[]',
        '-p', 'log.enabled:=false',
        *(argument for name, value in given.items() for argument in ('-p', f'{name}:=[{value}]'))])
    try:
        node = node_type(context=context)
        try:
            for name in lists:
                parameter = node.get_parameter(name)
                assert (parameter.type_, parameter.value) == (Parameter.Type.STRING_ARRAY, []), (
                    name)
        finally:
            node.destroy_node()
    finally:
        rclpy.shutdown(context=context)
