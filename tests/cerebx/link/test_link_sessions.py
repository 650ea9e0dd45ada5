"""The link under attack, in one process: two ends joined by an in-process pipe run the real handshake,
and a recorded session, replayed control packets and signed packets with hostile fields are refused,
counted and dropped, never raised. (The same attacks over real sockets and processes: test_link_attacks.py.)"""

from __future__ import annotations

import json
import math
import struct
import threading
import time
import types
import uuid

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cerebx.errors import PeerEnded
from cerebx.link import clock
from cerebx.link.auth import Signer
from cerebx.link.channel import SEQ_AHEAD, LinkEnd
from cerebx.link.pairing import NotPaired, Pings, hello, pong, wait_for_hello, within
from cerebx.link.transport import Arrival, Inbox
from cerebx.link.wire import HEADER, MAX_DEPTH, VERSION, Kind, WireError, encode, parse_json
from cerebx.loop.brain_side import BrainSide, sync_clock
from cerebx.loop.robot_side import RobotSide, pair
from cerebx.signals import Message

KEY = Signer(b"s" * 32)
FP = "0123456789abcdef"
SENSORS = {"joint.q": 2, "joint.qd": 2}
COMMANDS = {"joint.torque": 2}
FACTS = {"fingerprint": FP, "boot_id": "b", "host": "h"}


class PipeEnd:
    """One end of an in-process link: what it sends arrives in the peer's inbox (and is recorded)."""

    def __init__(self) -> None:
        self.inbox = Inbox()
        self.peer: PipeEnd | None = None
        self.sent: list[bytes] = []
        self.locked = False

    def send(self, path, hop, data):
        self.sent.append(data)
        if self.peer is not None:
            self.peer.inbox.put(Arrival(path, 0, data, time.monotonic_ns()))

    def lock_to_peer(self):
        self.locked = True


class SlowPipeEnd(PipeEnd):
    """Takes 6 ms to deliver what it sends (after its send time is stamped)."""

    def send(self, path, hop, data):
        time.sleep(0.006)
        super().send(path, hop, data)


def pipe(slow_b: bool = False) -> tuple[PipeEnd, PipeEnd]:
    a, b = PipeEnd(), (SlowPipeEnd() if slow_b else PipeEnd())
    a.peer, b.peer = b, a
    return a, b


def ends(brain_t: PipeEnd, robot_t: PipeEnd) -> tuple[LinkEnd, LinkEnd]:
    return (LinkEnd(brain_t, KEY, "brain", SENSORS, run_id=uuid.uuid4().bytes, max_tick=10_000),
            LinkEnd(robot_t, KEY, "robot", COMMANDS, max_tick=10_000))


def run_robot_pairing(robot: LinkEnd, out: dict) -> threading.Thread:
    def work():
        try:
            first = wait_for_hello(robot, FP, 5.0)
            pair(robot, first, FACTS, 5.0)
            out["paired"] = True
        except Exception as err:  # noqa: BLE001 - reported by the test
            out["error"] = err

    t = threading.Thread(target=work, daemon=True)
    t.start()
    return t


def paired() -> tuple[LinkEnd, LinkEnd, PipeEnd, PipeEnd]:
    """A brain end and a robot end that went through HELLO, WELCOME and START."""
    bt, rt = pipe()
    brain, robot = ends(bt, rt)
    out: dict = {}
    t = run_robot_pairing(robot, out)
    hello(brain, FP, {}, 5.0)
    brain.send_control(Kind.START, {"offset_ns": 0})
    t.join(10)
    assert out.get("paired"), out
    return brain, robot, bt, rt


def test_a_paired_session_has_its_own_key_and_locks_to_the_peer():
    brain, robot, bt, rt = paired()
    assert brain.session is not None and robot.session is not None
    assert brain.session.tag(b"x") == robot.session.tag(b"x") != KEY.tag(b"x")
    assert robot.run_id == brain.run_id and bt.locked and rt.locked
    brain.send_message(Message(0.002, {"joint.torque": np.ones(2)}), 1)
    data, _ = robot.poll()
    assert [a.tick for a in data] == [1]


