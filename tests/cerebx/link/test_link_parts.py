"""The pieces of a wall-clock run, each alone: the watchdog's levels, the clock-offset estimate, pairing
fingerprints, the relay's holding, the merge of the two logs, the delay trace, the configuration rules."""

from __future__ import annotations

import time

import numpy as np
import pytest

from cerebx.build import build_components
from cerebx.errors import ConfigError
from cerebx.link import clock
from cerebx.link.auth import Signer
from cerebx.link.pairing import fingerprint
from cerebx.link.relay import Relay
from cerebx.link.schema import SheddingConfig
from cerebx.link.shedding import Watchdog, shed_targets
from cerebx.link.trace import _fill
from cerebx.link.transport import Inbox
from cerebx.link.wire import Kind, encode
from cerebx.recording.pair import merge

PD_WALL = ["+task=circle", "controller=pd", "link=udp", "clock=wall"]


class Target:
    pathway_delay_ms = 50.0

    def __init__(self):
        self.levels = []

    def shed(self, level):
        self.levels.append(level)


def test_watchdog_sheds_at_the_original_thresholds_and_recovers():
    t = Target()
    w = Watchdog(SheddingConfig(), [t])
    assert w.max_lead_ms == pytest.approx(45.0)  # 0.9 x the pathway delay
    assert w.update(1.0, 0.0) is None  # keeping up: the whole lead
    lag_for = {r: 45.0 * (1 - r) for r in (0.29, 0.09, 0.04)}
    assert w.update(lag_for[0.29], 0.002).name == "plasticity_off"
    assert w.update(lag_for[0.09], 0.004).name == "spikes_off"
    assert w.update(lag_for[0.04], 0.006).name == "all_off"
    assert w.update(0.5, 0.008) is None  # caught up, but a level is left only after recover_ms
    assert w.update(0.5, 0.050) is None
    change = w.update(0.5, 0.110)
    assert change.level == 0 and t.levels == [1, 2, 3, 0]
    assert [c.t_s for c in w.changes] == [0.002, 0.004, 0.006, 0.110]
    assert w.max_level == 3


def test_watchdog_has_nothing_to_shed_without_targets():
    w = Watchdog(SheddingConfig(), [])
    assert not w.active and w.update(1e6, 1.0) is None


def test_snn_controller_is_a_shedding_target(load):
    ctx = build_components(load(["+experiment=small_snn", "+task=circle", "trials=1"]))
    (target,) = shed_targets(ctx.brain)
    net = target.net
    target.shed(1)
    assert net.learn is False
    target.shed(2)
    t_sub = net.t_sub
    out = target._simulate([np.zeros(0, np.int32)] * 3, 0)
    assert net.t_sub == t_sub + 3 * net.n_sub and out.out.shape[0] == 3 and not out.out.any()
    assert not out.counts.any() and out.spikes is None
    target.shed(0)
    assert net.learn is True
    assert shed_targets(build_components(load(["+task=circle", "controller=pd", "trials=1"])).brain) == []


def test_clock_offset_from_the_fastest_probe():
    # robot clock = brain clock + 5 ms; one-way 0.1 ms each way on the fastest probe, slower ones skewed
    off = 5_000_000
    probes = [(t1, t1 + 100_000 + off, t1 + 150_000 + off, t1 + 250_000) for t1 in (0, 10_000_000)]
    probes.append((20_000_000, 20_000_000 + 3_000_000 + off, 20_000_000 + 3_100_000 + off, 20_000_000 + 3_200_000))
    est = clock.estimate(probes, 0)
    assert est.offset_ns == off and est.uncertainty_ns == 100_001 and est.method == "ping"
    assert clock.estimate([], 0) is None
    assert clock.shared(1).offset_ns == 0


def test_pace_never_wakes_early():
    for _ in range(5):
        deadline = clock.now_ns() + 3_000_000
        woke = clock.pace(deadline, 300_000)
        assert woke >= deadline


def test_fingerprint_covers_what_both_sides_compute_from(load):
    base = fingerprint(load(PD_WALL))
    assert fingerprint(load(PD_WALL + ["link.robot=10.0.0.1:7447", "link.spawn_robot=false",
                                       "link.beyond_loopback=true", "recording.progress=off",
                                       "link.rt_priority=50"])) == base
    assert fingerprint(load(PD_WALL + ["trials=11"])) != base
    assert fingerprint(load(PD_WALL + ["delay=gamma45"])) != base


