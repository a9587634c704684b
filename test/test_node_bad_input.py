# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
linkage_node under bad input.

Every parameter tried with wrong types, NaN, ±inf, zero, negative and huge values, at start-up and
at run time, and a crank driven into a dead point.

The full matrix runs through ``build_configuration`` (pure); real node processes cover each class
of bad value at start-up, all of them at run time (with logging on, so the bag must keep every
message), and the dead point under 'loop', 'bounce' and 'stop'.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
import math

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from linkage_kinematics.bag.reader import bag_files, iter_messages, read_states
from linkage_kinematics.kinematics.drive import DriveLaw
from linkage_kinematics.kinematics.geometry import preset
from linkage_kinematics.kinematics.solver import solve
from linkage_kinematics.run.configuration import build_configuration
from linkage_kinematics.run.motion import (
    dead_point_problem,
    met_dead_point,
    sample_at_step,
    sample_at_time,
)
from linkage_kinematics.run.parameter_specs import PARAMETER_NAMES, parameter_specs
from linkage_kinematics.run.parameter_values import ConfigurationError
from node_process import (
    configuration_values,
    expected_state_point,
    Listener,
    PROCESS_TIMEOUT,
    ros_context,
    stamp_ns,
)
import numpy as np
import pytest
from rclpy.parameter import Parameter, parameter_value_to_python
from rclpy.parameter_client import AsyncParameterClient
from sensor_msgs.msg import JointState
from trajectory_msgs.msg import JointTrajectory

PAPER = preset('paper').geometry
DEAD_POINT = min(PAPER.reachability.dead_points, key=abs)  # ≈ −1.941°, clockwise from 0
DEFAULTS = {spec.name: spec.default for spec in parameter_specs('paper')}

# --- the expectation table ----------------------------------------------------------------------

BAD_CLASSES = ('wrong type', 'bool', 'nan', '+inf', '-inf', 'zero', 'negative', 'huge', '-huge')
# A value of the wrong type, by the type of the parameter's default.
WRONG_TYPE = {float: 'fast', int: 'fast', str: 1.5, bool: 'true', list: 'fast'}
# Where -1 is not the telling negative value: one that is valid for the parameter.
NEGATIVE = {'alpha_start': -0.01, 'alpha_end': -0.01, 'omega0': -1.0, 'ground_y': -0.1}
# Other values under which a parameter's case is judged (a clockwise drive needs a lower end).
CONTEXT = {'omega0': {'alpha_end': -0.01}, 'alpha_end': {'omega0': -1.0}}

