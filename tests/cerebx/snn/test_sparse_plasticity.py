"""Learning rules of sparse projections (docs/models.md#pair-stdp, #symmetric-cos) against hand-computed updates:
one pre and one post (or teaching) spike at a chosen Δt."""

from __future__ import annotations

import numpy as np
import pytest

from cerebx.snn.network import Network
from cerebx.snn.presets import DCN
from cerebx.snn.schema import NetworkConfig

W0 = 0.5
DT = 0.5


def pair_net(rule: dict, delay_ms: float, post_neuron: dict = DCN, teacher: bool = False) -> Network:
    """pre -> post (plastic, one synapse); drv -> post drives the post spike; with ``teacher`` a teaching input
    population tch -> post (the partner of symmetric_cos)."""
    pops = {"pre": {"size": 1, "neuron": {"kind": "input"}}, "drv": {"size": 1, "neuron": {"kind": "input"}},
            "tch": {"size": 1, "neuron": {"kind": "input"}}, "post": {"size": 1, "neuron": post_neuron}}
    one = {"kind": "one_to_one"}
    projections = {
        "syn": {"pre": "pre", "post": "post", "rule": one, "receptor": "ampa", "synapses": 1, "weight_nS": W0,
                "weight_range_nS": [0.0, 1.0], "delay_ms": delay_ms, "plasticity": rule},
        "drive": {"pre": "drv", "post": "post", "rule": one, "receptor": "ampa", "synapses": 1, "weight_nS": 5.0,
                  "delay_ms": 0.5},
    }
    if teacher:
        projections["tch_post"] = {"pre": "tch", "post": "post", "rule": one, "receptor": "gaba", "synapses": 1,
                                   "weight_nS": 0.0, "delay_ms": 1.0}
    cfg = NetworkConfig.model_validate({
        "name": "pair", "dt_ms": DT, "populations": pops, "projections": projections,
        "io": {"mossy": "pre", "climbing": "drv", "output": "post", "purkinje": ["post"], "granule": "post"}})
    return Network(cfg, parallel=False)


def run(net: Network, schedule: dict[int, list[str]], n_steps: int) -> list[int]:
    """Feeds input populations at the steps given; returns the post neuron's spike times (substeps)."""
    spikes = []
    post = net.index("post").start
    for k in range(n_steps):
        inputs = np.array([net.index(p).start for p in schedule.get(k, [])], dtype=np.int32)
        out = net.step(inputs)
        spikes += [4 * k + int(s) for i, s in zip(out.idx, out.sub, strict=True) if i == post]
    return spikes


def weight(net: Network) -> float:
    return float(net.sparse_weights("syn")[2][0])


def post_spike_time(rule: dict, drive_step: int, post_neuron: dict = DCN) -> int:
    spikes = run(pair_net(rule, 0.5, post_neuron), {drive_step: ["drv"]}, drive_step + 6)
    assert len(spikes) == 1, spikes
    return spikes[0]


def arrange(t_arrival: int) -> tuple[int, float]:
    """Input step and delay (ms) that make a pre spike arrive at substep t_arrival."""
    step = (t_arrival - 1) // 4
    return step, (t_arrival - 4 * step) * DT


STDP = {"kind": "pair_stdp", "lam": 0.01, "alpha": 1.0, "tau_plus_ms": 20.0, "tau_minus_ms": 20.0}


@pytest.mark.parametrize("mu", [0.0, 1.0])
@pytest.mark.parametrize("dt_ms", [10.0, -10.0])
def test_pair_stdp_one_pair_matches_nest_update(dt_ms, mu):
    """NEST stdp_synapse, W = 1: Δt > 0 w += λ (1 − w)^μ+ e^(−Δt/τ+); Δt < 0 w −= α λ w^μ− e^(−|Δt|/τ−)."""
    rule = dict(STDP, mu_plus=mu, mu_minus=mu)
    t_post = post_spike_time(rule, 10)
    t_arr = t_post - int(dt_ms / DT)
    step, delay = arrange(t_arr)
    net = pair_net(rule, delay)
    assert run(net, {10: ["drv"], step: ["pre"]}, 20) == [t_post]
    factor = (1 - W0) ** mu if dt_ms > 0 else -(W0**mu)
    assert weight(net) == pytest.approx(W0 + 0.01 * factor * np.exp(-abs(dt_ms) / 20.0), abs=1e-6)


def test_pair_stdp_traces_add_over_pairs():
    """Two pre arrivals 10 and 20 ms before one post spike (additive): λ (e^(−1/2) + e^(−1))."""
    rule = dict(STDP, mu_plus=0.0, mu_minus=0.0)
    t_post = post_spike_time(rule, 12)
    s1, d1 = arrange(t_post - 20)
    s2, d2 = arrange(t_post - 40)
    assert d1 == d2  # (one delay for the projection)
    net = pair_net(rule, d1)
    assert run(net, {12: ["drv"], s1: ["pre"], s2: ["pre"]}, 20) == [t_post]
    assert weight(net) == pytest.approx(W0 + 0.01 * (np.exp(-0.5) + np.exp(-1.0)), abs=1e-6)


