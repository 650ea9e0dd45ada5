"""The spinal cord stage (thesis §4.3.2, Eq. 4.1-4.3) and the direct muscle commands, with known answers:
the rate neuron's step response, the Ia afferent's 30 ms delay, the stretch reflex and reciprocal inhibition."""

from __future__ import annotations

import math
from types import SimpleNamespace

import mujoco
import numpy as np
import pytest

from cerebx.loop.runner import run_experiment
from cerebx.plants.upper_limb import UpperLimb
from cerebx.schema.plant import MUSCLES_UPPER_LIMB, UpperLimbConfig
from cerebx.schema.spinal import DirectMusclesConfig, SpinalCordConfig
from cerebx.signals import Frame
from cerebx.stages.spinal import DirectMuscles, SpinalCord

M = {name: i for i, name in enumerate(MUSCLES_UPPER_LIMB)}


def sigma(x: float) -> float:
    return 1.0 / (1.0 + math.exp(-6.0 * (x - 0.5)))


@pytest.fixture(scope="module")
def arm():
    return UpperLimb(UpperLimbConfig())


def _cord(arm, **kw) -> SpinalCord:
    st = SpinalCord(SpinalCordConfig(**kw), SimpleNamespace(plant=arm))
    st.reset(np.random.default_rng(0))
    return st


def _tick(st, length, velocity, ag=(0.0, 0.0), at=(0.0, 0.0)) -> np.ndarray:
    sig = {"muscle.ag": np.asarray(ag, float), "muscle.at": np.asarray(at, float),
           "muscle.length": np.asarray(length, float), "muscle.velocity": np.asarray(velocity, float)}
    frame = Frame(0, 0.0, sig)
    st.step(frame)
    return frame.signals["muscle.activation"]


def _bounds(arm):
    return arm.sensor_signals()["muscle.length"].bounds()


def test_rate_neuron_step_response_time_constant_and_sigmoid(arm):
    lo, hi = _bounds(arm)
    # normalise 'range': shortest length, fastest shortening: Ia = 0; longest, fastest lengthening: Ia = 1
    st = _cord(arm, afferent_delay_ms=0.0, normalise="range", velocity_range_mm_per_s=100.0)
    v = 100.0
    assert np.allclose(st.afferent(lo, np.full(7, -v)), 0.0) and np.allclose(st.afferent(hi, np.full(7, v)), 1.0)
    mid = 0.5 * (lo + hi)
    assert np.allclose(st.afferent(mid, np.zeros(7)), 0.5)  # at rest in mid-range: half rate
    assert np.allclose(st.afferent(mid, np.full(7, 32.0)), 0.5 + 4.3 * 32**0.6 / (st.r_hi - st.r_lo))  # Eq. 4.3
    # normalise 'peak' (default): the rate over its value at the longest length and the velocity range
    peak = _cord(arm, afferent_delay_ms=0.0)
    vp = peak.cfg.velocity_range_mm_per_s
    assert np.allclose(peak.afferent(mid, np.zeros(7)), (2 * mid + 10) / (4.3 * vp**0.6 + 2 * hi + 10))
    assert np.allclose(peak.afferent(hi, np.full(7, 2 * vp)), 1.0)  # clipped at the range
    ins = []
    for _ in range(100):
        _tick(st, hi, np.full(7, v))
        ins.append(st.ia_in.copy())
    ins = np.array(ins)
    t = 0.002 * np.arange(1, 101)
    want = sigma(1.0) * (1 - np.exp(-t / 0.010))  # tau_m dr/dt = -r + sigma(1)
    assert np.allclose(ins[:, 0], want, atol=1e-12)
    assert np.isclose(ins[4, 0] / sigma(1.0), 1 - math.exp(-1))  # 63 % after one time constant (10 ms)
    assert np.isclose(ins[-1, 0], 1 / (1 + math.exp(-3)), atol=1e-4)  # sigma(1) = 0.9526
    # MN at steady state: sigma(w_exc (command + Ia) - w_inh * mean antagonist IN)
    st = _cord(arm, afferent_delay_ms=0.0, normalise="range", velocity_range_mm_per_s=100.0)
    for _ in range(200):
        mn = _tick(st, mid, np.zeros(7), ag=(1.0, 0.0))
    in_ss = sigma(0.5)  # every Ia IN driven by Ia = 0.5
    assert np.isclose(mn[M["deltoid"]], sigma(1.0 + 0.5 - 0.5 * in_ss), atol=1e-9)
    assert np.isclose(mn[M["biceps_long"]], sigma(0.5 + 0.5 - 0.5 * in_ss), atol=1e-9)  # mean of 1 and 0
    assert np.isclose(mn[M["brachialis"]], sigma(0.0 + 0.5 - 0.5 * in_ss), atol=1e-9)
    assert np.isclose(sigma(0.5), 0.5)


