# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
``linkage_node``.

Publishes the linkage's exact state as the drive law turns the crank, or as a measured joint
moves it.

A thin shell that wires pure modules to ROS: ``run.configuration`` validates the parameter
values into a frozen RunConfiguration; one source gives the states, with this node as its
``source.SourceHost``: ``drive_law_source`` over ``motion.DriveLawRun`` (the drive law on the
node's timer), ``measured_source`` over ``measured.MeasuredFollower`` (the driver joint of each
``measured_joint_states`` message) or ``loop_source`` over ``loops.follower`` (every loop of a
lab's URDF); ``run.diagnostics`` says what ``/diagnostics`` reports;
``ros.outputs`` publishes and logs; ``ros.process`` runs its process. Topics, parameters,
diagnostics and exit statuses are documented in docs/parameters.md.
"""

from __future__ import annotations

from collections.abc import Callable
import sys
from typing import Any

from linkage_kinematics.kinematics.solver import LinkageState
from linkage_kinematics.model.joints import TreeValues
from linkage_kinematics.ros.drive_law_source import DriveLawTimer
from linkage_kinematics.ros.loop_source import robot_from_parameter, RobotLoopsSubscription
from linkage_kinematics.ros.measured_source import MeasuredSubscription
from linkage_kinematics.ros.outputs import NodeOutputs
from linkage_kinematics.ros.parameters import (
    add_ranges,
    declare_parameters,
    keep_declared_types,
    parameter_values,
)
from linkage_kinematics.ros.process import run_node
from linkage_kinematics.ros.source import RunStatus, Source
from linkage_kinematics.run.configuration import (
    build_configuration,
    LoopsSource,
    NODE_NAME,
    RunConfiguration,
    SourceKind,
)
from linkage_kinematics.run.control import RunControl, ServiceAnswer
from linkage_kinematics.run.diagnostics import RateMeter, report, StatusInputs, StatusSchedule
from linkage_kinematics.run.motion import blocked_note
from linkage_kinematics.run.parameter_specs import PARAMETER_NAMES, unknown_parameters
from linkage_kinematics.run.parameter_values import ConfigurationError
from linkage_kinematics.run.placement import CpuPlacement
from rcl_interfaces.msg import SetParametersResult
from rclpy.node import Node
from rclpy.parameter import Parameter
from std_srvs.srv import Trigger

DIAGNOSTICS_PERIOD = 1.0  # s


# --- the node ------------------------------------------------------------------------------


class LinkageNode(RunStatus, Node):
    """
    Publishes the linkage's state as its source moves it (docs/parameters.md: Topics, Parameters).

    Markers at display_rate_hz, diagnostics at 1 Hz and whenever the activity changes.
    Construction raises ConfigurationError for bad parameters before anything is published or
    written. ``exit_code`` becomes an ExitCode when the run has ended (docs/parameters.md,
    exit statuses). The node is its source's ``SourceHost`` and owns the run's status
    (``RunStatus``: activity, problem, exit code), which the source changes only through it.
    """

    def __init__(self, **node_options: Any) -> None:
        super().__init__(NODE_NAME, **node_options)
        specs = declare_parameters(self)
        # rclpy has no public accessor of the overrides given for this node; they include the
        # `-p` arguments and the /** entries of parameter files, which rcl keeps as one set.
        for warning in unknown_parameters(self._parameter_overrides,
                                          self.list_parameters([], 0).names):
            self.get_logger().warning(warning)
        self.config = config = build_configuration(self.parameter_values())
        self.control = RunControl(config.autostart)
        add_ranges(self, specs)
        if blocked_note(config) is not None:
            self.get_logger().warning(blocked_note(config))
        self._pending: tuple[RunConfiguration, list[str]] | None = None
        self._state: LinkageState | None = None
        self._state_ns = 0
        self._motion_started = False  # a state of this motion published (not only the scene)
        self._rate_meter = RateMeter()
        self._status_schedule = StatusSchedule()
        self._placement = CpuPlacement()
        self._place(config.logging.cpu_affinity)
        loops = config.loops.source is LoopsSource.ROBOT_DESCRIPTION
        # A description given as a parameter is read before anything is published or written.
        robot = robot_from_parameter(config) if loops else None
        self.outputs = NodeOutputs(self, config, self.parameter_values(),
                                   self._placement.bag_writer_cpus)
        self._marker_timer = self.create_timer(1.0 / config.outputs.display_rate_hz,
                                               self.publish_markers)
        self._diagnostics_timer = self.create_timer(DIAGNOSTICS_PERIOD, self.publish_diagnostics)
        self.add_pre_set_parameters_callback(keep_declared_types)
        self.add_on_set_parameters_callback(self._validate_change)
        self.add_post_set_parameters_callback(self._apply_change)
        self._source: Source
        if loops:
            self._source = RobotLoopsSubscription(self, self.outputs, robot)
        elif config.joints.source is SourceKind.MEASURED:
            self._source = MeasuredSubscription(self)
        else:
            self._source = DriveLawTimer(self)
        for name, act in (('pause', self._source.pause), ('resume', self._source.resume),
                          ('reset', self._source.reset)):
            self.create_service(Trigger, f'~/{name}', self._answer(act))
        self._source.start()

    # parameters

    def parameter_values(self) -> dict[str, Any]:
        """Return the current values of the node's own parameters (name → value)."""
        return parameter_values(self)

    def _validate_change(self, changed: list[Parameter]) -> SetParametersResult:
        """Validate the whole configuration the change would produce; keep it for the post-set."""
        current = self.parameter_values()
        updates = {p.name: p.value for p in changed if p.name in PARAMETER_NAMES}
        try:
            config = build_configuration({**current, **updates})
            self._placement.check(config.logging.cpu_affinity)
        except ConfigurationError as error:
            self._pending = None
            return SetParametersResult(successful=False, reason=str(error))
        differing = [name for name, value in updates.items() if value != current[name]]
        self._pending = (config, differing)
        return SetParametersResult(successful=True)

    def _apply_change(self, changed: list[Parameter]) -> None:
        if self._pending is None:
            return
        (new, differing), self._pending = self._pending, None
        if not differing:
            return  # e.g. `ros2 param load` of the node's own dump: nothing changes
        old = self.config
        self._apply(new)
        restarts = new.restarts_motion(old)
        self.get_logger().info(
            'parameters changed: '
            + ', '.join(f'{name}={self.get_parameter(name).value!r}' for name in differing)
            + ('; motion restarts at alpha_start' if restarts else '')
        )
        if blocked_note(new) is not None:
            self.get_logger().warning(blocked_note(new))
        if new.outputs.display_rate_hz != old.outputs.display_rate_hz:
            self.destroy_timer(self._marker_timer)
            self._marker_timer = self.create_timer(1.0 / new.outputs.display_rate_hz,
                                                   self.publish_markers)
        if new.logging.cpu_affinity != old.logging.cpu_affinity:
            self._place(new.logging.cpu_affinity)
            if self.outputs.log.recorder is not None:
                self.outputs.log.recorder.run_writer_on(
                    self._placement.bag_writer_cpus or self._placement.available)
        if new.joints.lab != old.joints.lab:
            self.publish_description()  # the lab's names, axes and offsets
        if restarts:
            self.forget_state()
            self._source.restart()

    def _apply(self, new: RunConfiguration) -> None:
        """Swap in a new configuration: the one way every holder of it takes it."""
        self.config = new
        self.outputs.config = new
        self._source.reconfigure(new)

    def _answer(self, act: Callable[[], ServiceAnswer]) -> Callable[..., Trigger.Response]:
        """Return a Trigger service callback (~/pause, ~/resume, ~/reset) answering as ``act``."""
        def callback(_request: Trigger.Request, response: Trigger.Response) -> Trigger.Response:
            answer = act()
            response.success, response.message = answer.success, answer.message
            if answer.success:
                self.get_logger().info(answer.message)
            return response
        return callback

    def _place(self, cpu: int) -> None:
        change = self._placement.place(cpu)
        if change is not None:
            self.get_logger().info(change)

    # the source's host (source.SourceHost): publishing, and the status it changes

    def now_ns(self) -> int:
        """Return the node clock's time (ns)."""
        return self.get_clock().now().nanoseconds

    @property
    def state(self) -> LinkageState | None:
        """Return the latest state shown (published, or the scene of a motion waiting)."""
        return self._state

    @property
    def motion_started(self) -> bool:
        """Whether a state of this motion was published (not only the scene of it waiting)."""
        return self._motion_started

    def flush_log(self) -> None:
        """Have the bag writer write out what it holds (before the run's last status)."""
        self.outputs.log.flush()

    # the process (process.ProcessNode): the end of the run

    def flush(self, timeout: float = 1.0) -> None:
        """Give subscribers up to ``timeout`` s in all to acknowledge what was published."""
        self.outputs.flush(timeout)

    def close_log(self) -> bool:
        """Finalize the bag (idempotent); False, with an error logged, if that failed."""
        return self.outputs.log.close()

    def forget_state(self) -> None:
        """Make the next state a motion's first: its scene and status go out before it."""
        self._state = None
        self._motion_started = False

    def show_waiting(self, state: LinkageState, stamp_ns: int) -> None:
        """Publish the scene of ``state``, the URDF if new, and the status; no state."""
        self._state = state
        self._state_ns = stamp_ns
        self.publish_markers()
        self.outputs.publish_description(stamp_ns)
        self.publish_diagnostics()

    def publish_state(self, state: LinkageState, stamp_ns: int, motion_time: float,
                      joints: TreeValues | None = None) -> None:
        """
        Publish a state stamped ``stamp_ns`` (and the tree's joints, if the source solved them).

        The first of a motion comes after its scene (so a viewer knows the frame before anything
        refers to it), the URDF if the geometry is new, and the status that says it moves.
        """
        first = not self._motion_started
        self._motion_started = True
        self._state = state
        self._state_ns = stamp_ns
        self._rate_meter.tick()
        if first:
            self.publish_markers()
            self.outputs.publish_description(stamp_ns)
            self.publish_diagnostics()
        self.outputs.publish_state(state, stamp_ns, motion_time, joints)
        if self._status_schedule.due(stamp_ns):
            self.publish_diagnostics()

    def publish_markers(self) -> None:
        """Publish the scene of the latest state, stamped with that state's time."""
        if self._state is not None:
            self.outputs.publish_markers(self._state, self._state_ns)

    def publish_description(self) -> None:
        """Publish the URDF if it is new, at the latest state's time (or now before one)."""
        self.outputs.publish_description(
            self._state_ns if self._state is not None else self.now_ns())

    def publish_diagnostics(self, event: str | None = None, at_ns: int | None = None) -> None:
        """
        Publish the status, stamped ``at_ns``.

        By default the latest state's time, so that log times never fall behind the states',
        or now before the first state and while measured data is stale; ``event``, a problem
        of this moment only, makes it ERROR.
        """
        now_ns = self.now_ns()
        if at_ns is None:
            fresh = self._state is not None and not self._source.stale
            at_ns = self._state_ns if fresh else now_ns
        self._rate_meter.update(now_ns)
        self._status_schedule.sent(at_ns)
        recorder = self.outputs.log.recorder
        inputs = StatusInputs(
            config=self.config,
            run_state=self.control.state,
            state=self._state,
            activity=self.activity,
            achieved_rate=self._rate_meter.rate,
            missed_deadlines=self._source.missed_deadlines,
            log_file=None if recorder is None else str(recorder.bag_path),
            log_size=None if recorder is None else recorder.size_bytes,
            problem=event or self.problem or self.outputs.log.error,
            health=self._source.health,
            now_ns=now_ns,
        )
        statuses = self._source.statuses(inputs)
        self.outputs.publish_statuses(at_ns, (report(inputs),) if statuses is None else statuses)


# --- process ------------------------------------------------------------------------------


def main(args: list[str] | None = None) -> int:
    """Run the node until it finishes, or until SIGINT or SIGTERM; return the exit status."""
    return run_node(NODE_NAME, LinkageNode, args)


if __name__ == '__main__':
    sys.exit(main())
