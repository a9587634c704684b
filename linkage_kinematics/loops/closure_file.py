# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The closure file of toolbox-parallel-robots, read against its URDF.

Gepetto/example-parallel-robots keeps beside each ``robot.urdf`` a ``robot.yaml`` (the "Extended
URDF" of arXiv 2504.04767), which its loader (``example_parallel_robots/loader_tools.py``,
``completeRobotLoader``, on top of Pinocchio and PyPI's toolbox-parallel-robots) reads::

    closed_loop: [['closedloop1_A', 'closedloop1_B']]   # pairs of frames held together
    type: ['6d']                                         # per pair: '3d' or '6d'
    name_mot: ['mot1', 'mot2']                           # the actuated joints
    joint_name: ['ankle_1', 'foot_1']                    # optional: URDF joints read as ...
    joint_type: ['UJOINT_ZY', 'SPHERICAL']               # ... these joints instead

* A frame is one of Pinocchio's frames of the URDF: a link's, or a joint's, which is its child
  link's frame (every closure frame of the example models is a link, or a revolute joint's
  frame). ``3d`` (or ``3D``) is a ball: the frames' origins coincide (Pinocchio's CONTACT_3D);
  ``6d`` a weld: the frames coincide (CONTACT_6D). The loader names the closure
  ``<frame1>C<frame2>``; so does this reader. The first frame is the parent side.
* ``name_mot`` names the actuated joints, the default measured joints.
* ``joint_type`` reads a URDF joint as ``SPHERICAL``, ``UJOINT_AB`` (A, B each of X, Y, Z) or
  ``FIXED`` (see ``JointOverride``); an override that cannot be read so is refused by name: a
  fixed joint (Pinocchio merges it into its links, so the loader never sees it), a joint in a
  mimic pair, a coordinate name the URDF already uses, an actuated joint.

