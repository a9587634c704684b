# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
A URDF text read once: its links and joints as ROS's own Python URDF parser reads them.

``read_urdf`` parses the text with lxml and hands the ``<robot>`` element to ``urdf_parser_py``
(the urdfdom_py package, the Python twin of urdfdom, which robot_state_publisher reads a URDF
with), then checks what robot_state_publisher's kdl_parser needs of the tree: one root link,
every other link the child of exactly one joint, each joint's links links of the robot, no two
links or joints of one name, a known joint type, a movable joint's axis not zero, every number
finite, a mimic's joint a joint of the robot. Whatever cannot be read is a ``UrdfError`` of one
line naming the element and what is wrong.

Each joint comes with urdfdom's defaults filled in (origin 0, axis (1, 0, 0), mimic multiplier 1
and offset 0, a ``<limit>``'s lower and upper 0), its origin's rotation also as urdfdom keeps it
(a quaternion) and its axis made unit as KDL makes it. As urdfdom, a revolute or prismatic joint
without a ``<limit>`` is refused (its effort and velocity are required attributes); a continuous
joint may have one, whose lower and upper bound nothing. The parsed XML tree is kept for the
elements urdf_parser_py does not read (the ``<constraint>`` and ``<loop_joint>`` elements that
close loops, read in ``loops``). Pure: urdf_parser_py and lxml, no ROS graph.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
import contextlib
from dataclasses import dataclass
import enum
import math
import re
import threading

import lxml.etree
from urdf_parser_py import urdf as urdf_parser
from urdf_parser_py.xml_reflection import core as xml_reflection_core

Vector = tuple[float, float, float]
Quaternion = tuple[float, float, float, float]  # x, y, z, w


class UrdfError(ValueError):
    """The URDF text cannot be read as a robot's links and joints; the message says what."""


class JointType(enum.Enum):
    """URDF joint types."""

    FIXED = 'fixed'
    REVOLUTE = 'revolute'
    CONTINUOUS = 'continuous'
    PRISMATIC = 'prismatic'
    FLOATING = 'floating'
    PLANAR = 'planar'


ROTATING_TYPES = frozenset({JointType.REVOLUTE, JointType.CONTINUOUS})
# kdl_parser gives floating and planar joints no degree of freedom: they stay at their origin.
MOVABLE_TYPES = ROTATING_TYPES | {JointType.PRISMATIC}
# the joints whose <limit> bounds their position; urdfdom requires one of them
_BOUNDED_TYPES = frozenset({JointType.REVOLUTE, JointType.PRISMATIC})


@dataclass(frozen=True)
class Mimic:
    """A mimic joint's position = multiplier · (the position of ``joint``) + offset."""

    joint: str
    multiplier: float
    offset: float


@dataclass(frozen=True)
class JointLimit:
    """
    A joint's ``<limit>`` as urdfdom reads it: lower and upper (rad or m, 0 when not given).

    ``velocity`` (rad/s or m/s) and ``effort`` (N·m or N) are required by urdfdom.
    """

    lower: float
    upper: float
    velocity: float
    effort: float


@dataclass(frozen=True)
class UrdfJoint:
    """
    A URDF joint: its links, origin (xyz; rpy, and as a quaternion), unit axis, mimic, limit.

    ``limit`` is None where the joint has no ``<limit>`` (a fixed or continuous joint may not).
    """

    name: str
    joint_type: JointType
    parent: str
    child: str
    origin_translation: Vector
    origin_rpy: Vector
    origin_rotation: Quaternion
    axis: Vector
    mimic: Mimic | None
    limit: JointLimit | None = None

    @property
    def movable(self) -> bool:
        return self.joint_type in MOVABLE_TYPES

    @property
    def revolute(self) -> bool:
        return self.joint_type in ROTATING_TYPES

    @property
    def position_limits(self) -> tuple[float, float] | None:
        """
        Return (lower, upper) for a revolute or prismatic joint, None where nothing bounds it.

        A continuous joint turns without bound whatever its ``<limit>`` says (the URDF
        specification: "a continuous hinge joint ... has no upper and lower limits").
        """
        if self.limit is None or self.joint_type not in _BOUNDED_TYPES:
            return None
        return (self.limit.lower, self.limit.upper)

    @property
    def velocity_limit(self) -> float | None:
        """Return the largest |velocity|, None where none is given (no limit, or 0 in it)."""
        return _bound(None if self.limit is None else self.limit.velocity)

    @property
    def effort_limit(self) -> float | None:
        """Return the largest |effort|, None where none is given (no limit, or 0 in it)."""
        return _bound(None if self.limit is None else self.limit.effort)


