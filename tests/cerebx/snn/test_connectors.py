"""Connectors (docs/models.md#connectors): degree and count statistics, determinism per seed and projection,
per-synapse weights and delays, and the counts validation checks."""

from __future__ import annotations

import numpy as np
import pytest
from pydantic import ValidationError

from cerebx.snn.connectors import SIGMAS, projection_rng
from cerebx.snn.network import Network
from cerebx.snn.presets import PC
from cerebx.snn.schema import NetworkConfig
from cerebx.snn.topology import build_topology


def net_cfg(rule: dict, synapses: int, n_pre: int = 30, n_post: int = 20, same: bool = False, **proj) -> NetworkConfig:
    pops = {"a": {"size": n_pre, "neuron": {"kind": "input"}}, "b": {"size": n_post, "neuron": PC}}
    projections = {"p": {"pre": "b" if same else "a", "post": "b", "rule": rule, "receptor": "ampa",
                         "synapses": synapses, "weight_nS": 0.1, **proj},
                   "q": {"pre": "b" if same else "a", "post": "b", "rule": rule, "receptor": "ampa",
                         "synapses": synapses, "weight_nS": 0.1}}
    return NetworkConfig.model_validate({
        "name": "c", "populations": pops, "projections": projections,
        "io": {"mossy": "a", "climbing": "a", "output": "b", "purkinje": ["b"], "granule": "b"}})