def test_a_replayed_session_cannot_pair_with_a_fresh_robot_side_and_the_real_brain_does():
    brain1, robot1, bt1, _ = paired()
    for k in range(5):
        brain1.send_message(Message(k * 0.002, {"joint.torque": np.ones(2)}), k)
    recorded = list(bt1.sent)  # everything the first brain side sent: HELLOs, START, commands

    bt2, rt2 = pipe()
    brain2, robot2 = ends(bt2, rt2)
    for data in recorded:  # the replay reaches the fresh robot side before the real brain side starts
        rt2.inbox.put(Arrival("c2r", 0, data, time.monotonic_ns()))
    out: dict = {}
    t = run_robot_pairing(robot2, out)
    time.sleep(0.3)
    assert "paired" not in out  # the replayed HELLO was answered, but nothing after it could be signed
    hello(brain2, FP, {}, 5.0)
    brain2.send_control(Kind.START, {"offset_ns": 0})
    t.join(10)
    assert out.get("paired"), out
    assert robot2.run_id == brain2.run_id != brain1.run_id
    assert robot2.session.tag(b"x") == brain2.session.tag(b"x") != brain1.session.tag(b"x")
    assert robot2.rejected["unauthenticated"] >= 6  # the replayed START and 5 commands
    assert brain2.rejected["unmatched"] >= 1  # the WELCOME to the replayed HELLO reached the real brain side
    for data in recorded:  # again, now that the session holds
        rt2.inbox.put(Arrival("c2r", 0, data, time.monotonic_ns()))
    brain2.send_message(Message(0.0, {"joint.torque": np.ones(2)}), 0)
    data, _ = robot2.poll()
    assert len(data) == 1 and robot2.data.received == 1


def test_replayed_pings_and_pongs_change_no_offset():
    brain, robot, bt, rt = paired()
    pings = Pings(brain)
    pings.new_burst()
    for n in range(4):
        pings.send(3 - n, offset_ns=0)
    _, control = robot.poll()
    for p in control:
        pong(robot, p)
    _, control = brain.poll()
    assert [pings.answer(p) for p in control] == [True] * 4
    est = clock.estimate(pings.probes, clock.now_ns())
    assert abs(est.offset_ns) <= est.uncertainty_ns
    ping_bytes, pong_bytes = bt.sent[-4:], rt.sent[-4:]
    for _ in range(20):  # 80 replayed PINGs: no PONG answers them
        for data in ping_bytes:
            rt.inbox.put(Arrival("c2r", 0, data, time.monotonic_ns()))
    sent_before = len(rt.sent)
    _, control = robot.poll(limit=1000)
    assert control == [] and robot.rejected["replayed"] == 80 and len(rt.sent) == sent_before
    for data in pong_bytes:  # replayed PONGs: refused before the burst sees them
        bt.inbox.put(Arrival("r2c", 0, data, time.monotonic_ns()))
    _, control = brain.poll()
    assert control == [] and brain.rejected["replayed"] == 4
    robot.send_control(Kind.PONG, {"ping": 99, "burst": pings.burst, "t2": 5})  # a PONG of no PING sent
    robot.send_control(Kind.PONG, {"ping": 0, "burst": pings.burst - 1, "t2": 5})  # of an earlier burst
    _, control = brain.poll()
    assert [pings.answer(p) for p in control] == [False, False] and brain.rejected["unmatched"] == 2
    assert len(pings.probes) == 4 and clock.estimate(pings.probes, est.at_ns) == est


def test_a_clock_estimate_beyond_the_bound_is_refused(load):
    est = clock.estimate([(0, 5_000_000, 5_000_000, 10_000_000)], 0)  # 10 ms round trip: +-5 ms
    assert not within(est, 2.0) and within(est, 6.0)
    cfg = load(["+task=circle", "controller=pd", "link=udp", "clock=wall", "link.clock_sync=ping", "link.pings=2",
                "link.pair_timeout_s=5"])
    bt, rt = pipe(slow_b=True)
    brain, robot = ends(bt, rt)
    brain.session = robot.session = KEY
    robot.run_id = brain.run_id
    stop = threading.Event()

    def slow_robot():  # each PONG takes 6 ms to arrive: no estimate is within 2 ms
        while not stop.is_set():
            rt.inbox.wait(0.01)
            _, control = robot.poll()
            for p in control:
                pong(robot, p)

    t = threading.Thread(target=slow_robot, daemon=True)
    t.start()
    with pytest.raises(NotPaired, match="uncertain by .* after 3 ping bursts"):
        sync_clock(brain, cfg, types.SimpleNamespace(info={}))
    stop.set()
    t.join(2)


