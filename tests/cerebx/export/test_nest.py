"""cerebx beside NEST 3.10 (slow; skipped where no Python with NEST is found: ``pip install -e .[nest]`` or
``$CEREBX_NEST_PYTHON``). The exported network holds in NEST exactly cerebx's synapses; one neuron and whole
networks driven by the same spike trains fire as in cerebx within the tolerances docs/guide/nest.md states."""

from __future__ import annotations

import json
import subprocess

import numpy as np
import pytest

from cerebx.errors import CerebxError
from cerebx.export.crosscheck import crosscheck, nest_python, seeded_inputs, single_neuron
from cerebx.export.source import load_network
from cerebx.export.writer import count_and_sum, export, synapse_tables
from cerebx.snn.presets import DCN, PC, network
from cerebx.snn.topology import build_topology

try:
    PYTHON = nest_python()
except CerebxError as err:
    PYTHON, WHY = None, str(err)
else:
    WHY = ""

pytestmark = [pytest.mark.slow, pytest.mark.skipif(PYTHON is None, reason=WHY)]
GC_AT_DT = "controller.network.neurons.gc.integration={method: rk4, dt_ms: null, bifixed_substeps: 1}"


def test_nest_holds_the_exported_synapses(tmp_path):
    cfg = network(joints=2, fibers=3, per_joint=6)
    topo = build_topology(cfg)
    topo.dense_w[:] = np.random.default_rng(2).uniform(0, 5, topo.dense_w.size)
    export(cfg, tmp_path, to=("nest",), static=True, approximate=True, topo=topo)
    proc = subprocess.run([PYTHON, str(tmp_path / "nest_network.py"), "--connections"], capture_output=True,
                          text=True, check=True)
    got = json.loads(proc.stdout.strip().splitlines()[-1])
    want = {k: v for k, v in count_and_sum(synapse_tables(topo)).items() if k != "cf_dcn_nmda"}
    assert set(got) == set(want)
    for name, (n, w) in want.items():
        assert got[name]["synapses"] == n
        assert got[name]["weight_sum_nS"] == pytest.approx(w, rel=1e-6, abs=1e-9)


def test_the_pynn_script_fires_as_the_nest_one(tmp_path):
    cfg = load_network("small")
    export(cfg, tmp_path, to=("nest", "pynn"), static=True, approximate=True, inputs=seeded_inputs(cfg, 300.0, 1))
    for script in ("nest_network.py", "pynn_network.py"):
        subprocess.run([PYTHON, str(tmp_path / script), "--ms", "300"], capture_output=True, check=True)
    a, b = np.load(tmp_path / "spikes_nest.npz"), np.load(tmp_path / "spikes_pynn.npz")
    assert len(a["gc/t"]) > 10 and len(a["pc/t"]) > 10 and len(a["dcn/t"]) > 10
    for pop in ("gc", "pc", "dcn"):
        assert sorted(zip(a[f"{pop}/idx"], a[f"{pop}/t"])) == sorted(zip(b[f"{pop}/idx"], b[f"{pop}/t"]))


@pytest.mark.parametrize(("neuron", "weights"), [(PC, (3.0, 15.0)), (DCN, (0.5, 3.0))], ids=["pc", "dcn"])
def test_one_neuron_fires_as_iaf_cond_exp(neuron, weights, tmp_path):
    """cerebx's RK4 at 0.5 ms against NEST's RKF45: rates within 0.2 %, >= 98 % of spikes on the same step."""
    r = single_neuron(neuron, weights, 250.0, 2000.0, 0.5, tmp_path, python=PYTHON)
    assert r["rate_cerebx_hz"] > 20
    assert abs(r["rate_diff"]) < 0.002
    assert r["count_corr"] > 0.999 and r["matched_same_step"] > 0.98


def test_the_small_network_fires_as_in_nest(tmp_path):
    """With the granule cells integrated at the network step, both compute the same spikes; as configured (GCs
    in 1 ms steps, spiking on that grid) the GC and PC counts are equal, their times up to 0.5 ms later, and the
    DCN rate moves by a few per cent (docs/guide/nest.md)."""
    same = crosscheck(load_network("small", [GC_AT_DT]), tmp_path / "a", ms=1000.0, python=PYTHON)
    for row in same.rows:
        assert abs(row.rate_diff) < 0.005 and row.matched > 0.99, row
    conf = {r.population: r for r in crosscheck(load_network("small"), tmp_path / "b", ms=1000.0,
                                                 python=PYTHON).rows}
    assert conf["gc"].rate_diff == 0 and conf["pc"].rate_diff == 0 and conf["pc"].count_corr == 1
    assert conf["pc"].matched_step < 0.5 and conf["pc"].matched == 1.0
    assert abs(conf["dcn"].rate_diff) < 0.1 and conf["dcn"].count_corr > 0.6


def test_the_thesis_purkinje_and_dcn_layer_fires_as_in_nest(tmp_path):
    """The thesis network's PC and DCN in NEST, fed with the GC, MF and CF spikes of cerebx's whole network."""
    res = crosscheck(load_network("thesis_ch3"), tmp_path, ms=1000.0, layer=["pc", "dcn"], python=PYTHON)
    rows = {r.population: r for r in res.rows}
    assert set(rows) == {"pc", "dcn"}
    for r in rows.values():
        assert abs(r.rate_diff) < 0.01 and r.count_corr > 0.9 and r.matched > 0.98, r
    assert rows["dcn"].output_corr > 0.9


def test_nest_holds_drawn_connectors_weights_and_delays(tmp_path):
    """A fixed in-degree projection with drawn weights and delays (seed 5): NEST holds its synapses with their
    weights and their delays."""
    from cerebx.snn.presets import network_dict
    from cerebx.snn.schema import NetworkConfig

    d = network_dict(joints=1, fibers=2, per_joint=4)
    d["projections"]["mf_dcn"].update(
        rule={"kind": "fixed_indegree", "indegree": 3}, synapses=3 * d["populations"]["dcn"]["size"],
        weight_nS={"dist": "uniform", "low": 0.1, "high": 0.9}, delay_ms={"dist": "uniform", "low": 0.5, "high": 3.0})
    cfg = NetworkConfig.model_validate(d)
    topo = build_topology(cfg, seed=5)
    export(cfg, tmp_path, to=("nest",), static=True, approximate=True, topo=topo)
    proc = subprocess.run([PYTHON, str(tmp_path / "nest_network.py"), "--connections"], capture_output=True,
                          text=True, check=True)
    got = json.loads(proc.stdout.strip().splitlines()[-1])["mf_dcn"]
    t = synapse_tables(topo)["mf_dcn"]
    assert got["synapses"] == len(t["w"]) == 3 * cfg.populations["dcn"].size
    assert got["weight_sum_nS"] == pytest.approx(float(t["w"].sum(dtype=np.float64)), rel=1e-6)
    assert got["delay_sum_ms"] == pytest.approx(float(t["d"].sum()), rel=1e-9)
