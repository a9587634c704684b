"""The node's side of logging: rclpy messages in, a rosbag2 MCAP bag (bag_writer) out.

rclpy's ``serialize_message`` sizes its buffer from an estimate and can return a few bytes more
than the message's CDR encoding (e.g. after an empty ``effort`` in a JointState); independent
readers such as rosbags reject such messages. ``cdr_length`` computes the exact XCDR1 length
from the message's field types (cached per class, no copying), and only that many bytes are
logged.

The node serializes each message once (``Recorder.serialize``), publishes those bytes and logs
the same bytes. Walking a message in Python for its length costs about as much as serializing
it, so ``Recorder.serialize`` keeps each topic's last length together with the message's shape
(``message_shape``: every string and every sequence length), and walks again only when the
shape differs: for the per-tick topics, whose strings and arrays stay the same in a run, only
on the first message.
"""
from __future__ import annotations

import functools
import importlib
import time
from pathlib import Path
from typing import Any

import yaml
from rclpy.qos import QoSProfile
from rclpy.serialization import serialize_message
from rosidl_parser.definition import (
    AbstractGenericString,
    AbstractNestedType,
    AbstractString,
    AbstractWString,
    Array,
    BasicType,
    NamespacedType,
)

from linkage_kinematics.bag_writer import (
    BagExistsError,
    BagWriteError,
    BagWriter,
    message_definition,
)

ENCAPSULATION_HEADER_BYTES = 4
_PRIMITIVE_BYTES = {
    "boolean": 1, "octet": 1, "char": 1, "int8": 1, "uint8": 1,
    "int16": 2, "uint16": 2, "int32": 4, "uint32": 4, "float": 4,
    "int64": 8, "uint64": 8, "double": 8,
}


class RecordingError(OSError):
    """Logging cannot go on (folder not writable, disk full); the message names the file."""


def ros_type_name(msg_type: type) -> str:
    """``sensor_msgs/msg/JointState`` for the rclpy class ``sensor_msgs.msg.JointState``."""
    package, interface_kind = msg_type.__module__.split(".")[:2]
    return f"{package}/{interface_kind}/{msg_type.__name__}"


@functools.cache
def _layout(msg_type: type) -> tuple[tuple[str, Any], ...]:
    return tuple(zip(msg_type.get_fields_and_field_types(), msg_type.SLOT_TYPES))


def _aligned(offset: int, size: int) -> int:
    return offset + (-offset % size)


def _end_of_message(message: Any, offset: int) -> int:
    for name, slot_type in _layout(type(message)):
        offset = _end_of_value(slot_type, getattr(message, name), offset)
    return offset


def _end_of_value(slot_type: Any, value: Any, offset: int) -> int:
    if isinstance(slot_type, BasicType):
        size = _PRIMITIVE_BYTES[slot_type.typename]
        return _aligned(offset, size) + size
    if isinstance(slot_type, AbstractString):
        return _aligned(offset, 4) + 4 + len(value.encode("utf-8")) + 1
    if isinstance(slot_type, NamespacedType):
        return _end_of_message(value, offset)
    if isinstance(slot_type, AbstractWString):
        raise TypeError("wstring fields are not supported by the recorder")
    if isinstance(slot_type, AbstractNestedType):
        if not isinstance(slot_type, Array):
            offset = _aligned(offset, 4) + 4  # sequence length
        element_type = slot_type.value_type
        if isinstance(element_type, BasicType):
            if len(value) == 0:
                return offset
            size = _PRIMITIVE_BYTES[element_type.typename]
            return _aligned(offset, size) + len(value) * size
        for element in value:
            offset = _end_of_value(element_type, element, offset)
        return offset
    raise TypeError(f"unsupported field type {slot_type!r}")


def cdr_length(message: Any) -> int:
    """The exact length in bytes of ``message`` serialized as little-endian XCDR1 with header."""
    return ENCAPSULATION_HEADER_BYTES + _end_of_message(message, 0)


def serialize_exact(message: Any) -> bytes:
    """rclpy's CDR serialization cut to the message's true length (see the module docstring)."""
    return serialize_message(message)[: cdr_length(message)]


# How message_shape reads a field: a string or a sequence of strings as its text (which fixes
# its encoded length), a sequence of primitives or of fixed-size messages by its length, a
# message by its own shape, a sequence of messages by its length and each element's shape.
_TEXT, _TEXTS, _LENGTH, _MESSAGE, _MESSAGES = range(5)


def _message_class(slot_type: NamespacedType) -> type:
    return getattr(importlib.import_module(".".join(slot_type.namespaces)), slot_type.name)


