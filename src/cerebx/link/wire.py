"""The wire format of the link, version 2: one packet per UDP datagram or zenoh sample.

All integers and floats are little-endian. A packet is a fixed 60-byte header, a body and a 16-byte
tag::

    offset  size  field
         0     4  magic       b"CBXL"
         4     1  version     2 (a packet of another version is refused, never guessed at)
         5     1  kind        see :class:`Kind`
         6     2  flags       0 (reserved; anything else is refused)
         8    16  run id      the run's id (UUID bytes), chosen by the brain side when it pairs
        24     8  seq         u64, counts the sender's packets of this kind in this session from 0
        32     8  tick        i64 >= 0, the control tick the packet belongs to (sensor: measured at;
                              command: the brain tick that computed it)
        40     8  stamp_s     f64, finite, >= 0: simulated-time stamp of the values (sensor: measured at;
                              command: meant to be applied at)
        48     8  send_ns     i64 >= 0, the sender's monotonic clock when it sent the packet, ns
        56     4  body_len    u32, bytes of body
        60     n  body        SENSOR, COMMAND: u16 signal count, then per signal: u8 name length,
                              the name (ASCII, e.g. ``joint.torque``), u16 value count, the values
                              (f64 each); every other kind: a UTF-8 JSON object (nested at most
                              :data:`MAX_DEPTH` deep, no NaN or infinity; its fields are checked
                              per kind by ``fields.py``)
      60+n    16  tag         HMAC-SHA256 of bytes 0 .. 60+n, first 16 bytes: under the shared key for
                              HELLO, WELCOME and REFUSE, under the session key for every other kind

A receiver refuses a packet that is truncated, has another magic, version or flags, fails the tag,
belongs to another run, names a signal it does not expect, carries a signal of the wrong size, misses
one, holds a non-finite value or a field out of its range or type; it counts the refusal under one of
:data:`REASONS` and drops the packet. It never raises anything but :class:`WireError`.
"""

from __future__ import annotations

import enum
import json
import math
import struct
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from cerebx.link.auth import TAG_BYTES, Signer

MAGIC = b"CBXL"
VERSION = 2
HEADER = struct.Struct("<4sBBH16sQqdqI")
HEADER_BYTES = HEADER.size  # 60
MIN_BYTES = HEADER_BYTES + TAG_BYTES
MAX_BYTES = 60_000  # fits one UDP datagram
KIND_OFFSET = 5
SEQ_OFFSET = 24


class Kind(enum.IntEnum):
    """What a packet is. SENSOR and COMMAND carry signals; the others a JSON object."""

    HELLO = 1  # brain -> robot: fingerprint, run id, what the robot side needs from the controller
    WELCOME = 2  # robot -> brain: paired; the robot's host facts for the clock
    REFUSE = 3  # robot -> brain: the configs differ (both sides stop)
    START = 4  # robot -> brain: tick 0 starts at this monotonic time of the robot's clock
    SENSOR = 5  # robot -> brain: the plant's sensor signals of one tick
    COMMAND = 6  # brain -> robot: the brain side's output of one tick
    PING = 7  # brain -> robot: clock-offset probe
    PONG = 8  # robot -> brain: its answer with the robot's receive and send times
    TRIAL = 9  # robot -> brain: one trial's metrics
    BYE = 10  # either way: this side has finished (status, reason)


DATA_KINDS = frozenset({Kind.SENSOR, Kind.COMMAND})
PAIRING_KINDS = frozenset({Kind.HELLO, Kind.WELCOME, Kind.REFUSE})
"""Signed with the shared key; every other kind with the session key."""

MAX_DEPTH = 8
MAX_STAMP_S = 1e9

REASONS = ("truncated", "malformed", "version", "unauthenticated", "other_run", "unknown_signal", "wrong_size",
           "missing_signal", "non_finite", "unexpected_kind", "stale", "replayed", "seq_window", "bad_field",
           "too_deep", "unmatched", "foreign", "queue_full")
