"""Robot-side stages: the receivers (torque filters) and the watchdog supervisor, against hand-computed values."""

from __future__ import annotations

import numpy as np
import pytest

from cerebx.schema.stages import FuturePastFilterConfig, SupervisorConfig
from cerebx.signals import Frame, Message, Signal
from cerebx.stages.receivers import FuturePastFilter, MeanFilter
from cerebx.stages.supervisor import Supervisor

TAU = (Signal("joint.torque", 1, "N·m"),)


def _msg(stamp: float, v: float) -> Message:
    return Message(stamp, {"joint.torque": np.array([v])})


def test_mean_filter_is_15_tap_average():
    f = MeanFilter(TAU, 15)
    outs = [f.receive([_msg(0.0, float(v))], 0.0)["joint.torque"][0] for v in range(1, 31)]
    assert outs[0] == 1.0
    assert outs[14] == pytest.approx(np.mean(range(1, 16)))
    assert outs[29] == pytest.approx(np.mean(range(16, 31)))


def test_mean_filter_one_sample_a_tick_is_the_running_mean_bit_for_bit():
    """The compiled push-and-mean gives the doubles of the running sum as array operations (the sum recomputed
    exactly every 1000 samples), on ticks with one, several or no samples."""
    rng = np.random.default_rng(5)
    sig = (Signal("joint.torque", 6),)
    fast, taps = MeanFilter(sig, 15), 15
    buf, total, count, want = np.zeros((taps, 6)), np.zeros(6), 0, np.zeros(6)
    for tick in range(2600):
        k = 1 if tick % 97 else int(rng.integers(0, 3))  # now and then none or two at once
        msgs = [Message(0.0, {"joint.torque": rng.normal(0.0, 30.0, 6)}) for _ in range(k)]
        got = fast.receive(msgs, 0.0)["joint.torque"]
        for m in msgs:  # the array form
            x = m.values["joint.torque"]
            total += x - buf[count % taps]
            buf[count % taps] = x
            count += 1
            if count % 1000 == 0:
                total = buf.sum(0)
            want = total / min(count, taps)
        assert got.tobytes() == want.tobytes(), tick


def test_future_past_filter_hand_computed():
    f = FuturePastFilter(TAU, FuturePastFilterConfig(past_samples=2, min_future_samples=2))
    dt = 0.002
    # samples stamped for ticks 0..5 with values 10, 20, ..., 60 all arrive at tick 0
    f.receive([_msg(i * dt, 10.0 * (i + 1)) for i in range(6)], 0.0)
    # at t = 2 dt: future = ticks 2..5 (30,40,50,60) -> F = min(4, 3) = 3 -> 30,40,50; past = 10,20 -> 2 newest
    out = f.receive([], 2 * dt)["joint.torque"]
    assert out[0] == pytest.approx(np.mean([30, 40, 50, 10, 20]))


def test_future_past_filter_decays_when_starved():
    f = FuturePastFilter(TAU, FuturePastFilterConfig(past_samples=10, min_future_samples=2, decay_per_step=0.998))
    f.receive([_msg(i * 0.002, 5.0) for i in range(4)], 0.0)
    first = f.receive([], 0.002)["joint.torque"][0]
    assert first == pytest.approx(5.0)
    outs = [f.receive([], (k + 2) * 0.002)["joint.torque"][0] for k in range(10)]
    # from tick 2 on, fewer than 3 future samples remain: each step multiplies by 0.998
    assert outs[-1] == pytest.approx(outs[-2] * 0.998)
    assert outs[0] == pytest.approx(5.0 * 0.998, rel=1e-12)
    assert outs[-1] == pytest.approx(5.0 * 0.998 ** 10, rel=1e-12)


def test_supervisor_acts_only_outside_and_ramps():
    sup = Supervisor(SupervisorConfig(kp=(20.0,), kd=(5.0,)), np.array([-1.0]), np.array([1.0]))

    def run(q: float, qd: float) -> float:
        frame = Frame(0, 0.0, {"joint.q": np.array([q]), "joint.qd": np.array([qd]), "joint.torque": np.array([1.0])})
        sup.step(frame)
        return frame.signals["joint.torque"][0] - 1.0  # the supervisor adds to the command

    assert run(0.5, 1.0) == 0.0
    assert run(1.1, 2.0) == pytest.approx(20 * (1.0 - 1.1) - 0.02 * 5 * 2.0)
    assert run(1.1, 2.0) == pytest.approx(20 * (1.0 - 1.1) - 0.04 * 5 * 2.0)
    assert sup.record()["tau_supervisor"][0] == pytest.approx(20 * (1.0 - 1.1) - 0.04 * 5 * 2.0)
    assert run(0.0, 2.0) == 0.0
    assert sup.s[0] == 0.0


def test_supervisor_correction_is_its_rule_on_every_tick():
    """The shortcut for a tick with every joint inside its bounds gives what the full rule gives."""
    cfg = SupervisorConfig(kp=(20.0, 10.0, 5.0), kd=(5.0, 2.0, 1.0), ramp_per_step=0.3)
    sup = Supervisor(cfg, np.array([-1.0, -0.5, 0.0]), np.array([1.0, 0.5, 2.0]))
    rng = np.random.default_rng(1)
    s = np.zeros(3)
    for _ in range(300):
        q, qd = rng.normal(0.3, 0.9, 3), rng.normal(0.0, 1.0, 3)
        below, above = q < sup.lo, q > sup.hi
        outside = below | above
        s = np.where(outside, np.minimum(s + sup.ramp, 1.0), 0.0)
        want = np.where(outside, sup.kp * (np.where(below, sup.lo, sup.hi) - q) - s * sup.kd * qd, 0.0)
        got = sup.correction(q, qd)
        assert got.tobytes() == want.tobytes() and sup.s.tobytes() == s.tobytes()


def test_mean_filter_running_sum_is_the_array_rule_bit_for_bit():
    """The compiled push against ``sum += x - buf[i]; buf[i] = x`` and the exact re-sum every 1000 samples."""
    f = MeanFilter((Signal("joint.torque", 3),), 15)
    rng = np.random.default_rng(2)
    buf, total = np.zeros((15, 3)), np.zeros(3)
    for k in range(2500):
        x = rng.normal(0.0, 10.0 ** rng.integers(-3, 3), 3)
        total += x - buf[k % 15]
        buf[k % 15] = x
        if (k + 1) % 1000 == 0:
            total = buf.sum(0)
        got = f.receive([Message(k * 0.002, {"joint.torque": x})], k * 0.002)["joint.torque"]
        assert got.tobytes() == (total / min(k + 1, 15)).tobytes()
    with pytest.raises(ValueError, match="shape"):
        f.receive([Message(0.0, {"joint.torque": np.zeros(2)})], 0.0)
