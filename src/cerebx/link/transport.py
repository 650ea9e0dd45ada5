"""The transport contract: bytes on the link's two paths, between the processes of one run.

``r2c`` runs from the robot side to the brain side, ``c2r`` back. Each path has one hop, or two when a
relay stands on it: hop 0 leaves the sender (to the relay, or straight to the receiver), hop 1 leaves
the relay. A transport kind (registered in the ``link`` group with its schema) implements
:meth:`Transport.send` for the hops its role sends on, and puts what arrives for its role into
:attr:`Transport.inbox`, stamped with the monotonic clock at arrival. The loop never sees the transport;
it sees the packets of ``channel.py``.

=======  ====================  ==========================
role     sends                 receives
=======  ====================  ==========================
robot    r2c hop 0             c2r (hop 1 with a relay)
brain    c2r hop 0             r2c (hop 1 with a relay)
relay    r2c hop 1, c2r hop 1  r2c hop 0, c2r hop 0
=======  ====================  ==========================
"""

from __future__ import annotations

import socket
import sys
import threading
import time
from abc import ABC, abstractmethod
from collections import Counter, deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Literal

from cerebx.errors import CerebxError
from cerebx.link.schema import RealLink, is_loopback, split_address

Role = Literal["robot", "brain", "relay"]
PATHS = ("r2c", "c2r")
SENDS = {"robot": "r2c", "brain": "c2r"}
RECEIVES = {"robot": "c2r", "brain": "r2c"}


@dataclass(frozen=True)
class Arrival:
    """Bytes that arrived on ``path`` (at hop ``hop``) at ``recv_ns`` on this host's monotonic clock."""

    path: str
    hop: int
    data: bytes
    recv_ns: int


INBOX_SLOTS = 256
"""Packets the inbox holds at most (about half a second of both paths' traffic); more are dropped."""


class Inbox:
    """What the transport's threads received, for the loop's thread to take (thread-safe, bounded).

    ``admit``, when set (a side's :class:`~cerebx.link.channel.LinkEnd` sets it), runs on the transport's
    thread for each arrival before it is queued: it checks and decodes the packet (the tag included) and
    returns what to queue, or None to drop it. So nothing unauthenticated reaches the paced loop and the
    loop's thread spends no time on it. A full inbox drops the newest arrival and counts it."""

    def __init__(self, slots: int = INBOX_SLOTS) -> None:
        self._items: deque[Any] = deque()
        self._cond = threading.Condition()
        self.slots = slots
        self.admit: Callable[[Arrival], Any] | None = None
        self.dropped: Counter = Counter()

    def put(self, item: Arrival) -> None:
        admit = self.admit
        got: Any = admit(item) if admit is not None else item
        if got is None:
            return
        with self._cond:
            if len(self._items) >= self.slots:
                self.dropped["queue_full"] += 1
                return
            self._items.append(got)
            self._cond.notify()

    def take(self, limit: int | None = None) -> list[Any]:
        """What has arrived (possibly nothing; at most ``limit`` items, oldest first), without waiting."""
        with self._cond:
            if limit is None or len(self._items) <= limit:
                out = list(self._items)
                self._items.clear()
            else:
                out = [self._items.popleft() for _ in range(limit)]
        return out

    def wait(self, timeout_s: float) -> bool:
        """Wait until something is there or ``timeout_s`` passed; whether something is there."""
        with self._cond:
            if self._items:
                return True
            if timeout_s > 0:
                self._cond.wait(timeout_s)
            return bool(self._items)


class Transport(ABC):
    """One process's end of the link."""

    def __init__(self, cfg: RealLink, role: Role, via_relay: bool):
        self.cfg, self.role, self.via_relay = cfg, role, via_relay
        self.inbox = Inbox()

    @abstractmethod
    def send(self, path: str, hop: int, data: bytes) -> None:
        """Send ``data`` on ``path`` from hop ``hop`` (0: from its sender, 1: from the relay)."""

    def close(self) -> None:
        """Release sockets and threads."""

    def describe(self) -> dict[str, Any]:
        """Where this end listens and sends, for the run's metadata."""
        return {}

    def receive_hop(self) -> int:
        """The hop this role's incoming path arrives on."""
        return 1 if self.via_relay else 0

    def lock_to_peer(self) -> None:
        """After pairing: from now on take packets only from the paired peer's address, where the transport
        can tell (UDP: the socket is connected to it, so the kernel drops every other sender's datagrams)."""

    def now_ns(self) -> int:
        return time.monotonic_ns()


def free_port(host: str, kind: int = socket.SOCK_STREAM) -> int:
    """A port the OS considers free on ``host`` now (for ``port 0`` addresses of processes this run starts)."""
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    with socket.socket(family, kind) as s:
        s.bind((host, 0))
        return s.getsockname()[1]


def resolve(address: str, kind: int = socket.SOCK_DGRAM) -> tuple[int, tuple]:
    """The address family and socket address of ``host:port``; one line when the host cannot be resolved."""
    host, port = split_address(address)
    try:
        family, _, _, _, sockaddr = socket.getaddrinfo(host, port, type=kind)[0]
    except (OSError, UnicodeError) as err:
        raise CerebxError(f"link: {address}: the host cannot be resolved "
                          f"({getattr(err, 'strerror', None) or err})") from None
    return family, sockaddr[:2]


def announce_bind(cfg: RealLink, role: Role) -> None:
    """The warning line of a side that listens beyond this machine (the schema already required the opt-in)."""
    address = getattr(cfg, role)
    host, _ = split_address(address)
    if is_loopback(host):
        return
    where = "on every interface" if host in ("0.0.0.0", "::") else "beyond this machine"
    print(f"warning: link: the {role} side listens {where} ({address}; link.beyond_loopback=true); only "
          "packets signed with the shared key are used", file=sys.stderr)


def with_free_ports(cfg: RealLink, udp: bool) -> RealLink:
    """``cfg`` with every ``host:0`` address given a free port (TCP for zenoh, UDP for udp)."""
    kind = socket.SOCK_DGRAM if udp else socket.SOCK_STREAM
    changes = {}
    for name in ("robot", "brain", "relay"):
        host, port = split_address(getattr(cfg, name))
        if port == 0:
            h = f"[{host}]" if ":" in host else host
            changes[name] = f"{h}:{free_port(host, kind)}"
    return cfg.model_copy(update=changes)


def build_sim(cfg: Any, *args: Any) -> None:
    """The ``sim`` link has no transport: its channels are the tick-grid ones of ``delay_channel.py``."""
    return None
