# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The measured source: one measured driver joint in, the exact state of the linkage out.

``MeasuredFollower.follow`` takes the fields of one ``sensor_msgs/JointState`` (stamp, names,
positions, velocities), takes the driver joint in through the measured modes' one
``loops.intake.Intake`` (by its lab name, mapped to the node's convention by
``joints.JointMapping.from_lab``, unwrapped across turns) and solves the linkage at it: the
crank directly, the rocker through the mechanism seen from C (``inversion``).

The passive joints come the general way, as from a lab's URDF: the node's own URDF for the
configuration (``model.urdf``, whose ``<constraint>`` closes its loop; its text read once,
``node_description``) is read by ``loops.plan``, planned with the driver measured, and its
``LoopSolver`` turns the driver's lab value and velocity into the passive joints' lab values and
velocities. The four-bar's
``LinkageState`` (``linkage/state``, the scene, diagnostics) still comes from its closed form:
it holds the accelerations and pins the loop solver does not compute.

What is measured, exact or estimated:

* the driver's angle is measured; every position (β, γ, α or θ_BC, the pins, the passive
  joints) is an exact function of it;
* the driver's angular velocity is measured when the message carries one for it; otherwise it
  is estimated by the backward difference (θ_k − θ_{k−1})/(t_k − t_{k−1}) of the unwrapped
  angles over the header stamps (the mean over the last interval: it lags by half a sample
  period), and 0 for a first sample; the other velocities are exact functions of angle and ω;
* the driver's angular acceleration is never in a JointState: it is estimated from the
  driver's velocities (measured or estimated) by a first-order low-pass filter of their
  backward differences, ω̇_k = a·ω̇_{k−1} + (1 − a)·(ω_k − ω_{k−1})/(t_k − t_{k−1}) with
  a = exp(−(t_k − t_{k−1})/τ), τ = ``measured.acceleration_time_constant`` (τ = 0: the raw
  difference; a step in ω̇ is followed with time constant τ, so the estimate lags by about τ),
  and 0 for a first sample; every other acceleration is then an estimate too.

A sample that cannot be used is dropped and its ``DropReason`` returned; nothing of it is kept.
No ROS.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
import math

from linkage_kinematics.kinematics.geometry import TWO_PI, UnreachableError
from linkage_kinematics.kinematics.inversion import solve_from_rocker
from linkage_kinematics.kinematics.planar_loop import continued_branch_of
from linkage_kinematics.kinematics.solver import (
    continued_branch,
    CrankRates,
    DeadPointError,
    LinkageState,
    solve,
    unwrap_near,
)
from linkage_kinematics.loops.intake import DropReason, Estimate, Intake
from linkage_kinematics.loops.plan import find_loops, LoopPlan, RobotLoops
from linkage_kinematics.loops.solver import LoopSampleError, LoopSolver
from linkage_kinematics.model.joints import Driver, Link, TREE_ORDER, TreeValues
from linkage_kinematics.model.urdf import node_description
from linkage_kinematics.run.configuration import RunConfiguration

# Far below any distance between two change points, far above the rounding of the loop's
# geometry (rad): where the four-bar's and the loop's change points are told apart.
_CHANGE_POINT_CLEARANCE = 1e-9


@dataclass(frozen=True)
class FollowedSample:
    """
    The exact state at one measured sample, and how its driver rates were obtained.

    ``state.alpha`` is the unwrapped crank angle; ``driver_angle`` the unwrapped driver angle in
    the node's convention (α, or θ_BC = π − β for the rocker); ``motion_time`` the stamp's time
    since the first sample followed (s); ``joints`` the lab's positions and velocities of the
    driver's tree, root (the driver, unwrapped) first, the passive joints from the node's loop.
    """

    stamp_ns: int
    state: LinkageState
    driver_angle: float
    velocity: Estimate
    motion_time: float
    joints: TreeValues


@dataclass(frozen=True)
class _Anchor:
    """Where the followed motion is known: a driver angle, its assembly and its stamp."""

    stamp_ns: int
    encoder_angle: float  # as measured, node convention
    crank_angle: float  # α, unwrapped
    omega: float
    omega_dot: float


