# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
One parameter value checked against its spec, and the error that names a bad one.

``parameter_value`` checks a value by its spec's kind (``parameter_specs``: a real in its
interval and unit, an integer or its off value, a sign, a flag, a text, a choice, a list of
texts) and returns it in its Python type; ``ConfigurationError`` names the parameter and what
its spec asks for. The node's and the relay's configurations (``configuration``), the placement
and the ROS shell's parameter events all check through it. Pure: no ROS.
"""

from __future__ import annotations

from collections.abc import Mapping
from enum import StrEnum
import math
from typing import Any

from linkage_kinematics.run.parameter_specs import Kind, ParameterSpec, SPECS


class ConfigurationError(ValueError):
    """A parameter value (or a combination of them) the node cannot run with."""

    def __init__(self, parameter: str, reason: str) -> None:
        super().__init__(f'{parameter}: {reason}')
        self.parameter = parameter
        self.reason = reason


def describe_value(value: object) -> str:
    """Return a parameter value and its type, for error messages."""
    if value is None:
        return 'no value'
    return f'{type(value).__name__} {value!r}'


def _real(spec: ParameterSpec, value: object) -> float:
    # bool is an int in Python but a different parameter type in ROS.
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ConfigurationError(spec.name, f'must be a number, got {describe_value(value)}')
    value = float(value)
    if not math.isfinite(value):
        raise ConfigurationError(spec.name, f'must be finite, got {value!r}')
    interval, unit = spec.interval, spec.unit  # set for every real (ParameterSpec)
    if value in interval:
        return value
    if interval.open_low:
        reason = (f'must be greater than {interval.low:g} {unit} and at most {interval.high:g} '
                  f'{unit}')
    else:
        reason = f'must lie in [{interval.low:g}, {interval.high:g}] {unit}'
    raise ConfigurationError(spec.name, f'{reason}, got {value!r}')


def _integer(spec: ParameterSpec, value: object) -> int:
    interval, off = spec.interval, spec.off  # both set for every integer (ParameterSpec)
    if (isinstance(value, bool) or not isinstance(value, int)
            or not (value == off.value or value in interval)):
        unit = f' {spec.unit}' if spec.unit else ''
        raise ConfigurationError(
            spec.name,
            f'must be {off.value} ({off.meaning}) or a {spec.noun} in [{interval.low}, '
            f'{interval.high}]{unit}, got {describe_value(value)}',
        )
    return value


def _sign(spec: ParameterSpec, value: object) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value not in (1, -1):
        raise ConfigurationError(
            spec.name, f'must be the integer 1 or -1, got {describe_value(value)}')
    return value


def _flag(spec: ParameterSpec, value: object) -> bool:
    if not isinstance(value, bool):
        raise ConfigurationError(spec.name, f'must be true or false, got {describe_value(value)}')
    return value


def _text(spec: ParameterSpec, value: object) -> str:
    if not isinstance(value, str):
        raise ConfigurationError(spec.name, f'must be a string, got {describe_value(value)}')
    if not value and not spec.allow_empty:
        raise ConfigurationError(spec.name, 'must not be empty')
    return value


def _choice(spec: ParameterSpec, value: object) -> StrEnum:
    if not isinstance(value, str):
        raise ConfigurationError(spec.name, f'must be a string, got {describe_value(value)}')
    choices = spec.choices  # set for every choice (ParameterSpec)
    if value not in tuple(choices):
        raise ConfigurationError(
            spec.name, f"must be one of {', '.join(choices)}; got {value!r}")
    return choices(value)


def _texts(spec: ParameterSpec, value: object) -> list[str]:
    if not isinstance(value, (list, tuple)) or not all(isinstance(item, str) for item in value):
        raise ConfigurationError(
            spec.name, f'must be a list of strings, got {describe_value(value)}')
    if '' in value:
        raise ConfigurationError(spec.name, 'must not hold an empty string')
    duplicates = sorted({item for item in value if value.count(item) > 1})
    if duplicates:
        raise ConfigurationError(spec.name, f'names {duplicates} more than once')
    return list(value)


_CHECKS = {
    Kind.REAL: _real,
    Kind.INTEGER: _integer,
    Kind.SIGN: _sign,
    Kind.FLAG: _flag,
    Kind.TEXT: _text,
    Kind.CHOICE: _choice,
    Kind.TEXTS: _texts,
}


def parameter_value(values: Mapping[str, Any], name: str,
                    specs: Mapping[str, ParameterSpec] = SPECS) -> Any:
    """
    Return parameter ``name``'s value in ``values``, checked against its spec in ``specs``.

    A real comes back as a float (a whole number is accepted), a choice as its enum member.
    Raises ConfigurationError naming the parameter and what its spec asks for (a missing value
    is refused as ``no value``).
    """
    spec = specs[name]
    return _CHECKS[spec.kind](spec, values.get(name))
