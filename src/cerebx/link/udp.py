"""The plain UDP transport: one datagram per packet, one socket per process.

Each process binds its own address (``link.robot``, ``link.brain``, ``link.relay``) and sends from it.
The relay tells the two paths apart by the sender's address (the robot's datagrams are ``r2c``, the
brain's ``c2r``); a datagram from any other address is dropped and counted. A reader thread stamps
each datagram with the monotonic clock as it is read and puts it into the inbox.
"""

from __future__ import annotations

import socket
import threading
import time
from typing import Any

from cerebx.link.schema import UdpLink, split_address
from cerebx.link.transport import RECEIVES, Arrival, Role, Transport

RECV_BYTES = 65_536


def _resolve(address: str) -> tuple[int, tuple]:
    host, port = split_address(address)
    family, _, _, _, sockaddr = socket.getaddrinfo(host, port, type=socket.SOCK_DGRAM)[0]
    return family, sockaddr[:2]


class UdpTransport(Transport):
    def __init__(self, cfg: UdpLink, role: Role, via_relay: bool):
        super().__init__(cfg, role, via_relay)
        family, self.local = _resolve(getattr(cfg, role))
        self.robot_addr = _resolve(cfg.robot)[1]
        self.brain_addr = _resolve(cfg.brain)[1]
        self.relay_addr = _resolve(cfg.relay)[1]
        self.sock = socket.socket(family, socket.SOCK_DGRAM)
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 22)
        try:
            self.sock.bind(self.local)
        except OSError as err:
            self.sock.close()
            raise OSError(f"udp cannot bind {getattr(cfg, role)} ({err.strerror})") from None
        self.foreign = 0  # datagrams from an address that is no side of this run (relay only)
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

    def _path_of(self, sender: tuple) -> tuple[str, int] | None:
        if self.role != "relay":
            return RECEIVES[self.role], self.receive_hop()
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
            except OSError:
                return  # closed
            if self._closed:
                return
            now = time.monotonic_ns()
            where = self._path_of(sender)
            if where is None:
                self.foreign += 1
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
