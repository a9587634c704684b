# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
Message definitions and type hashes as rosbag2 stores them, read from the ament index.

``message_definition`` is the ``ros2msg`` schema text of a type with every type it uses;
``type_description_hash`` is the RIHS01 hash rosidl generated for it. Both read the installed
interface files (``share/<package>/msg/<Name>.msg`` and ``.json``) of the packages on
AMENT_PREFIX_PATH, and for tf2_msgs, which is not on PyPI, the copies this package ships
(``share/linkage_kinematics/interfaces/``). Plain Python (no rclpy).
"""

from __future__ import annotations

import functools
import json
from pathlib import Path

from ament_index_python.packages import get_package_share_directory, PackageNotFoundError
from linkage_kinematics.bag.errors import MessageDefinitionError
from linkage_kinematics.bag.metadata import PACKAGE_NAME

SCHEMA_ENCODING = 'ros2msg'
DEFINITION_SEPARATOR = '=' * 80
_PRIMITIVE_TYPES = frozenset(
    'bool byte char float32 float64 int8 uint8 int16 uint16 int32 uint32 int64 uint64 '
    'string wstring'.split()
)


def _interface_file(package: str, name: str, suffix: str) -> Path | None:
    """
    Return the installed ``<package>/msg/<name><suffix>``.

    From the package in the ament index, or where that package is not installed, from the copies
    this package ships of the types it logs without publishing them (tf2_msgs, which has no
    package on PyPI; see interfaces/README.md).
    """
    try:
        share = Path(get_package_share_directory(package))
    except PackageNotFoundError:
        try:
            share = Path(get_package_share_directory(PACKAGE_NAME)) / 'interfaces' / package
        except PackageNotFoundError:
            return None
    except OSError as error:  # ament_index_python's EnvironmentError: no ament index at all
        raise MessageDefinitionError(
            f'cannot look up {package}/msg/{name}{suffix}: {error} (source the ROS 2 setup '
            'file, e.g. /opt/ros/jazzy/setup.bash, or a colcon install/setup.bash)'
        ) from None
    candidate = share / 'msg' / f'{name}{suffix}'
    return candidate if candidate.is_file() else None


def _split_type_name(type_name: str) -> tuple[str, str]:
    parts = type_name.split('/')
    if len(parts) == 3 and parts[1] == 'msg':
        return parts[0], parts[2]
    if len(parts) == 2:
        return parts[0], parts[1]
    raise MessageDefinitionError(
        f'message type {type_name!r} is not of the form package/msg/Name or package/Name'
    )


def _field_base_type(line: str) -> str | None:
    """
    Return the type a field (or constant) line refers to.

    It is ``pkg/Name``, ``Name`` or a primitive.
    """
    code = line.split('#', 1)[0].strip()
    if not code:
        return None
    return code.split()[0].split('[', 1)[0].split('<=', 1)[0]


@functools.cache
def message_definition(type_name: str) -> str:
    """
    Return the full ros2msg schema text of ``type_name`` (``pkg/msg/Name``) as rosbag2 stores it.

    The root .msg text comes first, then each dependency once, behind an 80-'=' line and a
    ``MSG: pkg/Name`` line. A dependency is named exactly as the referencing field spells it
    (``std_msgs/Header``, not ``std_msgs/msg/Header``), with the package of the referencing
    file added to bare names: Foxglove resolves field types against these names.
    """
    package, name = _split_type_name(type_name)
    root = _read_msg(package, name)
    sections = [root.rstrip('\n')]
    seen: set[str] = set()
    pending = _dependencies(package, root)
    while pending:
        dependency = pending.pop(0)
        if dependency in seen:
            continue
        seen.add(dependency)
        dep_package, dep_name = dependency.split('/')
        text = _read_msg(dep_package, dep_name)
        sections.append(f'{DEFINITION_SEPARATOR}\nMSG: {dependency}\n{text.rstrip(chr(10))}')
        pending += _dependencies(dep_package, text)
    return '\n'.join(sections) + '\n'


def _read_msg(package: str, name: str) -> str:
    path = _interface_file(package, name, '.msg')
    if path is None:
        raise MessageDefinitionError(
            f'no {package}/msg/{name}.msg in the ament index (AMENT_PREFIX_PATH): '
            'is the message package installed and the environment sourced?'
        )
    return path.read_text(encoding='utf-8')


def _dependencies(package: str, text: str) -> list[str]:
    found = []
    for line in text.splitlines():
        base = _field_base_type(line)
        if base is None or base in _PRIMITIVE_TYPES:
            continue
        found.append(base if '/' in base else f'{package}/{base}')
    return found


@functools.cache
def type_description_hash(type_name: str) -> str:
    """
    Return the RIHS01 type hash rosidl generated for ``type_name``.

    '' if it is not installed.
    """
    package, name = _split_type_name(type_name)
    path = _interface_file(package, name, '.json')
    if path is None:
        return ''
    full_name = f'{package}/msg/{name}'
    for entry in json.loads(path.read_text(encoding='utf-8')).get('type_hashes', []):
        if entry.get('type_name') == full_name:
            return str(entry.get('hash_string', ''))
    return ''
