# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
No module of the package uses another module's private names.

A name with a leading underscore belongs to its module: what another module needs is public
where it is defined (``kinematics.decimal_arithmetic``, ``continuation.turns_past``). Read from
each module's syntax: ``from linkage_kinematics.x import _name`` and ``x._name`` on a module of
the package, however it was imported, wherever the import stands. An underscore attribute of an
object (``loop._slide``) is not seen here; only its own module reaches such names today.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = 'linkage_kinematics'


def module_name(path: Path) -> str:
    """Return the dotted module name of a file of the package."""
    parts = path.relative_to(ROOT).with_suffix('').parts
    return '.'.join(parts[:-1] if parts[-1] == '__init__' else parts)


MODULES = {module_name(path): path for path in sorted((ROOT / PACKAGE).rglob('*.py'))}


def is_private(name: str) -> bool:
    """Return True for ``_name`` (not a dunder such as ``__all__``)."""
    return name.startswith('_') and not (name.startswith('__') and name.endswith('__'))


def absolute(node: ast.ImportFrom, importer: str) -> str:
    """Return the module a ``from … import`` names, a relative one made absolute."""
    if not node.level:
        return node.module or ''
    package = importer if MODULES[importer].name == '__init__.py' else importer.rpartition('.')[0]
    base = package.rsplit('.', node.level - 1)[0] if node.level > 1 else package
    return f'{base}.{node.module}' if node.module else base


def dotted(node: ast.expr) -> str | None:
    """Return ``a.b.c`` for an attribute chain on a name, None for anything else."""
    if isinstance(node, ast.Name):
        return node.id
    if isinstance(node, ast.Attribute):
        inner = dotted(node.value)
        return None if inner is None else f'{inner}.{node.attr}'
    return None


def private_uses(importer: str) -> list[str]:
    """Return each use of another module's private name in module ``importer``, with its line."""
    tree = ast.parse(MODULES[importer].read_text(encoding='utf-8'))
    # local name → the package module it is bound to
    bound: dict[str, str] = {}
    uses = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split('.')[0] != PACKAGE:
                    continue
                if alias.asname:
                    bound[alias.asname] = alias.name
                else:
                    bound[PACKAGE] = PACKAGE
        elif isinstance(node, ast.ImportFrom):
            source = absolute(node, importer)
            if source.split('.')[0] != PACKAGE or source == importer:
                continue
            for alias in node.names:
                if is_private(alias.name):
                    uses.append((node.lineno, node.col_offset,
                                 f'from {source} import {alias.name}'))
                elif f'{source}.{alias.name}' in MODULES:
                    bound[alias.asname or alias.name] = f'{source}.{alias.name}'
    for node in ast.walk(tree):
        if not isinstance(node, ast.Attribute) or not is_private(node.attr):
            continue
        chain = dotted(node.value)
        if chain is None:
            continue
        head, _, rest = chain.partition('.')
        if head not in bound:
            continue
        module = bound[head] + (f'.{rest}' if rest else '')
        if module in MODULES and module != importer:
            uses.append((node.lineno, node.col_offset, f'{chain}.{node.attr}'))
    return [f'line {line}: {text}' for line, _, text in sorted(uses)]


@pytest.mark.parametrize('name', sorted(MODULES))
def test_a_module_uses_no_private_name_of_another(name: str) -> None:
    assert private_uses(name) == []


def test_the_check_sees_both_ways_of_reaching_a_private_name(tmp_path: Path,
                                                             monkeypatch: pytest.MonkeyPatch
                                                             ) -> None:
    importer = tmp_path / 'importer.py'
    importer.write_text(
        'from linkage_kinematics.kinematics.geometry import _hidden, TWO_PI\n'
        'from linkage_kinematics.kinematics import geometry\n'
        'import linkage_kinematics.kinematics.solver as solver\n'
        'import linkage_kinematics.kinematics.continuation\n'
        'from . import drive\n'
        'geometry._other, solver._cache, geometry.__name__, geometry.TWO_PI\n'
        'linkage_kinematics.kinematics.continuation._count\n'
        'drive._law\n',
        encoding='utf-8')
    monkeypatch.setitem(MODULES, 'linkage_kinematics.kinematics.importer', importer)
    assert private_uses('linkage_kinematics.kinematics.importer') == [
        'line 1: from linkage_kinematics.kinematics.geometry import _hidden',
        'line 6: geometry._other',
        'line 6: solver._cache',
        'line 7: linkage_kinematics.kinematics.continuation._count',
        'line 8: drive._law',
    ]
