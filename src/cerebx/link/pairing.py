"""How the two sides of a wall-clock run find each other: config fingerprints, the run id, the clock
offset and the start time.

1. The brain side sends HELLO (its config fingerprint, the run id it chose, what the robot side needs
   from its controller) until the robot side answers. A robot side whose fingerprint differs answers
   REFUSE and both stop with one line (exit code 2) before writing anything.
2. The robot side answers WELCOME (its host's boot id: the same one means one monotonic clock).
3. The brain side estimates the clock offset (shared clock, or a burst of PINGs) and sends START.
4. The robot side answers START with the time of tick 0 on its clock, a moment ahead; both sides
   then pace their ticks from it.

The fingerprint covers everything both sides compute from: all of the config except where each side
listens, whether the relay runs, and what only one side reads (``init_from``, ``resume``, progress
display).
"""

from __future__ import annotations

import hashlib
import json
import time
import uuid
from typing import Any

from cerebx import __version__
from cerebx.builders import BuildContext
from cerebx.errors import CerebxError
from cerebx.link import clock
from cerebx.link.channel import LinkEnd
from cerebx.link.wire import Kind, Packet

NOT_PAIRED = {"init_from": True, "resume": True, "recording": {"progress": True},
              "link": {"robot": True, "brain": True, "relay": True, "spawn_robot": True, "drop_fraction": True,
                       "rt_priority": True}}
"""Config keys the two sides may differ in."""

HELLO_EVERY_S = 0.1
START_LEAD_S = 0.25  # tick 0 is this far ahead of the robot's START answer


class PairingRefused(CerebxError):
    """The other side runs another configuration (or wire version): the run does not start."""


def fingerprint(cfg: Any) -> str:
    """A short hash of the config both sides must share."""
    data = cfg.model_dump(mode="json", exclude=NOT_PAIRED)
    return hashlib.sha256(json.dumps(data, sort_keys=True).encode()).hexdigest()[:16]


def new_run_id() -> bytes:
    return uuid.uuid4().bytes


def controller_facts(ctx: BuildContext) -> dict[str, Any]:
    """What the robot side needs from the brain side's controller: the position bounds its supervisor
    watches (the controller's encoder ranges), when the controller has them."""
    bounds = getattr(ctx.controller, "position_bounds", None)
    if not callable(bounds):
        return {}
    lo, hi = bounds()
    return {"position_bounds": [[float(x) for x in lo], [float(x) for x in hi]]}


class RemoteController:
    """The brain side's controller as the robot side knows it (for stage builders that ask it)."""

    def __init__(self, facts: dict[str, Any]):
        self._bounds = facts.get("position_bounds")
        if self._bounds is not None:
            self.position_bounds = self._position_bounds

    def _position_bounds(self) -> tuple[list[float], list[float]]:
        return self._bounds[0], self._bounds[1]


def _refused_line(mine: str, theirs: str, side: str) -> str:
    return (f"link: the {side} side runs another configuration (fingerprint {theirs}, this side {mine}); compose "
            "both sides from the same overrides")


def wait_for_hello(end: LinkEnd, fp: str, timeout_s: float, alive: Any = None) -> Packet:
    """Robot side: the first HELLO of a brain side with the same fingerprint (REFUSE and raise otherwise)."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if alive is not None and not alive():
            raise CerebxError("link: stopped while waiting for the brain side")
        end.transport.inbox.wait(0.05)
        _, control = end.poll()
        for pkt in control:
            if pkt.kind != Kind.HELLO:
                continue
            theirs = str(pkt.info.get("fingerprint"))
            if theirs != fp:
                end.run_id = pkt.run_id
                for _ in range(3):
                    end.send_control(Kind.REFUSE, {"fingerprint": fp, "version": __version__})
                    time.sleep(0.02)
                raise PairingRefused(_refused_line(fp, theirs, "brain"))
            end.run_id = pkt.run_id
            return pkt
    raise CerebxError(f"link: no brain side paired within {timeout_s:g} s")


def hello(end: LinkEnd, fp: str, facts: dict[str, Any], timeout_s: float, alive: Any = None) -> Packet:
    """Brain side: HELLO until WELCOME (returned) or REFUSE (raised); ``alive()`` False stops waiting."""
    info = {"fingerprint": fp, "version": __version__, "controller": facts, **clock.host_identity()}
    deadline = time.monotonic() + timeout_s
    next_hello = 0.0
    while time.monotonic() < deadline:
        if alive is not None and not alive():
            break
        if time.monotonic() >= next_hello:
            end.send_control(Kind.HELLO, info)
            next_hello = time.monotonic() + HELLO_EVERY_S
        end.transport.inbox.wait(0.02)
        _, control = end.poll()
        for pkt in control:
            if pkt.kind == Kind.REFUSE:
                raise PairingRefused(_refused_line(fp, str(pkt.info.get("fingerprint")), "robot"))
            if pkt.kind == Kind.WELCOME:
                return pkt
    raise CerebxError(f"link: no robot side answered within {timeout_s:g} s")


def pong(end: LinkEnd, ping: Packet) -> None:
    """Robot side: answer a PING (t1 = its send time, t2 = its arrival here; t3 is this packet's send time)."""
    end.send_control(Kind.PONG, {"t1": ping.send_ns, "t2": ping.recv_ns, "n": ping.info.get("n", 0)})
    if "offset_ns" in ping.info:
        end.offset_ns = int(ping.info["offset_ns"])


def probe(pong_pkt: Packet) -> tuple[int, int, int, int]:
    """Brain side: the four times of one answered PING."""
    return int(pong_pkt.info["t1"]), int(pong_pkt.info["t2"]), pong_pkt.send_ns, pong_pkt.recv_ns