def pairs(cfg: NetworkConfig, name: str = "p", seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    topo = build_topology(cfg, seed=seed)
    pre, post = [], []
    for s in topo.sparse:
        if s.name == name:
            pre.append(np.repeat(np.arange(s.n_pre), np.diff(s.ptr)))
            post.append(s.post - topo.slice(cfg.projections[name].post).start)
    return np.concatenate(pre), np.concatenate(post)


def test_fixed_indegree_gives_every_post_k_distinct_pre():
    pre, post = pairs(net_cfg({"kind": "fixed_indegree", "indegree": 4}, 80))
    assert len(pre) == 80
    assert (np.bincount(post, minlength=20) == 4).all()
    assert len(set(zip(pre.tolist(), post.tolist(), strict=True))) == 80  # no multapses
    assert 0 <= pre.min() and pre.max() < 30


def test_fixed_outdegree_gives_every_pre_k_distinct_post():
    pre, post = pairs(net_cfg({"kind": "fixed_outdegree", "outdegree": 3}, 90))
    assert (np.bincount(pre, minlength=30) == 3).all()
    assert len(set(zip(pre.tolist(), post.tolist(), strict=True))) == 90


def test_autapses_excluded_when_asked():
    rule = {"kind": "fixed_indegree", "indegree": 19, "allow_autapses": False}
    pre, post = pairs(net_cfg(rule, 380, same=True))
    assert not (pre == post).any()
    pre, post = pairs(net_cfg({"kind": "fixed_probability", "p": 1.0, "allow_autapses": False}, 380, same=True))
    assert len(pre) == 380 and not (pre == post).any()


def test_fixed_probability_count_and_degrees_are_binomial():
    n_pre, n_post, p = 200, 150, 0.1
    cfg = net_cfg({"kind": "fixed_probability", "p": p}, int(n_pre * n_post * p), n_pre=n_pre, n_post=n_post)
    counts = [len(pairs(cfg, seed=s)[0]) for s in range(5)]
    sigma = np.sqrt(n_pre * n_post * p * (1 - p))
    assert all(abs(c - 3000) < 4 * sigma for c in counts)
    assert len(set(counts)) > 1  # different seeds, different draws
    pre, post = pairs(cfg)
    indeg = np.bincount(post, minlength=n_post)
    assert abs(indeg.mean() - n_pre * p) < 1.5 and abs(indeg.var() - n_pre * p * (1 - p)) < 6


def test_same_seed_same_synapses_and_projections_independent():
    cfg = net_cfg({"kind": "fixed_indegree", "indegree": 5}, 100)
    a, b = pairs(cfg, "p", seed=7), pairs(cfg, "p", seed=7)
    np.testing.assert_array_equal(a[0], b[0])
    assert not np.array_equal(pairs(cfg, "p", seed=8)[0], a[0])
    assert not np.array_equal(pairs(cfg, "q", seed=7)[0], a[0])  # same rule, other projection: other draw


def test_weight_distribution_drawn_and_clipped():
    cfg = net_cfg({"kind": "fixed_indegree", "indegree": 10}, 200,
                  weight_nS={"dist": "normal", "mean": 1.0, "std": 0.5}, weight_range_nS=[0.5, 1.5])
    w = build_topology(cfg, seed=1).sparse[0].w
    assert w.min() == pytest.approx(0.5) and w.max() == pytest.approx(1.5)
    assert 0.9 < w.mean() < 1.1 and len(np.unique(w)) > 50


def test_delays_split_into_one_piece_per_step():
    cfg = net_cfg({"kind": "all_to_all"}, 600, delay_ms={"dist": "uniform", "low": 0.5, "high": 3.0})
    topo = build_topology(cfg, seed=2)
    pieces = [s for s in topo.sparse if s.name == "p"]
    delays = [s.delay for s in pieces]
    assert delays == sorted(set(delays)) and set(delays) <= {1, 2, 3, 4, 5, 6}
    assert sum(len(s.post) for s in pieces) == 600
    want = np.maximum(np.round(projection_rng(2, "p").uniform(0.5, 3.0, 600) / 0.5), 1)
    assert sorted(np.bincount(want.astype(int))[1:].tolist()) == sorted(
        [0] * (6 - len(pieces)) + [len(s.post) for s in pieces])


def test_drawn_delays_shift_arrivals_by_exactly_the_drawn_delay():
    """Every fibre fires at t = 0 onto its own post neuron; each post's AMPA conductance, read at the end of every
    2 ms step, first appears and then decays exactly from the drawn arrival substep."""
    n = 12
    cfg = NetworkConfig.model_validate({
        "name": "d", "dt_ms": 0.5,
        "populations": {"a": {"size": n, "neuron": {"kind": "input"}}, "b": {"size": n, "neuron": PC}},
        "projections": {"p": {"pre": "a", "post": "b", "rule": {"kind": "one_to_one"}, "receptor": "ampa",
                              "synapses": n, "weight_nS": 0.5,
                              "delay_ms": {"dist": "uniform", "low": 0.5, "high": 9.0}}},
        "io": {"mossy": "a", "climbing": "a", "output": "b", "purkinje": ["b"], "granule": "b"}})
    want = np.maximum(np.round(projection_rng(5, "p").uniform(0.5, 9.0, n) / 0.5), 1).astype(int)
    net = Network(cfg, parallel=False, seed=5)
    first = np.full(n, -1)
    d = np.exp(-0.5 / PC["tau_AMPA_ms"])
    for k in range(6):
        net.step(np.arange(n, dtype=np.int32) if k == 0 else np.zeros(0, np.int32))
        g = net.g[0, net.index("b")]
        end = 4 * (k + 1)  # substeps elapsed
        new = (g > 0) & (first < 0)
        first[new] = np.round(end - np.log(g[new] / 0.5) / np.log(d)).astype(int)
    np.testing.assert_array_equal(first, want)
    assert len(set(want.tolist())) > 5


def test_from_file_lists_synapses_weights_and_delays(tmp_path):
    path = tmp_path / "syn.npz"
    np.savez(path, pre=np.array([0, 0, 29, 5]), post=np.array([1, 2, 19, 1]),
             weight_nS=np.array([0.1, 0.2, 0.3, 0.4]), delay_ms=np.array([0.5, 1.0, 1.0, 2.0]))
    cfg = net_cfg({"kind": "from_file", "path": str(path)}, 4)
    topo = build_topology(cfg)
    got = sorted((int(s.delay), j, int(i) - 30, round(float(w), 6))
                 for s in topo.sparse if s.name == "p"
                 for j in range(s.n_pre) for i, w in zip(s.post[s.ptr[j]:s.ptr[j + 1]], s.w[s.ptr[j]:s.ptr[j + 1]],
                                                          strict=True))
    assert got == [(1, 0, 1, 0.1), (2, 0, 2, 0.2), (2, 29, 19, 0.3), (4, 5, 1, 0.4)]


@pytest.mark.parametrize("rule, synapses, message", [
    ({"kind": "fixed_indegree", "indegree": 4}, 81, "declared 81 but rule fixed_indegree gives 80"),
    ({"kind": "fixed_outdegree", "outdegree": 2}, 61, "declared 61 but rule fixed_outdegree gives 60"),
    ({"kind": "fixed_indegree", "indegree": 31}, 620, "indegree 31 is more than the 30 distinct pre neurons"),
    ({"kind": "fixed_probability", "p": 0.5}, 200, "gives 300.0 ± 61.2 (5 sigma)"),
    ({"kind": "from_file", "path": "no/such.npz"}, 4, "projections.p.rule.path: no/such.npz does not exist"),
])
def test_counts_checked_at_validation(rule, synapses, message):
    with pytest.raises(ValidationError, match=message.replace("(", r"\(").replace(")", r"\)")):
        net_cfg(rule, synapses)


def test_fixed_probability_accepts_counts_within_five_sigma():
    sigma = np.sqrt(600 * 0.5 * 0.5)
    net_cfg({"kind": "fixed_probability", "p": 0.5}, int(300 + SIGMAS * sigma) - 1)
    with pytest.raises(ValidationError):
        net_cfg({"kind": "fixed_probability", "p": 0.5}, int(300 + SIGMAS * sigma) + 1)


def test_from_file_indices_checked_at_validation(tmp_path):
    path = tmp_path / "bad.npz"
    np.savez(path, pre=np.array([0, 30]), post=np.array([0, 1]))
    with pytest.raises(ValidationError, match=r"pre indices must be in \[0, 30\), found \[0, 30\]"):
        net_cfg({"kind": "from_file", "path": str(path)}, 2)


def test_built_count_recorded():
    cfg = net_cfg({"kind": "fixed_probability", "p": 0.5}, 300)
    net = Network(cfg, parallel=False, seed=4)
    built = net.built_synapses["p"]
    assert built == len(pairs(cfg, seed=4)[0]) and built != 300  # (this seed's draw is not the expectation)


def test_a_schema_pickled_under_its_old_module_still_loads():
    """The connectors' and rules' schemas moved to snn/schema.py; a checkpoint that pickled one as
    ``cerebx.snn.connectors.X`` / ``cerebx.snn.plasticity.X`` still loads it."""
    import pickle

    from cerebx.snn import schema

    for old, cls in (("cerebx.snn.connectors", schema.FixedIndegree(indegree=4)),
                     ("cerebx.snn.connectors", schema.Normal(mean=1.0, std=0.5)),
                     ("cerebx.snn.plasticity", schema.PairSTDP())):
        data = pickle.dumps(cls, protocol=2).replace(b"cerebx.snn.schema", old.encode())
        assert old.encode() in data
        assert pickle.loads(data) == cls
