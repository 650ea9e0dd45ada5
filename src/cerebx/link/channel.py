"""One side's end of a real link: what the loop sends and receives, as packets of ``wire.py`` over a
transport, with the counts of everything refused.

A data packet (SENSOR, COMMAND) carries one :class:`~cerebx.signals.Message` (its named signals and
stamp), the tick it belongs to, a sequence number and its send time. The receiving end measures its
one-way delay from the stamps (arrival - send, less the clock offset across hosts), drops a packet
older than one already received (``stale``) and counts the sequence numbers it never saw (``lost``).

Every packet is checked on the transport's own thread as it arrives (:meth:`LinkEnd.admit`): the tag
(under the shared key for the handshake kinds, under the session key for the others), the run, the kind
this side may receive, the range of every field (``fields.py``). Only what passes is queued for the
loop, which then checks the sequence numbers: each control kind against a window of the last 64 (a
repeat is ``replayed``), data against the newest; a number more than :data:`SEQ_AHEAD` beyond the newest
is ``seq_window``. The loop takes at most :data:`POLL_BUDGET` packets per poll.
"""

from __future__ import annotations

import threading
from collections import Counter
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from cerebx.link import fields
from cerebx.link.auth import Signer, new_nonce
from cerebx.link.clock import now_ns
from cerebx.link.transport import RECEIVES, SENDS, Arrival, Transport
from cerebx.link.wire import DATA_KINDS, PAIRING_KINDS, Kind, Packet, WireError, decode, encode, peek_kind
from cerebx.signals import Message

ACCEPTS = {
    "robot": frozenset({Kind.HELLO, Kind.START, Kind.COMMAND, Kind.PING, Kind.BYE}),
    "brain": frozenset({Kind.WELCOME, Kind.REFUSE, Kind.START, Kind.SENSOR, Kind.PONG, Kind.TRIAL, Kind.BYE}),
}
SEQ_AHEAD = 1 << 16
"""How far beyond the newest sequence number a packet's may be (at 500 Hz, two minutes of losses)."""
WINDOW = 64
POLL_BUDGET = 64
MAX_CANDIDATES = 8
"""HELLOs (distinct brain nonces) a robot side answers before one of them proves the session key."""


class ReplayWindow:
    """The sequence numbers of one control kind seen in this session: the newest and a bitmap of the 64
    before it."""

    def __init__(self) -> None:
        self.top = -1
        self.bits = 0

    def accept(self, seq: int) -> str | None:
        """None when ``seq`` is new (and now seen), else why it is refused."""
        if seq > self.top:
            if seq - self.top > SEQ_AHEAD:
                return "seq_window"
            shift = seq - self.top
            self.bits = ((self.bits << shift) | 1) & ((1 << WINDOW) - 1) if shift < WINDOW else 1
            self.top = seq
            return None
        back = self.top - seq
        if back >= WINDOW or (self.bits >> back) & 1:
            return "replayed"
        self.bits |= 1 << back
        return None


@dataclass
class Candidate:
    """A session the robot side offered in answer to one HELLO; it holds once the brain side signs with it."""

    brain_nonce: bytes
    robot_nonce: bytes
    run_id: bytes
    hello: Packet
    session: Signer


@dataclass
class Arrived:
    """A data message that arrived: the message, its packet facts and its measured one-way delay."""

    message: Message
    seq: int
    tick: int
    delay_ms: float
    recv_ns: int


@dataclass
class DataCounts:
    received: int = 0
    lost: int = 0  # sequence numbers skipped (dropped on the way)
    last_seq: int = -1


