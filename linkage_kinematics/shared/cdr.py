# Copyright 2026 linkage_kinematics maintainers
# SPDX-License-Identifier: Apache-2.0

"""
CDR encoding: rclpy messages in, the bytes the node publishes and logs out; and back for one.

The node encodes each message once (``encode_cdr``, or for its per-tick messages and its
scene a ``FixedShapeEncoder`` that writes the same bytes), publishes those bytes and logs the
same bytes, so subscribers receive exactly what the bag holds.

``encode_cdr`` writes a message as little-endian XCDR1 (the encoding rmw_fastrtps publishes
and rosbag2 stores) from the message's field types alone: one walk over the fields collects a
``struct`` format and its values, and one ``struct.pack`` writes them. Each run of consecutive
fixed-size fields (primitives, and messages made only of them such as a Time or a Pose) is one
step of the walk: one ``attrgetter`` reads all its values and its struct codes are prepared
for each alignment it can start at. It is the encoding rosbags' serializer produces, byte for
byte: alignment padding is zero and the length exact.
rclpy's ``serialize_message`` is not used because it builds a type support object per call (at
a 1 kHz tick it cost more than the rest of the node's Python), can return a few bytes more
than the message's encoding (after an empty ``effort`` in a JointState; rosbags rejects such
messages), and leaves padding bytes as it finds them.

``JointStateDecoder`` reads the measured sources' input the other way, straight from the bytes
of their raw subscriptions, in a sixth of ``deserialize_message``'s time (both endiannesses),
the efforts too where a follower asks for them.
"""
from __future__ import annotations

from collections.abc import Callable
import functools
import importlib
import operator
import struct
from typing import Any

from rosidl_parser.definition import (
    AbstractNestedType,
    AbstractString,
    AbstractWString,
    Array,
    BasicType,
    NamespacedType,
)

# XCDR1, little endian: the representation identifier and two option bytes.
ENCAPSULATION_HEADER = b'\x00\x01\x00\x00'
# struct code and size of each primitive (rclpy holds an octet as a 1-byte bytes, a char as an
# int).
_PRIMITIVES = {
    'boolean': ('?', 1), 'octet': ('c', 1), 'char': ('B', 1), 'int8': ('b', 1),
    'uint8': ('B', 1), 'int16': ('h', 2), 'uint16': ('H', 2), 'int32': ('i', 4),
    'uint32': ('I', 4), 'float': ('f', 4), 'int64': ('q', 8), 'uint64': ('Q', 8),
    'double': ('d', 8),
}
# How a plan entry is written: a run of fixed-size fields (primitives and messages made only of
# them) in one struct code, a string, a message, and sequences (or arrays) of each.
_FIXED, _STRING, _MESSAGE, _PRIMITIVE_LIST, _FIXED_LIST, _STRING_LIST, _MESSAGE_LIST = range(7)


def ros_type_name(msg_type: type) -> str:
    """``sensor_msgs/msg/JointState`` for the rclpy class ``sensor_msgs.msg.JointState``."""
    package, interface_kind = msg_type.__module__.split('.')[:2]
    return f'{package}/{interface_kind}/{msg_type.__name__}'


def _message_class(slot_type: NamespacedType) -> type:
    return getattr(importlib.import_module('.'.join(slot_type.namespaces)), slot_type.name)


# One entry of a plan: its getter, how it is written, a detail (the struct codes and lengths
# of a fixed run, by offset mod 8; the code and size of a primitive sequence's elements), the
# element getter or message class of a sequence or message, and whether a length comes first.
_Entry = tuple[Callable[[Any], Any], int, Any, Any, bool]
PADDING = ('',) + tuple(f'{n}x' for n in range(1, 8))  # struct codes of 0 to 7 zero bytes


def _fields(msg_type: type) -> list[tuple[str, Any]]:
    return list(zip(msg_type.get_fields_and_field_types(), msg_type.SLOT_TYPES))