def test_link_and_clock_rules(load):
    with pytest.raises(ConfigError, match="add clock=wall"):
        load(["+task=circle", "controller=pd", "link=zenoh"])
    with pytest.raises(ConfigError, match="needs a real link"):
        load(["+task=circle", "controller=pd", "clock=wall"])
    with pytest.raises(ConfigError, match="host:port"):
        load(PD_WALL + ["link.robot=nowhere"])
    cfg = load(PD_WALL)
    assert cfg.link.robot.startswith("127.0.0.1:") and cfg.link.brain.startswith("127.0.0.1:")
    assert load(["+task=circle", "controller=pd"]).link.kind == "sim"


class FakeTransport:
    def __init__(self):
        self.inbox = Inbox()
        self.sent = []

    def send(self, path, hop, data):
        self.sent.append((time.monotonic_ns(), path, hop, data))


def test_relay_holds_data_in_order_and_passes_the_rest(load):
    cfg = load(PD_WALL + ["delay=constant", "delay.total_ms=20"])
    t = FakeTransport()
    relay = Relay(cfg, t)
    key = Signer(b"k" * 32)
    now = time.monotonic_ns()
    sensors = [encode(key, Kind.SENSOR, bytes(16), s, s, 0.0, 0, {"joint.q": np.zeros(6)}) for s in range(3)]
    for s, data in enumerate(sensors):
        relay._arrive("r2c", data, now + s * 1_000_000)
    relay._arrive("c2r", encode(key, Kind.PING, bytes(16), 0, 0, 0.0, 0, info={}), now)
    assert [x[1:3] for x in t.sent] == [("c2r", 1)]  # control passes at once
    while relay.queues["r2c"]:
        relay._release_due()
    out = [x for x in t.sent if x[1] == "r2c"]
    assert [x[3] for x in out] == sensors and all(x[2] == 1 for x in out)
    held = [(x[0] - (now + i * 1_000_000)) / 1e6 for i, x in enumerate(out)]
    assert all(10.0 <= h < 200.0 for h in held), held  # 10 ms per path (total 20 split evenly), never less
    assert relay.summary()["r2c"]["drawn_ms"]["mean"] == 10.0


def test_relay_drops_the_fraction_it_is_told(load):
    cfg = load(PD_WALL + ["delay=constant", "delay.total_ms=0", "link.drop_fraction=0.05"])
    relay = Relay(cfg, FakeTransport())
    data = encode(Signer(b"k" * 32), Kind.COMMAND, bytes(16), 0, 0, 0.0, 0, {"joint.torque": np.zeros(6)})
    for _ in range(4000):
        relay._arrive("c2r", data, time.monotonic_ns())
    assert 0.035 < relay.counts["c2r"]["dropped"] / 4000 < 0.065


def test_merge_joins_each_ticks_control_messages():
    brain = [("/control", 0, {"t": 0.0, "tau_controller": [1]}), ("/timing/brain", 0, {"lag_ms": 1}),
             ("/control", 2, {"t": 0.002, "tau_controller": [2]})]
    robot = [("/joint_states/actual", 0, {}), ("/control", 0, {"t": 0.0, "error": [0.1]}),
             ("/control", 2, {"t": 0.002, "error": [0.2]}), ("/control", 4, {"t": 0.004, "error": [0.3]})]
    out = list(merge(iter(brain), iter(robot)))
    controls = [(t, m) for topic, t, m in out if topic == "/control"]
    assert controls == [(0, {"t": 0.0, "error": [0.1], "tau_controller": [1]}),
                        (2, {"t": 0.002, "error": [0.2], "tau_controller": [2]}), (4, {"t": 0.004, "error": [0.3]})]
    assert [t for _, t, _ in out] == sorted(t for _, t, _ in out)
    assert len(out) == 5


def test_trace_fill_takes_the_previous_delay():
    filled, missing = _fill(np.array([np.nan, 4.0, np.nan, 6.0]), 6)
    assert filled.tolist() == [4.0, 4.0, 4.0, 6.0, 6.0, 6.0] and missing == 2
