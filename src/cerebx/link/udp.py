"""The plain UDP transport: one datagram per packet, one socket per process.

Each process binds its own address (``link.robot``, ``link.brain``, ``link.relay``) and sends from it.
A datagram from any address but the configured peer's (the relay's, when there is one) is dropped and
counted (``foreign``); the relay tells the two paths apart by the sender's address (the robot's
datagrams are ``r2c``, the brain's ``c2r``). After pairing the robot and brain sides connect their
socket to the peer (:meth:`UdpTransport.lock_to_peer`), so the kernel drops every other sender's
datagrams before they cost the process anything. A reader thread stamps each datagram with the
monotonic clock as it is read and hands it to the inbox (which checks it on that thread).

UDP authenticates (every packet carries a tag) but does not encrypt: joint states and torques can be
read by anyone who sees the traffic. Use zenoh with TLS (``link.tls``) where that matters.
"""

from __future__ import annotations

import socket
import threading
import time
from typing import Any

from cerebx.errors import CerebxError
from cerebx.link.schema import UdpLink
from cerebx.link.transport import RECEIVES, Arrival, Role, Transport, announce_bind, resolve

RECV_BYTES = 65_536


class UdpTransport(Transport):
    def __init__(self, cfg: UdpLink, role: Role, via_relay: bool):
        super().__init__(cfg, role, via_relay)
        family, self.local = resolve(getattr(cfg, role))
        self.robot_addr = resolve(cfg.robot)[1]
        self.brain_addr = resolve(cfg.brain)[1]
        self.relay_addr = resolve(cfg.relay)[1]
        self.peer = None if role == "relay" else (
            self.relay_addr if via_relay else (self.brain_addr if role == "robot" else self.robot_addr))
        self.sock = socket.socket(family, socket.SOCK_DGRAM)
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 22)
        try:
            self.sock.bind(self.local)
        except OSError as err:
            self.sock.close()
            raise CerebxError(f"link: udp cannot listen on {getattr(cfg, role)} ({err.strerror})") from None
        announce_bind(cfg, role)
        self._closed = False
        self._thread = threading.Thread(target=self._read, name=f"cerebx-udp-{role}", daemon=True)
        self._thread.start()

    def _destination(self, path: str, hop: int) -> tuple:
        if hop == 0 and self.via_relay:
            return self.relay_addr
        return self.brain_addr if path == "r2c" else self.robot_addr

    def send(self, path: str, hop: int, data: bytes) -> None:
        try:
            self.sock.sendto(data, self._destination(path, hop))
        except OSError:
            pass  # nobody listening (yet, or any more): a lost datagram, as on any network

    def lock_to_peer(self) -> None:
        if self.peer is not None and not self._closed:
            try:
                self.sock.connect(self.peer)
            except OSError:
                pass  # unconnected, the reader thread still drops other senders' datagrams

    def _path_of(self, sender: tuple) -> tuple[str, int] | None:
        if self.role != "relay":
            return (RECEIVES[self.role], self.receive_hop()) if sender[:2] == self.peer else None
        if sender[:2] == self.robot_addr:
            return "r2c", 0
        if sender[:2] == self.brain_addr:
            return "c2r", 0
        return None

    def _read(self) -> None:
        sock, inbox = self.sock, self.inbox
        while not self._closed:
            try:
                data, sender = sock.recvfrom(RECV_BYTES)
            except ConnectionRefusedError:
                continue  # the peer's port was closed when we sent (an ICMP answer on the connected socket)
            except OSError:
                return  # closed
            if self._closed:
                return
            now = time.monotonic_ns()
            where = self._path_of(sender)
            if where is None:
                inbox.dropped["foreign"] += 1
                continue
            inbox.put(Arrival(where[0], where[1], data, now))

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        try:
            self.sock.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass
        self.sock.close()
        self._thread.join(timeout=1.0)

    def describe(self) -> dict[str, Any]:
        return {"transport": "udp", "bound": list(self.local)}
