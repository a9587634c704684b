# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The node's sources, hosted by a fake of the node's narrow host interface.

``FakeHost`` is a ``SourceHost`` of our own (the interface is ours, not ROS's): a clock the
test sets, timers the test holds, and a record, in order, of what the source had published and
of the run's status (through the node's own ``RunStatus``, so the end-of-run order is the
node's). No ROS process runs; the node's behaviour over real DDS is test_node*.py's.
"""

from __future__ import annotations

from collections.abc import Callable
import math
from typing import Any

from linkage_kinematics.kinematics.solver import LinkageState
from linkage_kinematics.model.joints import TreeValues
from linkage_kinematics.ros.drive_law_source import DriveLawTimer
from linkage_kinematics.ros.exit_codes import ExitCode
from linkage_kinematics.ros.measured_source import MeasuredSubscription
from linkage_kinematics.ros.source import RunStatus, SourceHost
from linkage_kinematics.run.configuration import build_configuration, RunConfiguration
from linkage_kinematics.run.control import RunControl
from linkage_kinematics.run.motion import dead_point_problem
from linkage_kinematics.run.parameter_specs import parameter_specs
import pytest
from rclpy.serialization import serialize_message
from sensor_msgs.msg import JointState

START_NS = 5_000_000_000  # the node clock's time when the motion starts
PERIOD_NS = 10_000_000  # rate_hz 100


def configuration(**overrides: Any) -> RunConfiguration:
    """Return the paper's default run (no log) with ``overrides``, by parameter name."""
    values = {spec.name: spec.default for spec in parameter_specs('paper')}
    return build_configuration({**values, 'log.enabled': False, **overrides})


class FakeTimer:
    """A timer the test fires by calling ``callback``; it keeps its period and whether it runs."""

    def __init__(self, timer_period_sec: float, callback: Callable[[], None]) -> None:
        self.timer_period_ns = round(timer_period_sec * 1e9)
        self.callback = callback
        self.canceled = False

    def cancel(self) -> None:
        self.canceled = True

    def reset(self) -> None:
        self.canceled = False


class FakeLogger:
    """Records each line logged into the host's record."""

    def __init__(self, record: list[tuple]) -> None:
        self._record = record

    def info(self, text: str) -> None:
        self._record.append(('log info', text))

    def error(self, text: str) -> None:
        self._record.append(('log error', text))


class FakeHost(RunStatus):
    """
    A ``SourceHost``: ``record`` holds, in order, what was published and the status events.

    ``('state', α, stamp, motion time)``, ``('scene', α)``, ``('description',)``,
    ``('status', message, stamp or None)``, ``('flush log',)``, ``('log info' | 'log error',
    text)``. Like the node, it publishes a motion's first state after its scene, the URDF and a
    status.
    """

    def __init__(self, config: RunConfiguration) -> None:
        self.config = config
        self.control = RunControl(config.autostart)
        self.clock_ns = START_NS
        self.state: LinkageState | None = None
        self.motion_started = False
        self.joints: TreeValues | None = None
        self.record: list[tuple] = []
        self.timers: list[FakeTimer] = []
        self.subscriptions: dict[str, Callable[[Any], None]] = {}
        self._logger = FakeLogger(self.record)

    def now_ns(self) -> int:
        return self.clock_ns

    def get_logger(self) -> FakeLogger:
        return self._logger

    def create_timer(self, timer_period_sec: float, callback: Callable[[], None]) -> FakeTimer:
        timer = FakeTimer(timer_period_sec, callback)
        self.timers.append(timer)
        return timer

    def destroy_timer(self, timer: FakeTimer) -> bool:
        self.timers.remove(timer)
        return True

    def create_subscription(self, msg_type: type, topic: str, callback: Callable[[Any], None],
                            qos_profile: object, *, raw: bool = False) -> object:
        self.subscriptions[topic] = callback
        return topic

    def publish_state(self, state: LinkageState, stamp_ns: int, motion_time: float,
                      joints: TreeValues | None = None) -> None:
        self.joints = joints
        if not self.motion_started:
            self.motion_started = True
            self.show_waiting(state, stamp_ns)
        self.state = state
        self.record.append(('state', state.alpha, stamp_ns, motion_time))

    def show_waiting(self, state: LinkageState, stamp_ns: int) -> None:
        self.state = state
        self.publish_markers()
        self.publish_description()
        self.publish_diagnostics()

    def forget_state(self) -> None:
        self.state = None
        self.motion_started = False

    def publish_markers(self) -> None:
        self.record.append(('scene', self.state.alpha))

    def publish_description(self) -> None:
        self.record.append(('description',))

    def publish_diagnostics(self, event: str | None = None, at_ns: int | None = None) -> None:
        self.record.append(('status', event or self.problem or self.activity, at_ns))

    def flush_log(self) -> None:
        self.record.append(('flush log',))

    def take(self) -> list[tuple]:
        """Return what was recorded since the last call."""
        taken, self.record[:] = list(self.record), []
        return taken


def hosted(**overrides: Any) -> tuple[FakeHost, DriveLawTimer]:
    host = FakeHost(configuration(**overrides))
    source: DriveLawTimer = DriveLawTimer(host)
    typed: SourceHost = host  # the fake is a host as the node is
    assert typed is host
    return host, source


def test_the_first_state_comes_after_its_scene_and_the_status_that_says_it_moves():
    host, source = hosted()
    (timer,) = host.timers
    assert timer.timer_period_ns == PERIOD_NS
    source.start()
    assert host.take() == [('scene', 0.0), ('description',), ('status', 'moving', None),
                           ('state', 0.0, START_NS, 0.0)]
    host.clock_ns += PERIOD_NS
    timer.callback()
    alpha = host.config.motion.drive.alpha_at(0.0, 0.01)
    assert host.take() == [('state', pytest.approx(alpha, abs=1e-15), START_NS + PERIOD_NS,
                            pytest.approx(0.01, abs=1e-15))]
    assert not host.finished


def test_the_final_state_of_stop_ends_the_run_with_the_log_flushed_before_the_last_status():
    host, source = hosted(end_behavior='stop')
    source.start()
    host.take()
    duration = host.config.motion.segment_duration
    host.clock_ns = START_NS + round(duration * 1e9) + 3 * PERIOD_NS
    host.timers[0].callback()
    stopped = 'reached alpha_end = 90.000000°; stopped'
    # The final state is stamped when the drive law reaches alpha_end, not at the late tick.
    assert host.take() == [
        ('state', host.config.motion.alpha_end, START_NS + round(duration * 1e9), duration),
        ('log info', stopped), ('scene', host.config.motion.alpha_end), ('flush log',),
        ('status', stopped, None)]
    assert host.exit_code is ExitCode.OK
    host.clock_ns += PERIOD_NS
    host.timers[0].callback()
    assert host.take() == []  # finished: nothing more


def test_a_dead_point_before_alpha_end_under_stop_fails_the_run():
    host, source = hosted(end_behavior='stop', alpha_end=4.0)
    assert host.config.motion.blocked_at == pytest.approx(3.1754688640491766)
    source.start()
    host.take()
    host.clock_ns = START_NS + round((host.config.motion.segment_duration + 0.5) * 1e9)
    host.timers[0].callback()
    problem = dead_point_problem(host.config)
    assert problem.endswith('it stops; the run cannot go on')
    assert host.take() == [('log error', problem), ('flush log',), ('status', problem, None)]
    assert host.exit_code is ExitCode.FAILED


def test_paused_the_source_publishes_no_state_and_a_reset_shows_alpha_start_once():
    host, source = hosted(autostart=False, alpha_start=0.25)
    (timer,) = host.timers
    source.start()
    waiting = 'paused: waiting at alpha_start for ~/resume'
    assert host.take() == [('scene', 0.25), ('description',), ('status', waiting, None)]
    assert timer.canceled  # until ~/resume

    assert source.resume().message == 'started from alpha_start'
    assert host.take() == [('scene', 0.25), ('description',), ('status', 'moving', None),
                           ('state', 0.25, START_NS, 0.0)]
    host.clock_ns += 20 * PERIOD_NS
    timer.callback()
    (_, held_alpha, _, _), = host.take()
    assert held_alpha > 0.25
    answer = source.pause()
    assert answer.success
    assert host.take() == [('status', f'paused at α = {math.degrees(held_alpha):.6f}°; '
                                      '~/resume goes on', None)]
    host.clock_ns += PERIOD_NS
    timer.callback()
    assert host.take() == []  # paused: no state
    assert timer.canceled

    # A reset while paused publishes the state at alpha_start once, with its scene and status.
    host.clock_ns += PERIOD_NS
    answer = source.reset()
    assert answer.message == 'back to alpha_start = 14.323945°; paused: ~/resume starts the motion'
    assert host.take() == [('scene', 0.25), ('description',), ('status', waiting, None),
                           ('state', 0.25, host.clock_ns, 0.0)]
    assert timer.canceled and host.control.paused
    host.clock_ns += PERIOD_NS
    timer.callback()
    assert host.take() == []


def joint_state(seconds: float, crank: float) -> bytes:
    """Return the CDR bytes of a crank sample, as the measured source's raw subscription gets."""
    message = JointState(name=['crank_joint'], position=[crank])
    message.header.stamp.sec = int(seconds)
    message.header.stamp.nanosec = round((seconds % 1) * 1e9)
    return serialize_message(message)


def test_the_measured_source_takes_a_new_configuration_through_its_follower():
    host = FakeHost(configuration(source='measured', **{'measured.timeout': 1.0}))
    source = MeasuredSubscription(host)
    follow = host.subscriptions['measured_joint_states']
    (freshness,) = host.timers
    assert freshness.timer_period_ns == 250_000_000
    follow(joint_state(1.0, 0.3))
    assert host.take()[-1] == ('state', pytest.approx(0.3), 1_000_000_000, 0.0)
    # the follower's joints go with the state (its loop's passive joints, test_node_loop.py)
    assert host.joints[0][0] == 0.3

    new = configuration(source='measured', **{'measured.timeout': 2.0, 'measured.max_jump': 0.1})
    host.config = new
    source.reconfigure(new)
    (freshness,) = host.timers
    assert freshness.timer_period_ns == 500_000_000
    follow(joint_state(1.1, 0.5))  # 0.2 rad from the last: further than the new max_jump
    assert host.take() == []
    dropped = source.health.values(host.now_ns(), new)
    assert dropped['dropped jumping further than measured.max_jump'] == '1'
    follow(joint_state(1.2, 0.35))
    assert host.take() == [('state', pytest.approx(0.35), 1_200_000_000, pytest.approx(0.2))]


def test_the_measured_source_drops_and_counts_malformed_bytes() -> None:
    """Bytes that are no JointState (truncated, another encapsulation) are counted, not fatal."""
    host = FakeHost(configuration(source='measured'))
    source = MeasuredSubscription(host)
    follow = host.subscriptions['measured_joint_states']
    follow(joint_state(1.0, 0.3)[:24])  # within the name
    follow(b'\x00\x07' + joint_state(1.0, 0.3)[2:])
    assert host.take() == []
    values = source.health.values(host.now_ns(), host.config)
    assert values['dropped whose bytes are not a well-formed JointState'] == '2'
    assert values['dropped samples'] == '2'
    follow(joint_state(1.1, 0.3))  # the next good sample is followed
    assert host.take()[-1] == ('state', pytest.approx(0.3), 1_100_000_000, 0.0)
