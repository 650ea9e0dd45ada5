"""The zenoh transport: each process is a zenoh peer with explicit TCP endpoints and no scouting, so
nothing is sent to an address the configuration did not name.

Key expressions ``<namespace>/<path>/<hop>`` (e.g. ``cerebx/r2c/0``). The robot side listens on
``link.robot``; the relay listens on ``link.relay`` and connects to the robot; the brain side listens on
``link.brain`` and connects to the robot (and the relay). Publishers are express (no batching) with
real-time priority and a 16-slot queue; samples that arrive are handed to the inbox by zenoh's own threads
(which check them there, off the paced loop).

Any process that can reach an endpoint can join the session and read or publish samples: the packets'
tags keep what it publishes from being used, but without TLS it reads joint states and torques. With
``link.tls`` every endpoint is ``tls/host:port`` and zenoh's TLS encrypts the traffic; with
``link.tls.mutual`` (the default) a process without a certificate signed by ``root_ca_certificate``
cannot join at all.
"""

from __future__ import annotations

import json
import time
from typing import Any

import zenoh

from cerebx.errors import CerebxError
from cerebx.link.schema import ZenohLink, ZenohTls, split_address
from cerebx.link.transport import RECEIVES, SENDS, Arrival, Role, Transport, announce_bind, resolve


def _endpoint(address: str, proto: str = "tcp") -> str:
    host, port = split_address(address)
    return f"{proto}/[{host}]:{port}" if ":" in host else f"{proto}/{host}:{port}"


def tls_settings(tls: ZenohTls) -> dict[str, Any]:
    """zenoh's ``transport/link/tls`` settings for ``link.tls``."""
    return {"root_ca_certificate": tls.root_ca_certificate, "listen_certificate": tls.listen_certificate,
            "listen_private_key": tls.listen_private_key,
            "connect_certificate": tls.connect_certificate or tls.listen_certificate,
            "connect_private_key": tls.connect_private_key or tls.listen_private_key,
            "enable_mtls": tls.mutual, "verify_name_on_connect": tls.verify_name_on_connect}


class ZenohTransport(Transport):
    def __init__(self, cfg: ZenohLink, role: Role, via_relay: bool):
        super().__init__(cfg, role, via_relay)
        for address in (cfg.robot, cfg.brain, cfg.relay):
            resolve(address, kind=0)
        proto = "tls" if cfg.tls is not None else "tcp"
        listen = [_endpoint(getattr(cfg, role), proto)]
        connect = {"robot": [], "relay": [_endpoint(cfg.robot, proto)],
                   "brain": [_endpoint(cfg.robot, proto)] + ([_endpoint(cfg.relay, proto)] if via_relay else [])}[role]
        conf = zenoh.Config()
        conf.insert_json5("mode", '"peer"')
        conf.insert_json5("listen/endpoints", json.dumps(listen))
        conf.insert_json5("connect/endpoints", json.dumps(connect))
        conf.insert_json5("scouting/multicast/enabled", "false")
        conf.insert_json5("scouting/gossip/enabled", "false")
        # express packets are not batched, so each is one queue slot: 16 slots (zenoh's maximum; 2 by default)
        # ride out a send thread stalled for a few ticks instead of dropping after 1 ms
        conf.insert_json5("transport/link/tx/queue/size/real_time", "16")
        if cfg.tls is not None:
            for key, value in tls_settings(cfg.tls).items():
                conf.insert_json5(f"transport/link/tls/{key}", json.dumps(value))
        self._endpoints = {"listen": listen, "connect": connect}
        try:
            self.session = zenoh.open(conf)
        except zenoh.ZError as err:
            raise CerebxError(f"link: zenoh cannot listen on {listen[0]} ({str(err).splitlines()[0][:200]})") from None
        announce_bind(cfg, role)
        ns = cfg.namespace
        self._pubs: dict[tuple[str, int], Any] = {}
        if role == "relay":
            outgoing = [("r2c", 1), ("c2r", 1)]
            incoming = [("r2c", 0), ("c2r", 0)]
        else:
            outgoing = [(SENDS[role], 0)]
            incoming = [(RECEIVES[role], self.receive_hop())]
        for path, hop in outgoing:
            self._pubs[(path, hop)] = self.session.declare_publisher(
                f"{ns}/{path}/{hop}", express=True, congestion_control=zenoh.CongestionControl.DROP,
                priority=zenoh.Priority.REAL_TIME)
        self._subs = [self.session.declare_subscriber(f"{ns}/{path}/{hop}", self._on_sample(path, hop))
                      for path, hop in incoming]

    def _on_sample(self, path: str, hop: int):
        inbox = self.inbox

        def callback(sample: Any) -> None:
            inbox.put(Arrival(path, hop, sample.payload.to_bytes(), time.monotonic_ns()))

        return callback

    def send(self, path: str, hop: int, data: bytes) -> None:
        self._pubs[(path, hop)].put(data)

    def close(self) -> None:
        session, self.session = getattr(self, "session", None), None
        if session is not None:
            try:
                for sub in self._subs:
                    sub.undeclare()
                session.close()
            except zenoh.ZError:
                pass

    def describe(self) -> dict[str, Any]:
        return {"transport": "zenoh", **self._endpoints}
