# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The robots the parallel-mechanisms section closes, as every solver of it reads them.

Each model is a URDF and its closures, read by the package's own readers (``read_urdf``,
``loops.encodings.read_closures``: any of the three encodings). The peers (bench/parallel_peers.py)
are handed one URDF text that already says everything they must know, so that they all solve the
same tree:

* a joint the closure file overrides (``JointOverride``) is written as the revolute joints it
  reads as, one per axis of its joint frame, each about the axis as the previous ones turned it,
  named as ``JointOverride.coordinates`` names them (``ankle_Z``, ``ankle_Y``), joined by
  massless links; ``FIXED`` is a fixed joint (the Gepetto loader freezes it at 0);
* each side of a closure is a frame of its own: a massless link on a fixed joint at the side's
  ``xyz``/``rpy`` from its link, named ``<closure>/parent`` and ``<closure>/child``;
* a continuous joint is a revolute joint without limits (Pinocchio reads a continuous joint as
  two coordinates, the cosine and sine of its angle).

So a peer's closure is always between two named frames (a weld: they coincide; a ball: their
origins do), and its coordinates are the URDF's moving joints by name. A pin closure (five
equations) is not among the peers' closure kinds and is refused by name here, as are mimic,
floating and planar joints, which the section's models do not have and the peers' parsers read
differently from ROS.

The models (``MODELS``): Gepetto/example-parallel-robots' (``example_model``) and the package's
humanoid ankle (urdf/humanoid_ankle.urdf, its two ``<constraint>`` balls, the motors measured).
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
import pathlib

from linkage_kinematics.loops.closures import ClosureKind, ClosureSide, JointOverride, ORIGIN
from linkage_kinematics.loops.encodings import read_closures
from linkage_kinematics.model.urdf_reader import JointType, read_urdf
import lxml.etree

ROOT = pathlib.Path(__file__).resolve().parent.parent
EXAMPLE_FOLDER = ROOT / 'test' / 'models' / 'example_parallel_robots'
# Gepetto/example-parallel-robots' models (test/models/example_parallel_robots/README.md), in
# the order of that table.
EXAMPLE_MODELS = ('5bar_linkage', 'robot_delta', 'cassie_like', 'digit_like', 'kangaroo_like',
                  'battobot_6d', 'wl16_like', 'disney_like')
ANKLE = 'humanoid_ankle'
ANKLE_URDF = ROOT / 'urdf' / 'humanoid_ankle.urdf'
ANKLE_MOTORS = ('motor_left', 'motor_right')
MODELS = (ANKLE, *EXAMPLE_MODELS)
# Far beyond any turn of a joint the overrides or a continuous joint make (the URDF
# joint's limits no longer hold; a continuous joint has none).
OVERRIDE_LIMIT = 1e3


class ModelError(ValueError):
    """A model the peers cannot be handed; the message names what and why."""


@dataclass(frozen=True)
class PeerClosure:
    """A closure between two frames of the peers' URDF: ``kind`` WELD or BALL."""

    name: str
    kind: ClosureKind
    parent_frame: str
    child_frame: str


@dataclass(frozen=True)
class ParallelModel:
    """
    One robot as the section's solvers read it.

    ``urdf`` is the peers' URDF text (overrides written out, closure frames added);
    ``coordinates`` the moving joints of that URDF in its order (the names every solver's answer
    uses), ``actuated`` the measured ones (the closure file's ``name_mot``) and ``passive`` the
    others.
    """

    name: str
    urdf: str
    closures: tuple[PeerClosure, ...]
    actuated: tuple[str, ...]
    coordinates: tuple[str, ...]
    source_urdf: str
    closure_file: str | None

    @property
    def passive(self) -> tuple[str, ...]:
        """Return the coordinates the solvers find, in URDF order."""
        return tuple(name for name in self.coordinates if name not in self.actuated)


def example_model(name: str) -> ParallelModel:
    """Return Gepetto/example-parallel-robots' model ``name`` (URDF and robot.yaml)."""
    folder = EXAMPLE_FOLDER / name
    return parallel_model(name, (folder / 'robot.urdf').read_text(),
                          (folder / 'robot.yaml').read_text())


def section_model(name: str) -> ParallelModel:
    """Return the section's model ``name`` (``MODELS``)."""
    if name == ANKLE:
        return parallel_model(ANKLE, ANKLE_URDF.read_text(encoding='utf-8'), None, ANKLE_MOTORS)
    return example_model(name)


