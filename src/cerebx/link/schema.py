"""Configuration of the link (``link=``): which transport, where each side listens, and how the two
sides of a wall-clock run keep time (pacing, how long each waits, when the safe stop starts, load
shedding).

``link=sim`` (the default) is the tick-grid link of one simulated-time process. ``link=zenoh`` and
``link=udp`` split the experiment into the brain side (``cerebx run``) and the robot side
(``cerebx robot``, started by ``cerebx run`` itself unless ``link.spawn_robot=false``); they need
``clock=wall``. Addresses are ``host:port``; port 0 lets ``cerebx run`` pick a free port when it
starts the other processes itself. Every address defaults to the loopback interface: an address beyond
it needs ``link.beyond_loopback=true`` (and each side that listens there says so in a warning line).
"""

from __future__ import annotations

import ipaddress
import math
import re
from typing import Annotated, Any, ClassVar, Literal

from pydantic import AfterValidator, Field, model_validator

from cerebx.schema.base import Strict

_ADDRESS = re.compile(r"^(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9.\-]+):(\d{1,5})$")


def _address(value: str) -> str:
    m = _ADDRESS.match(value)
    if not m or int(m.group(2)) > 65535:
        raise ValueError(f"{value!r} is not host:port (e.g. 127.0.0.1:7447)")
    return value


Address = Annotated[str, AfterValidator(_address)]


def split_address(value: str) -> tuple[str, int]:
    host, _, port = value.rpartition(":")
    return host.strip("[]"), int(port)