# The classes whose value is valid for the parameter; every other class is refused with a
# ConfigurationError that names the parameter. With the paper's mechanism from α = 0 to 90°:
ACCEPTED = {
    'preset': set(),
    'crank_length': set(),                   # lengths: finite, > 0 and at most 1e6 m
    'coupler_length': set(),
    'rocker_length': set(),
    'ground_x': {'negative'},                # C left of O; 0 puts C on O, where this cannot close
    'ground_y': {'zero', 'negative'},        # |ground_*| at most 1e6 m
    'branch': {'negative'},                  # −1 is the other assembly; only ±1 exist
    'omega0': {'negative'},                  # clockwise; 0 leaves the crank at rest
    'k': {'zero', 'negative'},               # constant law; ω = 2 − α still reaches 90°
    'alpha_start': {'zero', 'negative'},     # −0.01 rad is reachable (the dead point is at −0.034)
    'alpha_end': {'negative'},               # driven clockwise; 0 would be an empty pass
    'end_behavior': set(),
    'mode': set(),
    'alpha_step': set(),                     # in (0, 2π]
    'rate_hz': set(),                        # in (0, 10000]
    'display_rate_hz': set(),                # in (0, 1000]
    'frame_id': set(),
    'frame_prefix': set(),                   # any string, "" for none
    'diagnostics.min_transmission_angle': {'zero'},  # 0 turns the warning off
    'diagnostics.dead_point_warning': {'zero'},
    'log.enabled': set(),
    'log.folder': set(),
    'log.max_bag_size': {'zero', 'huge'},    # 0 never splits; else at least 1024 bytes
    'log.max_bag_duration': {'zero'},        # 0 never splits; at most 1e9 s
    'cpu_affinity': {'zero', 'negative'},    # CPU 0; −1 is no pinning; at most 1023
    'source': set(),
    'driver': set(),
    **{f'joints.{link}.{field}': accepted
       for link in ('crank', 'coupler', 'rocker')
       for field, accepted in (('name', set()),
                               ('direction', {'negative'}),  # −1 reverses the axis; only ±1
                               ('offset', {'zero', 'negative'}))},  # rad, at most 1e6
    'publish_robot_description': set(),
    'measured.timeout': set(),               # in (0, 3600] s
    'measured.max_jump': set(),              # in (0, π] rad
    'measured.acceleration_time_constant': {'zero'},  # 0 is the raw difference
    'loops': set(),
    'loops.measured_joints': set(),          # a list of strings
    'loops.branches': set(),
    'loops.assemblies': set(),
    'loops.output_joints': set(),
    'robot_description': set(),              # any string, '' for the topic
    'robot_description_closures': set(),     # any string, '' for none
    'autostart': set(),
}
# Valid in another context: C straight below O (the mechanism turned by −90°).
ACCEPTED_IN_CONTEXT = [{'ground_x': 0.0, 'ground_y': -1.3}, {'ground_x': 0, 'ground_y': -1.3}]
# Where an accepted value shows in the configuration.
CONFIGURED = {
    'ground_x': lambda config: config.geometry.linkage.ground_x,
    'ground_y': lambda config: config.geometry.linkage.ground_y,
    'branch': lambda config: config.motion.branch,
    'omega0': lambda config: config.motion.drive.omega0,
    'k': lambda config: config.motion.drive.k,
    'alpha_start': lambda config: config.motion.alpha_start,
    'alpha_end': lambda config: config.motion.alpha_end,
    'diagnostics.min_transmission_angle': lambda config: config.outputs.min_transmission_angle,
    'diagnostics.dead_point_warning': lambda config: config.outputs.dead_point_warning,
    'cpu_affinity': lambda config: config.logging.cpu_affinity,
    **{f'joints.{link}.{field}': (
        lambda config, link=link, field=field: getattr(getattr(config.joints.lab, link), field))
       for link in ('crank', 'coupler', 'rocker') for field in ('direction', 'offset')},
    'measured.acceleration_time_constant':
        lambda config: config.measured.acceleration_time_constant,
    'log.max_bag_size': lambda config: config.logging.max_bag_size,
    'log.max_bag_duration': lambda config: config.logging.max_bag_duration,
}


def bad_value(name: str, bad_class: str):
    """Return the value of ``bad_class`` for parameter ``name`` (typed like the parameter)."""
    integer = isinstance(DEFAULTS[name], int) and not isinstance(DEFAULTS[name], bool)
    return {
        'wrong type': WRONG_TYPE[type(DEFAULTS[name])],
        'bool': True,
        'nan': math.nan,
        '+inf': math.inf,
        '-inf': -math.inf,
        'zero': 0 if integer else 0.0,
        'negative': -1 if integer else NEGATIVE.get(name, -1.0),
        'huge': 2**62 if integer else 1e308,
        '-huge': -(2**62) if integer else -1e308,
    }[bad_class]


def applies(name: str, bad_class: str) -> bool:
    # True is the right type for log.enabled, whose wrong type is the string "true".
    return not (bad_class == 'bool' and isinstance(DEFAULTS[name], bool))


def refused_classes(name: str) -> list[str]:
    return [c for c in BAD_CLASSES if applies(name, c) and c not in ACCEPTED[name]]


MATRIX = [(name, c) for name in PARAMETER_NAMES for c in BAD_CLASSES if applies(name, c)]


def test_the_table_covers_every_parameter():
    assert set(ACCEPTED) == set(PARAMETER_NAMES)
    assert set(CONFIGURED) == {name for name, classes in ACCEPTED.items() if classes}


