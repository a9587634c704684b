# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Argparse value types shared by the command-line tools.

Each refusal names the rule the value broke, so that argparse prints one line such as
``argument --rows: must be at least 1, got '0'`` instead of a traceback.
"""

from __future__ import annotations

import argparse
import math
from typing import Callable


def number(
    kind: type = float,
    *,
    above: float | None = None,
    at_least: float | None = None,
    rule: str = '',
) -> Callable[[str], float]:
    """
    Return a type converting text to a finite ``kind`` (float or int) within a bound.

    The value must be greater than ``above`` or at least ``at_least`` when given; ``rule`` says
    the bound in the error message.
    """
    noun = 'a whole number' if kind is int else 'a number'

    def convert(text: str) -> float:
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f'not {noun}: {text!r}') from None
        if not math.isfinite(value):
            raise argparse.ArgumentTypeError(f'must be a finite number, got {text!r}')
        if (above is not None and not value > above) or (
            at_least is not None and not value >= at_least
        ):
            raise argparse.ArgumentTypeError(f'must be {rule}, got {text!r}')
        return value

    return convert
