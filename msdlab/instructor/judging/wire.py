"""Plain-data messages between a grader and a sandboxed submission (never pickle).

A message is a JSON header plus raw array buffers. Values are None, bool, int,
float, str, tuples, lists, dicts with str keys, numpy arrays of numeric or bool
dtype, and references to objects that stay on the other side (``{"$r": id}``).
Decoding builds nothing else, so a hostile peer can only send data.
"""

from __future__ import annotations

import json
import math
import os
import struct
from collections.abc import Callable
from typing import Any

import numpy as np

MAX_MESSAGE_BYTES = 512 * 2**20
MAX_DEPTH = 32
_KINDS = "biufc"  # bool, int, uint, float, complex
_AS_IS = frozenset({str, bool, int, type(None)})  # exact types a frame holds as they are
_SCALARS = _AS_IS | {float}
_JSON = json.JSONEncoder(allow_nan=False)  # json.dumps(..., allow_nan=False), built once


class WireError(Exception):
    """A message that is not plain data, too big, or cut short."""


class Ref:
    """A reference to an object living on the other side, with a hint of what it is."""

    __slots__ = ("id", "kind")

    def __init__(self, ref_id: int, kind: str = "object") -> None:
        self.id = ref_id
        self.kind = kind

    def __repr__(self) -> str:
        return f"Ref({self.id}, {self.kind!r})"


def encode(value: Any, reference: Callable[[Any], Ref] | None = None) -> bytes:
    """Frame ``value``; objects that are not plain data become references via ``reference``."""
    buffers: list[bytes] = []

    def frame_array(item: np.ndarray) -> dict:
        array = np.ascontiguousarray(item)  # (a 0-d array goes as shape (1,))
        buffers.append(array.tobytes())
        return {"$a": len(buffers) - 1, "dtype": array.dtype.str, "shape": list(array.shape)}

    def walk(item: Any, depth: int) -> Any:
        if depth > MAX_DEPTH:
            raise WireError("value nested too deeply")
        kind = type(item)  # the common exact types first; the same frames as below
        if kind in _AS_IS:
            return item
        if kind is float and math.isfinite(item):
            return item
        if kind is np.ndarray and item.dtype.kind in _KINDS:
            return frame_array(item)
        if kind is tuple:
            return {"$t": [walk(x, depth + 1) for x in item]}
        if kind is dict and all(isinstance(k, str) for k in item):
            return {"$d": {k: walk(x, depth + 1) for k, x in item.items()}}
        if kind is Ref:
            return {"$r": item.id, "k": item.kind}
        if item is None or isinstance(item, (bool, str)):
            return item
        if isinstance(item, (int, np.integer)) and not isinstance(item, np.bool_):
            return int(item)
        if isinstance(item, (float, np.floating)):
            number = float(item)
            return number if math.isfinite(number) else {"$f": repr(number)}
        if isinstance(item, np.bool_):
            return bool(item)
        if isinstance(item, np.ndarray) and item.dtype.kind in _KINDS:
            return frame_array(item)
        if isinstance(item, tuple):
            return {"$t": [walk(x, depth + 1) for x in item]}
        if isinstance(item, list):
            return [walk(x, depth + 1) for x in item]
        if isinstance(item, dict) and all(isinstance(k, str) for k in item):
            return {"$d": {k: walk(x, depth + 1) for k, x in item.items()}}
        if reference is not None and not isinstance(item, Ref):
            item = reference(item)
        if isinstance(item, Ref):
            return {"$r": item.id, "k": item.kind}
        raise WireError(f"{type(item).__name__} is not plain data")

    header = _JSON.encode(walk(value, 0)).encode()
    parts = [struct.pack("<QQ", len(header), len(buffers)), header]
    for buffer in buffers:
        parts += [struct.pack("<Q", len(buffer)), buffer]
    message = b"".join(parts)
    if len(message) > MAX_MESSAGE_BYTES:
        raise WireError(f"message of {len(message)} bytes is over the limit")
    return message


def decode(read: Callable[[int], bytes]) -> Any:
    """Read one framed value with ``read(n)`` (which returns exactly n bytes or raises)."""
    header_size, count = struct.unpack("<QQ", read(16))
    if header_size > MAX_MESSAGE_BYTES or count > 1_000_000:
        raise WireError("message header too large")
    header = json.loads(read(header_size))
    buffers, total = [], header_size
    for _ in range(count):
        (size,) = struct.unpack("<Q", read(8))
        total += size
        if total > MAX_MESSAGE_BYTES:
            raise WireError("message too large")
        buffers.append(read(size))

    def build(item: Any, depth: int) -> Any:
        if depth > MAX_DEPTH:
            raise WireError("value nested too deeply")
        if type(item) in _SCALARS or isinstance(item, (bool, int, float, str)):
            return item
        if isinstance(item, list):
            return [build(x, depth + 1) for x in item]
        if not isinstance(item, dict) or len(item) == 0:
            raise WireError("malformed message")
        if "$f" in item:
            return float(item["$f"]) if item["$f"] in ("nan", "inf", "-inf") else _bad()
        if "$t" in item:
            return tuple([build(x, depth + 1) for x in _list(item["$t"])])
        if "$d" in item and isinstance(item["$d"], dict):
            return {str(k): build(x, depth + 1) for k, x in item["$d"].items()}
        if "$r" in item and isinstance(item["$r"], int):
            return Ref(item["$r"], str(item.get("k", "object")))
        if "$a" in item:
            dtype = np.dtype(str(item["dtype"]))
            shape = tuple([int(n) for n in _list(item["shape"])])
            if dtype.kind not in _KINDS or min(shape, default=0) < 0:
                raise WireError("array of a forbidden dtype or shape")
            data = buffers[int(item["$a"])]
            if len(data) != dtype.itemsize * math.prod(shape):
                raise WireError("array buffer does not match its shape")
            return np.frombuffer(data, dtype=dtype).reshape(shape).copy()
        raise WireError("malformed message")

    return build(header, 0)


def _list(value: Any) -> list:
    if not isinstance(value, list):
        raise WireError("malformed message")
    return value


def _bad() -> float:
    raise WireError("malformed float")


CHUNK_BYTES = 1 << 16  # a pipe's buffer: one read takes a whole message of a few arrays


class Reader:
    """``read(n)`` over a file descriptor: exactly n bytes, EOFError when the peer is gone.

    Buffered: each ``os.read`` takes what has arrived (at least the bytes asked
    for, up to a pipe's buffer), so a message costs one system call, not one per
    part. ``wait()``, if given, runs before each ``os.read`` (the grader's time
    limit) and raises to give up.
    """

    def __init__(self, fd: int, wait: Callable[[], None] | None = None) -> None:
        self.fd, self.wait = fd, wait
        self.buffer = bytearray()

    def __call__(self, size: int) -> bytes:
        buffer = self.buffer
        while len(buffer) < size:
            if self.wait is not None:
                self.wait()
            wanted = min(max(size - len(buffer), CHUNK_BYTES), 1 << 20)
            chunk = os.read(self.fd, wanted)
            if not chunk:
                raise EOFError  # the grader names the reason (`SandboxProcess._death_reason`)
            buffer += chunk
        data = bytes(buffer[:size])
        del buffer[:size]
        return data


def reader(fd: int) -> Callable[[int], bytes]:
    """``read(n)`` over a file descriptor (a `Reader` without a time limit)."""
    return Reader(fd)


def write_all(fd: int, data: bytes) -> None:
    """Write every byte of ``data`` to ``fd``."""
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view) :]