def test_sequence_numbers_far_ahead_are_refused_and_later_ones_still_count():
    brain, robot, bt, rt = paired()
    session = brain.session

    def command(seq, tick):
        return encode(session, Kind.COMMAND, brain.run_id, seq, tick, tick * 0.002, 1, {"joint.torque": np.ones(2)})

    for seq, tick in ((0, 0), (2**64 - 1, 1), (SEQ_AHEAD + 5, 2), (1, 3)):
        rt.inbox.put(Arrival("c2r", 0, command(seq, tick), 5))
    data, _ = robot.poll()
    assert [a.tick for a in data] == [0, 3] and robot.rejected["seq_window"] == 2 and robot.data.lost == 0
    rt.inbox.put(Arrival("c2r", 0, command(2, 10_001), 5))  # beyond the run's last tick
    assert robot.poll()[0] == [] and robot.rejected["bad_field"] == 1


def test_the_end_of_the_run_is_agreed():
    """A robot side that completed every trial ends the run as completed even before the brain's last tick."""
    side = types.SimpleNamespace(robot_bye=None, robot_done=False, cfg=types.SimpleNamespace(trials=3), trials={},
                                 pings=None)
    bye = types.SimpleNamespace(kind=Kind.BYE, info={"status": "completed", "trials_completed": 3})
    BrainSide._control(side, bye)
    assert side.robot_done
    BrainSide.wait_for_end(side, 0.0)  # returns at once
    early = types.SimpleNamespace(robot_bye=None, robot_done=False, cfg=types.SimpleNamespace(trials=3))
    with pytest.raises(PeerEnded):
        BrainSide._control(early, types.SimpleNamespace(kind=Kind.BYE, info={"status": "completed",
                                                                           "trials_completed": 2}))


# ---------------------------------------------------------------------- hostile fields, signed
HOSTILE_VALUES = st.one_of(
    st.none(), st.booleans(), st.integers(-2**70, 2**70), st.sampled_from([2**64 - 1, -1, 0, 10**30]),
    st.floats(allow_nan=False, allow_infinity=False), st.text(max_size=30), st.sampled_from(["x", "", "0" * 32]),
    st.lists(st.floats(-1e3, 1e3), max_size=8), st.dictionaries(st.text(max_size=5), st.integers(), max_size=3))
FIELD_NAMES = ["fingerprint", "nonce", "answers", "controller", "offset_ns", "t0_ns", "n", "burst", "ping", "t2",
               "trial", "mae", "mae_per_joint", "vel_mae", "torque_variability_Nm_per_ms", "ee_error_m", "label",
               "status", "reason", "trials_completed", "wall_seconds", "timing", "events", "ticks"]
RAW_BODIES = st.sampled_from([
    b'{"t2": 1e400, "ping": 0, "burst": 1}', b'{"offset_ns": "x", "n": 1, "burst": 1}', b'{"n": NaN, "burst": 1}',
    b'{"offset_ns": 1e400, "n": 0, "burst": 0}', b'{"t1": "x"}', b'{"trial": Infinity}', b"[1, 2]", b"nul",
    b'{"a": ' + b"[" * 20_000 + b"]" * 20_000 + b"}", b'{"ping": ' + b"9" * 5000 + b', "burst": 1, "t2": 1}',
    b'{"status": "completed", "trials_completed": 3, "events": ' + b"[" * 9 + b"]" * 9 + b"}",
    b'{"t0_ns": -5}', b'{"mae_per_joint": [1e308, -1], "trial": 0, "mae": 0, "vel_mae": 0, '
                      b'"torque_variability_Nm_per_ms": 0}'])


def hostile(kinds: list[Kind]) -> st.SearchStrategy:
    body = st.one_of(st.dictionaries(st.sampled_from(FIELD_NAMES), HOSTILE_VALUES, max_size=8).map(
        lambda d: json.dumps(d).encode()), RAW_BODIES)
    return st.tuples(st.sampled_from(kinds), body, st.integers(0, 2**64 - 1), st.integers(-2**63, 2**63 - 1),
                     st.floats(allow_nan=True, allow_infinity=True), st.integers(-2**63, 2**63 - 1))


def signed(signer: Signer, run_id: bytes, kind: Kind, body: bytes, seq: int, tick: int, stamp: float,
           send_ns: int) -> bytes:
    head = HEADER.pack(b"CBXL", VERSION, int(kind), 0, run_id, seq, tick, stamp, send_ns, len(body))
    return head + body + signer.tag(head + body)