def _bound(value: float | None) -> float | None:
    """
    Return a velocity or effort limit that bounds something, else None.

    URDFs write 0 where their author has no such limit (the attributes are required), and a
    limit of 0 would forbid every motion of the joint; a negative one bounds nothing either.
    """
    return value if value is not None and value > 0.0 else None


@dataclass(frozen=True)
class UrdfTree:
    """A URDF's links and joints, checked to form one tree, and the XML they were read from."""

    name: str
    root_link: str
    links: tuple[str, ...]  # in URDF order
    joints: dict[str, UrdfJoint]  # in URDF order
    # what urdf_parser_py said about the text, other than that it does not know <constraint>
    parser_messages: tuple[str, ...]
    # the <robot> element, for the elements urdf_parser_py does not read
    element: lxml.etree._Element


def quaternion_from_rpy(roll: float, pitch: float, yaw: float) -> Quaternion:
    """Return the quaternion of URDF's rpy (about fixed x, y, z, in that order), as urdfdom."""
    sr, cr = math.sin(0.5 * roll), math.cos(0.5 * roll)
    sp, cp = math.sin(0.5 * pitch), math.cos(0.5 * pitch)
    sy, cy = math.sin(0.5 * yaw), math.cos(0.5 * yaw)
    x = sr * cp * cy - cr * sp * sy
    y = cr * sp * cy + sr * cp * sy
    z = cr * cp * sy - sr * sp * cy
    w = cr * cp * cy + sr * sp * sy
    norm = math.sqrt(x * x + y * y + z * z + w * w)
    return (x / norm, y / norm, z / norm, w / norm)


# urdf_parser_py reports what it does not know through the module-level function
# xml_reflection.core.on_error, which by default writes each message to stderr; Reflection's
# set_from_xml looks the name up in that module at call time. A <constraint> or a <loop_joint>
# (the cut joint of a closed loop in urdfdom PR #264's and Isaac Sim's words, which loops reads)
# is not known to it, so every lab's good URDF with loops would print 'Unknown tag "constraint"
# in /robot[...]'. The parse below swaps the function for one that drops exactly that message
# (either element directly under <robot>, whose path is /robot[@name='…']) and keeps every other
# one, a <constraint> misplaced inside a <joint> included, for the caller; then it restores the
# function. The lock keeps two threads' parses from restoring each other's function.
_CLOSURE_ELEMENT_COMPLAINT = re.compile(
    r'Unknown tag "(constraint|loop_joint)" in /robot(\[@name=\'[^/]*\'\])?')
_PARSER_HOOK = threading.Lock()


@contextlib.contextmanager
def _parser_messages() -> Iterator[list[str]]:
    messages: list[str] = []

    def keep(message: str) -> None:
        if not _CLOSURE_ELEMENT_COMPLAINT.fullmatch(message):
            messages.append(message)

    with _PARSER_HOOK:
        previous = xml_reflection_core.on_error
        xml_reflection_core.on_error = keep
        try:
            yield messages
        finally:
            xml_reflection_core.on_error = previous


# A step of urdf_parser_py's error path (xml_reflection.core.Path): its suffix is empty, an
# element's 1-based index among its kind ([2]) or its name ([@name='…']), then perhaps the
# attribute that could not be read ([@xyz]).
_PATH_SUFFIX = re.compile(
    r"(?:\[(?P<index>\d+)\]|\[@name='(?P<name>.*)'\])?(?:\[@(?P<attribute>[^\]]+)\])?")
_NOT_A_FLOAT = 'could not convert string to float: '


def _parse_problem(robot: lxml.etree._Element, error: xml_reflection_core.ParseError) -> str:
    """Return a ParseError as one line: the element (and attribute, with its text), and why."""
    steps = []
    path = error.path
    while path is not None:
        steps.append(path)
        path = path.parent
    words: list[str] = []
    element: lxml.etree._Element | None = robot
    attribute = None
    for depth, step in enumerate(reversed(steps)):
        match = _PATH_SUFFIX.fullmatch(step.suffix)
        if match is None:  # a name the path cannot hold plainly: the parser's own path
            words, attribute = [str(error.path)], None
            break
        attribute = match['attribute']
        if depth == 0:  # the <robot> element itself
            continue
        kin = [child for child in element if child.tag == step.tag] if element is not None else []
        if match['name'] is not None:
            words.append(f"{step.tag} {match['name']!r}")
            element = next((child for child in kin if child.get('name') == match['name']), None)
        elif match['index'] is not None:
            words.append(f"{step.tag} {match['index']}")
            position = int(match['index']) - 1
            element = kin[position] if position < len(kin) else None
        else:
            words.append(step.tag)
            element = kin[0] if kin else None
    where = ' '.join(words) or 'the <robot> element'
    text = None
    if attribute is not None:
        where += f' {attribute}'
        text = element.get(attribute) if element is not None else None
    return f'{where}: {_plain_cause(error.e, text)}'