@functools.cache
def _fixed_leaves(msg_type: type) -> tuple[tuple[str, str, int], ...] | None:
    """
    Return (attribute path, struct code, size) of every primitive of a flat message, in order.

    A flat message is made only of primitives and such messages; None for any other message.
    """
    leaves: list[tuple[str, str, int]] = []
    for name, slot_type in _fields(msg_type):
        if isinstance(slot_type, BasicType):
            leaves.append((name, *_PRIMITIVES[slot_type.typename]))
        elif isinstance(slot_type, NamespacedType):
            nested = _fixed_leaves(_message_class(slot_type))
            if nested is None:
                return None
            leaves += [(f'{name}.{path}', code, size) for path, code, size in nested]
        else:
            return None
    return tuple(leaves)


def _fixed_entry(leaves: list[tuple[str, str, int]]) -> tuple[Callable[[Any], tuple], tuple]:
    """
    Return the getter of a run of fixed-size leaves and its struct codes and byte lengths.

    The getter returns a tuple of their values; there is a struct code and byte length for each
    start offset mod 8 (the padding depends on nothing else).
    """
    layouts = []
    for phase in range(8):
        codes, offset = [], phase
        for _, code, size in leaves:
            padding = -offset % size
            codes.append(PADDING[padding] + code)
            offset += padding + size
        layouts.append((''.join(codes), offset - phase))
    paths = [path for path, _, _ in leaves]
    if len(paths) == 1:
        single = operator.attrgetter(paths[0])
        return (lambda message: (single(message),)), tuple(layouts)
    return operator.attrgetter(*paths), tuple(layouts)


def _run_entry(leaves: list[tuple[str, str, int]]) -> _Entry:
    get, layouts = _fixed_entry(leaves)
    return (get, _FIXED, layouts, None, False)


@functools.cache
def _plan(msg_type: type) -> tuple[_Entry, ...]:
    """
    How ``encode_cdr`` writes ``msg_type``.

    Its fields in order, each run of consecutive fixed-size fields merged into one entry.
    """
    plan: list[_Entry] = []
    run: list[tuple[str, str, int]] = []
    for name, slot_type in _fields(msg_type):
        element = slot_type.value_type if isinstance(slot_type, AbstractNestedType) else slot_type
        if isinstance(element, AbstractWString):
            raise TypeError(f'{ros_type_name(msg_type)}.{name}: wstring fields are not supported')
        if not isinstance(element, (BasicType, AbstractString, NamespacedType)):
            raise TypeError(f'{ros_type_name(msg_type)}.{name}: unsupported type {element!r}')
        message_class = _message_class(element) if isinstance(element, NamespacedType) else None
        fixed = _fixed_leaves(message_class) if message_class is not None else None
        if not isinstance(slot_type, AbstractNestedType):
            if isinstance(element, BasicType):
                run.append((name, *_PRIMITIVES[element.typename]))
                continue
            if fixed is not None:
                run += [(f'{name}.{path}', code, size) for path, code, size in fixed]
                continue
        if run:
            plan.append(_run_entry(run))
            run = []
        get = operator.attrgetter(name)
        counted = isinstance(slot_type, AbstractNestedType) and not isinstance(slot_type, Array)
        if not isinstance(slot_type, AbstractNestedType):
            kind = _STRING if isinstance(element, AbstractString) else _MESSAGE
            plan.append((get, kind, None, message_class, False))
        elif isinstance(element, BasicType):
            plan.append((get, _PRIMITIVE_LIST, _PRIMITIVES[element.typename], None, counted))
        elif isinstance(element, AbstractString):
            plan.append((get, _STRING_LIST, None, None, counted))
        elif fixed is not None:
            element_get, layouts = _fixed_entry(list(fixed))
            plan.append((get, _FIXED_LIST, layouts, element_get, counted))
        else:
            plan.append((get, _MESSAGE_LIST, None, message_class, counted))
    if run:
        plan.append(_run_entry(run))
    return tuple(plan)