HOSTILE = settings(max_examples=1000, derandomize=True, deadline=None, database=None,
                   suppress_health_check=list(HealthCheck))


def handled(fn, *args) -> None:
    """Call a side's handler: a PeerEnded (a BYE says the other side ended) is how a side ends, not a crash."""
    try:
        fn(*args)
    except PeerEnded:
        pass


def test_1000_hostile_signed_packets_to_the_robot_side_raise_nothing():
    brain, robot, bt, rt = paired()
    session, run_id = brain.session, brain.run_id
    side = types.SimpleNamespace(end=robot, t0=0, welcome_facts=FACTS)
    seen = {"n": 0}

    @HOSTILE
    @given(hostile([Kind.PING, Kind.START, Kind.BYE, Kind.COMMAND, Kind.HELLO]))
    def fire(packet):
        kind, body, seq, tick, stamp, send_ns = packet
        signer = KEY if kind == Kind.HELLO else session
        rt.inbox.put(Arrival("c2r", 0, signed(signer, run_id, kind, body, seq, tick, stamp, send_ns), 1))
        _, control = robot.poll()
        for pkt in control:
            handled(RobotSide._control, side, pkt)
        seen["n"] += 1

    fire()
    assert seen["n"] == 1000
    assert sum(robot.rejected.values()) > 500  # most are refused, each with its reason
    assert math.isfinite(robot.offset_ns) and abs(robot.offset_ns) <= 2**62


def test_1000_hostile_signed_packets_to_the_brain_side_raise_nothing():
    brain, robot, bt, rt = paired()
    session, run_id = brain.session, brain.run_id
    side = types.SimpleNamespace(robot_bye=None, robot_done=False, cfg=types.SimpleNamespace(trials=3), trials={},
                                 pings=Pings(brain))
    side.pings.new_burst()
    for n in range(4):
        side.pings.send(n)
    seen = {"n": 0}

    @HOSTILE
    @given(hostile([Kind.PONG, Kind.TRIAL, Kind.BYE, Kind.START, Kind.SENSOR, Kind.WELCOME, Kind.REFUSE]))
    def fire(packet):
        kind, body, seq, tick, stamp, send_ns = packet
        signer = KEY if kind in (Kind.WELCOME, Kind.REFUSE) else session
        bt.inbox.put(Arrival("r2c", 0, signed(signer, run_id, kind, body, seq, tick, stamp, send_ns), 1))
        _, control = brain.poll()
        for pkt in control:
            side.robot_bye = None
            handled(BrainSide._control, side, pkt)
        BrainSide.metrics(side)
        if side.pings.probes:
            clock.estimate(side.pings.probes, 0)
        seen["n"] += 1

    fire()
    assert seen["n"] == 1000 and sum(brain.rejected.values()) > 500


@pytest.mark.parametrize("body,reason", [(b"[" * 20_000 + b"]" * 20_000, "too_deep"),
                                         (b'{"x": 1e400}', "non_finite"), (b'{"x": NaN}', "non_finite"),
                                         (b'{"x": -Infinity}', "non_finite"), (b'{"x": ' + b"1" * 5000 + b"}",
                                                                                "malformed")])
def test_json_bodies_that_would_crash_a_parser_are_refused(body, reason):
    with pytest.raises(WireError) as err:
        parse_json(body)
    assert err.value.reason == reason
    assert parse_json(b'{"a": "[[[[[[[[[[[[[[[[", "b": ' + b"[" * (MAX_DEPTH - 1) + b"]" * (MAX_DEPTH - 1) + b"}")["a"]


def test_the_session_key_is_hkdf_of_the_key_and_both_nonces():
    a, b, run = bytes(16), bytes([1]) * 16, bytes([2]) * 16
    s = KEY.session(a, b, run)
    assert s.tag(b"x") != KEY.session(b, a, run).tag(b"x") != KEY.session(a, b, bytes(16)).tag(b"x")
    # RFC 5869: PRK = HMAC(salt, IKM), OKM(32) = HMAC(PRK, info || 0x01)
    import hashlib
    import hmac

    prk = hmac.new(a + b, b"s" * 32, hashlib.sha256).digest()
    okm = hmac.new(prk, b"cerebx link session v2" + run + b"\x01", hashlib.sha256).digest()
    assert s.tag(b"x") == Signer(okm).tag(b"x")
    assert struct.calcsize("<4sBBH16sQqdqI") == 60