@functools.cache
def _shape_fields(msg_type: type) -> tuple[tuple[str, int, type | None], ...]:
    """The fields of ``msg_type`` whose encoded length can vary, each with how to read it;
    fields of fixed encoded length (primitives, fixed arrays of them, such messages) are left
    out."""
    fields = []
    for name, slot_type in _layout(msg_type):
        if isinstance(slot_type, AbstractGenericString):
            fields.append((name, _TEXT, None))
        elif isinstance(slot_type, NamespacedType):
            nested = _message_class(slot_type)
            if _shape_fields(nested):
                fields.append((name, _MESSAGE, nested))
        elif isinstance(slot_type, AbstractNestedType):
            element_type = slot_type.value_type
            if isinstance(element_type, AbstractGenericString):
                fields.append((name, _TEXTS, None))
            elif isinstance(element_type, NamespacedType):
                nested = _message_class(element_type)
                if _shape_fields(nested):
                    fields.append((name, _MESSAGES, nested))
                elif not isinstance(slot_type, Array):
                    fields.append((name, _LENGTH, None))
            elif not isinstance(slot_type, Array):
                fields.append((name, _LENGTH, None))
    return tuple(fields)


def _add_shape(message: Any, fields: tuple[tuple[str, int, type | None], ...],
               shape: list[Any]) -> None:
    for name, kind, nested in fields:
        value = getattr(message, name)
        if kind == _TEXT:
            shape.append(value)
        elif kind == _LENGTH:
            shape.append(len(value))
        elif kind == _TEXTS:
            shape.append(tuple(value))
        elif kind == _MESSAGE:
            _add_shape(value, _shape_fields(nested), shape)
        else:
            shape.append(len(value))
            nested_fields = _shape_fields(nested)
            for element in value:
                _add_shape(element, nested_fields, shape)


def message_shape(message: Any) -> list[Any]:
    """Everything ``cdr_length(message)`` depends on besides the message's type: equal shapes
    of two messages of one type mean equal lengths."""
    shape: list[Any] = []
    _add_shape(message, _shape_fields(type(message)), shape)
    return shape


def _duration(nanoseconds: int) -> dict[str, int]:
    return {"sec": nanoseconds // 1_000_000_000, "nsec": nanoseconds % 1_000_000_000}


def offered_qos_profiles_yaml(qos: QoSProfile) -> str:
    """rosbag2's (Jazzy, metadata version 9) YAML text for a publisher offering ``qos``."""
    profile = {
        "history": qos.history.name.lower(),
        "depth": qos.depth,
        "reliability": qos.reliability.name.lower(),
        "durability": qos.durability.name.lower(),
        "deadline": _duration(qos.deadline.nanoseconds),
        "lifespan": _duration(qos.lifespan.nanoseconds),
        "liveliness": qos.liveliness.name.lower(),
        "liveliness_lease_duration": _duration(qos.liveliness_lease_duration.nanoseconds),
        "avoid_ros_namespace_conventions": qos.avoid_ros_namespace_conventions,
    }
    return yaml.safe_dump([profile], sort_keys=False)


class Recorder:
    """Logs a run into a new rosbag2 bag folder inside ``folder`` (never overwriting one)."""

    def __init__(self, folder: Path, *, metadata: dict[str, str]) -> None:
        folder = Path(folder)
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as error:
            raise RecordingError(
                f"cannot create log folder {folder}: {error.strerror or error}"
            ) from None
        base_name = time.strftime("rosbag2_%Y_%m_%d-%H_%M_%S")
        suffix = 0
        while True:
            name = base_name if suffix == 0 else f"{base_name}_{suffix}"
            try:
                self._writer = BagWriter(folder / name, metadata=metadata)
                break
            except BagExistsError:
                suffix += 1
            except BagWriteError as error:
                raise RecordingError(f"cannot log into folder {folder}: {error}") from None
        self.bag_path: Path = self._writer.bag_path
        self._channels: dict[str, int] = {}
        self._last_lengths: dict[str, tuple[type, list[Any], int]] = {}

    @property
    def size_bytes(self) -> int:
        return self._writer.size_bytes

    def add_topic(self, topic: str, msg_type: type, qos: QoSProfile) -> None:
        type_name = ros_type_name(msg_type)
        try:
            self._channels[topic] = self._writer.add_topic(
                topic, type_name, message_definition(type_name), offered_qos_profiles_yaml(qos)
            )
        except BagWriteError as error:
            raise RecordingError(str(error)) from None

    def serialize(self, topic: str, message: Any) -> bytes:
        """``serialize_exact(message)``, with the length walk skipped while ``topic``'s messages
        keep their shape; the bytes to publish and to ``record``."""
        data = serialize_message(message)
        shape = message_shape(message)
        last = self._last_lengths.get(topic)
        if last is None or last[0] is not type(message) or last[1] != shape:
            last = self._last_lengths[topic] = (type(message), shape, cdr_length(message))
        return data[: last[2]]

    def record(self, topic: str, data: bytes, log_time_ns: int) -> None:
        """Logs ``data``, a message of ``topic`` serialized by ``serialize``."""
        try:
            self._writer.write(self._channels[topic], data, log_time_ns, log_time_ns)
        except BagWriteError as error:
            raise RecordingError(str(error)) from None

    def close(self) -> None:
        try:
            self._writer.close()
        except BagWriteError as error:
            raise RecordingError(str(error)) from None