def test_ia_afferent_is_delayed_exactly_30_ms(arm):
    lo, hi = _bounds(arm)
    st = _cord(arm)
    assert st.delay_steps == 15
    seen = []
    for k in range(40):
        _tick(st, lo if k < 10 else hi, np.zeros(7))
        seen.append(st.ia[0])
    seen = np.array(seen)
    # the step at tick 10 (t = 20 ms) reaches the afferent at tick 25 (t = 50 ms): 15 ticks = 30 ms later
    assert np.all(seen[:25] == seen[0]) and np.all(seen[25:] == seen[25]) and seen[25] > seen[0] + 0.1


def _stretch(arm, st, qd_elbow: float, steps: int) -> np.ndarray:
    """Hold the passive arm still for 20 ms, then move it kinematically (elbow at qd_elbow rad/s from 1.2 rad),
    commands 0; the MN rates."""
    m, d = arm.model, arm.data
    arm.reset(np.array([0.3, 1.2]), np.random.default_rng(0))
    st.reset(np.random.default_rng(0))
    out = []
    for k in range(steps):
        moving = max(k - 10, 0)
        d.qpos[:] = (0.3, 1.2 + qd_elbow * 0.002 * moving)
        d.qvel[:] = (0.0, qd_elbow if k >= 10 else 0.0)
        mujoco.mj_forward(m, d)
        out.append(_tick(st, **{"length": 1000 * d.actuator_length, "velocity": 1000 * d.actuator_velocity}))
    return np.array(out)


def test_stretch_reflex_raises_own_mn_and_lowers_the_antagonists(arm):
    st = _cord(arm)
    still = _stretch(arm, st, 0.0, 100)
    stretched = _stretch(arm, st, -2.0, 100)  # elbow extending: elbow flexors stretched, extensors shorten
    flexor, extensor = M["brachialis"], M["triceps_medial"]
    # the stretch starts at tick 10; until the 30 ms afferent delay has passed nothing differs
    assert np.array_equal(stretched[:25], still[:25]) and not np.allclose(stretched[25], still[25])
    late = slice(40, 100)
    assert np.all(stretched[late, flexor] > still[late, flexor] + 0.02)  # stretch reflex: own MN up
    assert np.all(stretched[late, extensor] < still[late, extensor] - 0.005)  # antagonist MN down
    # reciprocal inhibition: the stretched flexor's Ia IN fires more (it inhibits the extensor's MN)
    _stretch(arm, st, 0.0, 100)
    in_still = st.ia_in[flexor]
    _stretch(arm, st, -2.0, 100)
    assert st.ia_in[flexor] > in_still + 0.01


def test_direct_commands_biarticular_take_the_mean(arm):
    st = DirectMuscles(DirectMusclesConfig(), SimpleNamespace(plant=arm))
    frame = Frame(0, 0.0, {"muscle.ag": np.array([1.0, 0.0]), "muscle.at": np.array([0.2, 0.6])})
    st.step(frame)
    u = frame.signals["muscle.activation"]
    assert np.allclose(u, [1.0, 0.5, 0.0, 0.0, 0.4, 0.6, 0.6])


def test_bad_muscle_maps_refused_with_one_line():
    from pydantic import ValidationError

    with pytest.raises(ValidationError, match="antagonists: unknown muscles biceps"):
        SpinalCordConfig(antagonists={**SpinalCordConfig().antagonists, "deltoid": ("biceps",)})
    with pytest.raises(ValidationError, match="afferent_delay_ms: 31.0 is not a whole number"):
        SpinalCordConfig(afferent_delay_ms=31.0)


@pytest.mark.parametrize("spinal", ["cord", "direct"])
def test_upper_limb_runs_in_the_loop(load, tmp_path, spinal):
    cfg = load(["+experiment=upper_limb_pd", "+task=vertical_circle_fast", f"spinal={spinal}", "trials=2"])
    s = run_experiment(cfg, tmp_path)
    assert s["status"] == "completed", s
    assert s["mae_per_trial"][-1] < 0.3


def test_a_restored_cord_goes_on_as_the_original(arm):
    """The stage pickles as its arrays (its kernel struct is made again on load): after a round trip in the middle
    of a stretch, both copies give the same activations bit for bit, and neither writes into the other."""
    import pickle

    lo, hi = _bounds(arm)
    st = _cord(arm)
    for t in range(10):
        _tick(st, lo + (hi - lo) * 0.05 * t, np.full(len(lo), 30.0), ag=(0.2, 0.0))
    again = pickle.loads(pickle.dumps(st))
    for t in range(30):
        length, velocity = lo + (hi - lo) * (0.5 + 0.01 * t), np.full(len(lo), 20.0 - t)
        np.testing.assert_array_equal(_tick(st, length, velocity, at=(0.1, 0.3)),
                                      _tick(again, length, velocity, at=(0.1, 0.3)))
    assert again.mn is not st.mn and np.array_equal(again.mn, st.mn)
