"""How the two sides of a wall-clock run find each other: config fingerprints, the session, the clock
offset and the start time.

1. The brain side sends HELLO (its config fingerprint, the run id it chose, a fresh nonce, what the
   robot side needs from its controller) until the robot side answers. A robot side whose fingerprint
   differs answers REFUSE (naming the HELLO's nonce) and both stop with one line (exit code 2) before
   writing anything.
2. The robot side answers WELCOME with a fresh nonce of its own and the HELLO's nonce. Both sides now
   derive the session key from the shared key and the two nonces (``auth.Signer.session``); every later
   packet is signed with it. The robot side answers every matching HELLO this way (each gets its own
   nonce) and takes as its brain side the first one that signs a packet with the session key: a HELLO
   recorded from another run and replayed gets a WELCOME, but whoever replayed it cannot sign anything
   that follows, and the real brain side's HELLO is answered all the same. A WELCOME or REFUSE that does
   not name the brain side's current nonce is refused (``unmatched``).
3. The brain side estimates the clock offset (shared clock, or bursts of PINGs; each PONG must answer a
   PING of the current burst, and an estimate whose uncertainty exceeds
   ``link.max_clock_uncertainty_ms`` is refused and recorded) and sends START.
4. The robot side answers START with the time of tick 0 on its clock, a moment ahead; both sides
   then pace their ticks from it. From pairing on, the robot and brain sides take packets only from the
   paired peer's address where the transport can tell (UDP: a connected socket).

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
from cerebx.link.auth import new_nonce
from cerebx.link.channel import LinkEnd
from cerebx.link.wire import Kind, Packet

NOT_PAIRED = {"init_from": True, "resume": True, "recording": {"progress": True},
              "link": {"robot": True, "brain": True, "relay": True, "spawn_robot": True, "drop_fraction": True,
                       "rt_priority": True, "beyond_loopback": True, "tls": True}}
"""Config keys the two sides may differ in."""

HELLO_EVERY_S = 0.1
START_LEAD_S = 0.25  # tick 0 is this far ahead of the robot's START answer


class NotPaired(CerebxError):
    """The two sides did not pair (no answer, no usable clock estimate, a port taken): the run does not start,
    and the brain side leaves nothing behind."""


class PairingRefused(NotPaired):
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
    """Robot side: the first HELLO of a brain side with the same fingerprint (REFUSE and raise otherwise); it
    is offered a session (:meth:`LinkEnd.offer`) but not answered yet."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if alive is not None and not alive():
            raise NotPaired("link: stopped while waiting for the brain side")
        end.transport.inbox.wait(0.05)
        _, control = end.poll()
        for pkt in control:
            if pkt.kind != Kind.HELLO:
                continue
            theirs = str(pkt.info.get("fingerprint"))
            if theirs != fp:
                for _ in range(3):
                    end.send_control(Kind.REFUSE, {"fingerprint": fp, "version": __version__,
                                                   "answers": pkt.info["nonce"].hex()}, run_id=pkt.run_id)
                    time.sleep(0.02)
                raise PairingRefused(_refused_line(fp, theirs, "brain"))
            end.offer(pkt)
            return pkt
    raise NotPaired(f"link: no brain side paired within {timeout_s:g} s")


def welcome(end: LinkEnd, hello_pkt: Packet, facts: dict[str, Any]) -> None:
    """Robot side: answer ``hello_pkt`` with the session offered for it (the same one when it repeats)."""
    cand = end.committed if end.committed is not None else end.offer(hello_pkt)
    if cand.brain_nonce != hello_pkt.info["nonce"]:
        end.reject("other_run")  # a HELLO of another brain side after pairing
        return
    end.send_control(Kind.WELCOME, {**facts, "nonce": cand.robot_nonce.hex(), "answers": cand.brain_nonce.hex()},
                     run_id=cand.run_id)


def hello(end: LinkEnd, fp: str, facts: dict[str, Any], timeout_s: float, alive: Any = None) -> Packet:
    """Brain side: HELLO until the WELCOME that answers it (returned; the session is then established) or a
    REFUSE of it (raised); ``alive()`` False stops waiting."""
    nonce = new_nonce()
    info = {"fingerprint": fp, "version": __version__, "nonce": nonce.hex(), "controller": facts,
            **clock.host_identity()}
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
            if pkt.kind not in (Kind.REFUSE, Kind.WELCOME):
                continue
            if pkt.info["answers"] != nonce or pkt.run_id != end.run_id:
                end.reject("unmatched")  # an answer to another HELLO (replayed, or of an earlier run)
                continue
            if pkt.kind == Kind.REFUSE:
                raise PairingRefused(_refused_line(fp, str(pkt.info.get("fingerprint")), "robot"))
            end.establish(end.signer.session(nonce, pkt.info["nonce"], end.run_id or bytes(16)))
            return pkt
    raise NotPaired(f"link: no robot side answered within {timeout_s:g} s")


def pong(end: LinkEnd, ping: Packet) -> None:
    """Robot side: answer a PING (its sequence number and arrival here, t2; t3 is this packet's send time)."""
    end.send_control(Kind.PONG, {"ping": ping.seq, "burst": ping.info["burst"], "t2": ping.recv_ns})
    if "offset_ns" in ping.info:
        end.offset_ns = ping.info["offset_ns"]


class Pings:
    """Brain side: bursts of PINGs and the answers that belong to the current one (t1 is this side's own record
    of when it sent the PING; a PONG of no PING in the burst, or of one answered already, is ``unmatched``)."""

    def __init__(self, end: LinkEnd):
        self.end = end
        self.burst = 0
        self.sent: dict[int, int] = {}
        self.probes: list[tuple[int, int, int, int]] = []

    def new_burst(self) -> None:
        self.burst += 1
        self.sent, self.probes = {}, []

    def send(self, n: int, offset_ns: int | None = None) -> None:
        info: dict[str, Any] = {"n": n, "burst": self.burst}
        if offset_ns is not None:
            info["offset_ns"] = offset_ns
        seq = self.end.send_control(Kind.PING, info)
        self.sent[seq] = self.end.last_send_ns

    def answer(self, pkt: Packet) -> bool:
        t1 = self.sent.pop(pkt.info["ping"], None) if pkt.info["burst"] == self.burst else None
        if t1 is None:
            self.end.reject("unmatched")
            return False
        self.probes.append((t1, pkt.info["t2"], pkt.send_ns, pkt.recv_ns))
        return True


def within(est: clock.OffsetEstimate, max_uncertainty_ms: float) -> bool:
    return est.uncertainty_ns <= max_uncertainty_ms * 1e6
