"""A granular layer with Golgi cells (MF -> GoC, GC -> GoC, GoC -> GC with fixed in-degrees, GABA onto GC) and
the distributed plasticity at MF–DCN and PC–DCN, expressed as data and run on a small network."""

from __future__ import annotations

import numpy as np

from cerebx.snn.network import Network
from cerebx.snn.presets import DCN, GC_RK4, PC
from cerebx.snn.schema import NetworkConfig

N_MF, N_GC, N_GOC, N_PC = 20, 100, 10, 4


def golgi_cfg(goc_gc_nS: float = 0.5) -> NetworkConfig:
    def proj(pre, post, rule, receptor, synapses, weight, **more):
        return {"pre": pre, "post": post, "rule": rule, "receptor": receptor, "synapses": synapses,
                "weight_nS": weight, **more}

    indeg = lambda k: {"kind": "fixed_indegree", "indegree": k}  # noqa: E731
    return NetworkConfig.model_validate({
        "name": "golgi", "dt_ms": 0.5,
        "populations": {"mf": {"size": N_MF, "neuron": {"kind": "input"}},
                        "cf": {"size": N_PC, "neuron": {"kind": "input"}},
                        "gc": {"size": N_GC, "neuron": GC_RK4},
                        "goc": {"size": N_GOC, "neuron": dict(GC_RK4, C_m_pF=4.0)},
                        "pc": {"size": N_PC, "neuron": PC}, "dcn": {"size": N_PC, "neuron": DCN}},
        "projections": {
            "mf_gc": proj("mf", "gc", indeg(4), "ampa", 4 * N_GC, {"dist": "normal", "mean": 0.6, "std": 0.1},
                          delay_ms={"dist": "uniform", "low": 0.5, "high": 2.0}),
            "mf_goc": proj("mf", "goc", indeg(4), "ampa", 4 * N_GOC, 0.5),
            "gc_goc": proj("gc", "goc", indeg(20), "ampa", 20 * N_GOC, 0.1),
            "goc_gc": proj("goc", "gc", indeg(4), "gaba", 4 * N_GC, goc_gc_nS),
            "pf_pc": proj("gc", "pc", {"kind": "all_to_all"}, "ampa", N_GC * N_PC, 1.0, weight_range_nS=[0.0, 5.0],
                          plasticity={"kind": "kernel_stdp", "teacher": "cf_pc"}),
            "cf_pc": proj("cf", "pc", {"kind": "one_to_one"}, "ampa", N_PC, 0.0, teaching=True),
            "mf_dcn": proj("mf", "dcn", {"kind": "all_to_all"}, "ampa", N_MF * N_PC, 0.6, weight_range_nS=[0.0, 1.0],
                           plasticity={"kind": "symmetric_cos", "teacher": "pc_dcn"}),
            "pc_dcn": proj("pc", "dcn", {"kind": "one_to_one"}, "gaba", N_PC, 1.0, weight_range_nS=[0.0, 3.0],
                           plasticity={"kind": "symmetric_cos_stdp", "fixed_nS": -0.001, "kernel_nS": 0.005}),
        },
        "io": {"mossy": "mf", "climbing": "cf", "output": "dcn", "purkinje": ["pc"], "granule": "gc"},
    })


def run(net: Network, steps: int = 400) -> dict[str, int]:
    rng = np.random.default_rng(0)
    counts = dict.fromkeys(("gc", "goc", "pc", "dcn"), 0)
    for _ in range(steps):
        spikes = net.step(np.flatnonzero(rng.random(N_MF + N_PC) < 0.1).astype(np.int32)).idx
        for pop in counts:
            s = net.index(pop)
            counts[pop] += int(((spikes >= s.start) & (spikes < s.stop)).sum())
    return counts


def test_golgi_cells_fire_and_inhibit_the_granule_layer():
    """(With C = 2 pF granule cells, explicit RK4 at 0.5 ms is unstable above ~10 nS of total conductance: strong
    Golgi inhibition then makes the granule layer fire more, not less. The weights here stay well below.)"""
    inhibited = run(Network(golgi_cfg(0.5), parallel=False, seed=1))
    free = run(Network(golgi_cfg(0.0), parallel=False, seed=1))
    assert inhibited["goc"] > 0 and inhibited["gc"] > 0
    assert inhibited["gc"] < 0.8 * free["gc"], (inhibited, free)


def test_mf_dcn_and_pc_dcn_learn_and_freeze():
    net = Network(golgi_cfg(), parallel=False, seed=1)
    assert run(net)["dcn"] > 0  # the PC–DCN rule's partner (DCN spikes) occurs
    for name, w0 in (("mf_dcn", 0.6), ("pc_dcn", 1.0)):
        w = net.sparse_weights(name)[2]
        assert np.abs(w - w0).max() > 1e-3, name
    frozen = Network(golgi_cfg(), parallel=False, seed=1)
    frozen.learn = False
    run(frozen, 100)
    assert (frozen.sparse_weights("mf_dcn")[2] == np.float32(0.6)).all()
