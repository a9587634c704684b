# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A robot description's loop closures, whichever of the three encodings wrote each.

A URDF may hold ``<constraint>`` and ``<loop_joint>`` elements side by side, and a closure file
may come with it; all three are read (one reader each), their closures put together, in that
order, kinds and encodings mixed. Only the closure file names actuated joints and overrides
joints. Two closures of one name are one too many: the first is kept, the other refused by name.
"""

from __future__ import annotations

from linkage_kinematics.loops.closure_file import read_closure_file
from linkage_kinematics.loops.closures import Closure, ClosureDescription, Encoding
from linkage_kinematics.loops.constraint_element import read_constraints
from linkage_kinematics.loops.loop_joint_element import read_loop_joints
from linkage_kinematics.model.urdf_reader import UrdfTree

# How a problem line names the encoding a closure came from.
SOURCES = {Encoding.CONSTRAINT: 'a <constraint>', Encoding.LOOP_JOINT: 'a <loop_joint>',
           Encoding.CLOSURE_FILE: 'the closure file'}


def read_closures(tree: UrdfTree, closure_file: str | None = None) -> ClosureDescription:
    """
    Return every closure of URDF ``tree`` and of closure file text ``closure_file`` (if any).

    The URDF is the one ``model.urdf_reader.read_urdf`` parsed (its ``element`` holds the
    elements urdf_parser_py does not read); it is not parsed again. ``actuated`` and
    ``overrides`` are the closure file's (None and none without one). ``problems`` holds one
    line for each closure or entry that cannot be read, and for each name used by two closures.
    Raises ClosureError (one line) for a closure file text that is not YAML, is empty or is not a
    mapping of the file's keys: unreadable input, as UrdfError is for the URDF.
    """
    constraints, constraint_problems = read_constraints(tree)
    loop_joints, loop_joint_problems = read_loop_joints(tree)
    in_file = (read_closure_file(tree, closure_file) if closure_file is not None
               else ClosureDescription())
    problems = [*constraint_problems, *loop_joint_problems, *in_file.problems]
    closures: dict[str, Closure] = {}
    for closure in (*constraints, *loop_joints, *in_file.closures):
        first = closures.get(closure.name)
        if first is None:
            closures[closure.name] = closure
        else:
            problems.append(f'closure {closure.name!r}: the name is used twice, by '
                            f'{SOURCES[first.encoding]} and {SOURCES[closure.encoding]}')
    return ClosureDescription(tuple(closures.values()), in_file.actuated, in_file.overrides,
                              tuple(problems))