@pytest.mark.parametrize(('name', 'bad_class'), MATRIX, ids=[f'{n}-{c}' for n, c in MATRIX])
def test_build_configuration_refuses_each_bad_value_naming_its_parameter(name, bad_class):
    value = bad_value(name, bad_class)
    values = configuration_values(**{**CONTEXT.get(name, {}), name: value})
    if bad_class in ACCEPTED[name]:
        config = build_configuration(values)
        assert CONFIGURED[name](config) == value
        return
    with pytest.raises(ConfigurationError) as raised:
        build_configuration(values)
    error = raised.value
    assert name in error.parameter.split(', '), str(error)
    assert str(error) == f'{error.parameter}: {error.reason}'
    assert '\n' not in str(error) and 'nan°' not in str(error)


@pytest.mark.parametrize('overrides', ACCEPTED_IN_CONTEXT)
def test_values_valid_in_their_context_are_accepted(overrides):
    config = build_configuration(configuration_values(**overrides))
    assert (config.geometry.linkage.ground_x, config.geometry.linkage.ground_y) == (0.0, -1.3)


# --- start-up: one node process per class of bad value -----------------------------------------

START_UP_CASES = {
    'wrong type': ('frame_id', 1.5),
    'bool': ('display_rate_hz', True),
    'nan': ('diagnostics.dead_point_warning', math.nan),
    '+inf': ('ground_y', math.inf),
    '-inf': ('alpha_start', -math.inf),
    'zero': ('rocker_length', 0.0),
    'negative': ('rate_hz', -5.0),
    'huge': ('crank_length', 1e308),
    'huge drive': ('omega0', 1e308),
}


def test_bad_values_at_start_up_end_each_node_with_one_line_and_nothing_written(
    nodes, tmp_path
):
    # All at once: each process ends during start-up, so they cannot disturb each other.
    runs = {}
    for case, (name, value) in START_UP_CASES.items():
        folder = tmp_path / case.replace(' ', '_')
        folder.mkdir()
        runs[case] = (nodes.start({name: value, 'log.folder': str(folder / 'bags')},
                                  folder / 'node.log'), folder)
    statuses = {case: process.wait(timeout=PROCESS_TIMEOUT)
                for case, (process, _) in runs.items()}
    for case, (name, _) in START_UP_CASES.items():
        folder = runs[case][1]
        output = (folder / 'node.log').read_text()
        assert statuses[case] == 2, output
        assert 'Traceback' not in output
        plain = [line for line in output.splitlines() if line.startswith('linkage_node: invalid')]
        assert plain == [plain[0]] and plain[0].startswith(
            f'linkage_node: invalid parameter {name}: '), output
        assert any('[FATAL]' in line and name in line for line in output.splitlines()), output
        assert not (folder / 'bags').exists()


# --- run time: every bad value through the parameter service, logging on -----------------------