def parallel_model(name: str, urdf: str, closure_file: str | None = None,
                   actuated: tuple[str, ...] | None = None) -> ParallelModel:
    """
    Return robot ``name`` from its URDF text and closure file text (if any).

    ``actuated`` names the measured joints where no closure file does. ModelError (one line) for
    what the readers report as a problem and for what the peers cannot hold.
    """
    tree = read_urdf(urdf)
    description = read_closures(tree, closure_file)
    if description.problems:
        raise ModelError(f'{name}: {description.problems[0]}')
    measured = description.actuated if description.actuated is not None else actuated
    if not measured:
        raise ModelError(f'{name}: no actuated joints (name_mot) to follow')
    robot = copy.deepcopy(tree.element)
    for joint in tree.joints.values():
        if joint.mimic is not None or joint.joint_type not in (
                JointType.FIXED, JointType.REVOLUTE, JointType.CONTINUOUS, JointType.PRISMATIC):
            what = 'a mimic joint' if joint.mimic is not None else joint.joint_type.value
            raise ModelError(f'{name}: joint {joint.name!r} is {what}, which the peers '
                             'read otherwise than ROS')
        if joint.joint_type is JointType.CONTINUOUS:
            _unlimited(robot.find(f"joint[@name='{joint.name}']"))
    for joint, override in description.overrides.items():
        _write_override(robot, joint, override)
    closures = []
    for closure in description.closures:
        if closure.kind is ClosureKind.PIN:
            raise ModelError(f'{name}: closure {closure.name!r} is a pin, which no peer holds')
        closures.append(PeerClosure(
            closure.name, closure.kind,
            _side_frame(robot, f'{closure.name}/parent', closure.parent),
            _side_frame(robot, f'{closure.name}/child', closure.child)))
    coordinates = tuple(joint.get('name') for joint in robot.iterfind('joint')
                        if joint.get('type') != 'fixed')
    return ParallelModel(name, lxml.etree.tostring(robot, encoding='unicode'), tuple(closures),
                         tuple(measured), coordinates, urdf, closure_file)


def _write_override(robot: lxml.etree._Element, name: str, override: JointOverride) -> None:
    """Replace joint ``name`` by the joints ``override`` reads it as (see the module's text)."""
    joint = robot.find(f"joint[@name='{name}']")
    if override is JointOverride.FIXED:
        joint.set('type', 'fixed')
        for element in joint.findall('axis') + joint.findall('limit'):
            joint.remove(element)
        return
    child = joint.find('child').get('link')
    parent = joint.find('parent').get('link')
    origin = joint.find('origin')
    position = list(robot).index(joint)
    robot.remove(joint)
    coordinates = override.coordinates(name)
    for index, (coordinate, axis) in enumerate(zip(coordinates, override.axes)):
        last = index == len(coordinates) - 1
        link = child if last else f'{coordinate}/link'
        element = lxml.etree.Element('joint', name=coordinate, type='revolute')
        if index == 0 and origin is not None:
            element.append(copy.deepcopy(origin))
        lxml.etree.SubElement(element, 'parent', link=parent)
        lxml.etree.SubElement(element, 'child', link=link)
        lxml.etree.SubElement(element, 'axis',
                              xyz={'x': '1 0 0', 'y': '0 1 0', 'z': '0 0 1'}[axis])
        lxml.etree.SubElement(element, 'limit', lower=f'{-OVERRIDE_LIMIT}',
                              upper=f'{OVERRIDE_LIMIT}', effort='0', velocity='0')
        robot.insert(position, element)
        position += 1
        if not last:
            robot.insert(position, lxml.etree.Element('link', name=link))
            position += 1
        parent = link


def _unlimited(joint: lxml.etree._Element) -> None:
    """Make a continuous joint a revolute one that no limit holds (see the module's text)."""
    joint.set('type', 'revolute')
    for element in joint.findall('limit'):
        joint.remove(element)
    lxml.etree.SubElement(joint, 'limit', lower=f'{-OVERRIDE_LIMIT}', upper=f'{OVERRIDE_LIMIT}',
                          effort='0', velocity='0')


def _side_frame(robot: lxml.etree._Element, frame: str, side: ClosureSide) -> str:
    """Return the frame of closure ``side``: its link's own, else a link ``frame`` added for it."""
    if side.xyz == ORIGIN and side.rpy == ORIGIN:
        return side.link
    robot.append(lxml.etree.Element('link', name=frame))
    joint = lxml.etree.SubElement(robot, 'joint', name=f'{frame}/joint', type='fixed')
    lxml.etree.SubElement(joint, 'origin', xyz=' '.join(repr(value) for value in side.xyz),
                          rpy=' '.join(repr(value) for value in side.rpy))
    lxml.etree.SubElement(joint, 'parent', link=side.link)
    lxml.etree.SubElement(joint, 'child', link=frame)
    return frame
