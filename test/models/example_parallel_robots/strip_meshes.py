# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Copy example-parallel-robots' models here, their meshes stripped (README.md says what and why).

Usage: ``python strip_meshes.py GIT_DIR [COMMIT]``, GIT_DIR a clone (bare or not) of
github.com/Gepetto/example-parallel-robots. Each model's ``robots/<model>/robot.urdf`` is written
to ``<model>/robot.urdf`` without its ``<visual>`` and ``<collision>`` elements (every one holds
a mesh, which the package does not read and the models' directory does not hold), the rest as
written but for lxml's spelling of an empty element (``<x/>`` for ``<x />``); ``robot.yaml`` and
the repository's ``LICENSE`` are copied unchanged.
"""

from pathlib import Path
import subprocess
import sys

import lxml.etree

MODELS = ('5bar_linkage', 'robot_delta', 'cassie_like', 'digit_like', 'kangaroo_like',
          'battobot_6d', 'wl16_like', 'disney_like')
HERE = Path(__file__).resolve().parent


def show(git_dir: str, commit: str, path: str) -> bytes:
    """Return the file at ``path`` in ``commit`` of the repository at ``git_dir``."""
    return subprocess.run(['git', '--git-dir', git_dir, 'show', f'{commit}:{path}'],
                          check=True, capture_output=True).stdout


def stripped(urdf: bytes) -> bytes:
    """Return ``urdf`` without <visual> and <collision>, each element's indentation kept."""
    robot = lxml.etree.fromstring(urdf)
    for element in list(robot.iter('visual', 'collision')):
        # the whitespace before the element stays; the element's tail (the indentation of what
        # follows it) takes its place, so a link's closing tag keeps its own indentation
        previous, parent = element.getprevious(), element.getparent()
        if previous is not None:
            previous.tail = element.tail
        else:
            parent.text = element.tail
        parent.remove(element)
    return lxml.etree.tostring(robot) + b'\n'


def main(git_dir: str, commit: str = 'HEAD') -> None:
    for model in MODELS:
        folder = HERE / model
        folder.mkdir(exist_ok=True)
        (folder / 'robot.urdf').write_bytes(stripped(show(git_dir, commit,
                                                          f'robots/{model}/robot.urdf')))
        (folder / 'robot.yaml').write_bytes(show(git_dir, commit, f'robots/{model}/robot.yaml'))
    (HERE / 'LICENSE').write_bytes(show(git_dir, commit, 'LICENSE'))


if __name__ == '__main__':
    main(*sys.argv[1:])
