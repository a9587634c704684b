# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
``linkage-demo``: the paper's numerical experiments, run through the real node and logged.

Runs ``linkage_node`` once per drive law of the paper (constant ω = 2 rad/s, and
ω = 0.10 + 2.3·α) over the 90° turn in the paper's fixed steps of 0.5°, each step published when
the drive law reaches it (the turns last 0.785 s and 1.571 s), each run logged to a new bag
under the log folder, then reads every bag back and prints the head and tail of the paper's
Tables 1–4 from what was logged, and draws the four-panel figure beside each bag.
"""

from __future__ import annotations

import argparse
from pathlib import Path
import subprocess
import sys

from ament_index_python.packages import get_package_share_directory, PackageNotFoundError
from linkage_kinematics.bag.reader import read_states
from linkage_kinematics.cli.arguments import number
from linkage_kinematics.cli.sweep import format_tables, write_plot

SCENARIOS = (
    ('seed_constant.yaml', "Constant law, ω = 2 rad/s (the paper's Tables 1 and 2)"),
    ('seed_variable.yaml', "Variable law, ω = 0.10 + 2.3·α rad/s (the paper's Tables 3 and 4)"),
)


def _run_node(params_file: Path, log_folder: Path) -> Path:
    """Run one scenario to its end; return the bag it wrote."""
    before = set(log_folder.iterdir()) if log_folder.is_dir() else set()
    command = [
        sys.executable, '-m', 'linkage_kinematics.ros.node', '--ros-args',
        '--params-file', str(params_file),
        '-p', 'mode:=fixed_step',
        '-p', f'log.folder:={log_folder}',
    ]
    completed = subprocess.run(command, check=False)
    if completed.returncode != 0:
        raise RuntimeError(f'linkage_node exited with status {completed.returncode}')
    new_bags = sorted(path for path in set(log_folder.iterdir()) - before if path.is_dir())
    if len(new_bags) != 1:
        raise RuntimeError(f'expected one new bag in {log_folder}, found {len(new_bags)}')
    return new_bags[0]


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``linkage-demo``."""
    parser = argparse.ArgumentParser(prog='linkage-demo',
                                     description=__doc__.strip().splitlines()[0])
    parser.add_argument('--log-folder', type=Path, default=Path('bags'),
                        help='folder that receives one new bag per run (default: bags)')
    parser.add_argument('--rows', type=number(int, at_least=1, rule='at least 1'), default=2,
                        help='rows shown at the head and at the tail of each table (default: 2)')
    arguments = parser.parse_args(argv)
    try:
        config_folder = Path(get_package_share_directory('linkage_kinematics')) / 'config'
    except (PackageNotFoundError, OSError) as error:
        # OSError: AMENT_PREFIX_PATH is not set at all.
        print(f'linkage-demo: cannot find the installed package ({error}); run it through '
              './dev demo or from a sourced colcon workspace', file=sys.stderr)
        return 1
    for params_name, title in SCENARIOS:
        try:
            bag = _run_node(config_folder / params_name, arguments.log_folder)
            _stamps, state = read_states(bag)
        except (RuntimeError, OSError) as error:  # a BagError is an OSError
            print(f'linkage-demo: {title}: {error}', file=sys.stderr)
            return 1
        figure = bag.parent / f'{bag.name}.png'
        write_plot(state, figure, title)
        print(format_tables(state, rows=arguments.rows,
                            title=f'{title}\nlogged in {bag}, figure {figure}'))
    return 0


if __name__ == '__main__':
    sys.exit(main())