Where the loader reads a malformed file silently (unequal lists are cut short, an unknown
``type`` is a weld, an unknown ``name_mot`` is left out), this reader refuses it: one line for
each problem, naming the key; a text that is not such a file at all is a ``ClosureError``.
Pure: PyYAML (its safe loader, as the loader's) and the URDF tree ``model.urdf_reader`` read.
"""

from __future__ import annotations

from linkage_kinematics.loops.closures import (
    Closure,
    ClosureDescription,
    ClosureError,
    ClosureKind,
    ClosureSide,
    Encoding,
    JointOverride,
)
from linkage_kinematics.model.urdf_reader import JointType, UrdfTree
import yaml

KEYS = ('closed_loop', 'type', 'name_mot', 'joint_name', 'joint_type')
KINDS = {'3d': ClosureKind.BALL, '3D': ClosureKind.BALL,
         '6d': ClosureKind.WELD, '6D': ClosureKind.WELD}
KIND_WORDS = "'3d' (a ball: the frames' origins coincide) or '6d' (a weld: the frames coincide)"
OVERRIDE_WORDS = ', '.join(override.name for override in JointOverride)


def _content(text: str) -> dict:
    """Return the file's mapping of keys; ClosureError if it is not YAML or not such a mapping."""
    try:
        content = yaml.safe_load(text)
    except yaml.MarkedYAMLError as error:
        mark = error.problem_mark
        where = f' at line {mark.line + 1}, column {mark.column + 1}' if mark is not None else ''
        raise ClosureError(f'the closure file is not YAML: {error.problem}{where}') from None
    except yaml.YAMLError as error:
        raise ClosureError('the closure file is not YAML: '
                           + ' '.join(str(error).split())) from None
    if content is None:
        raise ClosureError('the closure file is empty')
    if not isinstance(content, dict):
        raise ClosureError(f'the closure file is not a mapping of keys ({", ".join(KEYS)})')
    return content


def _paired(content: dict, first: str, second: str, problems: list[str]) -> bool:
    """
    Return whether lists ``first`` and ``second`` are both there, entry for entry.

    Both absent is no problem; one without the other, a value that is not a list or two lists
    of different lengths is one.
    """
    given = [key for key in (first, second) if key in content]
    if len(given) == 1:
        missing = second if given[0] == first else first
        problems.append(f'{missing}: missing: {given[0]} needs it, entry for entry')
    if len(given) < 2:
        return False
    lists = True
    for key in given:
        if not isinstance(content[key], list):
            problems.append(f'{key}: {content[key]!r} is not a list')
            lists = False
    if lists and len(content[first]) != len(content[second]):
        problems.append(f'{first} and {second}: {len(content[first])} and '
                        f'{len(content[second])} entries, not as many')
        return False
    return lists


def _frame_link(tree: UrdfTree, name: str, where: str) -> str:
    """Return the link whose frame Pinocchio's frame ``name`` is: a link's, or a joint's child."""
    joint = tree.joints.get(name)
    if name in tree.links:
        if joint is not None and joint.child != name:
            raise ClosureError(f'{where}: {name!r} names a link and a joint of another child '
                               f'link ({joint.child!r}): two frames')
        return name
    if joint is not None:
        return joint.child
    raise ClosureError(f'{where}: {name!r} is not a link or joint of the URDF')


def _closures(tree: UrdfTree, content: dict, problems: list[str]) -> tuple[Closure, ...]:
    if not _paired(content, 'closed_loop', 'type', problems):
        return ()
    closures, names = [], set()
    for index, (pair, kind) in enumerate(zip(content['closed_loop'], content['type']), start=1):
        where = f'closed_loop: entry {index}'
        try:
            if (not isinstance(pair, list) or len(pair) != 2
                    or not all(isinstance(frame, str) and frame for frame in pair)):
                raise ClosureError(f'{where} {pair!r} is not a pair of frame names')
            if not isinstance(kind, str) or kind not in KINDS:
                raise ClosureError(f'type: entry {index} {kind!r} is not {KIND_WORDS}')
            name = f'{pair[0]}C{pair[1]}'
            if name in names:
                raise ClosureError(f'{where}: the pair {pair[0]!r}, {pair[1]!r} is listed twice')
            sides = [ClosureSide(_frame_link(tree, frame, where)) for frame in pair]
            names.add(name)
            closures.append(Closure(name, KINDS[kind], sides[0], sides[1], Encoding.CLOSURE_FILE))
        except ClosureError as error:
            problems.append(str(error))
    return tuple(closures)


def _override_problem(tree: UrdfTree, joint: str, override: JointOverride) -> str | None:
    """Return why URDF joint ``joint`` cannot be read as ``override``, or None."""
    urdf_joint = tree.joints.get(joint)
    if urdf_joint is None:
        return f'joint_name: {joint!r} is not a joint of the URDF'
    if urdf_joint.joint_type is JointType.FIXED:
        return (f'joint_name: {joint!r} is a fixed joint, which Pinocchio merges into its links: '
                f'toolbox-parallel-robots does not read it as {override.name}')
    mimicked = [other.name for other in tree.joints.values()
                if other.mimic is not None and other.mimic.joint == joint]
    if urdf_joint.mimic is not None or mimicked:
        pair = (f'mimics {urdf_joint.mimic.joint!r}' if urdf_joint.mimic is not None
                else f'is mimicked by {mimicked[0]!r}')
        return (f'joint_name: {joint!r} {pair}: a joint read as {override.name} has no one '
                'position to mimic by')
    taken = [name for name in override.coordinates(joint) if name in tree.joints]
    if taken:
        return (f'joint_name: {joint!r} would be read as {", ".join(override.coordinates(joint))}'
                f', but the URDF has a joint {taken[0]!r}')
    return None


def _overrides(tree: UrdfTree, content: dict,
               problems: list[str]) -> dict[str, JointOverride]:
    if not _paired(content, 'joint_name', 'joint_type', problems):
        return {}
    overrides: dict[str, JointOverride] = {}
    for index, (joint, word) in enumerate(zip(content['joint_name'], content['joint_type']),
                                          start=1):
        if not isinstance(joint, str) or not joint:
            problems.append(f'joint_name: entry {index} {joint!r} is not a joint name')
            continue
        if not isinstance(word, str) or word not in JointOverride.__members__:
            problems.append(f'joint_type: entry {index} {word!r} (for {joint!r}) is not one of '
                            f'{OVERRIDE_WORDS}')
            continue
        override = JointOverride[word]
        problem = (f'joint_name: {joint!r} is listed twice' if joint in overrides
                   else _override_problem(tree, joint, override))
        if problem is None:
            overrides[joint] = override
        else:
            problems.append(problem)
    return overrides


def _actuated(tree: UrdfTree, content: dict, overrides: dict[str, JointOverride],
              problems: list[str]) -> tuple[str, ...] | None:
    if 'name_mot' not in content:
        return None
    if not isinstance(content['name_mot'], list):
        problems.append(f"name_mot: {content['name_mot']!r} is not a list")
        return ()
    actuated: list[str] = []
    for index, name in enumerate(content['name_mot'], start=1):
        joint = tree.joints.get(name) if isinstance(name, str) else None
        if not isinstance(name, str) or not name:
            problems.append(f'name_mot: entry {index} {name!r} is not a joint name')
        elif joint is None:
            problems.append(f'name_mot: {name!r} is not a joint of the URDF')
        elif joint.joint_type is JointType.FIXED:
            problems.append(f'name_mot: {name!r} is a fixed joint: it moves nothing to measure')
        elif name in overrides:
            problems.append(f'name_mot: {name!r} is read as {overrides[name].name} (joint_type):'
                            ' an actuated joint is measured as the one URDF joint it is')
        elif name in actuated:
            problems.append(f'name_mot: {name!r} is listed twice')
        else:
            actuated.append(name)
    return tuple(actuated)


def read_closure_file(tree: UrdfTree, text: str) -> ClosureDescription:
    """
    Return the closures, actuated joints and joint overrides of closure file ``text``.

    Its frames and joints are those of ``tree``, the URDF it accompanies. What cannot be read is
    one line of ``problems`` each, naming the key (the rest is still read). Raises ClosureError,
    one line, for a text that is no closure file at all (not YAML, empty, not a mapping of keys):
    unreadable input, as a text that is no URDF is to ``read_urdf``.
    """
    content = _content(text)
    problems = [f'{key!r}: not a key of a closure file ({", ".join(KEYS)})'
                for key in content if key not in KEYS]
    closures = _closures(tree, content, problems)
    overrides = _overrides(tree, content, problems)
    actuated = _actuated(tree, content, overrides, problems)
    return ClosureDescription(closures, actuated, overrides, tuple(problems))
