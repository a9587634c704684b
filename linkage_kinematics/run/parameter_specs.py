# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The node's parameters as declared: each one's name, default, descriptor text and limits.

Pure, no ROS: one small function per group of parameters (geometry, motion, outputs, logging,
measured input and joints), in the order the node declares them. ``parameters`` owns the limits
and the validation of values; ``node_parameters`` turns these specifications into ROS
descriptors.
"""

from __future__ import annotations

from collections.abc import Collection, Iterable
from dataclasses import dataclass
import difflib
import math
from typing import Any

from linkage_kinematics.kinematics.geometry import DIMENSIONS, LINK_LENGTHS, preset, TWO_PI
from linkage_kinematics.model.joints import DEFAULT_JOINT_NAMES, Driver, Link
from linkage_kinematics.model.urdf import DEFAULT_FRAME_ID
from linkage_kinematics.run.configuration import EndBehavior, MotionMode, NODE_NAME, SourceKind
from linkage_kinematics.run.limits import (
    MAX_ANGLE,
    MAX_BAG_DURATION,
    MAX_BAG_SIZE,
    MAX_CPU,
    MAX_DISPLAY_RATE_HZ,
    MAX_DRIVE_GAIN,
    MAX_OMEGA0,
    MAX_PARAMETER_LENGTH,
    MAX_RATE_HZ,
    MAX_TIME_CONSTANT,
    MAX_TIMEOUT,
    MIN_SPLIT_SIZE,
    NO_CPU_AFFINITY,
    NO_SPLIT,
)


@dataclass(frozen=True)
class ParameterSpec:
    """One node parameter: its default (None: no default), descriptor text and limits."""

    name: str
    default: Any
    description: str
    read_only: bool = False
    floating_range: tuple[float, float] | None = None
    integer_range: tuple[int, int, int] | None = None


_DIMENSION_TEXTS = {
    'crank_length': 'disk radius OA, greater than 0',
    'coupler_length': 'coupler length AB, greater than 0',
    'rocker_length': 'rocker length BC, greater than 0',
    'ground_x': 'x of the fixed pivot C relative to O',
    'ground_y': 'y of the fixed pivot C relative to O',
}


def _geometry_specs(preset_name: str) -> tuple[ParameterSpec, ...]:
    """Return the preset and the five dimensions, which default to the preset's."""
    geometry = preset(preset_name).geometry if preset_name else None
    return (
        ParameterSpec(
            'preset', 'paper',
            "mechanism whose dimensions are the geometry parameters' defaults: "
            "paper, paper_full_turn, grashof_crank_rocker, or '' for none",
            read_only=True,
        ),
        *(
            ParameterSpec(
                name,
                getattr(geometry, name) if geometry is not None else None,
                f"{_DIMENSION_TEXTS[name]} (m); defaults to the preset's value, required when "
                "preset is ''",
                floating_range=((0.0 if name in LINK_LENGTHS else -MAX_PARAMETER_LENGTH),
                                MAX_PARAMETER_LENGTH),
            )
            for name in DIMENSIONS
        ),
    )


def _motion_specs() -> tuple[ParameterSpec, ...]:
    """Return the assembly branch, the drive law, the pass and how it is stepped."""
    return (
        ParameterSpec('branch', 1,
                      'assembly at alpha_start: +1 (B left of A→C) or −1; through change points '
                      'the motion continues on its smooth branch',
                      integer_range=(-1, 1, 2)),
        ParameterSpec('omega0', 2.0, 'drive law ω = omega0 + k·α: omega0 (rad/s)',
                      floating_range=(-MAX_OMEGA0, MAX_OMEGA0)),
        ParameterSpec('k', 0.0, 'drive law ω = omega0 + k·α: k (1/s)',
                      floating_range=(-MAX_DRIVE_GAIN, MAX_DRIVE_GAIN)),
        ParameterSpec('alpha_start', 0.0, 'crank angle where the motion starts (rad)',
                      floating_range=(-MAX_ANGLE, MAX_ANGLE)),
        ParameterSpec('alpha_end', math.pi / 2.0,
                      'crank angle where one pass ends (rad), not alpha_start',
                      floating_range=(-MAX_ANGLE, MAX_ANGLE)),
        # A node runs until it is stopped, as every ROS node does: by default the crank swings
        # to and fro over its pass, which suits the paper's mechanism (it cannot turn fully).
        ParameterSpec('end_behavior', EndBehavior.BOUNCE.value,
                      'at the end of a pass: stop (and exit), loop or bounce'),
        ParameterSpec('mode', MotionMode.REAL_TIME.value,
                      'real_time: α from node-clock time at rate_hz; fixed_step: steps of '
                      'alpha_step, each published when the drive law reaches it'),
        ParameterSpec('alpha_step', math.radians(0.5),
                      'crank step in fixed_step mode (rad), greater than 0',
                      floating_range=(0.0, TWO_PI)),
        ParameterSpec('rate_hz', 100.0,
                      'state compute and publish rate in real_time mode (Hz), greater than 0; '
                      'unused in fixed_step mode',
                      floating_range=(0.0, MAX_RATE_HZ)),
    )


