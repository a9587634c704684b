# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The ``<constraint>`` elements of a URDF, as proposed for urdfdom, read as closures.

urdfdom PR #264 (its parser: ``urdf_parser/src/constraint.cpp``, ``parseConstraint``) and
urdfdom_headers PR #108 (``urdf_model/constraint.h``) write the cut joint of a closed loop as a
direct child of ``<robot>``::

    <constraint name="N" type="revolute">
      <parent link="L1"/><parent_origin xyz="…" rpy="…"/><parent_axis xyz="…"/>
      <child link="L2"/><child_origin xyz="…" rpy="…"/><child_axis xyz="…"/>
    </constraint>

The frame ``L1``·parent_origin and the frame ``L2``·child_origin are held together:

* ``revolute`` (the PR also writes ``revolute_joint``): a pin about the axis;
* ``spherical`` (``spherical_joint``): a ball, the origins coincide;
* ``fixed``, or the PR's ``link`` (a cut link): a weld, the frames coincide.

The PR's ``prismatic`` and ``universal`` are refused by name. As in the PR, a missing origin is
the identity, and a pin reads its axis from ``<parent_axis>``; the child frame turns about the
same axis (as a URDF joint's child frame turns about the joint's axis), so without a
``<child_axis>`` the child's axis has the parent's coordinates. Without any axis the pin turns
about its loop's first revolute joint's axis, as the planar loops have always read it (the PR
takes (1, 0, 0) there; this package's planar readers never did). The attributes are read by
``xml_values``, with the refusals the planar loops have always had.
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

# The PR's type words (parseConstraint); 'fixed' is this package's and <loop_joint>'s word for
# the PR's 'link', whose two frames coincide.
TYPES = {
    'revolute': ClosureKind.PIN, 'revolute_joint': ClosureKind.PIN,
    'spherical': ClosureKind.BALL, 'spherical_joint': ClosureKind.BALL,
    'fixed': ClosureKind.WELD, 'link': ClosureKind.WELD,
}


def _axis(element: lxml.etree._Element | None, where: str) -> Vector | None:
    """Return an axis element's unit xyz, (1, 0, 0) without one; None if absent."""
    if element is None:
        return None
    return unit_axis(three_numbers(element.get('xyz'), (1.0, 0.0, 0.0), where), where)


def _side(tree: UrdfTree, element: lxml.etree._Element, side: str, where: str,
          axis: Vector | None) -> ClosureSide:
    link = robot_link(tree, element.find(side), side, where)
    origin = element.find(f'{side}_origin')
    xyz = three_numbers(origin.get('xyz') if origin is not None else None, ORIGIN,
                        f'{where} {side}_origin xyz')
    rpy = three_numbers(origin.get('rpy') if origin is not None else None, ORIGIN,
                        f'{where} {side}_origin rpy')
    return ClosureSide(link, xyz, rpy, axis)


def _closure(tree: UrdfTree, element: lxml.etree._Element, name: str) -> Closure:
    where = f'constraint {name!r}'
    written = element.get('type')
    if written is None:
        raise ClosureError(f'{where}: no type: a constraint is {TYPE_WORDS}')
    if written not in TYPES:
        raise ClosureError(f'{where}: type {written!r} is not supported: a constraint is '
                           f'{TYPE_WORDS}')
    kind = TYPES[written]
    parent_axis = child_axis = None
    if kind is ClosureKind.PIN:
        parent_axis = _axis(element.find('parent_axis'), f'{where} parent_axis')
        child_axis = _axis(element.find('child_axis'), f'{where} child_axis')
        if child_axis is None:
            child_axis = parent_axis
    return Closure(name, kind, _side(tree, element, 'parent', where, parent_axis),
                   _side(tree, element, 'child', where, child_axis), Encoding.CONSTRAINT)


def read_constraints(tree: UrdfTree) -> tuple[tuple[Closure, ...], tuple[str, ...]]:
    """
    Return the closures of the ``<constraint>`` elements under ``<robot>``, in URDF order.

    Also returns one line for each element that cannot be read (naming it, and why): no name, a
    name used twice, no type or another type, a missing or unknown link, a malformed number, a
    zero axis.
    """
    closures, problems = [], []
    names: set[str] = set()
    for element in tree.element.findall('constraint'):
        name = element.get('name')
        try:
            if not name:
                raise ClosureError('a <constraint> has no name')
            if name in names:
                raise ClosureError(f'constraint {name!r}: the name is used twice')
            names.add(name)
            closures.append(_closure(tree, element, name))
        except ClosureError as error:
            problems.append(str(error))
    return tuple(closures), tuple(problems)