def test_bad_values_at_run_time_are_refused_and_the_node_and_its_log_go_on(nodes, tmp_path):
    bags = tmp_path / 'bags'
    with ros_context(nodes.domain_id) as context:
        listener = Listener('bad_input_tester', context)
        listener.subscribe('/linkage/state', JointTrajectory)
        states = listener.received['/linkage/state']
        process = nodes.start({'end_behavior': 'loop', 'log.folder': str(bags)},
                              tmp_path / 'node.log')
        try:
            client = AsyncParameterClient(listener.node, 'linkage_node')
            assert client.wait_for_services(timeout_sec=PROCESS_TIMEOUT)
            assert listener.spin_until(lambda: len(states) > 5)
            # The last good configuration differs from the start-up one.
            (result,) = listener.result_of(
                client.set_parameters([Parameter('omega0', value=3.0)])).results
            assert result.successful
            values = listener.result_of(client.get_parameters(PARAMETER_NAMES)).values
            good = {name: parameter_value_to_python(value)
                    for name, value in zip(PARAMETER_NAMES, values)}
            assert good == {**DEFAULTS, 'omega0': 3.0, 'log.folder': str(bags),
                            'end_behavior': 'loop'}
            assert listener.spin_until(lambda: states[-1].points[0].velocities[0] == 3.0)
            before_rejections = stamp_ns(states[-1])

            for name in PARAMETER_NAMES:
                tried = [bad_value(name, c) for c in refused_classes(name)]
                # The service sets each parameter of a request on its own.
                results = listener.result_of(client.set_parameters(
                    [Parameter(name, value=value) for value in tried])).results
                assert len(results) == len(tried)
                for value, result in zip(tried, results):
                    assert not result.successful, (name, value)
                    assert name in result.reason, (name, value, result.reason)

            after = listener.result_of(client.get_parameters(PARAMETER_NAMES)).values
            assert {name: parameter_value_to_python(value)
                    for name, value in zip(PARAMETER_NAMES, after)} == good
            after_rejections = len(states)
            assert listener.spin_until(lambda: len(states) > after_rejections + 20)
            assert process.poll() is None
            status = nodes.interrupt(process)
        finally:
            listener.destroy()

    assert status == 0, (tmp_path / 'node.log').read_text()
    faster = DriveLaw(3.0)
    for message in states[after_rejections:]:
        point = message.points[0]
        state = solve(PAPER, point.positions[0], faster)
        positions, velocities, _ = expected_state_point(PAPER, state)
        assert (tuple(point.positions), tuple(point.velocities)) == (positions, velocities)

    (bag,) = bags.iterdir()
    assert all(part.complete for part in bag_files(bag))
    stamps, logged = read_states(bag)
    received = [stamp_ns(message) for message in states]
    assert len(stamps) >= len(received)
    assert set(received) <= set(stamps.tolist())
    assert stamps.min() < before_rejections < stamps.max()
    log_times = [message.log_time_ns for message in iter_messages(bag)]
    assert all(later >= earlier for earlier, later in zip(log_times, log_times[1:]))
    # Every logged state is the library's, at ω = 2 before the change and 3 after it.
    for omega0 in (2.0, 3.0):
        rows = np.flatnonzero(logged.omega == omega0)
        assert rows.size > 5
        for row in rows:
            expected = solve(PAPER, float(logged.alpha[row]), DriveLaw(omega0))
            for field in ('beta', 'gamma', 'omega_ab', 'omega_bc', 'pin_b_x', 'acceleration_b_y'):
                assert getattr(logged, field)[row] == getattr(expected, field), (row, field)
    assert np.all(np.isin(logged.omega, (2.0, 3.0)))


# --- dead point: alpha_end beyond the reachable interval ----------------------------------------


def _values(status: DiagnosticStatus) -> dict[str, str]:
    return {pair.key: pair.value for pair in status.values}


def _finite(message) -> bool:
    if isinstance(message, JointState):
        numbers = [*message.position, *message.velocity]
    else:
        point = message.points[0]
        numbers = [*point.positions, *point.velocities, *point.accelerations]
    return all(math.isfinite(number) for number in numbers)


def test_passes_cut_short_by_a_dead_point_are_counted_as_meetings():
    bounce = build_configuration(configuration_values(
        omega0=-1.0, alpha_end=-0.1, end_behavior='bounce', **{'log.enabled': False}))
    assert bounce.motion.blocked_at == pytest.approx(DEAD_POINT, abs=1e-15)
    duration = bounce.motion.segment_duration
    samples = [sample_at_time(bounce, fraction * duration) for fraction in (0.5, 1.5, 2.5, 3.5)]
    assert [sample.pass_index for sample in samples] == [0, 1, 2, 3]
    assert [sample.is_reversed for sample in samples] == [False, True, False, True]
    last_out = sample_at_step(bounce, bounce.motion.step_count - 1)
    first_back = sample_at_step(bounce, bounce.motion.step_count)
    assert (last_out.pass_index, first_back.pass_index) == (0, 1) and first_back.is_reversed
    # Bounce meets the dead point at the end of each forward pass only; loop at every pass end.
    assert met_dead_point(bounce, 0, 1) and met_dead_point(bounce, 1, 3)
    assert not met_dead_point(bounce, 1, 2) and not met_dead_point(bounce, 2, 2)
    loop = replace(bounce, motion=replace(bounce.motion, end_behavior='loop'))
    assert sample_at_time(loop, 2.5 * duration).pass_index == 2
    assert met_dead_point(loop, 1, 2)
    clear = build_configuration(configuration_values(end_behavior='loop'))
    assert not met_dead_point(clear, 0, 1)
    assert dead_point_problem(bounce) == (
        f'the crank cannot go past the dead point at {math.degrees(DEAD_POINT):.6f}° before '
        f'alpha_end = {math.degrees(-0.1):.6f}°: it reverses')


