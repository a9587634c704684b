# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
~/pause, ~/resume and ~/reset of a node closing a robot's loops, over DDS.

test_loop_source.py checks the same through a fake host, where the order of services and
samples is the test's own. Here a real ``loops:=robot_description`` node gets both from this
process: a sample sent while paused is acknowledged by the node's reader before the next
service call goes out, so that the node has it queued before that call (its events executor
takes them in the order they came).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from diagnostic_msgs.msg import DiagnosticStatus
from loop_robots import ROBOTS
from node_process import PROCESS_TIMEOUT, ros_context, stamp_ns
import pytest
from rclpy.duration import Duration
from test_node_start_control import Services
from test_robot_loops import loop_node, LoopNode, PERIOD_NS, START_NS, values

KNEE = ROBOTS['four_bar_knee']
MEASURED = 'knee_front'
PAUSED = 'paused: the measured joints are not followed until ~/resume'
RESUMED = 'following the measured joints again from their next sample'


@pytest.fixture(scope='module')
def context(domain_id: int):
    with ros_context(domain_id) as ros:
        yield ros


def answer(response: Any) -> tuple[bool, str]:
    return response.success, response.message


def node_status(node: LoopNode, since: int, done: Callable[[Any, Any], bool]) -> Any:
    """
    Wait for the node's own status, among the arrays received from index ``since`` on.

    ``done(array, status)`` picks it; return the status.
    """
    received = node.listener.received['/diagnostics']

    def found() -> Any:
        return next((status for array in received[since:] for status in array.status
                     if status.name == 'linkage_node: robot loops' and done(array, status)),
                    None)

    assert node.listener.spin_until(lambda: found() is not None), node.log.read_text()
    return found()


def assert_started_afresh(message: Any) -> None:
    """
    Check that the passive joints of ``message`` are a motion's first.

    The input has no velocities: each sample's is the backward difference from the sample
    before it in the same motion, 0 for a motion's first, and so are the passive joints'.
    """
    assert sorted(message.name) == sorted(KNEE.passive_joints)
    assert message.velocity.tolist() == [0.0] * len(KNEE.passive_joints)


def send_while_paused(node: LoopNode, stamp: int, angle: float) -> None:
    """
    Publish a sample and wait until the node's reader has acknowledged it.

    Its event is then queued in the node before that of any service call made after.
    """
    node.send(stamp, [MEASURED], [angle], answered=False)
    assert node.inputs.wait_for_all_acked(Duration(seconds=PROCESS_TIMEOUT))


def test_paused_samples_are_not_followed_and_resume_follows_the_next_afresh(
        context, nodes, tmp_path):
    """
    Paused, the node ignores samples (a reset keeps it paused); resumed, it follows the next.

    The statuses say paused and count no paused sample. The first sample followed after each
    ~/resume starts the motion afresh: no earlier sample to difference, its velocity 0.
    """
    with loop_node(context, nodes, tmp_path,
                   {'robot_description': KNEE.urdf(), 'log.enabled': False}) as node:
        services = Services(node.listener)
        diagnostics = node.listener.received['/diagnostics']
        node.send(START_NS, [MEASURED], [0.1])

        before = len(diagnostics)
        assert answer(services.call('pause')) == (True, 'paused: the measured joints are ignored')
        paused = node_status(node, before, lambda _, status: status.message == PAUSED)
        assert paused.level == DiagnosticStatus.OK
        assert (values(paused)['run state'], values(paused)['valid samples']) == ('paused', '1')
        send_while_paused(node, START_NS + PERIOD_NS, 0.2)
        assert answer(services.call('pause')) == (False, 'already paused; ~/resume goes on')
        assert answer(services.call('resume')) == (True, RESUMED)
        node.send(START_NS + 2 * PERIOD_NS, [MEASURED], [0.3])
        # The node's outputs come in the order of its inputs: had it followed the paused
        # sample, that joint state would have come before this one.
        assert [stamp_ns(message) for message in node.outputs] == [
            START_NS, START_NS + 2 * PERIOD_NS]
        assert_started_afresh(node.outputs[-1])

        assert services.call('pause').success
        before = len(diagnostics)
        assert answer(services.call('reset')) == (
            True, 'the motion starts afresh at the next valid sample; paused: ~/resume follows it')
        # the status the reset publishes with its answer
        later = node_status(node, before, lambda _, status: True)
        assert (later.message, values(later)['run state']) == (PAUSED, 'paused')
        assert (values(later)['valid samples'], values(later)['dropped samples']) == ('2', '0')
        send_while_paused(node, START_NS + 3 * PERIOD_NS, 0.4)

        before = len(diagnostics)
        assert answer(services.call('resume')) == (True, RESUMED)
        node.send(START_NS + 4 * PERIOD_NS, [MEASURED], [0.5])
        assert [stamp_ns(message) for message in node.outputs] == [
            START_NS, START_NS + 2 * PERIOD_NS, START_NS + 4 * PERIOD_NS]
        assert_started_afresh(node.outputs[-1])
        following = node_status(node, before, lambda _, status: status.message.startswith(
            'following'))
        assert following.message == f'following {MEASURED}'
        assert (values(following)['run state'], values(following)['valid samples'],
                values(following)['dropped samples']) == ('running', '3', '0')
        assert nodes.interrupt(node.process) == 0, node.log.read_text()