class MeasuredFollower:
    """Follows the measured driver joint; one per run, ``restart`` forgets the motion."""

    def __init__(self, config: RunConfiguration) -> None:
        joints = config.joints
        self.config = config
        self._mapping = joints.lab[Link(joints.driver.value)]
        # Messages that hold only the joints this node publishes are its own output coming
        # back (it may listen on the topic it publishes to): ignored, not counted.
        self._passive = tuple(joints.lab[link] for link in TREE_ORDER[joints.driver][1:])
        self._intake = Intake(
            (self._mapping.name,), (self._mapping.name,), config.measured.max_jump,
            DropReason.NO_DRIVER, own_output=(mapping.name for mapping in self._passive),
            mappings=(self._mapping,))
        self._loops = _node_loops(config)
        # The passive joints published last (lab values), kept across restarts so that they
        # stay continuous; at first the node's zero, as every joint stream starts.
        self._previous = tuple(mapping.offset for mapping in self._passive)
        self.restart()

    def restart(self) -> None:
        """Forget the motion: the next valid sample starts it again on ``branch``."""
        self._intake.restart()
        self._first: _Anchor | None = None
        self._last: _Anchor | None = None
        self._solver: LoopSolver | None = None  # planned at the motion's first sample

    def reconfigure(self, config: RunConfiguration) -> None:
        """
        Take a new configuration of the same joints.

        New thresholds (timeout, jump, filter) go on following the same motion; a new geometry
        (a new loop) comes with a restart of the motion.
        """
        if config.geometry.linkage != self.config.geometry.linkage:
            self._loops = _node_loops(config)
        self._intake.max_jump = config.measured.max_jump
        self.config = config

    def follow(
        self,
        stamp_ns: int,
        names: Sequence[str],
        positions: Sequence[float],
        velocities: Sequence[float],
    ) -> FollowedSample | DropReason | None:
        """
        Return the state at one message's driver sample, or why it was dropped.

        None for a message that is this node's own output (see ``__init__``).
        """
        taken = self._intake.take(stamp_ns, names, positions, velocities)
        if taken.__class__ is not tuple:
            return None if taken is None else taken.reason
        (measured_angle,), (angle,), (omega,), (estimate,) = taken
        # the driver's angle as measured, and the whole turns the intake unwrapped it by
        encoder_angle = self._mapping.from_lab(measured_angle)
        turns = round((angle - encoder_angle) / TWO_PI)
        omega_dot = self._acceleration(stamp_ns, omega)
        try:
            state = self._solve(encoder_angle, turns, omega, omega_dot)
            joints = self._complete(encoder_angle, measured_angle,
                                    self._mapping.direction * omega)
        except (DeadPointError, UnreachableError, LoopSampleError):
            return DropReason.DRIVER_UNREACHABLE
        self._intake.keep(stamp_ns, taken[1])
        anchor = _Anchor(stamp_ns, encoder_angle, state.alpha, omega, omega_dot)
        if self._first is None:
            self._first = anchor
        self._last = anchor
        self._previous = joints[0]
        return FollowedSample(
            stamp_ns, state, angle, estimate, (stamp_ns - self._first.stamp_ns) * 1e-9,
            ((self._mapping.to_lab(angle), *joints[0]),
             (self._mapping.direction * omega, *joints[1])))

    def _complete(self, encoder_angle: float, lab_angle: float, lab_velocity: float
                  ) -> tuple[tuple[float, float], tuple[float, float]]:
        """
        Return the passive joints' lab positions and velocities at the driver's lab values.

        ``encoder_angle`` is ``lab_angle`` in the node's convention. Solved by the node's loop
        (module docstring); raises LoopSampleError where it does not close. The solver is kept
        only once it has solved a sample, so that a refused first sample leaves the motion
        unstarted.
        """
        solver = self._solver or LoopSolver(self._plan(encoder_angle))
        name = self._mapping.name
        positions, velocities = solver.solve({name: lab_angle}, {name: lab_velocity})
        self._solver = solver
        return (
            tuple(unwrap_near(positions[mapping.name], previous)
                  for mapping, previous in zip(self._passive, self._previous)),
            tuple(velocities[mapping.name] for mapping in self._passive),
        )

    def _plan(self, encoder_angle: float) -> LoopPlan:
        """
        Return the node's loop planned to start on ``branch`` at the first sample.

        ``branch`` names the assembly at the driver's ``encoder_angle`` as the four-bar's closed
        form does (at a change point, the one just counterclockwise of it). The loop's geometry,
        read back from the URDF's rounded numbers, may put that change point an ulp to the other
        side of the sample, so the branch is carried a hair counterclockwise, where the two agree,
        and continued from there to the zero pose, where a LoopSolver starts (the continuation
        is symmetric: from the zero pose it comes back to this branch).
        """
        config = self.config
        nearby = encoder_angle + _CHANGE_POINT_CLEARANCE
        branch = continued_branch(config.geometry.driven_linkage, encoder_angle,
                                  config.motion.branch, nearby)
        (loop,) = self._loops.loops
        known = loop.joint(self._mapping.name)
        branch = continued_branch_of(loop.planar, known.index,
                                     known.sign * self._mapping.to_lab(nearby), branch, 0.0)
        return self._loops.plan([known.name], {loop.constraint: branch})

    def _acceleration(self, stamp_ns: int, omega: float) -> float:
        """Return the driver's ω̇ (node convention) at ``omega``: the filtered difference."""
        last = self._last
        if last is None:
            return 0.0
        interval = (stamp_ns - last.stamp_ns) * 1e-9
        raw = (omega - last.omega) / interval
        time_constant = self.config.measured.acceleration_time_constant
        keep = math.exp(-interval / time_constant) if time_constant > 0.0 else 0.0
        return keep * last.omega_dot + (1.0 - keep) * raw

    def _solve(self, encoder_angle: float, turns: int, omega: float,
               omega_dot: float) -> LinkageState:
        """
        Return the state at the measured driver angle ``encoder_angle`` + 2π·``turns``.

        Solved at the angle as measured (its precision kept), on the assembly the motion has
        reached from its first sample through any change points, with α unwrapped.
        """
        config = self.config
        driven = config.geometry.driven_linkage
        first = self._first
        if first is None:
            branch = config.motion.branch
        else:
            branch = continued_branch(driven, first.encoder_angle, config.motion.branch,
                                      encoder_angle, turns=turns)
        rates = CrankRates(omega, omega_dot)
        if config.joints.driver is Driver.CRANK:
            state = solve(driven, encoder_angle, rates, branch)
            return replace(state, alpha=state.alpha + turns * TWO_PI) if turns else state
        state = solve_from_rocker(config.geometry.linkage, driven, encoder_angle, rates, branch)
        if self._last is None:
            return state
        # The crank driven by the rocker may turn fully (a double crank): α stays continuous.
        return replace(state, alpha=unwrap_near(state.alpha, self._last.crank_angle))


def _node_loops(config: RunConfiguration) -> RobotLoops:
    """Return the loop of the node's own URDF for ``config`` (one four-bar, ``model.urdf``)."""
    return find_loops(node_description(config.geometry.linkage, config.outputs.frame_id,
                                       config.joints.lab, config.joints.driver).tree)
