# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
docs/parameters.md's table of linkage_command_node's parameters is relay_parameter_specs.

Every parameter the relay declares, in its order, and no other; each one's default, each real
one's range, and which are read-only, as the specs have them (as
test_node_parameters.py holds the loops node's ranges to its specs).
"""

from __future__ import annotations

import math
from pathlib import Path
import re
from typing import Any

from linkage_kinematics.run.parameter_specs import Kind, relay_parameter_specs
import pytest

from test_node_parameters import documented_number

REPOSITORY = Path(__file__).resolve().parent.parent


def relay_table() -> list[list[str]]:
    """Return the cells of each row of the relay's parameter table."""
    text = (REPOSITORY / 'docs' / 'parameters.md').read_text(encoding='utf-8')
    start = text.index('## linkage_command_node')
    section = text[start:text.index('\n## ', start + 1)]
    table = section[section.index('| parameter | default |'):]
    rows = []
    for line in table.splitlines()[2:]:
        if not line.startswith('|'):
            break
        rows.append([cell.strip() for cell in line.strip('|').split(' | ')])
    return rows


def documented_default(cell: str) -> Any:
    """Return a default as the table writes it: `''`, `[]`, `true`, `position`, `1.0`, π/2."""
    text = cell.strip('`')
    if text == "''":
        return ''
    if text == '[]':
        return []
    if text in ('true', 'false'):
        return text == 'true'
    if re.fullmatch(r'-?\d+', text):
        return int(text)
    if re.fullmatch(r'-?\d+\.\d+', text):
        return float(text)
    if 'π' in text:
        return documented_number(text)
    return text


def test_the_table_names_every_relay_parameter_in_order():
    assert [row[0].strip('`') for row in relay_table()] == [
        spec.name for spec in relay_parameter_specs()]


@pytest.mark.parametrize('spec', relay_parameter_specs(), ids=lambda spec: spec.name)
def test_each_row_states_its_default_range_and_run_time_as_the_spec(spec):
    (row,) = [row for row in relay_table() if row[0] == f'`{spec.name}`']
    _, default, meaning, run_time = row
    documented = documented_default(default)
    if isinstance(spec.default, float):
        assert math.isclose(documented, spec.default, rel_tol=1e-15)
    else:
        assert documented == spec.default
    assert (run_time == 'read-only') == spec.read_only
    if spec.kind is Kind.REAL:
        interval = re.search(r'in ([\[(])([^,]+), ([^\]]+)\]', meaning)
        assert interval is not None, spec.name
        assert (documented_number(interval[2]), documented_number(interval[3])) == (
            pytest.approx((spec.interval.low, spec.interval.high)))
        assert (interval[1] == '(') == spec.interval.open_low
