# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The four-bar's measured source: its driver joint on ``measured_joint_states``.

``MeasuredSubscription`` is a ``source.Source`` over ``measured.MeasuredFollower``: each message
of the input (``measured_input.MeasuredInput``) is followed, and the state it gives handed to its
host, the node, which publishes it; dropped samples and freshness go to its ``MeasuredHealth``.
"""

from __future__ import annotations

from linkage_kinematics.loops.intake import DropReason
from linkage_kinematics.model.joints import Link
from linkage_kinematics.ros.measured_input import MeasuredInput
from linkage_kinematics.ros.source import SourceHost
from linkage_kinematics.run.configuration import RunConfiguration
from linkage_kinematics.run.diagnostics import MeasuredHealth, StatusInputs
from linkage_kinematics.run.measured import MeasuredFollower


class MeasuredSubscription(MeasuredInput):
    """The measured source: ``measured_joint_states`` into a ``MeasuredFollower``."""

    def __init__(self, host: SourceHost) -> None:
        config = host.config
        self._follower = MeasuredFollower(config)
        self.health = MeasuredHealth(host.now_ns())
        self._driver_name = config.joints.lab[Link(config.joints.driver.value)].name
        super().__init__(host, self.health)
        self._show_activity()

    @property
    def paused_answer(self) -> str:
        return f'paused: samples of {self._driver_name} are ignored'

    @property
    def resumed_answer(self) -> str:
        return f'following {self._driver_name} again from its next sample'

    def start(self) -> None:
        """Publish the URDF (before the first sample, for robot_state_publisher) and status."""
        self._host.publish_description()
        self._host.publish_diagnostics()

    @staticmethod
    def statuses(_inputs: StatusInputs) -> None:
        """Return None: the measured four-bar's status is ``diagnostics.report``'s."""
        return None

    def reconfigure(self, new: RunConfiguration) -> None:
        """Take the node's new configuration: thresholds, and the lab's names and mapping."""
        if new.joints.lab != self._follower.config.joints.lab:
            # The lab's names and mapping: the driver is read anew under them.
            self._follower = MeasuredFollower(new)
            self._driver_name = new.joints.lab[Link(new.joints.driver.value)].name
        else:
            self._follower.reconfigure(new)
        self._retime(new)

    def restart(self) -> None:
        """Forget the motion: the next valid sample starts it afresh on ``branch``."""
        self._follower.restart()
        self._host.publish_description()

    def _forget_motion(self) -> None:
        self._follower.restart()

    def _show_activity(self) -> None:
        self._host.set_activity(
            f'paused: {self._driver_name} is not followed until ~/resume'
            if self._host.control.paused
            else f'waiting for {self._driver_name} on measured_joint_states')

    def _on_message(self, data: bytes) -> None:
        if self._host.control.paused:
            return  # ~/pause: not followed, not counted
        try:
            stamp_ns, names, positions, velocities, _ = self._decoder.decode(data)
        except ValueError:
            self.health.drop(DropReason.MALFORMED)
            return
        followed = self._follower.follow(stamp_ns, names, positions, velocities)
        if followed is None:
            return  # this node's own joint states, heard back
        if isinstance(followed, DropReason):
            self.health.drop(followed)
            return
        self.health.accept(self._host.now_ns(), followed.velocity)
        if self.stale:
            self.stale = False
            self._host.forget_state()  # publish the scene and the status with the next state
        self._host.set_activity(f'following {self._driver_name}')
        self._host.publish_state(followed.state, followed.stamp_ns, followed.motion_time,
                                 followed.joints)