"""Why a packet was dropped: ``stale`` a data packet older than one already received; ``replayed`` a control
packet whose sequence number was seen; ``seq_window`` a sequence number too far ahead of the newest;
``bad_field`` a header or JSON field of the wrong type, range or finiteness; ``too_deep`` JSON nested beyond
:data:`MAX_DEPTH`; ``unmatched`` an answer to no question of this side (a PONG of no PING in the current
burst, a WELCOME to another HELLO); ``foreign`` a datagram from an address that is not the peer's;
``queue_full`` an authenticated packet that found the bounded inbox full."""


class WireError(Exception):
    """A packet that is refused; ``reason`` is one of :data:`REASONS`."""

    def __init__(self, reason: str, detail: str = ""):
        assert reason in REASONS
        self.reason = reason
        super().__init__(f"{reason}: {detail}" if detail else reason)


@dataclass
class Packet:
    """A decoded packet. ``values`` for SENSOR/COMMAND, ``info`` for the others; ``recv_ns`` and
    ``candidate`` are set by the receiving side (its monotonic clock when the bytes arrived)."""

    kind: Kind
    run_id: bytes
    seq: int
    tick: int
    stamp_s: float
    send_ns: int
    values: dict[str, np.ndarray] = field(default_factory=dict)
    info: dict[str, Any] = field(default_factory=dict)
    recv_ns: int = 0
    candidate: Any = None  # robot side before pairing: the offered session whose key the packet's tag passed


def encode(signer: Signer, kind: Kind, run_id: bytes, seq: int, tick: int, stamp_s: float, send_ns: int,
           values: dict[str, np.ndarray] | None = None, info: dict[str, Any] | None = None) -> bytes:
    """One signed packet."""
    if kind in DATA_KINDS:
        parts = [struct.pack("<H", len(values or {}))]
        for name, v in (values or {}).items():
            raw = name.encode("ascii")
            arr = np.ascontiguousarray(v, dtype="<f8").ravel()
            parts += [struct.pack("<B", len(raw)), raw, struct.pack("<H", arr.size), arr.tobytes()]
        body = b"".join(parts)
    else:
        body = json.dumps(info or {}, separators=(",", ":")).encode()
    head = HEADER.pack(MAGIC, VERSION, int(kind), 0, run_id, seq, tick, stamp_s, send_ns, len(body))
    data = head + body
    if len(data) + TAG_BYTES > MAX_BYTES:
        raise ValueError(f"packet of {len(data) + TAG_BYTES} bytes exceeds {MAX_BYTES}")
    return data + signer.tag(data)


def peek_kind(data: bytes) -> int | None:
    """The kind byte of a packet without checking anything (the relay routes by it)."""
    return data[KIND_OFFSET] if len(data) > KIND_OFFSET else None


def peek_seq(data: bytes) -> int | None:
    return struct.unpack_from("<Q", data, SEQ_OFFSET)[0] if len(data) >= SEQ_OFFSET + 8 else None


def decode(data: bytes, signer: Signer, run_id: bytes | None = None,
           expected: dict[str, int] | None = None) -> Packet:
    """Check and decode ``data``. ``run_id``: the paired run (None before pairing accepts any);
    ``expected``: signal name -> size for data packets (None: any). Raises :class:`WireError`."""
    n = len(data)
    if n < MIN_BYTES:
        raise WireError("truncated", f"{n} bytes, a packet has at least {MIN_BYTES}")
    magic, version, kind, flags, rid, seq, tick, stamp_s, send_ns, body_len = HEADER.unpack_from(data, 0)
    if magic != MAGIC:
        raise WireError("malformed", "not a cerebx link packet")
    if version != VERSION:
        raise WireError("version", f"wire format version {version}, this side speaks {VERSION}")
    if flags:
        raise WireError("malformed", f"flags {flags}")
    if HEADER_BYTES + body_len + TAG_BYTES != n:
        reason = "truncated" if HEADER_BYTES + body_len + TAG_BYTES > n else "malformed"
        raise WireError(reason, f"body of {body_len} bytes in a packet of {n}")
    if not signer.verify(data[:-TAG_BYTES], data[-TAG_BYTES:]):
        raise WireError("unauthenticated")
    try:
        kind = Kind(kind)
    except ValueError:
        raise WireError("malformed", f"unknown kind {kind}") from None
    if run_id is not None and rid != run_id:
        raise WireError("other_run")
    if not math.isfinite(stamp_s):
        raise WireError("non_finite", "stamp")
    if not 0.0 <= stamp_s <= MAX_STAMP_S or tick < 0 or send_ns < 0:
        raise WireError("bad_field", "negative tick, stamp or send time, or a stamp beyond 1e9 s")
    pkt = Packet(kind, rid, seq, tick, stamp_s, send_ns)
    body = memoryview(data)[HEADER_BYTES:HEADER_BYTES + body_len]
    if kind in DATA_KINDS:
        pkt.values = _signals(body, expected)
    else:
        pkt.info = parse_json(bytes(body))
    return pkt


