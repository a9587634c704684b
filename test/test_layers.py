# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The package's layers, read from its imports: each layer imports only the layers below it.

kinematics ← model ← run ← bag ← ros ← cli (README: Architecture). Every import counts, those
under ``if TYPE_CHECKING:`` and inside functions included, and no module imports itself back
through others. The pure layers (kinematics, model, run) load no ROS, MCAP or ament module.
"""

from __future__ import annotations

import ast
from pathlib import Path
import subprocess
import sys

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / 'linkage_kinematics'
LAYERS = ('kinematics', 'model', 'loops', 'run', 'bag', 'ros', 'cli')
PURE_LAYERS = ('kinematics', 'model', 'loops', 'run')
# What a pure module must not load, directly or through what it imports.
NOT_PURE = ('rclpy', 'rosidl_parser', 'rosidl_runtime_py', 'mcap', 'mcap_ros2',
            'ament_index_python', 'builtin_interfaces', 'sensor_msgs', 'std_msgs')


def module_name(path: Path) -> str:
    """Return the dotted module name of a file of the package."""
    parts = path.relative_to(PACKAGE.parent).with_suffix('').parts
    return '.'.join(parts[:-1] if parts[-1] == '__init__' else parts)


MODULES = {module_name(path): path for path in sorted(PACKAGE.rglob('*.py'))}


def own_imports(name: str) -> set[str]:
    """Return the package's modules that module ``name`` imports, wherever the import stands."""
    imported = set()
    for node in ast.walk(ast.parse(MODULES[name].read_text(encoding='utf-8'))):
        if isinstance(node, ast.ImportFrom) and node.module:
            imported.add(node.module)
            imported.update(f'{node.module}.{alias.name}' for alias in node.names)
        elif isinstance(node, ast.Import):
            imported.update(alias.name for alias in node.names)
    return {module for module in imported if module in MODULES and module != name}


def layer(name: str) -> int | None:
    """Return the rank of the layer module ``name`` belongs to (None: the package's root)."""
    parts = name.split('.')
    return LAYERS.index(parts[1]) if len(parts) > 1 else None


def test_every_module_is_in_a_layer():
    assert {name.split('.')[1] for name in MODULES if '.' in name} == set(LAYERS)
    assert [name for name in MODULES if '.' not in name] == ['linkage_kinematics']


@pytest.mark.parametrize('name', sorted(MODULES))
def test_a_module_imports_only_its_own_layer_and_those_below(name):
    own = layer(name)
    upward = sorted(module for module in own_imports(name)
                    if own is None or (layer(module) or 0) > own)
    assert not upward, f'{name} ({LAYERS[own] if own is not None else "root"}) imports {upward}'


def test_no_import_cycle():
    graph = {name: own_imports(name) for name in MODULES}
    # A package imports its own modules in its __init__; that edge is not a cycle of layers.
    graph = {name: {module for module in imports if not name.startswith(module + '.')}
             for name, imports in graph.items()}
    done: set[str] = set()

    def visit(name: str, path: tuple[str, ...]) -> None:
        if name in path:
            pytest.fail('import cycle: ' + ' → '.join(path[path.index(name):] + (name,)))
        if name in done:
            return
        for module in sorted(graph[name]):
            visit(module, path + (name,))
        done.add(name)

    for name in sorted(graph):
        visit(name, ())


def test_the_pure_layers_load_no_ros_mcap_or_ament_module():
    pure = sorted(name for name in MODULES if layer(name) is not None
                  and LAYERS[layer(name)] in PURE_LAYERS)
    script = (
        'import importlib, sys\n'
        f'for name in {pure!r}:\n'
        '    importlib.import_module(name)\n'
        f'print(sorted({{m.split(".")[0] for m in sys.modules}} & set({NOT_PURE!r})))\n'
    )
    loaded = subprocess.run([sys.executable, '-c', script], capture_output=True, text=True,
                            check=True).stdout.strip()
    assert loaded == '[]', f'the pure layers load {loaded}'
