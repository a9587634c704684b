# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Size budgets: a module, a class and a function each stay short enough to be read whole.

Lines from the first to the last (a function's or class's from its ``def``/``class`` line,
decorators not counted; a method counts in its class and on its own).
"""

import ast
from pathlib import Path

import pytest

REPOSITORY = Path(__file__).resolve().parent.parent
FOLDERS = ('linkage_kinematics', 'test', 'bench')
MODULE_LINES = 600
CLASS_LINES = 250
FUNCTION_LINES = 100


def _python_files() -> list[Path]:
    return sorted(path for folder in FOLDERS for path in (REPOSITORY / folder).rglob('*.py'))


def over_budget(path: Path, root: Path = REPOSITORY) -> list[str]:
    """Describe each part of the module at ``path`` (and the module) that is over its budget."""
    text = path.read_text()
    name = path.relative_to(root)
    offenders = []
    lines = len(text.splitlines())
    if lines > MODULE_LINES:
        offenders.append(f'{name}: module of {lines} lines (budget {MODULE_LINES})')
    for node in ast.walk(ast.parse(text, str(path))):
        if isinstance(node, ast.ClassDef):
            kind, budget = 'class', CLASS_LINES
        elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            kind, budget = 'function', FUNCTION_LINES
        else:
            continue
        size = node.end_lineno - node.lineno + 1
        if size > budget:
            offenders.append(
                f'{name}:{node.lineno}: {kind} {node.name} of {size} lines (budget {budget})')
    return offenders


def test_every_module_class_and_function_keeps_to_its_budget() -> None:
    files = _python_files()
    # The three folders are there and read: an empty walk would pass for the wrong reason.
    assert {path.relative_to(REPOSITORY).parts[0] for path in files} == set(FOLDERS)
    offenders = [offender for path in files for offender in over_budget(path)]
    assert offenders == [], '\n'.join(offenders)


@pytest.mark.parametrize(('source', 'expected'), [
    ('x = 1\n' * MODULE_LINES, []),
    ('x = 1\n' * (MODULE_LINES + 1), [f'module of {MODULE_LINES + 1} lines']),
    ('def f():\n' + '    pass\n' * (FUNCTION_LINES - 1), []),
    ('def f():\n' + '    pass\n' * FUNCTION_LINES, [f'function f of {FUNCTION_LINES + 1} lines']),
    ('class C:\n    async def g(self):\n' + '        pass\n' * FUNCTION_LINES,
     [f'function g of {FUNCTION_LINES + 1} lines']),
    ('class C:\n' + '    x = 1\n' * CLASS_LINES, [f'class C of {CLASS_LINES + 1} lines']),
])
def test_the_budgets_count_lines_from_first_to_last(
    tmp_path: Path, source: str, expected: list[str]
) -> None:
    path = tmp_path / 'example.py'
    path.write_text(source)
    offenders = over_budget(path, tmp_path)
    assert len(offenders) == len(expected), offenders
    for offender, part in zip(offenders, expected):
        assert part in offender and offender.startswith('example.py'), offender