def _refuse_constant(name: str) -> Any:
    raise WireError("non_finite", f"JSON {name}")


def _finite_float(text: str) -> float:
    v = float(text)
    if not math.isfinite(v):
        raise WireError("non_finite", f"JSON number {text[:20]}")
    return v


def parse_json(body: bytes) -> dict[str, Any]:
    """A JSON object of at most :data:`MAX_DEPTH` levels without NaN or infinities (``1e400`` included)."""
    if _depth_exceeds(body, MAX_DEPTH):
        raise WireError("too_deep", f"JSON nested deeper than {MAX_DEPTH}")
    try:
        info = json.loads(body, parse_constant=_refuse_constant, parse_float=_finite_float)
    except (ValueError, UnicodeDecodeError, RecursionError):
        raise WireError("malformed", "body is not JSON") from None
    if not isinstance(info, dict):
        raise WireError("malformed", "body is not a JSON object")
    return info


def _depth_exceeds(body: bytes, limit: int) -> bool:
    """Whether brackets outside strings nest deeper than ``limit`` (checked before parsing: a parser
    recurses once per level)."""
    opens = body.count(b"[") + body.count(b"{")
    if opens <= limit:
        return False
    depth, in_str, escaped = 0, False, False
    for c in body:
        if in_str:
            if escaped:
                escaped = False
            elif c == 0x5C:  # backslash
                escaped = True
            elif c == 0x22:
                in_str = False
        elif c == 0x22:
            in_str = True
        elif c in (0x5B, 0x7B):
            depth += 1
            if depth > limit:
                return True
        elif c in (0x5D, 0x7D):
            depth -= 1
    return False


def _signals(body: memoryview, expected: dict[str, int] | None) -> dict[str, np.ndarray]:
    n = len(body)
    if n < 2:
        raise WireError("truncated", "no signal count")
    (count,) = struct.unpack_from("<H", body, 0)
    pos, out = 2, {}
    for _ in range(count):
        if pos + 1 > n:
            raise WireError("truncated", "signal name")
        ln = body[pos]
        pos += 1
        if pos + ln + 2 > n:
            raise WireError("truncated", "signal name")
        try:
            name = bytes(body[pos:pos + ln]).decode("ascii")
        except UnicodeDecodeError:
            raise WireError("malformed", "signal name is not ASCII") from None
        pos += ln
        (size,) = struct.unpack_from("<H", body, pos)
        pos += 2
        if pos + 8 * size > n:
            raise WireError("truncated", f"values of {name}")
        if expected is not None:
            if name not in expected:
                raise WireError("unknown_signal", name)
            if expected[name] != size:
                raise WireError("wrong_size", f"{name}[{size}], expected {expected[name]}")
        if name in out:
            raise WireError("malformed", f"{name} twice")
        v = np.frombuffer(body, dtype="<f8", count=size, offset=pos).astype(float)
        if not np.isfinite(v).all():
            raise WireError("non_finite", name)
        out[name] = v
        pos += 8 * size
    if pos != n:
        raise WireError("malformed", f"{n - pos} bytes after the last signal")
    if expected is not None and len(out) != len(expected):
        raise WireError("missing_signal", ", ".join(sorted(set(expected) - set(out))))
    return out
