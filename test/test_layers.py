# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The package's layers: import-linter's contracts (.importlinter), and what they cannot see.

.importlinter states them: each layer imports only those beneath it (cli, ros, bag | run side by
side and independent, loops, model, kinematics, shared), every subpackage is a layer, the pure
layers import no ROS, MCAP or ament module directly or through the package's own modules, and no
modules of one package import each other in a cycle. grimp reads every import, those under
``if TYPE_CHECKING:`` and inside functions included. Running lint-imports here makes ./dev test
and colcon test enforce them.

lint-imports reads this package's source only: what a third-party library loads in turn is not
in its graph. The last test imports every module of the pure layers in a fresh interpreter and
lists the forbidden modules that got loaded all the same.
"""

from __future__ import annotations

import configparser
from pathlib import Path
import shutil
import subprocess
import sys

ROOT = Path(__file__).resolve().parents[1]
CONTRACTS = ROOT / '.importlinter'
# lint-imports' closing line when every contract of .importlinter holds
ALL_KEPT = 'Contracts: 3 kept, 0 broken.'


def test_lint_imports_keeps_every_contract() -> None:
    lint_imports = shutil.which('lint-imports')
    assert lint_imports, 'lint-imports not found: pip install import-linter (requirements.txt)'
    # run from the repository, whose directory lint-imports puts first on sys.path: it reads
    # these sources, not an installed copy
    completed = subprocess.run(
        [lint_imports, '--config', str(CONTRACTS), '--no-cache', '--no-logo'], cwd=ROOT,
        capture_output=True, text=True)
    assert completed.returncode == 0, completed.stdout + completed.stderr
    assert ALL_KEPT in completed.stdout, completed.stdout


def pure_contract() -> tuple[list[Path], list[str]]:
    """Return the pure layers' folders that exist, and the modules they must not load."""
    parser = configparser.ConfigParser()
    parser.read(CONTRACTS, encoding='utf-8')
    contract = parser['importlinter:contract:pure']
    # 'linkage_kinematics.loops.*' stands for loops' modules: the folder of the layer
    folders = [ROOT.joinpath(*line.removesuffix('.*').split('.'))
               for line in contract['source_modules'].split()]
    return ([folder for folder in folders if folder.is_dir()],
            contract['forbidden_modules'].split())


def test_the_pure_layers_load_no_ros_mcap_or_ament_module_at_run_time() -> None:
    folders, forbidden = pure_contract()
    assert {folder.name for folder in folders} >= {'kinematics', 'model', 'run'}
    modules = sorted(
        '.'.join(path.relative_to(ROOT).with_suffix('').parts).removesuffix('.__init__')
        for folder in folders for path in folder.rglob('*.py'))
    script = (
        'import importlib, sys\n'
        f'for name in {modules!r}:\n'
        '    importlib.import_module(name)\n'
        f'print(sorted({{m.split(".")[0] for m in sys.modules}} & set({forbidden!r})))\n'
    )
    loaded = subprocess.run([sys.executable, '-c', script], cwd=ROOT, capture_output=True,
                            text=True, check=True).stdout.strip()
    assert loaded == '[]', f'the pure layers load {loaded}'