def _output_specs() -> tuple[ParameterSpec, ...]:
    """Return the marker rate, the frames published in, and the diagnostics' thresholds."""
    return (
        ParameterSpec('display_rate_hz', 30.0,
                      'publish rate of linkage/markers (Hz), greater than 0',
                      floating_range=(0.0, MAX_DISPLAY_RATE_HZ)),
        ParameterSpec('frame_id', DEFAULT_FRAME_ID,
                      'frame of the markers and linkage/state, root link of the URDF',
                      read_only=True),
        ParameterSpec('frame_prefix', '',
                      "prefix of every frame id the node publishes (robot_state_publisher's "
                      "frame_prefix, e.g. 'left/'); the URDF stays unprefixed",
                      read_only=True),
        ParameterSpec('diagnostics.min_transmission_angle', math.radians(10.0),
                      'WARN when min(μ, π − μ) of the transmission angle μ is below this (rad)',
                      floating_range=(0.0, math.pi / 2.0)),
        ParameterSpec('diagnostics.dead_point_warning', math.radians(1.0),
                      'WARN when the crank is closer than this to a dead point or a change '
                      'point (rad)',
                      floating_range=(0.0, math.pi)),
    )


def _logging_specs() -> tuple[ParameterSpec, ...]:
    """Return the bag's parameters and where the node's process and its bag writer run."""
    return (
        ParameterSpec('log.enabled', True, 'record every published message to a bag',
                      read_only=True),
        ParameterSpec('log.folder', 'bags',
                      'folder that receives a new bag per run (relative to the working '
                      'directory)', read_only=True),
        ParameterSpec('log.max_bag_size', NO_SPLIT,
                      "bytes after which the bag goes on in a new file (rosbag2's "
                      f'--max-bag-size); 0 never splits, else at least {MIN_SPLIT_SIZE}',
                      read_only=True, integer_range=(NO_SPLIT, MAX_BAG_SIZE, 1)),
        ParameterSpec('log.max_bag_duration', float(NO_SPLIT),
                      "seconds after which the bag goes on in a new file (rosbag2's "
                      '--max-bag-duration, here also a fraction); 0 never splits',
                      read_only=True, floating_range=(0.0, MAX_BAG_DURATION)),
        ParameterSpec('cpu_affinity', NO_CPU_AFFINITY,
                      "CPU that every thread of the node's process runs on, its bag writer "
                      "process on the others (as ros2_control's cpu_affinity); -1 leaves "
                      'both to the operating system',
                      integer_range=(NO_CPU_AFFINITY, MAX_CPU, 1)),
    )


def _joint_specs() -> tuple[ParameterSpec, ...]:
    """Return the source, its driver joint, and each joint's lab name, direction and offset."""
    return (
        ParameterSpec('source', SourceKind.DRIVE_LAW.value,
                      'drive_law: a timer turns the crank under the drive law; measured: the '
                      'driver joint of each message on measured_joint_states',
                      read_only=True),
        ParameterSpec('driver', Driver.CRANK.value,
                      'joint that moves the linkage: crank (at O) or rocker (at C, '
                      'source measured only)',
                      read_only=True),
        *(
            spec
            for link in Link
            for spec in (
                ParameterSpec(f'joints.{link.value}.name', DEFAULT_JOINT_NAMES[link],
                              f'name of the {link.value} joint in joint_states and the URDF'),
                ParameterSpec(f'joints.{link.value}.direction', 1,
                              f'+1 or -1: lab value of the {link.value} joint = direction · '
                              'node value + offset', integer_range=(-1, 1, 2)),
                ParameterSpec(f'joints.{link.value}.offset', 0.0,
                              f'offset of the {link.value} joint (rad): lab value = '
                              'direction · node value + offset',
                              floating_range=(-MAX_ANGLE, MAX_ANGLE)),
            )
        ),
        ParameterSpec('publish_robot_description', True,
                      "publish the node's URDF on robot_description (false where the lab's "
                      'robot_state_publisher has its own)', read_only=True),
    )


def _measured_specs() -> tuple[ParameterSpec, ...]:
    """Return how the measured source judges and filters its samples."""
    return (
        ParameterSpec('measured.timeout', 1.0,
                      'diagnostics ERROR after this long without a valid measured sample (s), '
                      'greater than 0', floating_range=(0.0, MAX_TIMEOUT)),
        ParameterSpec('measured.max_jump', math.pi / 2.0,
                      'a measured driver angle further than this from the last one used is '
                      'dropped (rad, greater than 0; π drops none)',
                      floating_range=(0.0, math.pi)),
        ParameterSpec('measured.acceleration_time_constant', 0.02,
                      "time constant of the low-pass filter on the driver's angular "
                      'acceleration estimate (s); 0 for the raw difference of velocities',
                      floating_range=(0.0, MAX_TIME_CONSTANT)),
    )


def parameter_specs(preset_name: str) -> tuple[ParameterSpec, ...]:
    """All parameters; the geometry defaults come from ``preset_name`` ('' → no defaults)."""
    return (
        *_geometry_specs(preset_name),
        *_motion_specs(),
        *_output_specs(),
        *_logging_specs(),
        *_joint_specs(),
        *_measured_specs(),
        ParameterSpec('autostart', True,
                      'start the motion at once; false: publish the scene at alpha_start, the '
                      'URDF and the status, then wait for ~/resume',
                      read_only=True),
    )


PARAMETER_NAMES = tuple(spec.name for spec in parameter_specs(''))
REAL_PARAMETERS = frozenset(
    spec.name for spec in parameter_specs('') if spec.floating_range is not None
)


def unknown_parameters(given: Iterable[str], declared: Collection[str]) -> list[str]:
    """
    Return one warning per parameter in ``given`` that is not in ``declared``, sorted by name.

    Each names the parameter and the closest of the node's own parameters, if one is close
    (``rate`` → ``rate_hz``).
    """
    warnings = []
    for name in sorted(set(given) - set(declared)):
        closest = difflib.get_close_matches(name, PARAMETER_NAMES, n=1)
        hint = f"; did you mean '{closest[0]}'?" if closest else ''
        warnings.append(f"unknown parameter '{name}' ignored: {NODE_NAME} has no such "
                        f'parameter{hint}')
    return warnings