@dataclass
class LinkEnd:
    """The robot's or the brain's end: sends on its outgoing path, checks and decodes its incoming one."""

    transport: Transport
    signer: Signer  # the shared key: handshake packets
    role: str
    expected: dict[str, int]  # incoming data signals: name -> size
    run_id: bytes | None = None
    offset_ns: int = 0  # robot clock - brain clock
    max_tick: int = 2**62
    session: Signer | None = None
    rejected: Counter = field(default_factory=Counter)
    data: DataCounts = field(default_factory=DataCounts)
    candidates: dict[bytes, Candidate] = field(default_factory=dict)
    committed: Candidate | None = None
    last_send_ns: int = 0
    _seq: Counter = field(default_factory=Counter)
    _windows: dict[Kind, ReplayWindow] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.out_path, self.in_path = SENDS[self.role], RECEIVES[self.role]
        self._accepts = ACCEPTS[self.role]
        self._from_sender = -1 if self.role == "brain" else 1  # sign of the offset in (sender clock -> ours)
        self._lock = threading.Lock()
        self.transport.inbox.admit = self.admit

    # ------------------------------------------------------------------ sessions
    def establish(self, session: Signer) -> None:
        """Brain side: the WELCOME to this side's HELLO came; every later packet is under ``session``."""
        self.session = session
        self._windows = {}
        self.transport.lock_to_peer()

    def offer(self, hello: Packet) -> Candidate:
        """Robot side: the session answering ``hello`` (the same one for a repeated HELLO); at most
        :data:`MAX_CANDIDATES` are kept, the oldest dropped first."""
        nonce = hello.info["nonce"]
        cand = self.candidates.get(nonce)
        if cand is None:
            mine = new_nonce()
            cand = Candidate(nonce, mine, hello.run_id, hello, self.signer.session(nonce, mine, hello.run_id))
            with self._lock:
                while len(self.candidates) >= MAX_CANDIDATES:
                    self.candidates.pop(next(iter(self.candidates)))
                self.candidates[nonce] = cand
        return cand

    def _commit(self, cand: Candidate) -> None:
        """Robot side: the brain side signed a packet with ``cand``'s session key: it is the paired one."""
        self.committed, self.session, self.run_id = cand, cand.session, cand.run_id
        self._windows = {}
        with self._lock:
            self.candidates = {}
        self.transport.lock_to_peer()

    # ------------------------------------------------------------------ sending
    def _send(self, kind: Kind, tick: int, stamp_s: float, values: dict | None = None,
              info: dict | None = None, run_id: bytes | None = None) -> int:
        signer = self.signer if kind in PAIRING_KINDS else self.session
        if signer is None:
            return -1  # no session yet: nothing but the handshake is sent
        seq = self._seq[kind]
        self._seq[kind] = seq + 1
        self.last_send_ns = now_ns()
        data = encode(signer, kind, run_id or self.run_id or bytes(16), seq, tick, stamp_s, self.last_send_ns,
                      values, info)
        self.transport.send(self.out_path, 0, data)
        return seq

    def send_message(self, msg: Message, tick: int) -> int:
        kind = Kind.SENSOR if self.role == "robot" else Kind.COMMAND
        return self._send(kind, tick, msg.stamp_s, values=msg.values)

    def send_control(self, kind: Kind, info: dict[str, Any], tick: int = 0, stamp_s: float = 0.0,
                     run_id: bytes | None = None) -> int:
        return self._send(kind, tick, stamp_s, info=info, run_id=run_id)

    # ------------------------------------------------------------------ receiving
    def reject(self, reason: str, n: int = 1) -> None:
        with self._lock:
            self.rejected[reason] += n

    def delay_ms(self, pkt: Packet) -> float:
        """One-way delay of ``pkt`` from its stamps, on this side's clock."""
        sent_here = pkt.send_ns + self._from_sender * self.offset_ns
        return (pkt.recv_ns - sent_here) / 1e6

    def admit(self, item: Arrival) -> Packet | None:
        """On the transport's thread: the checked packet, or None (counted) when it is refused."""
        if item.path != self.in_path:
            self.reject("unexpected_kind")
            return None
        try:
            pkt = self._decode(item.data)
        except WireError as err:
            self.reject(err.reason)
            return None
        pkt.recv_ns = item.recv_ns
        return pkt

    def _decode(self, raw: bytes) -> Packet:
        kind = peek_kind(raw)
        cand = None
        if kind in PAIRING_KINDS or self.session is not None:
            pkt = decode(raw, self.signer if kind in PAIRING_KINDS else self.session, None, self.expected)
        else:  # robot side before pairing: the session of one of the HELLOs it answered, or none
            pkt = None
            with self._lock:
                offered = list(self.candidates.values())
            for cand in offered:
                try:
                    pkt = decode(raw, cand.session, cand.run_id, self.expected)
                    break
                except WireError as err:
                    if err.reason != "unauthenticated":
                        raise
            if pkt is None:
                raise WireError("unauthenticated", "no session yet")
        if pkt.kind not in self._accepts:
            raise WireError("unexpected_kind", pkt.kind.name)
        if pkt.kind not in PAIRING_KINDS and self.run_id is not None and pkt.run_id != self.run_id:
            raise WireError("other_run")
        if pkt.kind in DATA_KINDS:
            if self.run_id is None and cand is None:
                raise WireError("other_run", "data before pairing")
            if pkt.tick > self.max_tick:
                raise WireError("bad_field", f"tick {pkt.tick} beyond the run's {self.max_tick}")
        else:
            pkt.info = fields.check(pkt.kind, pkt.info)
        pkt.candidate = cand
        return pkt

    def poll(self, limit: int = POLL_BUDGET) -> tuple[list[Arrived], list[Packet]]:
        """What has arrived and passed every check (at most ``limit`` packets): (data messages in order,
        control packets). Refused packets are counted in :attr:`rejected` by reason and dropped."""
        data: list[Arrived] = []
        control: list[Packet] = []
        for pkt in self.transport.inbox.take(limit):
            if isinstance(pkt, Arrival):  # queued before this end took over the inbox
                pkt = self.admit(pkt)
                if pkt is None:
                    continue
            cand = pkt.candidate
            if cand is not None:
                if self.session is None and cand.brain_nonce in self.candidates:
                    self._commit(cand)
                elif cand is not self.committed:
                    self.reject("other_run")
                    continue
            if pkt.kind in PAIRING_KINDS:
                control.append(pkt)
                continue
            if pkt.kind in DATA_KINDS:
                counts = self.data
                if pkt.seq <= counts.last_seq:
                    self.reject("stale")
                    continue
                if pkt.seq - counts.last_seq > SEQ_AHEAD:
                    self.reject("seq_window")
                    continue
                counts.lost += pkt.seq - counts.last_seq - 1
                counts.last_seq = pkt.seq
                counts.received += 1
                data.append(Arrived(Message(pkt.stamp_s, pkt.values), pkt.seq, pkt.tick, self.delay_ms(pkt),
                                    pkt.recv_ns))
                continue
            why = self._windows.setdefault(pkt.kind, ReplayWindow()).accept(pkt.seq)
            if why is not None:
                self.reject(why)
                continue
            control.append(pkt)
        return data, control

    def dropped(self) -> dict[str, int]:
        """Everything dropped so far by reason: before decoding (the transport's) and refused packets."""
        out = Counter(self.transport.inbox.dropped)
        with self._lock:
            out.update(self.rejected)
        return dict(out)

    def counts(self) -> dict[str, Any]:
        with self._lock:
            rejected = dict(sorted(self.rejected.items()))
        return {"received": self.data.received, "lost": self.data.lost, "rejected": rejected,
                "rejected_total": sum(rejected.values()), "dropped_before_decoding": dict(self.transport.inbox.dropped)}


def values_equal(a: dict[str, np.ndarray], b: dict[str, np.ndarray]) -> bool:
    """Whether two signal sets are the same (names, sizes and values): for tests and checks."""
    return a.keys() == b.keys() and all(np.array_equal(a[k], b[k]) for k in a)