def _unplaced_problem(robot: lxml.etree._Element, error: Exception) -> str:
    """
    Return, as ``_parse_problem`` does, an error urdf_parser_py raised without its path.

    It wraps only an attribute's errors in a ParseError; an element read from one attribute
    (``<axis xyz>``, ``<mass value>``: its SimpleElementType) raises plainly. The element is
    the innermost ``path`` of the parser's frames, the attribute that type's.
    """
    path, attribute = None, None
    trace = error.__traceback__
    while trace is not None:
        local = trace.tb_frame.f_locals
        if isinstance(local.get('path'), xml_reflection_core.Path):
            path = local['path']
        if isinstance(local.get('self'), xml_reflection_core.SimpleElementType):
            attribute = local['self'].attribute
        trace = trace.tb_next
    if path is None:  # e.g. an unsupported URDF version
        return 'urdf_parser_py cannot read the URDF: ' + ' '.join(str(error).split('\n'))
    if attribute is not None:
        path = xml_reflection_core.Path(path.tag, path.parent, f'{path.suffix}[@{attribute}]')
        if isinstance(error, AttributeError):  # None.split(): the attribute is missing
            error = ValueError(f'Required attribute not set in XML: {attribute}')
    return _parse_problem(robot, xml_reflection_core.ParseError(error, path))


def _plain_cause(cause: Exception, text: str | None) -> str:
    """Return urdf_parser_py's reason in plain words, ``text`` the attribute's, if any."""
    message = ' '.join(str(cause).split('\n'))
    for prefix, plain in (('Required attribute not set in XML: ', 'no {} attribute'),
                          ('Required element not set in XML: ', 'no <{}> element'),
                          ('Invalid joint type: ', 'unknown type {!r}')):
        if message.startswith(prefix):
            return plain.format(message[len(prefix):])
    if message == 'Invalid vector length':
        shown = '' if text is None else f'{text!r} is '
        return shown + 'not the right count of numbers'
    if message.startswith(_NOT_A_FLOAT):
        word = message[len(_NOT_A_FLOAT):]
        inside = f' in {text!r}' if text is not None and repr(text) != word else ''
        return f'{word}{inside} is not a number'
    return message


def _numbers(values: Iterable[float], where: str) -> tuple[float, ...]:
    """
    Return ``values`` as floats; UrdfError naming ``where`` for one that is not finite.

    urdf_parser_py's float() takes 'nan', 'inf' and '1e400'; urdfdom's strToDouble refuses them.
    """
    numbers = tuple(float(value) for value in values)
    for number in numbers:
        if not math.isfinite(number):
            raise UrdfError(f'{where}: {number!r} is not a finite number')
    return numbers


def _vector(values: Iterable[float], where: str) -> Vector:
    """Return urdf_parser_py's three numbers (its vector3 has three) as finite floats."""
    x, y, z = _numbers(values, where)
    return (x, y, z)


def _joint(joint: urdf_parser.Joint, links: set[str]) -> UrdfJoint:
    """Return a parsed joint with urdfdom's defaults; UrdfError for what kdl_parser refuses."""
    where = f'joint {joint.name!r}'
    try:
        joint_type = JointType(joint.type)
    except ValueError:  # urdf_parser_py also accepts 'unknown', urdfdom does not
        raise UrdfError(f'{where}: unknown type {joint.type!r}') from None
    for role, link in (('parent', joint.parent), ('child', joint.child)):
        if link not in links:
            raise UrdfError(f'{where}: {role} link {link!r} is not a <link> of the robot')
    origin = joint.origin
    xyz = _vector(origin.xyz if origin is not None else (0.0, 0.0, 0.0), f'{where} origin xyz')
    rpy = _vector(origin.rpy if origin is not None else (0.0, 0.0, 0.0), f'{where} origin rpy')
    axis = _vector(joint.axis if joint.axis is not None else (1.0, 0.0, 0.0), f'{where} axis')
    # Added in order, not with sum(): Python 3.12's sum() of floats compensates, so a unit axis
    # would differ in its last bit between the 3.11 and 3.12 this package runs on.
    length = math.sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2])
    if joint_type in MOVABLE_TYPES and length == 0.0:
        raise UrdfError(f'{where}: the axis is zero')
    if length > 0.0:
        axis = (axis[0] / length, axis[1] / length, axis[2] / length)
    mimic = None
    if joint.mimic is not None:
        multiplier, offset = _numbers(
            (1.0 if joint.mimic.multiplier is None else joint.mimic.multiplier,
             0.0 if joint.mimic.offset is None else joint.mimic.offset), f'{where} mimic')
        mimic = Mimic(joint.mimic.joint, multiplier, offset)
    limit = None
    if joint.limit is not None:
        # urdf_parser_py refuses a <limit> without effort or velocity, as urdfdom does
        lower, upper, velocity, effort = _numbers(
            (0.0 if joint.limit.lower is None else joint.limit.lower,
             0.0 if joint.limit.upper is None else joint.limit.upper,
             joint.limit.velocity, joint.limit.effort), f'{where} limit')
        limit = JointLimit(lower, upper, velocity, effort)
    elif joint_type in _BOUNDED_TYPES:
        raise UrdfError(f'{where}: a {joint_type.value} joint needs a <limit> (lower, upper, '
                        'effort, velocity)')
    return UrdfJoint(joint.name, joint_type, joint.parent, joint.child, xyz, rpy,
                     quaternion_from_rpy(*rpy), axis, mimic, limit)