def _walk(message: Any, plan: tuple[_Entry, ...], codes: list[str], values: list[Any],
          offset: int) -> int:
    """Append the struct codes and values of ``message`` written at ``offset``; the end offset."""
    for get, kind, detail, extra, counted in plan:
        value = get(message)
        if kind == _FIXED:
            layout, length = detail[offset & 7]
            codes.append(layout)
            values.extend(value)
            offset += length
        elif kind == _STRING:
            offset = add_string(value, codes, values, offset)
        elif kind == _MESSAGE:
            offset = _walk(value, _plan(extra), codes, values, offset)
        else:
            if counted:
                padding = -offset % 4
                codes.append(PADDING[padding] + 'I')
                values.append(len(value))
                offset += padding + 4
            if kind == _PRIMITIVE_LIST:
                if len(value):  # a fixed-size array is a numpy array
                    code, size = detail
                    padding = -offset % size
                    codes.append(f'{PADDING[padding]}{len(value)}{code}')
                    values.extend(value)
                    offset += padding + len(value) * size
            elif kind == _FIXED_LIST:
                for element in value:
                    layout, length = detail[offset & 7]
                    codes.append(layout)
                    values.extend(extra(element))
                    offset += length
            elif kind == _STRING_LIST:
                for text in value:
                    offset = add_string(text, codes, values, offset)
            else:
                element_plan = _plan(extra)
                for element in value:
                    offset = _walk(element, element_plan, codes, values, offset)
    return offset


def add_string(text: str, codes: list[str], values: list[Any], offset: int) -> int:
    """
    Append a CDR string's struct codes and values at ``offset`` (from the body's start).

    Its alignment padding, its length (the terminating NUL counted) and its bytes; return the
    offset after it.
    """
    encoded = text.encode('utf-8')
    padding = -offset % 4
    length = len(encoded) + 1  # with the terminating NUL, which struct adds
    codes.append(f'{PADDING[padding]}I{length}s')
    values.extend((length, encoded))
    return offset + padding + 4 + length


def encode_cdr(message: Any) -> bytes:
    """``message`` (an rclpy message) as little-endian XCDR1 with its encapsulation header."""
    codes: list[str] = ['<']
    values: list[Any] = []
    _walk(message, _plan(type(message)), codes, values, 0)
    return ENCAPSULATION_HEADER + struct.pack(''.join(codes), *values)


class _Slot:
    """Stands for a value of a varying field while a template is walked."""

    __slots__ = ('path',)

    def __init__(self, path: str) -> None:
        self.path = path


class _Template:
    """
    A message seen through ``_walk``.

    The fields named in ``varying`` read as slots (one per element of a sequence), every other
    field as the message's own value.
    """

    __slots__ = ('_message', '_path', '_varying')

    def __init__(self, message: Any, path: str, varying: frozenset[str]) -> None:
        self._message = message
        self._path = path
        self._varying = varying

    def __getattr__(self, name: str) -> Any:
        path = f'{self._path}.{name}' if self._path else name
        value = getattr(self._message, name)
        if path in self._varying:
            return [_Slot(path)] * len(value) if _is_sequence(value) else _Slot(path)
        if hasattr(value, 'SLOT_TYPES'):
            return _Template(value, path, self._varying)
        if isinstance(value, list) and value and hasattr(value[0], 'SLOT_TYPES'):
            return [_Template(element, f'{path}[{index}]', self._varying)
                    for index, element in enumerate(value)]
        return value


def _is_sequence(value: Any) -> bool:
    return hasattr(value, '__len__') and not isinstance(value, (str, bytes))


