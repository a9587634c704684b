# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
linkage_node over a long run.

A Grashof crank driven through 10 000 revolutions on simulated time stays exact, and its published
angles stay continuous.

The test process owns the clock: the node runs with use_sim_time and ticks on each /clock step
(7° of crank per step); the clock then jumps 10 000 s (10 000 turns at 1 turn/s) and steps on.
"""

from __future__ import annotations

import math

from linkage_kinematics.kinematics.drive import DriveLaw
from linkage_kinematics.kinematics.geometry import preset, TWO_PI
from linkage_kinematics.kinematics.solver import solve
from node_process import (
    drive_sim_clock,
    Listener,
    NodeProcesses,
    ros_context,
    stamp_ns,
)
import pytest
from rclpy.qos import QoSProfile
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from trajectory_msgs.msg import JointTrajectory

CRANK_ROCKER = preset('grashof_crank_rocker').geometry
DRIVE = DriveLaw(TWO_PI)  # one turn per second
CLOCK_START = 1_000_000_000_000  # ns of simulated time at the first tick
STEP = 19_444_444  # ns of simulated time per tick: 7° of crank
STEPS = 60  # per stepping phase: more than a turn, so α crosses whole turns
REVOLUTIONS = 10_000
JUMP = REVOLUTIONS * 1_000_000_000  # ns: exactly REVOLUTIONS turns


def _seconds(nanoseconds: int) -> float:
    return nanoseconds * 1e-9


def _run_on_sim_time(
    nodes: NodeProcesses, tmp_path, parameters: dict, phases: list[list[int]]
) -> tuple[list, list]:
    """
    Run a node with ``parameters`` on simulated time.

    Stepping the clock through ``phases`` (a state for each step); return the /linkage/state and
    /joint_states messages received.
    """
    with ros_context(nodes.domain_id) as context:
        listener = Listener('sim_time_tester', context)
        listener.subscribe('/linkage/state', JointTrajectory)
        listener.subscribe('/joint_states', JointState)
        clock = listener.node.create_publisher(Clock, '/clock', QoSProfile(depth=10))
        states = listener.received['/linkage/state']
        process = nodes.start({**parameters, 'use_sim_time': True, 'log.enabled': False},
                              tmp_path / 'node.log')
        try:
            assert listener.spin_until(lambda: listener.node.count_subscribers('/clock') > 0)
            for phase in phases:
                for clock_ns in phase:
                    drive_sim_clock(listener, clock, states, clock_ns)
            assert listener.spin_until(
                lambda: len(listener.received['/joint_states']) >= len(states))
            assert process.poll() is None, (tmp_path / 'node.log').read_text()
        finally:
            listener.destroy()
    return states, listener.received['/joint_states']


def test_ten_thousand_revolutions_on_sim_time_stay_exact_and_continuous(nodes, tmp_path):
    phases = [[CLOCK_START + n * STEP for n in range(STEPS + 1)],
              [CLOCK_START + JUMP + n * STEP for n in range(STEPS + 1)]]
    states, joint_states = _run_on_sim_time(
        nodes, tmp_path,
        {'preset': 'grashof_crank_rocker', 'end_behavior': 'loop', 'alpha_start': 0.0,
         'alpha_end': TWO_PI, 'omega0': DRIVE.omega0, 'rate_hz': 100.0},
        phases)

    by_stamp = {stamp_ns(message): message.points[0] for message in states}
    # Simulated time drives the node: a state for every clock step and for nothing else.
    assert sorted(by_stamp) == [clock_ns for phase in phases for clock_ns in phase]
    assert by_stamp[CLOCK_START].positions[0] == 0.0

    for clock_ns, point in by_stamp.items():
        elapsed = _seconds(clock_ns - CLOCK_START)
        alpha = point.positions[0]
        assert alpha == pytest.approx(DRIVE.alpha_at(0.0, elapsed), rel=1e-9, abs=1e-12)
        assert point.time_from_start.sec + point.time_from_start.nanosec * 1e-9 == pytest.approx(
            elapsed, rel=1e-9, abs=1e-12)
        # The same angle less its whole turns, exactly from the integer-ns stamp (solving at the
        # published α itself would add the 7e-12 rad rounding of a 6e4 rad angle). The node's
        # elapsed time is float64 seconds, good to ulp(elapsed): 1.8e-12 s after 1e4 s.
        in_turn = DRIVE.alpha_at(0.0, _seconds((clock_ns - CLOCK_START) % 1_000_000_000))
        state = solve(CRANK_ROCKER, in_turn, DRIVE)
        crank_rounding = DRIVE.omega0 * math.ulp(elapsed)
        assert point.positions[1] == pytest.approx(
            state.beta, abs=1e-12 + abs(state.omega_bc / state.omega) * crank_rounding)
        assert point.positions[2] == pytest.approx(
            state.gamma, abs=1e-12 + abs(state.omega_ab / state.omega) * crank_rounding)
        assert point.velocities[0] == DRIVE.omega0

    # After 10 000 revolutions the same crank angle (mod 2π) gives the same β and γ.
    for first, later in zip(*phases):
        turned, start = by_stamp[later], by_stamp[first]
        assert turned.positions[0] - start.positions[0] == pytest.approx(
            REVOLUTIONS * TWO_PI, abs=1e-9)
        assert turned.positions[1] == pytest.approx(start.positions[1], abs=1e-9)
        assert turned.positions[2] == pytest.approx(start.positions[2], abs=1e-9)

    # /joint_states: the crank joint is α itself (it keeps counting), the coupler and rocker
    # joints move by what the library's angles move, never by a whole turn.
    joints = {stamp_ns(message): message.position for message in joint_states}
    assert sorted(joints) == sorted(by_stamp)
    for phase in phases:
        for before, after in zip(phase, phase[1:]):
            assert joints[after][0] == by_stamp[after].positions[0]
            step = [now - then for now, then in zip(joints[after], joints[before])]
            assert step[0] == pytest.approx(TWO_PI * _seconds(STEP), rel=1e-6)
            library = [solve(CRANK_ROCKER, by_stamp[stamp].positions[0], DRIVE)
                       for stamp in (before, after)]
            coupler, rocker = ([state.gamma - state.alpha for state in library],
                               [-state.beta - state.gamma for state in library])
            assert step[1] == pytest.approx(
                math.remainder(coupler[1] - coupler[0], TWO_PI), abs=1e-9)
            assert step[2] == pytest.approx(
                math.remainder(rocker[1] - rocker[0], TWO_PI), abs=1e-9)
            assert all(abs(change) < 0.5 for change in step)
    # Across the jump the coupler and rocker joints stay within π of where they were.
    last, resumed = joints[phases[0][-1]], joints[phases[1][0]]
    assert all(abs(now - then) <= math.pi for now, then in zip(resumed[1:], last[1:]))


PARALLELOGRAM = {'crank_length': 0.3, 'coupler_length': 1.0, 'rocker_length': 0.3,
                 'ground_x': 1.0, 'ground_y': 0.0}
QUARTER = 250_000_000  # ns of simulated time: a quarter turn, from change point to change point
TURNS = 1000


def test_a_parallelogram_turns_a_thousand_times_through_its_change_points(nodes, tmp_path):
    """
    OA = BC, AB = OC.

    Both cranks turn fully, and at α = 90° and 270° (where every tick of this run lands) the two
    assemblies meet. The node never ends a pass there: the parallelogram stays a parallelogram (γ =
    0, ω_AB = 0, ω_BC = ω), α keeps counting, joints stay continuous.
    """
    phases = [[CLOCK_START + n * QUARTER for n in range(9)],
              [CLOCK_START + (TURNS - 2) * 1_000_000_000 + n * QUARTER for n in range(9)]]
    states, joint_states = _run_on_sim_time(
        nodes, tmp_path,
        {'preset': '', **PARALLELOGRAM, 'branch': -1, 'end_behavior': 'loop',
         'alpha_start': 0.0, 'alpha_end': TWO_PI, 'omega0': DRIVE.omega0},
        phases)

    by_stamp = {stamp_ns(message): message.points[0] for message in states}
    assert sorted(by_stamp) == [clock_ns for phase in phases for clock_ns in phase]
    for clock_ns, point in by_stamp.items():
        assert point.positions[0] == pytest.approx(
            DRIVE.alpha_at(0.0, _seconds(clock_ns - CLOCK_START)), rel=1e-12)
        gamma, omega, omega_ab, omega_bc = (
            point.positions[2], point.velocities[0], point.velocities[2], point.velocities[7])
        assert abs(gamma) <= 1e-12 and abs(omega_ab) <= 1e-12 * omega
        assert omega_bc == pytest.approx(omega, rel=1e-12)
    joints = {stamp_ns(message): message.position for message in joint_states}
    for phase in phases:
        for before, after in zip(phase, phase[1:]):
            step = [now - then for now, then in zip(joints[after], joints[before])]
            assert step == pytest.approx([math.pi / 2, -math.pi / 2, math.pi / 2], abs=1e-9)
