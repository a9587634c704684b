# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The ``<loop_joint>`` elements of a URDF, as Isaac Sim writes and reads them, read as closures.

Isaac Sim's URDF importer and exporter close a loop with a direct child of ``<robot>``::

    <loop_joint name="N" type="spherical">
      <link1 link="L1" xyz="…" rpy="…"/>
      <link2 link="L2" xyz="…" rpy="…"/>
    </loop_joint>

What they accept, from their sources:

* the importer's parser (github isaac-sim/urdf-importer-extension,
  ``source/extensions/isaacsim.asset.importer.urdf/plugins/parse/UrdfParser.cpp``,
  ``parseLoopJoints``): a name (else the loop joints are not read), a type read as a URDF
  joint's type (``parseJointType``: revolute, continuous, prismatic, fixed, floating, planar,
  spherical), ``<link1>`` and ``<link2>`` each with a ``link``, and ``xyz`` (m) and ``rpy``
  (rad, URDF's roll–pitch–yaw) that default to zero;
* the importer (``plugins/import/UrdfImporter.cpp``, ``addLoopJoints``) makes a spherical one a
  USD spherical joint between body0 = link1 and body1 = link2 at those frames (``xyz`` scaled
  to the stage's unit); it skips every other type with a warning;
* the exporter (github isaac-sim/IsaacSim,
  ``source/extensions/isaacsim.asset.exporter.urdf/isaacsim/asset/exporter/urdf/converter/``:
  ``joint_reader.py`` ``read_loop_joints`` and ``urdf_writer.py`` ``_write_loop_joint``) writes
  every USD joint excluded from the articulation as a ``<loop_joint>``: type revolute,
  prismatic, fixed, else spherical; link1 and its frame from body0, link2 from body1. It writes
  no axis: a USD revolute joint turns about its joint frame's ``physics:axis``, X by default.

So ``spherical`` is a ball, ``fixed`` a weld, and ``revolute`` (or ``continuous``, the same
closure without limits) a pin about the x axis of its frames (of both: they coincide when the
pin is at zero). An ``<axis xyz>`` child gives another axis, in those frames, as
``<loop_joint>`` had in Drake's RigidBodyTree parser, where the element began (default
(1, 0, 0) there too); Isaac Sim ignores it. Other types are refused by name, and so are a
missing attribute and a malformed number, where Isaac Sim would read zero.
"""

from __future__ import annotations

from linkage_kinematics.loops.closures import (
    Closure,
    ClosureError,
    ClosureKind,
    ClosureSide,
    Encoding,
    ORIGIN,
    Vector,
)
from linkage_kinematics.loops.xml_values import (
    robot_link,
    three_numbers,
    TYPE_WORDS,
    unit_axis,
)
from linkage_kinematics.model.urdf_reader import UrdfTree
import lxml.etree

TYPES = {
    'revolute': ClosureKind.PIN, 'continuous': ClosureKind.PIN,
    'spherical': ClosureKind.BALL, 'fixed': ClosureKind.WELD,
}
X_AXIS = (1.0, 0.0, 0.0)


def _side(tree: UrdfTree, element: lxml.etree._Element, tag: str, where: str,
          axis: Vector | None) -> ClosureSide:
    end = element.find(tag)
    link = robot_link(tree, end, tag, where)
    xyz = three_numbers(end.get('xyz'), ORIGIN, f'{where} {tag} xyz')
    rpy = three_numbers(end.get('rpy'), ORIGIN, f'{where} {tag} rpy')
    return ClosureSide(link, xyz, rpy, axis)


def _closure(tree: UrdfTree, element: lxml.etree._Element, name: str) -> Closure:
    where = f'loop_joint {name!r}'
    written = element.get('type')
    if written is None:
        raise ClosureError(f'{where}: no type: a loop_joint is {TYPE_WORDS}')
    if written not in TYPES:
        raise ClosureError(f'{where}: type {written!r} is not supported: a loop_joint is '
                           f'{TYPE_WORDS}')
    kind = TYPES[written]
    axis = None
    if kind is ClosureKind.PIN:
        axis_element = element.find('axis')
        axis = unit_axis(three_numbers(
            axis_element.get('xyz') if axis_element is not None else None, X_AXIS,
            f'{where} axis'), f'{where} axis')
    return Closure(name, kind, _side(tree, element, 'link1', where, axis),
                   _side(tree, element, 'link2', where, axis), Encoding.LOOP_JOINT)


def read_loop_joints(tree: UrdfTree) -> tuple[tuple[Closure, ...], tuple[str, ...]]:
    """
    Return the closures of the ``<loop_joint>`` elements under ``<robot>``, in URDF order.

    The parent side is link1's frame, the child side link2's. Also returns one line for each
    element that cannot be read (naming it, and why): no name, a name used twice, no type or
    another type, a missing or unknown link, a malformed number, a zero axis.
    """
    closures, problems = [], []
    names: set[str] = set()
    for element in tree.element.findall('loop_joint'):
        name = element.get('name')
        try:
            if not name:
                raise ClosureError('a <loop_joint> has no name')
            if name in names:
                raise ClosureError(f'loop_joint {name!r}: the name is used twice')
            names.add(name)
            closures.append(_closure(tree, element, name))
        except ClosureError as error:
            problems.append(str(error))
    return tuple(closures), tuple(problems)
