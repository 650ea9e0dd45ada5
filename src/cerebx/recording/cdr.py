"""Joint states as ROS 2 ``sensor_msgs/msg/JointState`` and spikes as ``cerebx_msgs/msg/Spikes``, both in CDR, the
binary encoding Foxglove reads natively (plots, the 3-D panel's robot model, the raw messages).

The two joint-state channels are logged every control step. As JSON (``foxglove.JointStates``-shaped, the
format of older runs) a message was ~830 bytes of text: formatting 21 floats and compressing
the text cost the loop's thread ~3.9 us a message. In CDR it is 300 bytes written in place into a template,
~1.8 us. The spikes of a recorded population are logged every step too: ~150 DCN indices a step were ~740
bytes of JSON, formatted and logged on the loop's thread (~8 us a step). In CDR they are encoded for a whole
chunk of steps at once on the network's thread (``recording/spike_chunks.py``), and the loop's
thread only logs them. Everything else stays JSON.

The layout (XCDR1, little endian, after the 4-byte encapsulation header; every value aligned to its size
from the start of the body)::

    int32 sec, uint32 nanosec, string frame_id (""), string[] name,
    float64[] position, float64[] velocity, float64[] effort

:func:`decode_joint_state` reads it back into the dict the JSON messages held (``timestamp``, ``joints``: name,
position, velocity, effort), so every reader of a log sees the same values whichever way it was written.
A spikes message::

    float64 t, uint32[] indices

is 16 + 4 n bytes (the header, ``t``, the count, the indices); :func:`decode_spikes` gives the JSON messages'
dict (``t``, ``indices``).
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from typing import Any

import numpy as np

JOINT_STATE = "sensor_msgs/msg/JointState"
JOINT_STATE_DEFINITION = """\
std_msgs/Header header
string[] name
float64[] position
float64[] velocity
float64[] effort
================================================================================
MSG: std_msgs/Header
builtin_interfaces/Time stamp
string frame_id
================================================================================
MSG: builtin_interfaces/Time
int32 sec
uint32 nanosec
"""
"""The message definition as ROS 2 tools write it into MCAP schemas (encoding ``ros2msg``)."""

SPIKES = "cerebx_msgs/msg/Spikes"
SPIKES_DEFINITION = """\
# the local indices of a population's cells that fired in the 2 ms step at t (s)
float64 t
uint32[] indices
"""

_HEADER = b"\x00\x01\x00\x00"  # CDR, little endian
HEADER_WORD = 256
"""The encapsulation header as one little-endian uint32 (for encoders that write 32-bit words)."""
_SPIKES_HEAD = struct.Struct("<dI")
_STAMP = struct.Struct("<iI")
_U32 = struct.Struct("<I")


def _layout(names: tuple[str, ...]) -> tuple[bytearray, list[int]]:
    """An encoded message with zero values, and the byte offsets of its three arrays."""
    body = bytearray()

    def align(k: int) -> None:
        body.extend(b"\0" * (-len(body) % k))

    body += _STAMP.pack(0, 0) + _U32.pack(1) + b"\0"  # stamp, frame_id ""
    align(4)
    body += _U32.pack(len(names))
    for name in names:
        align(4)
        raw = name.encode()
        body += _U32.pack(len(raw) + 1) + raw + b"\0"
    offsets = []
    for _ in range(3):
        align(4)
        body += _U32.pack(len(names))
        if names:
            align(8)
        offsets.append(len(_HEADER) + len(body))
        body += bytes(8 * len(names))
    return bytearray(_HEADER + body), offsets


class JointStateEncoder:
    """Encodes the joint states of fixed joints: the values are written into one message kept in place."""

    __slots__ = ("names", "n", "_buf", "_offsets", "_position", "_velocity", "_effort")

    def __init__(self, names: tuple[str, ...]):
        self.names, self.n = tuple(names), len(names)
        self._buf, self._offsets = _layout(self.names)
        self._position, self._velocity, self._effort = (
            np.ndarray((self.n,), "<f8", self._buf, off) for off in self._offsets)

    def encode(self, t_ns: int, q: np.ndarray, qd: np.ndarray, effort: np.ndarray | None) -> bytes:
        """The message at ``t_ns`` with the first ``n`` positions, velocities, efforts (zeros if None)."""
        n = self.n
        _STAMP.pack_into(self._buf, 4, *divmod(t_ns, 1_000_000_000))
        self._position[:] = q[:n]
        self._velocity[:] = qd[:n]
        self._effort[:] = effort[:n] if effort is not None else 0.0
        return bytes(self._buf)

    def encode_many(self, t_ns: np.ndarray, q: np.ndarray, qd: np.ndarray) -> list[bytes]:
        """The messages at the times ``t_ns`` (int64) of the rows of ``q`` and ``qd`` (effort 0), each the bytes
        :meth:`encode` gives, written for all rows at once (a trial's desired states: ~0.1 us a message
        against ~1.2 us one by one)."""
        m, n, size = len(t_ns), self.n, len(self._buf)
        block = np.empty((m, size), np.uint8)
        block[:] = np.frombuffer(self._buf, np.uint8)
        block[:, self._offsets[2]:self._offsets[2] + 8 * n] = 0  # effort
        sec, nsec = np.divmod(np.asarray(t_ns, np.int64), 1_000_000_000)
        np.ndarray((m,), "<i4", block, 4, (size,))[:] = sec
        np.ndarray((m,), "<u4", block, 8, (size,))[:] = nsec
        for off, values in zip(self._offsets, (q, qd)):
            np.ndarray((m, n), "<f8", block, off, (size, 8))[:] = np.asarray(values)[:m, :n]
        raw = block.tobytes()
        return [raw[k:k + size] for k in range(0, m * size, size)]


def decode_joint_state() -> Callable[[bytes | memoryview], dict[str, Any]]:
    """A decoder for one channel's messages. Messages of a channel share their joints, so the names and
    offsets read from one message are reused while the next one has the same names."""
    names_raw = b""
    size_seen = 0
    names: list[str] = []
    offsets: list[int] = []

    def decode(data: bytes | memoryview) -> dict[str, Any]:
        nonlocal names_raw, size_seen, names, offsets
        data = bytes(data)
        if data[:4] != _HEADER:
            raise ValueError(f"{JOINT_STATE}: not little-endian CDR")
        sec, nsec = _STAMP.unpack_from(data, 4)
        (frame_len,) = _U32.unpack_from(data, 12)
        pos = 16 + frame_len
        pos += -(pos - 4) % 4
        start = pos
        (count,) = _U32.unpack_from(data, pos)
        if len(data) != size_seen or data[start:offsets[0]] != names_raw:
            pos += 4
            names = []
            for _ in range(count):
                pos += -(pos - 4) % 4
                (size,) = _U32.unpack_from(data, pos)
                names.append(data[pos + 4:pos + 3 + size].decode())
                pos += 4 + size
            offsets = []
            for _ in range(3):
                pos += -(pos - 4) % 4
                (k,) = _U32.unpack_from(data, pos)
                if k != count:
                    raise ValueError(f"{JOINT_STATE}: {count} names but {k} values")
                pos += 4
                if count:
                    pos += -(pos - 4) % 8
                offsets.append(pos)
                pos += 8 * count
            names_raw, size_seen = data[start:offsets[0]], len(data)
        fmt = f"<{count}d"
        p, v, e = (struct.unpack_from(fmt, data, off) for off in offsets)
        return {"timestamp": {"sec": sec, "nsec": nsec},
                "joints": [{"name": a, "position": b, "velocity": c, "effort": d}
                           for a, b, c, d in zip(names, p, v, e)]}

    return decode


def encode_spikes(t_s: float, indices: np.ndarray) -> bytes:
    """One spikes message: the cells (local indices, non-negative) that fired in the step at ``t_s``."""
    idx = np.asarray(indices)
    return _HEADER + _SPIKES_HEAD.pack(t_s, idx.size) + idx.astype("<u4").tobytes()


def decode_spikes(data: bytes | memoryview) -> dict[str, Any]:
    """A spikes message as the dict the JSON messages held: ``t`` (s) and ``indices`` (a list of ints)."""
    data = bytes(data)
    if data[:4] != _HEADER:
        raise ValueError(f"{SPIKES}: not little-endian CDR")
    t, n = _SPIKES_HEAD.unpack_from(data, 4)
    if len(data) != 16 + 4 * n:
        raise ValueError(f"{SPIKES}: {len(data)} bytes for {n} indices")
    return {"t": t, "indices": np.frombuffer(data, "<u4", n, 16).tolist()}
