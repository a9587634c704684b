# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The lists of modules a reader finds the code by name every module there is, and no other.

Each subpackage's ``__init__`` docstring names each of its modules (as ``module``), and only
modules of the package itself or of a sibling subpackage, names its modules define or take, or
the package's executables; and
CONTRIBUTING.md's architecture tree names each module under its subpackage (or, as for the
bag's table, as ``package.module``). A module added, moved or removed without its list fails
here.
"""

from __future__ import annotations

import ast
from pathlib import Path
import re

import pytest

REPOSITORY = Path(__file__).resolve().parent.parent
PACKAGE = REPOSITORY / 'linkage_kinematics'
SUBPACKAGES = sorted(path.parent.name for path in PACKAGE.glob('*/__init__.py'))
QUOTED = re.compile(r'``([A-Za-z_][\w.]*)``')


def modules(subpackage: str) -> set[str]:
    return {path.stem for path in (PACKAGE / subpackage).glob('*.py') if path.stem != '__init__'}


def defined_names(subpackage: str) -> set[str]:
    """Return every name the subpackage's modules define, import or take as an argument."""
    names = set()
    for path in (PACKAGE / subpackage).glob('*.py'):
        for node in ast.walk(ast.parse(path.read_text(encoding='utf-8'))):
            if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
                names.add(node.name)
            elif isinstance(node, ast.arg):
                names.add(node.arg)
            elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
                names.add(node.id)
            elif isinstance(node, (ast.Import, ast.ImportFrom)):
                names.update((alias.asname or alias.name).split('.')[0]
                             for alias in node.names)
    return names


def executables() -> set[str]:
    """Return the console scripts setup.py installs (linkage_node, linkage_command_node, …)."""
    setup = (REPOSITORY / 'setup.py').read_text(encoding='utf-8')
    return set(re.findall(r"'([\w-]+) = linkage_kinematics\.", setup))


def docstring(subpackage: str) -> str:
    source = (PACKAGE / subpackage / '__init__.py').read_text(encoding='utf-8')
    return ast.get_docstring(ast.parse(source)) or ''


@pytest.mark.parametrize('subpackage', SUBPACKAGES)
def test_each_subpackage_docstring_names_each_of_its_modules(subpackage: str) -> None:
    quoted = set(QUOTED.findall(docstring(subpackage)))
    assert modules(subpackage) - quoted == set()


@pytest.mark.parametrize('subpackage', SUBPACKAGES)
def test_a_subpackage_docstring_names_no_module_that_is_not_there(subpackage: str) -> None:
    """A lower-case name it quotes is a module, a name of its code, or an executable."""
    known = set(SUBPACKAGES) | defined_names(subpackage) | executables()
    for other in SUBPACKAGES:
        known |= modules(other)
    unknown = {name for name in QUOTED.findall(docstring(subpackage))
               if name.islower() and '.' not in name and name not in known}
    assert unknown == set()


def architecture() -> str:
    text = (REPOSITORY / 'CONTRIBUTING.md').read_text(encoding='utf-8')
    start = text.index('## Architecture')
    return text[start:text.index('\n## ', start)]


def tree_block(section: str, subpackage: str) -> str:
    """Return the lines of the tree under ``subpackage/``, up to the next subpackage."""
    lines = section.splitlines()
    header = re.compile(r'^  (\w+)/')
    (first,) = [index for index, line in enumerate(lines)
                if (match := header.match(line)) and match[1] == subpackage]
    block = [lines[first]]
    for line in lines[first + 1:]:
        if header.match(line) or line.startswith('```'):
            break
        block.append(line)
    return '\n'.join(block)


@pytest.mark.parametrize('subpackage', SUBPACKAGES)
def test_the_architecture_names_every_module_in_its_layer(subpackage: str) -> None:
    section = architecture()
    block = tree_block(section, subpackage)
    missing = {module for module in modules(subpackage)
               if not re.search(rf'\b{module}\b', block)
               and f'`{subpackage}.{module}`' not in section}
    assert missing == set()