def _unique(kind: str, names: list[str]) -> None:
    seen: set[str] = set()
    for name in names:
        if name in seen:
            raise UrdfError(f'{kind} {name!r} is defined twice')
        seen.add(name)


def _root_link(links: tuple[str, ...], joints: dict[str, UrdfJoint]) -> str:
    """Return the one root link; UrdfError unless the joints make the links one tree."""
    parent_joint: dict[str, str] = {}
    children: dict[str, list[str]] = {}
    for joint in joints.values():
        if joint.child in parent_joint:
            raise UrdfError(f'link {joint.child!r} is the child of more than one joint '
                            f'({parent_joint[joint.child]!r}, {joint.name!r})')
        parent_joint[joint.child] = joint.name
        children.setdefault(joint.parent, []).append(joint.child)
    roots = [link for link in links if link not in parent_joint]
    if len(roots) != 1:
        raise UrdfError(f'the URDF has {len(roots)} root links {sorted(roots)}, not one')
    reached, stack = {roots[0]}, [roots[0]]
    while stack:
        for child in children.get(stack.pop(), []):
            reached.add(child)
            stack.append(child)
    # every link but the root has a parent: a link the root does not reach sits on a cycle
    unreached = sorted(set(links) - reached)
    if unreached:
        raise UrdfError(f'links {unreached} are not reached from the root link {roots[0]!r}: '
                        'the joints form a cycle')
    return roots[0]


def read_urdf(urdf: str) -> UrdfTree:
    """
    Read a URDF text's links and joints with urdf_parser_py, checked to form one tree.

    Raises UrdfError, one line naming the element and what is wrong, for a text that is not a
    URDF robot or whose joints do not make its links one tree.
    """
    try:
        # bytes: lxml refuses a str that carries an XML encoding declaration, as xacro writes one
        robot = lxml.etree.fromstring(urdf.encode('utf-8'))
    except lxml.etree.XMLSyntaxError as error:
        raise UrdfError(f'the URDF is not XML: {error}') from None
    if robot.tag != 'robot':  # urdf_parser_py reads any root element as a robot
        raise UrdfError(f'the URDF root element is <{robot.tag}>, not <robot>')
    # urdf_parser_py reads a <parent/> or <child/> without its link attribute as link 'None'
    for end in robot.iterfind('joint/*'):
        if end.tag in ('parent', 'child') and end.get('link') is None:
            raise UrdfError(f"joint {end.getparent().get('name')!r} {end.tag}: no link attribute")
    with _parser_messages() as messages:
        try:
            parsed = urdf_parser.Robot.from_xml(robot, xml_reflection_core.Path('robot'))
        except xml_reflection_core.ParseError as error:
            raise UrdfError(_parse_problem(robot, error)) from None
        except Exception as error:  # raised outside its path bookkeeping
            raise UrdfError(_unplaced_problem(robot, error)) from None
    # urdf_parser_py reads each element on its own; what urdfdom's parseURDF then checks of the
    # whole (names unique, joints' links known, mimics' joints known, one root, a tree) and
    # what kdl_parser needs of a joint is checked here.
    links = tuple(link.name for link in parsed.links)
    _unique('link', list(links))
    _unique('joint', [joint.name for joint in parsed.joints])
    joints = {joint.name: _joint(joint, set(links)) for joint in parsed.joints}
    for joint in joints.values():
        if joint.mimic is not None and joint.mimic.joint not in joints:
            raise UrdfError(f'joint {joint.name!r} mimics {joint.mimic.joint!r}, which is not a '
                            'joint of the robot')
    return UrdfTree(str(parsed.name), _root_link(links, joints), links, joints,
                    tuple(messages), robot)