class FixedShapeEncoder:
    """
    Encode as ``encode_cdr`` does a stream of messages that differ only in some fields.

    The messages differ from ``template`` only in the fixed-size fields named by ``varying``
    (attribute paths such as ``header.stamp.sec``, ``position`` or ``markers[1].points[2].x``; a
    sequence keeps the template's length).

    The template is walked once: its struct format and constant values are kept, so encoding
    a message is one ``struct.pack`` of the constants and the new values, without building the
    message. ``encode`` takes the new values path by path in the order of ``varying``, a
    sequence's elements in order; the bytes equal ``encode_cdr`` of the message they describe.
    """

    def __init__(self, template: Any, varying: list[str]) -> None:
        codes: list[str] = ['<']
        values: list[Any] = []
        _walk(_Template(template, '', frozenset(varying)), _plan(type(template)), codes, values,
              0)
        constants = [value for value in values if not isinstance(value, _Slot)]
        argument = {path: [] for path in varying}
        for index, value in enumerate(values):
            if isinstance(value, _Slot):
                argument[value.path].append(index)
        unused = [path for path, indices in argument.items() if not indices]
        if unused:
            raise ValueError(f'{ros_type_name(type(template))} has no fixed-size field {unused}')
        # struct argument i is element order[i] of constants + given values
        given = [index for path in varying for index in argument[path]]
        order = [0] * len(values)
        constant_index = 0
        for index, value in enumerate(values):
            if not isinstance(value, _Slot):
                order[index] = constant_index
                constant_index += 1
        for position, index in enumerate(given):
            order[index] = len(constants) + position
        self.value_count = len(given)
        self._constants = tuple(constants)
        # itemgetter of one index returns the element itself, not a 1-tuple
        self._order = (operator.itemgetter(*order) if len(order) > 1
                       else lambda arguments: (arguments[order[0]],))
        self._struct = struct.Struct(''.join(codes))

    def encode(self, values: tuple) -> bytes:
        """Return the message with ``values`` (``value_count`` of them) in the varying fields."""
        return ENCAPSULATION_HEADER + self._struct.pack(*self._order(self._constants + values))


# A JointState received as bytes: the encapsulation's representation identifier (its first two
# bytes) → the struct byte order of the body. Only plain XCDR1 (rmw_fastrtps' and rosbag2's
# encoding, and what rosbags writes big endian): XCDR2 aligns differently, and a parameter list
# is not how a JointState is written.
_BYTE_ORDERS = {b'\x00\x00': '>', b'\x00\x01': '<'}
_COUNTS = {order: struct.Struct(order + 'I').unpack_from for order in '<>'}  # lengths, counts
JointStateFields = tuple[int, tuple[str, ...], tuple[float, ...], tuple[float, ...],
                         tuple[float, ...]]


class JointStateDecoder:
    """
    The fields a follower needs of a ``sensor_msgs/JointState`` received as CDR bytes.

    ``decode`` returns (header stamp in ns, names, positions, velocities, efforts) as rclpy's
    ``deserialize_message`` gives them, or raises ValueError naming what is wrong with the
    bytes: an encapsulation other than XCDR1, a length past the end, a string without its NUL or
    not UTF-8. Bytes after the efforts are allowed (rclpy's serializer can leave some). A source
    sends the same names message after message: the decoder keeps the last names' bytes and
    returns the same tuple while they repeat.

    The efforts are checked, and read only by a decoder made with ``efforts=True``: unpacking
    them would cost every message of a follower that has no use for them; to the others they
    are always empty.
    """

    def __init__(self, efforts: bool = False) -> None:
        # the last names: their byte order, where they start and their bytes
        self._names_key: tuple[str, int, bytes] | None = None
        self._names: tuple[str, ...] = ()
        self._sequences = _WITH_EFFORTS if efforts else _WITHOUT_EFFORTS

    def decode(self, data: bytes) -> JointStateFields:
        """Return the stamp (ns), names, positions, velocities and efforts; ValueError if bad."""
        order, body = cdr_body(data)
        end = len(body)
        if end < 12:
            raise ValueError(f'JointState of {end} bytes ends within its header')
        sec, nanosec, length = struct.unpack_from(order + 'iII', body)
        offset = string_end(body, 12, length, 'JointState header.frame_id')
        start = offset + (-offset & 3)
        key = self._names_key
        if (key is not None and key[0] == order and key[1] == start
                and body[start:start + len(key[2])] == key[2]):
            names, offset = self._names, start + len(key[2])
        else:
            names, offset = read_strings(body, order, start, 'JointState name')
            self._names_key = (order, start, body[start:offset])
            self._names = names
        positions, velocities, efforts = _float_sequences(body, order, offset, self._sequences)
        return sec * 1_000_000_000 + nanosec, names, positions, velocities, efforts


