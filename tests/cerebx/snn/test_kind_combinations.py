"""``cerebx validate`` accepts exactly what the engine runs: every registered connector x plasticity x receptor
(x teaching) combination on a tiny network either validates and runs a few steps, or is refused with one line."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from pydantic import ValidationError

from cerebx import registry
from cerebx.snn.network import Network
from cerebx.snn.presets import DCN
from cerebx.snn.schema import NetworkConfig

N = 4  # every population: 4 neurons (joint_combinations with 1 joint, 2 signals, 2 fibres fits)

RULES = {
    "all_to_all": ({"kind": "all_to_all"}, N * N),
    "one_to_one": ({"kind": "one_to_one"}, N),
    "joint_combinations": ({"kind": "joint_combinations", "joints": 1, "signals": 2, "fibers_per_signal": 2}, 2 * N),
    "fixed_indegree": ({"kind": "fixed_indegree", "indegree": 2}, 2 * N),
    "fixed_outdegree": ({"kind": "fixed_outdegree", "outdegree": 3}, 3 * N),
    "fixed_probability": ({"kind": "fixed_probability", "p": 0.5}, N * N // 2),
    "from_file": ({"kind": "from_file", "path": "FILE"}, 3),
}
PLASTICITY = {
    None: None,
    "kernel_stdp": {"kind": "kernel_stdp", "teacher": "cf_post"},
    "pair_stdp": {"kind": "pair_stdp"},
    "symmetric_cos": {"kind": "symmetric_cos", "teacher": "cf_post"},
    "symmetric_cos_stdp": {"kind": "symmetric_cos_stdp"},
}


def test_the_walk_covers_every_registered_kind():
    """Every kind cerebx registers (a plugin's kinds are its own tests' to walk)."""
    registry.load_plugins()
    for reg, walked in ((registry.connectors, set(RULES)), (registry.plasticity_rules, {k for k in PLASTICITY if k})):
        assert {k for k in reg.kinds() if reg[k].plugin == "core"} == walked


def config(rule: str, plasticity: str | None, receptor: str, teaching: bool, path: str) -> dict:
    spec, synapses = RULES[rule]
    spec = {k: (path if v == "FILE" else v) for k, v in spec.items()}
    proj = {"pre": "src", "post": "post", "rule": spec, "receptor": receptor, "synapses": synapses,
            "weight_nS": 0.5, "teaching": teaching}
    if plasticity is not None:
        proj |= {"weight_range_nS": [0.0, 1.0], "plasticity": PLASTICITY[plasticity]}
    return {
        "name": "walk", "dt_ms": 0.5,
        "populations": {"src": {"size": N, "neuron": {"kind": "input"}}, "cf": {"size": N, "neuron": {"kind": "input"}},
                        "post": {"size": N, "neuron": DCN}},
        "projections": {
            "x": proj,
            "cf_post": {"pre": "cf", "post": "post", "rule": {"kind": "one_to_one"}, "receptor": "ampa",
                        "synapses": N, "weight_nS": 0.0, "teaching": True},
            "drive": {"pre": "cf", "post": "post", "rule": {"kind": "one_to_one"}, "receptor": "ampa", "synapses": N,
                      "weight_nS": 5.0},
        },
        "io": {"mossy": "src", "climbing": "cf", "output": "post", "purkinje": ["post"], "granule": "post"},
    }


@pytest.fixture(scope="module")
def listed(tmp_path_factory) -> str:
    path = tmp_path_factory.mktemp("walk") / "syn.npz"
    np.savez(path, pre=np.array([0, 1, 3]), post=np.array([2, 2, 0]), delay_ms=np.array([0.5, 1.5, 1.0]))
    return str(path)


def test_validate_accepts_exactly_what_runs(listed):
    accepted, refused = [], []
    for rule, plasticity, receptor, teaching in itertools.product(RULES, PLASTICITY, ("ampa", "nmda", "gaba"),
                                                                   (False, True)):
        combo = f"{rule} x {plasticity} x {receptor} x teaching={teaching}"
        try:
            cfg = NetworkConfig.model_validate(config(rule, plasticity, receptor, teaching, listed))
        except ValidationError as err:
            lines = [e["msg"] for e in err.errors()]
            assert len(lines) == 1 and "\n" not in lines[0], f"{combo}: {lines}"
            refused.append((combo, lines[0]))
            continue
        net = Network(cfg, parallel=False, seed=1)  # accepted: must build and run
        rng = np.random.default_rng(0)
        for _ in range(30):
            net.step(np.flatnonzero(rng.random(2 * N) < 0.5).astype(np.int32))
        accepted.append(combo)
    assert len(accepted) + len(refused) == len(RULES) * len(PLASTICITY) * 3 * 2
    # what must be refused: kernel_stdp off all_to_all, and any rule on a teaching projection
    assert all(("kernel_stdp" in c and not c.startswith("all_to_all")) or "teaching=True" in c for c, _ in refused)
    assert not any("teaching=False" in c and "kernel_stdp" not in c for c, _ in refused)
    assert "pair_stdp" in " ".join(accepted) and "symmetric_cos_stdp" in " ".join(accepted)
