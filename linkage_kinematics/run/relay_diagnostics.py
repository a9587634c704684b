# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
What the command relay counts, logs and reports, without ROS.

``RelayRecord`` counts the messages relayed (trajectories and their points, forward commands)
and refused (by kind and reason), keeps the last refusal and the conversion time per message
and per point since the last status, and decides which refusals get a log line: the first of
each input and reason, then at most one a second of that input and reason, saying how many were
refused meanwhile (a 1 kHz stream of refusals would otherwise be a 1 kHz stream of lines; the
counts say them all).
``relay_status`` is the node's one status in ``diagnostics``' style: ERROR with a problem (no
description closes, the log failed), WARN when messages were refused since the last status
(each reason and its count), else OK with what the relay does; its key values give the counts,
the groups, the settings, the conversion times, the measured pose's age and the log.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from linkage_kinematics.loops.command import CommandRefusal
from linkage_kinematics.run.diagnostics import Level, LOG_DISABLED, Status
from linkage_kinematics.run.relay import GroupLine, MessageKind, REFUSALS, RelayRefusal

RELAY_TASK = 'command relay'
LOG_INTERVAL_NS = 1_000_000_000  # refusal lines of one input and reason at most this often


def _plural(count: int, word: str) -> str:
    return f'{count} {word}{"" if count == 1 else "s"}'


class RelayRecord:
    """The relay's counts, its last refusal, conversion times, and which refusals to log."""

    def __init__(self) -> None:
        self.relayed = dict.fromkeys(MessageKind, 0)
        self.points = 0  # trajectory points relayed
        self.refused = {kind: dict.fromkeys(REFUSALS, 0) for kind in MessageKind}
        self.last_refusal: str | None = None
        self._window = dict.fromkeys(REFUSALS, 0)
        # per input and reason: when its last line was logged, how many were not since
        self._logged_ns: dict[tuple[MessageKind, CommandRefusal | RelayRefusal], int] = {}
        self._unlogged: dict[tuple[MessageKind, CommandRefusal | RelayRefusal], int] = {}
        # conversion time (ns) and count since the last status: per command, per point
        self._times = {MessageKind.COMMANDS: [0, 0], MessageKind.TRAJECTORY: [0, 0]}
        self.mean_times: dict[MessageKind, float | None] = dict.fromkeys(MessageKind)

    def relay(self, kind: MessageKind, points: int, elapsed_ns: int) -> None:
        """Count a message relayed (``points``: a trajectory's) converted in ``elapsed_ns``."""
        self.relayed[kind] += 1
        times = self._times[kind]
        times[0] += elapsed_ns
        if kind is MessageKind.TRAJECTORY:
            self.points += points
            times[1] += points
        else:
            times[1] += 1

    def refuse(self, kind: MessageKind, reason: CommandRefusal | RelayRefusal, text: str,
               now_ns: int) -> str | None:
        """
        Count a refused message; return its log line, None within a second of the last alike.

        ``text``: the refusal in full (reason and detail); the line names the input.
        """
        self.refused[kind][reason] += 1
        self._window[reason] += 1
        line = f'refused {kind.value}: {text}'
        self.last_refusal = line
        key = (kind, reason)
        logged = self._logged_ns.get(key)
        if logged is not None and now_ns - logged < LOG_INTERVAL_NS:
            self._unlogged[key] += 1
            return None
        unlogged, self._unlogged[key] = self._unlogged.get(key, 0), 0
        self._logged_ns[key] = now_ns
        if unlogged:
            line += f' ({unlogged} more refused since the last such line)'
        return line

    def take_window(self) -> dict[CommandRefusal | RelayRefusal, int]:
        """Return the refusals since the last call, by reason; measure the mean times."""
        window, self._window = self._window, dict.fromkeys(REFUSALS, 0)
        for kind, times in self._times.items():
            if times[1]:
                self.mean_times[kind] = times[0] / times[1] * 1e-3  # µs
            times[0] = times[1] = 0
        return window


@dataclass(frozen=True, kw_only=True)
class RelayView:
    """What the node knows beyond the record when it sends a status."""

    robot_name: str | None  # None: no description closed yet
    description_from: str  # 'parameter robot_description' or the topic's resolved name
    groups: Sequence[GroupLine]
    interface: str
    joints: Sequence[str]
    controller_joints: Sequence[str]
    inputs: Sequence[str]  # the resolved topics relayed from
    outputs: Sequence[str]  # and to
    pose_age: float | None  # s since the last measured pose (velocity, effort); None: none
    measures_pose: bool
    problem: str | None
    log_file: str | None
    log_size: int | None


def relay_status(record: RelayRecord, view: RelayView) -> Status:
    """Return the relay's status (module docstring)."""
    window = record.take_window()
    refused = {reason: count for reason, count in window.items() if count}
    if view.problem is not None:
        level, message = Level.ERROR, view.problem
    elif view.robot_name is None:
        level, message = Level.OK, f'waiting for the robot description on {view.description_from}'
    elif refused:
        level = Level.WARN
        counts = '; '.join(f'{reason.value} ({count})' for reason, count in refused.items())
        message = (f'refused {_plural(sum(refused.values()), "message")} since the last '
                   f'status: {counts}')
    else:
        level = Level.OK
        message = (f'relaying {", ".join(view.inputs)} to {", ".join(view.outputs)}')
    values = {
        'relayed trajectories': str(record.relayed[MessageKind.TRAJECTORY]),
        'relayed trajectory points': str(record.points),
        'relayed commands': str(record.relayed[MessageKind.COMMANDS]),
        'refused trajectories': str(sum(record.refused[MessageKind.TRAJECTORY].values())),
        'refused commands': str(sum(record.refused[MessageKind.COMMANDS].values())),
    }
    for reason in REFUSALS:
        values[f'refused: {reason.value}'] = str(sum(record.refused[kind][reason]
                                                     for kind in MessageKind))
    values['last refusal'] = record.last_refusal or 'none'
    for kind, key in ((MessageKind.COMMANDS, 'conversion per command (µs)'),
                      (MessageKind.TRAJECTORY, 'conversion per trajectory point (µs)')):
        mean = record.mean_times[kind]
        values[key] = 'none yet' if mean is None else f'{mean:.1f}'
    if view.measures_pose:
        values['measured pose age (s)'] = ('none yet' if view.pose_age is None
                                           else f'{view.pose_age:.3f}')
    values['robot'] = view.robot_name or 'none yet'
    values['description from'] = view.description_from
    for group in view.groups:
        values[f'group {group.name}'] = group.describe().split(': ', 1)[1]
    values['commands interface'] = view.interface
    values['commands joints'] = ', '.join(view.joints)
    values['controller joints'] = ', '.join(view.controller_joints)
    if view.log_file is not None and view.log_size is not None:
        values['log size (bytes)'] = str(int(view.log_size))
    values['log file'] = LOG_DISABLED if view.log_file is None else view.log_file
    return Status(RELAY_TASK, view.robot_name or 'robot description', level, message, values)