def cdr_body(data: bytes) -> tuple[str, bytes]:
    """
    Return a message's struct byte order and its body (after the encapsulation header).

    CDR aligns relative to the body's start. ValueError for an encapsulation other than XCDR1.
    """
    order = _BYTE_ORDERS.get(data[:2])
    if order is None:
        raise ValueError(f'unknown CDR encapsulation {data[:2].hex() or "(none)"}: not '
                         'XCDR1 (00 00 big endian, 00 01 little endian)')
    return order, data[len(ENCAPSULATION_HEADER):]


def string_end(body: bytes, offset: int, length: int, field: str) -> int:
    """
    Check the string of ``length`` bytes (its NUL counted) at ``offset``; return its end.

    ``field`` names it in the ValueError (``JointState header.frame_id``).
    """
    if length == 0:
        raise ValueError(f'{field} has length 0 (a CDR string counts its NUL)')
    if offset + length > len(body):
        raise ValueError(f'{field} of {length} bytes at byte {offset} goes past the end '
                         f'({len(body)} bytes)')
    if body[offset + length - 1]:
        raise ValueError(f'{field} does not end in a NUL')
    return offset + length


def read_strings(body: bytes, order: str, offset: int,
                 field: str) -> tuple[tuple[str, ...], int]:
    """
    Return the sequence of strings at ``offset`` and where it ends.

    ``field`` names it in the ValueError (``JointState name``).
    """
    unpack_length = _COUNTS[order]
    offset += -offset & 3
    if offset + 4 > len(body):
        raise ValueError(f'{field} ends before its length')
    count = unpack_length(body, offset)[0]
    offset += 4
    if count * 5 > len(body) - offset:  # each string takes at least a length and its NUL
        raise ValueError(f'{field} claims {count} strings in {len(body) - offset} bytes')
    strings = []
    for index in range(count):
        offset += -offset & 3
        if offset + 4 > len(body):
            raise ValueError(f'{field}[{index}] ends before its length')
        start = offset + 4
        offset = string_end(body, start, unpack_length(body, offset)[0], f'{field}[{index}]')
        try:
            strings.append(str(body[start:offset - 1], 'utf-8'))
        except UnicodeDecodeError as error:
            raise ValueError(f'{field}[{index}] is not UTF-8: {error}') from None
    return tuple(strings), offset


# the float64 sequences after the names, and whether each is read: without the efforts (what
# most followers need) and with them
_WITHOUT_EFFORTS = (('position', True), ('velocity', True), ('effort', False))
_WITH_EFFORTS = (('position', True), ('velocity', True), ('effort', True))


def _float_sequences(body: bytes, order: str, offset: int,
                     sequences: tuple[tuple[str, bool], ...]
                     ) -> tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...]]:
    """Return the float64 sequences at ``offset``; one not read (``sequences``) is checked, ()."""
    unpack_count = _COUNTS[order]
    end = len(body)
    values = []
    for field, read in sequences:
        offset += -offset & 3
        if offset + 4 > end:
            raise ValueError(f'JointState ends before the length of its {field}')
        count = unpack_count(body, offset)[0]
        offset += 4
        if count:
            offset += -offset & 7  # the elements align to 8
            if offset + 8 * count > end:
                raise ValueError(f'JointState {field} of {count} values goes past the end '
                                 f'({end} bytes)')
            values.append(struct.unpack_from(f'{order}{count}d', body, offset) if read else ())
            offset += 8 * count
        else:
            values.append(())
    return values[0], values[1], values[2]
