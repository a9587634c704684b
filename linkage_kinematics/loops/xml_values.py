# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
The links and numbers of the closure elements a URDF may hold (``<constraint>``, ``<loop_joint>``).

urdf_parser_py reads neither element, so their attributes are read here from the XML tree it
read, as finite as ``model.urdf_reader`` asks a joint's numbers to be, with the one-line
refusals the planar loops have always had for a ``<constraint>``. Each refusal is a
``ClosureError`` whose message starts with ``where``, the element's name for people.
"""

from __future__ import annotations

import math

from linkage_kinematics.loops.closures import ClosureError, Vector
from linkage_kinematics.model.urdf_reader import UrdfTree
import lxml.etree

# Both elements spell their three supported types alike.
TYPE_WORDS = "'revolute' (a pin), 'spherical' (a ball) or 'fixed' (a weld)"


def three_numbers(text: str | None, default: Vector, where: str) -> Vector:
    """Return an attribute of three finite numbers (xyz, rpy, an axis); ``default`` if absent."""
    if text is None:
        return default
    try:
        values = [float(word) for word in text.split()]
    except ValueError:
        raise ClosureError(f'{where}: {text!r} is not three numbers') from None
    if len(values) != 3 or not all(math.isfinite(value) for value in values):
        raise ClosureError(f'{where}: {text!r} is not three finite numbers')
    return (values[0], values[1], values[2])


def unit_axis(axis: Vector, where: str) -> Vector:
    """Return ``axis`` made unit; ClosureError naming ``where`` for a zero axis."""
    # Added in order, not with sum(): Python 3.12's sum() of floats compensates, so the unit
    # axis would differ in its last bit between the 3.11 and 3.12 this package runs on.
    length = math.sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2])
    if length == 0.0:
        raise ClosureError(f'{where}: the axis is zero')
    return (axis[0] / length, axis[1] / length, axis[2] / length)


def robot_link(tree: UrdfTree, element: lxml.etree._Element | None, tag: str, where: str) -> str:
    """
    Return the ``link`` attribute of ``element`` (a ``<tag link="…"/>``), a link of the robot.

    Raises ClosureError naming ``where`` for a missing element or attribute or an unknown link.
    """
    link = element.get('link') if element is not None else None
    if not link:
        raise ClosureError(f'{where}: no <{tag} link="…"/>')
    if link not in tree.links:
        raise ClosureError(f'{where}: {tag} link {link!r} is not a <link> of the robot')
    return link
