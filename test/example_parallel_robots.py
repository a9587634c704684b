# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Gepetto/example-parallel-robots' models (test/models/example_parallel_robots), in three encodings.

Each model comes as its URDF and closure file (robot.yaml). ``with_constraints`` and
``with_loop_joints`` write the file's closures into the URDF as ``<constraint>`` or
``<loop_joint>`` elements instead, so that the three encodings of a model can be read and
compared. The frame a closure file names is resolved here on its own, with ElementTree, not with
the package's reader: a link's name is its frame, a joint's name its child link's frame (as
Pinocchio names a frame after every joint, at its child link's origin).
"""

from pathlib import Path
import xml.etree.ElementTree as ElementTree

import yaml

FOLDER = Path(__file__).resolve().parent / 'models' / 'example_parallel_robots'
MODELS = ('5bar_linkage', 'robot_delta', 'cassie_like', 'digit_like', 'kangaroo_like',
          'battobot_6d', 'wl16_like', 'disney_like')
# The closure file's kinds as both elements write them
ELEMENT_TYPES = {'3d': 'spherical', '6d': 'fixed'}


def urdf(model: str) -> str:
    """Return the model's URDF text (its meshes stripped)."""
    return (FOLDER / model / 'robot.urdf').read_text()


def closure_file(model: str) -> str:
    """Return the model's closure file text, as example-parallel-robots wrote it."""
    return (FOLDER / model / 'robot.yaml').read_text()


def closure_file_content(model: str) -> dict:
    """Return the model's closure file's keys, as PyYAML's safe loader reads them."""
    return yaml.safe_load(closure_file(model))


def frame_link(model: str, frame: str) -> str:
    """Return the link whose frame the closure file's ``frame`` is."""
    robot = ElementTree.fromstring(urdf(model))
    if any(link.get('name') == frame for link in robot.iter('link')):
        return frame
    (joint,) = [joint for joint in robot.iter('joint') if joint.get('name') == frame]
    return joint.find('child').get('link')


def closures(model: str) -> list[tuple[str, str, str, str]]:
    """Return each closure of the file: its name (the loader's), kind, parent and child links."""
    content = closure_file_content(model)
    return [(f'{first}C{second}', kind.lower(), frame_link(model, first),
             frame_link(model, second))
            for (first, second), kind in zip(content['closed_loop'], content['type'])]


def _with(model: str, elements: list[str]) -> str:
    text = urdf(model)
    end = text.rindex('</robot>')
    return text[:end] + ''.join(f'  {element}\n' for element in elements) + text[end:]


def with_constraints(model: str) -> str:
    """Return the model's URDF with its closures as urdfdom PR #264 <constraint> elements."""
    return _with(model, [
        f'<constraint name="{name}" type="{ELEMENT_TYPES[kind]}"><parent link="{parent}"/>'
        f'<parent_origin xyz="0 0 0" rpy="0 0 0"/><child link="{child}"/></constraint>'
        for name, kind, parent, child in closures(model)])


def with_loop_joints(model: str) -> str:
    """Return the model's URDF with its closures as Isaac Sim <loop_joint> elements."""
    return _with(model, [
        f'<loop_joint name="{name}" type="{ELEMENT_TYPES[kind]}"><link1 link="{parent}" '
        f'xyz="0 0 0" rpy="0 0 0"/><link2 link="{child}"/></loop_joint>'
        for name, kind, parent, child in closures(model)])


def without_closures(model: str) -> str:
    """Return the model's closure file without closed_loop and type: actuation and overrides."""
    content = closure_file_content(model)
    return yaml.safe_dump({key: value for key, value in content.items()
                           if key not in ('closed_loop', 'type')})