@pytest.mark.parametrize("delay_ms", [0.5, 5.0, 10.0])
@pytest.mark.parametrize("gap", [-4, 6])
def test_pair_stdp_dendritic_delay_pairs_as_nest(delay_ms, gap):
    """delay: dendritic (NEST stdp_synapse): the pair's Δt is t_post − t_pre + d, whichever side of the post spike
    the pre spike arrives (``gap``: arrival minus post spike, substeps); the axonal default pairs t_post − arrival."""
    d = int(delay_ms / DT)
    t_post = post_spike_time(STDP, 10)
    step = (t_post + gap - d) // 4
    t_pre = 4 * step
    weights = {}
    for conv in ("axonal", "dendritic"):
        net = pair_net(dict(STDP, delay=conv), delay_ms)
        assert run(net, {10: ["drv"], step: ["pre"]}, (t_post + 2 * d) // 4 + 3) == [t_post]
        weights[conv] = weight(net)

    def nest_pair(dt_ms: float) -> float:
        return W0 + 0.01 * ((1 - W0) if dt_ms > 0 else -W0) * np.exp(-abs(dt_ms) / 20.0)

    assert weights["dendritic"] == pytest.approx(nest_pair((t_post - t_pre + d) * DT), abs=1e-6)
    assert weights["axonal"] == pytest.approx(nest_pair((t_post - t_pre - d) * DT), abs=1e-6)


def test_pair_stdp_frozen_when_not_learning():
    net = pair_net(dict(STDP), 1.0)
    net.learn = False
    run(net, {0: ["pre"], 2: ["drv"], 4: ["pre"]}, 10)
    assert weight(net) == W0


COS = {"kind": "symmetric_cos", "fixed_nS": 0.001, "kernel_nS": -0.01, "tau_ms": 100.0, "n": 2.0,
       "teacher": "tch_post"}
# by hand: k(10 ms) = e^(-2 * 10/100) cos^2(pi * 10 / 200) = 0.818731 * 0.975528 = 0.798695
K10 = 0.798695


@pytest.mark.parametrize("pre_step, tch_step", [(0, 5), (5, 0)])
def test_symmetric_cos_mf_dcn_pair_10_ms_apart(pre_step, tch_step):
    """A MF spike and a PC (teaching) spike arriving 10 ms apart, either order: Δw = fixed + kernel k(10 ms)."""
    net = pair_net(COS, 1.0, teacher=True)
    run(net, {pre_step: ["pre"], tch_step: ["tch"]}, 10)
    assert weight(net) == pytest.approx(W0 + 0.001 - 0.01 * K10, abs=1e-6)


def test_symmetric_cos_beyond_tau_only_fixed_and_same_step_pairs_once():
    net = pair_net(COS, 1.0, teacher=True)
    run(net, {0: ["pre"], 50: ["tch"]}, 55)  # 100 ms apart: k = 0
    assert weight(net) == pytest.approx(W0 + 0.001, abs=1e-7)
    net = pair_net(COS, 1.0, teacher=True)
    run(net, {0: ["pre", "tch"]}, 3)  # same arrival: k(0) = 1, counted once
    assert weight(net) == pytest.approx(W0 + 0.001 - 0.01, abs=1e-7)


def test_symmetric_cos_stdp_pc_dcn_pairs_with_the_post_spike():
    """PC–DCN: partner = the DCN's own spike; a PC arrival 10 ms before it: fixed + kernel k(10 ms)."""
    rule = {"kind": "symmetric_cos_stdp", "fixed_nS": -0.002, "kernel_nS": 0.02, "tau_ms": 100.0, "n": 2.0}
    t_post = post_spike_time(rule, 10)
    step, delay = arrange(t_post - 20)
    net = pair_net(rule, delay)
    assert run(net, {10: ["drv"], step: ["pre"]}, 20) == [t_post]
    assert weight(net) == pytest.approx(W0 - 0.002 + 0.02 * K10, abs=1e-6)


def test_sparse_weights_survive_a_state_round_trip():
    net = pair_net(dict(STDP), 1.0)
    run(net, {0: ["pre"], 2: ["drv"], 6: ["pre"]}, 10)
    state = {k: v.copy() for k, v in net.state_arrays().items()}
    learned = weight(net)
    assert learned != W0 and "sp_w" in state and "sl_tr_v" in state
    other = pair_net(dict(STDP), 1.0)
    other.load_arrays(state)
    assert weight(other) == learned
    run(net, {0: ["pre"]}, 3)
    run(other, {0: ["pre"]}, 3)
    assert weight(other) == weight(net)