def _assert_errors_at_and_warnings_before_the_dead_point(
    diagnostics: list[DiagnosticArray], errors: Callable[[str], list[DiagnosticArray]],
    warning: float,
) -> None:
    """Each end behavior's ERROR at the dead point says what it does; WARN before it, moving."""
    where = f'the crank cannot go past the dead point at {math.degrees(DEAD_POINT):.6f}°'
    for behavior, outcome in (('loop', 'restarts from alpha_start'), ('bounce', 'reverses'),
                              ('stop', 'stops')):
        assert errors(behavior), behavior
        for error in (array.status[0] for array in errors(behavior)):
            assert error.message.startswith(where), error.message
            assert f': it {outcome}' in error.message
            # The last state shown is just before the dead point, on the reachable side.
            alpha = float(_values(error)['alpha (rad)'])
            assert DEAD_POINT < alpha < DEAD_POINT + 0.01
    # Before it, while moving: WARN, saying how close the dead point is and that it lies ahead.
    moving = [array.status[0] for array in diagnostics
              if array.status[0].level != DiagnosticStatus.ERROR
              and 'alpha (rad)' in _values(array.status[0])]
    assert any(_values(status_message)['end behavior'] == 'bounce' for status_message in moving)
    for status_message in moving:
        assert status_message.level == DiagnosticStatus.WARN
        distance = math.radians(float(_values(status_message)['dead point distance (deg)']))
        assert distance < warning
        assert 'from a dead point' in status_message.message
        assert 'before alpha_end' in status_message.message


def _assert_bounce_turns_at_the_dead_point_and_at_alpha_start(
    states: list[JointTrajectory], errors: Callable[[str], list[DiagnosticArray]],
    drive: DriveLaw,
) -> None:
    """
    Between two turns at the dead point, 'bounce' runs back to alpha_start and out again.

    Back: |α| decreasing, ω > 0; out: the reverse.
    """
    first_turn, second_turn = (stamp_ns(array) for array in errors('bounce')[:2])
    # The ERROR carries the stamp of the tick that met the dead point, as does that tick's state.
    cycle = [message.points[0] for message in states
             if first_turn < stamp_ns(message) < second_turn]
    assert len(cycle) > 100
    alphas_in_cycle = [point.positions[0] for point in cycle]
    speeds = [point.velocities[0] for point in cycle]
    peak = alphas_in_cycle.index(max(alphas_in_cycle))
    # The crank turned at the dead point somewhere after the last state before the turn, and
    # runs back at |ω| = 0.05 rad/s: its first state back lies within what it can turn since then
    # (a bound from the stamps, so that a late tick on a busy machine cannot fail it).
    last_before_turn = max(stamp_ns(message) for message in states
                           if stamp_ns(message) < first_turn)
    first_back = min(stamp_ns(message) for message in states if stamp_ns(message) > first_turn)
    turnable = abs(drive.omega0) * (first_back - last_before_turn) * 1e-9
    assert 0.0 < alphas_in_cycle[0] - DEAD_POINT <= turnable + 1e-12
    # The turn at alpha_start = 0 lies between the peak's neighbours; likewise bounded by stamps.
    stamps_in_cycle = [stamp_ns(message) for message in states
                       if first_turn < stamp_ns(message) < second_turn]
    widest_gap = max(stamps_in_cycle[peak + 1] - stamps_in_cycle[peak],
                     stamps_in_cycle[peak] - stamps_in_cycle[peak - 1])
    assert -abs(drive.omega0) * widest_gap * 1e-9 - 1e-12 <= alphas_in_cycle[peak] <= 0.0
    assert all(b > a for a, b in zip(alphas_in_cycle[:peak], alphas_in_cycle[1:peak + 1]))
    assert all(b < a for a, b in zip(alphas_in_cycle[peak:], alphas_in_cycle[peak + 1:]))
    assert all(speed > 0.0 for speed in speeds[:peak])
    assert all(speed < 0.0 for speed in speeds[peak + 1:])


