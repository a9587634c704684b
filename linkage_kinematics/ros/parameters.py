# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The node's parameters on the ROS side: declared with descriptors, whole numbers kept real.

``run.parameter_specs`` owns what each parameter is and ``run.configuration`` checks values
against it; this module only declares them on a node so that ``ros2 param describe`` shows their
meaning, unit and range.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from linkage_kinematics.kinematics.geometry import GeometryError
from linkage_kinematics.run.parameter_specs import (
    Kind,
    PARAMETER_NAMES,
    parameter_specs,
    ParameterSpec,
    REAL_PARAMETERS,
    relay_parameter_specs,
)
from linkage_kinematics.run.parameter_values import ConfigurationError, parameter_value
from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor
from rclpy.node import Node
from rclpy.parameter import Parameter


def parameter_descriptor(spec: ParameterSpec, with_range: bool = True) -> ParameterDescriptor:
    """Return a parameter's ROS descriptor (range and read-only flag only ``with_range``)."""
    # dynamic_typing lets a wrongly typed value reach build_configuration, whose message
    # names the parameter; rclpy's own type check does not.
    descriptor = ParameterDescriptor(
        name=spec.name,
        description=spec.description,
        # rclpy refuses a later descriptor, with its range, for a read-only parameter
        read_only=spec.read_only and with_range,
        dynamic_typing=True,
    )
    if with_range and spec.floating_range is not None:
        low, high = spec.floating_range
        descriptor.floating_point_range = [FloatingPointRange(from_value=low, to_value=high)]
    if with_range and spec.integer_range is not None:
        low_integer, high_integer, step = spec.integer_range
        descriptor.integer_range = [
            IntegerRange(from_value=low_integer, to_value=high_integer, step=step)
        ]
    return descriptor


def keep_declared_types(changed: list[Parameter]) -> list[Parameter]:
    """
    Turn whole numbers given for real parameters into those reals.

    So that a parameter never changes type (`ros2 param set /linkage_node rate_hz 50`).
    """
    return [
        Parameter(p.name, Parameter.Type.DOUBLE, float(p.value))
        if p.name in REAL_PARAMETERS and p.type_ == Parameter.Type.INTEGER
        else p
        for p in changed
    ]


def declare_parameters(node: Node) -> tuple[ParameterSpec, ...]:
    """Declare every parameter on ``node`` (without ranges, see ``add_ranges``)."""
    preset_spec = parameter_specs('paper')[0]
    node.declare_parameter(preset_spec.name, preset_spec.default,
                           parameter_descriptor(preset_spec, with_range=False))
    preset_name = parameter_value({'preset': node.get_parameter('preset').value}, 'preset')
    try:
        specs = parameter_specs(preset_name)
    except GeometryError as error:
        raise ConfigurationError('preset', str(error)) from None
    _declare(node, specs[1:])
    return specs


def declare_relay_parameters(node: Node) -> tuple[ParameterSpec, ...]:
    """Declare the command relay's parameters on ``node`` (without ranges, ``add_ranges``)."""
    specs = relay_parameter_specs()
    _declare(node, specs)
    return specs


def _declare(node: Node, specs: Sequence[ParameterSpec]) -> None:
    for spec in specs:
        node.declare_parameter(spec.name, spec.default,
                               parameter_descriptor(spec, with_range=False))
    # A whole number given for a real parameter (`-p rate_hz:=50`) is stored as that real.
    whole_numbers = [
        node.get_parameter(spec.name) for spec in specs if spec.name in REAL_PARAMETERS
        and node.get_parameter(spec.name).type_ == Parameter.Type.INTEGER
    ]
    if whole_numbers:
        node.set_parameters(keep_declared_types(whole_numbers))
    # An empty list of names is a string array: rclpy declares the default [] as a byte array
    # (so `ros2 param describe` and `get` said "byte array"), and rcl reads an empty YAML list
    # (`-p commands.joints:=[]`, or `[]` in a parameters file, as `ros2 param dump` writes
    # one) as no value at all, which the node refused.
    untyped = (Parameter.Type.BYTE_ARRAY, Parameter.Type.NOT_SET)
    empty_lists = [
        Parameter(spec.name, Parameter.Type.STRING_ARRAY, []) for spec in specs
        if spec.kind is Kind.TEXTS and node.get_parameter(spec.name).type_ in untyped
        and not node.get_parameter(spec.name).value
    ]
    if empty_lists:
        node.set_parameters(empty_lists)


def add_ranges(node: Node, specs: tuple[ParameterSpec, ...]) -> None:
    """
    Put the ranges into the descriptors, once the start-up values are validated.

    So that a bad start-up value gets build_configuration's message; from here on rclpy enforces
    them too.
    """
    for spec in specs:
        if (spec.floating_range is not None or spec.integer_range is not None
                or spec.read_only):
            node.set_descriptor(spec.name, parameter_descriptor(spec))


def parameter_values(node: Node, names: Sequence[str] = PARAMETER_NAMES) -> dict[str, Any]:
    """Return the current values of the node's own parameters ``names`` (name → value)."""
    return {name: node.get_parameter(name).value for name in names}