def is_loopback(host: str) -> bool:
    """Whether ``host`` is this machine's loopback interface (a host name other than localhost may be anything)."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def _finite(model: Any, where: str = "") -> None:
    """Every float of ``model`` (and its sub-models) is finite: ``inf`` is not a time limit."""
    for name in type(model).model_fields:
        v = getattr(model, name)
        if isinstance(v, float) and not math.isfinite(v):
            raise ValueError(f"{where}{name}: {v} is not a finite number")
        if isinstance(v, Strict):
            _finite(v, f"{where}{name}.")


class SheddingConfig(Strict):
    """The brain side's watchdog, after the original's real-time restriction: its lead is the maximum lead
    (``max_lead_fraction`` x the controller's pathway delay) less how late it finished its newest tick; as the
    lead shrinks below each fraction of the maximum, one more kind of work is shed."""

    enabled: bool = True
    max_lead_fraction: float = Field(0.9, gt=0, le=1, description="maximum lead as a fraction of the pathway delay")
    plasticity_off_below: float = Field(0.30, gt=0, lt=1, description="lead / maximum below which learning stops")
    spikes_off_below: float = Field(0.10, gt=0, lt=1, description="below which spikes are no longer propagated")
    all_off_below: float = Field(0.05, ge=0, lt=1, description="below which every non-essential event stops "
                                                               "(spike recording, weight summaries)")
    recover_ms: float = Field(100.0, ge=0, description="a level is left only after the lead stayed above its "
                                                       "threshold this long")

    @model_validator(mode="after")
    def _ordered(self) -> SheddingConfig:
        if not self.plasticity_off_below > self.spikes_off_below > self.all_off_below:
            raise ValueError("thresholds must fall: plasticity_off_below > spikes_off_below > all_off_below")
        return self


class SimLink(Strict):
    """The link simulated on the tick grid, in the one process of a simulated-time run."""

    real: ClassVar[bool] = False
    kind: Literal["sim"] = "sim"


class RealLink(Strict):
    """Base of the transports that cross processes and hosts."""

    real: ClassVar[bool] = True
    robot: Address = Field("127.0.0.1:0", description="where the robot side listens (the brain side sends there)")
    brain: Address = Field("127.0.0.1:0", description="where the brain side listens")
    relay: Address = Field("127.0.0.1:0", description="where the delay relay listens (when there is one)")
    spawn_robot: bool = Field(True, description="cerebx run starts the robot side on this machine; false: it pairs "
                                                "with one started by `cerebx robot`")
    use_relay: Literal["auto", "on", "off"] = Field(
        "auto", description="a relay process on the path holds each data packet for a delay drawn from the delay "
        "model (auto: when delay is not none or drop_fraction > 0)")
    drop_fraction: float = Field(0.0, ge=0, lt=1, description="fault injection: the relay drops this fraction of "
                                                              "data packets (seeded)")
    # wall-clock pacing and safe failure
    rt_priority: int = Field(0, ge=0, le=99, description="SCHED_FIFO priority of each side's process (0: normal "
                                                         "scheduling; needs root or CAP_SYS_NICE)")
    compression: Literal["lz4", "zstd", "none"] = Field(
        "lz4", description="chunk compression of each side's log in a wall-clock run (replaces recording."
        "compression): zstd takes about 1 ms per 256 kB chunk on the loop's thread, lz4 a tenth of that")
    spin_us: float = Field(300.0, ge=0, le=2000, description="pacing: sleep until this long before a tick, then "
                                                             "spin to it")
    command_wait_ms: float = Field(1.2, ge=0, lt=2, description="the robot waits this long after a tick starts for "
                                                                "the command the brain computes for that tick")
    brain_wait_ms: float = Field(0.6, ge=0, lt=2, description="the brain computes a tick when its sensor message "
                                                              "arrives, or this long after the tick starts")
    safe_stop_after_ms: float = Field(
        20.0, ge=0, description="robot: without a new command for this long, the previous command decays (the "
        "original's safe stop; a receiver with its own, as future_past, decides itself)")
    safe_stop_decay_per_step: float = Field(0.998, gt=0, le=1)
    hold_pose_after_ms: float = Field(500.0, gt=0, description="robot: without any command for this long, the "
                                                               "supervisor holds the current pose")
    sensor_timeout_ms: float = Field(100.0, gt=0, description="brain: without a sensor message for this long it "
                                                              "holds the last one and says so")
    link_lost_after_ms: float = Field(2000.0, gt=0, description="either side: nothing from the other for this long "
                                                                "ends the run (interrupted, link lost)")
    pair_timeout_s: float = Field(60.0, gt=0, description="how long a side waits for the other at the start")
    clock_sync: Literal["auto", "shared", "ping"] = Field(
        "auto", description="shared: one monotonic clock (same host); ping: offset estimated by a ping exchange; "
        "auto: shared when both sides run on the same host")
    resync_every_s: float = Field(1.0, gt=0, description="re-estimate the clock offset this often (ping)")
    pings: int = Field(16, ge=1, le=256, description="probes per offset estimate (the fastest round trip wins)")
    shedding: SheddingConfig = SheddingConfig()
    max_clock_uncertainty_ms: float = Field(
        2.0, gt=0, description="a clock-offset estimate whose uncertainty (half the fastest ping's round trip) "
        "exceeds this is refused and recorded; at pairing the run does not start without one within it")
    beyond_loopback: bool = Field(False, description="allow addresses beyond the loopback interface (each side "
                                                     "that listens there says so); off: loopback only")

    added_without_effect: ClassVar[dict[str, Any]] = {"max_clock_uncertainty_ms": 2.0, "beyond_loopback": False}
    """Fields added since runs were recorded, with the value that does what those runs did (read by
    ``cerebx.schema.legacy.upgrade`` through :meth:`upgrade_recorded`)."""

    @classmethod
    def upgrade_recorded(cls, link: dict[str, Any]) -> None:
        """Fill a recorded link config in place with the fields added since; ``beyond_loopback`` with what that
        run needed (a run recorded beyond loopback did so without the opt-in asked for now)."""
        for key, value in cls.added_without_effect.items():
            if key == "beyond_loopback" and key not in link:
                value = any(isinstance(link.get(k), str) and ":" in link[k]
                            and not is_loopback(split_address(link[k])[0]) for k in ("robot", "brain", "relay"))
            link.setdefault(key, value)

    @model_validator(mode="after")
    def _order(self) -> RealLink:
        _finite(self)
        if not self.beyond_loopback:
            for name in ("robot", "brain", "relay"):
                host, _ = split_address(getattr(self, name))
                if not is_loopback(host):
                    raise ValueError(f"{name}: {host} is beyond the loopback interface (allowed with "
                                     "link.beyond_loopback=true, a side then listens where other machines reach it)")
        if self.hold_pose_after_ms <= self.safe_stop_after_ms:
            raise ValueError("hold_pose_after_ms must be longer than safe_stop_after_ms")
        if self.link_lost_after_ms <= self.hold_pose_after_ms:
            raise ValueError("link_lost_after_ms must be longer than hold_pose_after_ms")
        return self

    def relay_on(self, delay_kind: str) -> bool:
        if self.use_relay == "auto":
            return delay_kind != "none" or self.drop_fraction > 0
        return self.use_relay == "on"


class ZenohTls(Strict):
    """zenoh's own TLS on the link's endpoints (``tls/host:port`` instead of ``tcp/``): the traffic is
    encrypted, and with ``mutual`` each side proves itself with a certificate. Paths to PEM files."""

    root_ca_certificate: str = Field(description="the CA that signed the other sides' certificates")
    listen_certificate: str = Field(description="this side's certificate, presented to those that connect")
    listen_private_key: str = Field(description="its private key")
    mutual: bool = Field(True, description="mTLS: a side that connects presents its certificate too")
    connect_certificate: str | None = Field(None, description="the certificate presented when connecting "
                                                              "(default: listen_certificate)")
    connect_private_key: str | None = Field(None, description="its key (default: listen_private_key)")
    verify_name_on_connect: bool = Field(True, description="the certificate must name the host connected to")


class ZenohLink(RealLink):
    """eclipse-zenoh peers joined by explicit TCP endpoints (no multicast scouting), optionally TLS."""

    kind: Literal["zenoh"] = "zenoh"
    added_without_effect: ClassVar[dict[str, Any]] = {**RealLink.added_without_effect, "tls": None}
    namespace: str = Field("cerebx", pattern=r"^[A-Za-z0-9_\-]+$", description="first part of the key expressions")
    tls: ZenohTls | None = Field(None, description="zenoh's TLS (mTLS by default) on every endpoint; None: TCP")


class UdpLink(RealLink):
    """One UDP datagram per packet."""

    kind: Literal["udp"] = "udp"


__all__ = ["Address", "RealLink", "SheddingConfig", "SimLink", "UdpLink", "ZenohLink",
           "ZenohTls", "is_loopback", "split_address"]