def test_dead_point_before_alpha_end_is_an_error_that_loop_bounce_and_stop_each_handle(
    nodes, tmp_path
):
    """
    Drive the paper's mechanism clockwise from 0 into its dead point at ≈ −1.941°.

    Aiming at −0.1 rad: 'loop' restarts there, 'bounce' reverses there, 'stop' ends with status 1;
    each time diagnostics report ERROR at once, and WARN (close to the dead point) before it.
    """
    warning = math.radians(3.0)  # the whole pass lies within 3° of the dead point
    drive = DriveLaw(-0.05)  # 0.68 s from 0 to the dead point
    with ros_context(nodes.domain_id) as context:
        listener = Listener('dead_point_tester', context)
        for topic, msg_type in (('/diagnostics', DiagnosticArray),
                                ('/linkage/state', JointTrajectory),
                                ('/joint_states', JointState)):
            listener.subscribe(topic, msg_type)
        diagnostics = listener.received['/diagnostics']
        process = nodes.start(
            {'end_behavior': 'loop', 'omega0': drive.omega0, 'alpha_end': -0.1,
             'rate_hz': 200.0, 'diagnostics.dead_point_warning': warning,
             'log.folder': str(tmp_path / 'bags')},
            tmp_path / 'node.log')

        def errors(behavior: str) -> list[DiagnosticArray]:
            return [array for array in diagnostics
                    if array.status[0].level == DiagnosticStatus.ERROR
                    and _values(array.status[0])['end behavior'] == behavior]

        try:
            client = AsyncParameterClient(listener.node, 'linkage_node')
            assert client.wait_for_services(timeout_sec=PROCESS_TIMEOUT)
            assert listener.spin_until(lambda: errors('loop'))
            (result,) = listener.result_of(
                client.set_parameters([Parameter('end_behavior', value='bounce')])).results
            assert result.successful
            # Two turns at the dead point, so a whole pass back and out lies between them.
            assert listener.spin_until(lambda: len(errors('bounce')) >= 2)
            (result,) = listener.result_of(
                client.set_parameters([Parameter('end_behavior', value='stop')])).results
            assert result.successful
            assert listener.spin_until(lambda: process.poll() is not None)
            listener.drain()
            status = process.wait(timeout=PROCESS_TIMEOUT)
        finally:
            listener.destroy()

    output = (tmp_path / 'node.log').read_text()
    assert status == 1, output
    _assert_errors_at_and_warnings_before_the_dead_point(diagnostics, errors, warning)

    states = listener.received['/linkage/state']
    joint_states = listener.received['/joint_states']
    assert all(map(_finite, states)) and all(map(_finite, joint_states))
    alphas = [message.points[0].positions[0] for message in states]
    assert all(DEAD_POINT < alpha <= 0.0 for alpha in alphas)
    for message in states:
        point = message.points[0]
        state = solve(PAPER, point.positions[0], DriveLaw(math.copysign(0.05,
                                                                        point.velocities[0])))
        assert tuple(point.positions[:3]) == (state.alpha, state.beta, state.gamma)
        assert tuple(point.velocities[:3]) == (state.omega, -state.omega_bc, state.omega_ab)
    _assert_bounce_turns_at_the_dead_point_and_at_alpha_start(states, errors, drive)
    # Stop: the run ends just before the dead point.
    # (as close as the last tick before it came: 0.01 rad is 0.2 s at |ω| = 0.05 rad/s, so a tick
    # late on a busy machine cannot fail this)
    assert DEAD_POINT < alphas[-1] < DEAD_POINT + 0.01
    assert 'cannot go on' in output
    # The log holds every status and state heard, in time order.
    (bag,) = (tmp_path / 'bags').iterdir()
    logged = list(iter_messages(bag))
    log_times = [message.log_time_ns for message in logged]
    assert all(later >= earlier for earlier, later in zip(log_times, log_times[1:]))
    for topic in ('/diagnostics', '/linkage/state'):
        assert sum(message.topic == topic for message in logged) >= len(
            listener.received[topic])
