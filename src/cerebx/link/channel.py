"""One side's end of a real link: what the loop sends and receives, as packets of ``wire.py`` over a
transport, with the counts of everything refused.

A data packet (SENSOR, COMMAND) carries one :class:`~cerebx.signals.Message` (its named signals and
stamp), the tick it belongs to, a sequence number and its send time. The receiving end measures its
one-way delay from the stamps (arrival - send, less the clock offset across hosts), drops a packet
older than one already received (``stale``) and counts the sequence numbers it never saw (``lost``).
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from cerebx.link.auth import Signer
from cerebx.link.clock import now_ns
from cerebx.link.transport import RECEIVES, SENDS, Transport
from cerebx.link.wire import DATA_KINDS, Kind, Packet, WireError, decode, encode
from cerebx.signals import Message

ACCEPTS = {
    "robot": frozenset({Kind.HELLO, Kind.START, Kind.COMMAND, Kind.PING, Kind.BYE}),
    "brain": frozenset({Kind.WELCOME, Kind.REFUSE, Kind.START, Kind.SENSOR, Kind.PONG, Kind.TRIAL, Kind.BYE}),
}


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
    """The robot's or the brain's end: sends on its outgoing path, decodes its incoming one."""

    transport: Transport
    signer: Signer
    role: str
    expected: dict[str, int]  # incoming data signals: name -> size
    run_id: bytes | None = None
    offset_ns: int = 0  # robot clock - brain clock
    rejected: Counter = field(default_factory=Counter)
    data: DataCounts = field(default_factory=DataCounts)
    _seq: Counter = field(default_factory=Counter)

    def __post_init__(self) -> None:
        self.out_path, self.in_path = SENDS[self.role], RECEIVES[self.role]
        self._accepts = ACCEPTS[self.role]
        self._from_sender = -1 if self.role == "brain" else 1  # sign of the offset in (sender clock -> ours)

    def _send(self, kind: Kind, tick: int, stamp_s: float, values: dict | None = None,
              info: dict | None = None) -> int:
        seq = self._seq[kind]
        self._seq[kind] = seq + 1
        data = encode(self.signer, kind, self.run_id or bytes(16), seq, tick, stamp_s, now_ns(), values, info)
        self.transport.send(self.out_path, 0, data)
        return seq

    def send_message(self, msg: Message, tick: int) -> int:
        kind = Kind.SENSOR if self.role == "robot" else Kind.COMMAND
        return self._send(kind, tick, msg.stamp_s, values=msg.values)

    def send_control(self, kind: Kind, info: dict[str, Any], tick: int = 0, stamp_s: float = 0.0) -> int:
        return self._send(kind, tick, stamp_s, info=info)

    def delay_ms(self, pkt: Packet) -> float:
        """One-way delay of ``pkt`` from its stamps, on this side's clock."""
        sent_here = pkt.send_ns + self._from_sender * self.offset_ns
        return (pkt.recv_ns - sent_here) / 1e6

    def poll(self) -> tuple[list[Arrived], list[Packet]]:
        """Decode everything that has arrived: (data messages in order, control packets). Refused packets
        are counted in :attr:`rejected` by reason and dropped."""
        data: list[Arrived] = []
        control: list[Packet] = []
        for item in self.transport.inbox.take():
            if item.path != self.in_path:
                self.rejected["unexpected_kind"] += 1
                continue
            try:
                pkt = self._decode(item.data)
            except WireError as err:
                self.rejected[err.reason] += 1
                continue
            pkt.recv_ns = item.recv_ns
            if pkt.kind in DATA_KINDS:
                counts = self.data
                if pkt.seq <= counts.last_seq:
                    self.rejected["stale"] += 1
                    continue
                counts.lost += pkt.seq - counts.last_seq - 1
                counts.last_seq = pkt.seq
                counts.received += 1
                data.append(Arrived(Message(pkt.stamp_s, pkt.values), pkt.seq, pkt.tick, self.delay_ms(pkt),
                                    pkt.recv_ns))
            else:
                control.append(pkt)
        return data, control

    def _decode(self, raw: bytes) -> Packet:
        # before pairing only a HELLO (robot) or the answers to one (brain) may name a new run
        pkt = decode(raw, self.signer, None, self.expected)
        if pkt.kind not in self._accepts:
            raise WireError("unexpected_kind", pkt.kind.name)
        if self.run_id is not None and pkt.run_id != self.run_id:
            raise WireError("other_run")
        if pkt.kind in DATA_KINDS and self.run_id is None:
            raise WireError("other_run", "data before pairing")
        return pkt

    def counts(self) -> dict[str, Any]:
        return {"received": self.data.received, "lost": self.data.lost,
                "rejected": dict(sorted(self.rejected.items())), "rejected_total": sum(self.rejected.values())}


def values_equal(a: dict[str, np.ndarray], b: dict[str, np.ndarray]) -> bool:
    """Whether two signal sets are the same (names, sizes and values): for tests and checks."""
    return a.keys() == b.keys() and all(np.array_equal(a[k], b[k]) for k in a)
