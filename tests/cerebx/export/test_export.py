"""``cerebx export``: the registry maps lif_cond to iaf_cond_exp and refuses what it cannot express, and the written
network.npz holds exactly the synapses cerebx builds (count, pairs and weight sum)."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from cerebx.cli import main
from cerebx.export.crosscheck import layer_config, seeded_inputs
from cerebx.export.mapping import NEURONS, plan, register
from cerebx.export.writer import count_and_sum, export, read_npz, synapse_tables
from cerebx.snn.presets import network, network_dict
from cerebx.snn.schema import NetworkConfig
from cerebx.snn.topology import build_topology


@pytest.fixture(scope="module")
def tiny() -> NetworkConfig:
    """The full network's layout at one joint, 2 fibres per signal, 4 PC/CF/DCN."""
    return network(joints=1, fibers=2, per_joint=4)


def test_the_kernel_rule_and_nmda_are_refused_in_one_line_naming_them(tiny, tmp_path):
    p = plan(tiny)
    assert len(p.problems) == 2
    assert "projections.pf_pc.plasticity: kind 'kernel_stdp' cannot be expressed" in p.problems[0]
    assert "projections.cf_dcn_nmda: receptor 'nmda' cannot be expressed" in p.problems[1]
    with pytest.raises(Exception, match="kernel_stdp.*nmda") as err:
        export(tiny, tmp_path / "x")
    assert "\n" not in str(err.value)
    assert not (tmp_path / "x").exists()


def test_static_and_approximate_export_with_notes(tiny):
    p = plan(tiny, static=True, approximate=True)
    assert p.problems == []
    assert list(p.dropped) == ["cf_dcn_nmda"]
    assert p.projections["pf_pc"].plastic and p.projections["pf_pc"].synapse == "static_synapse"
    assert p.projections["pc_dcn"].sign == -1 and p.projections["pc_dcn"].pynn_receptor == "inhibitory"
    assert p.projections["mf_dcn"].sign == 1
    assert any("exported with static weights" in n for n in p.notes)
    pc = p.populations["pc"]
    assert pc.nest_model == "iaf_cond_exp"
    assert pc.nest_params == {"C_m": 100.0, "g_L": 6.0, "E_L": -70.0, "V_reset": -70.0, "V_m": -70.0, "V_th": -52.0,
                              "t_ref": 2.0, "E_ex": 0.0, "E_in": -80.0, "tau_syn_ex": 1.2, "tau_syn_in": 10.0,
                              "I_e": 0.0}
    assert pc.pynn_params["cm"] == 0.1 and pc.pynn_params["tau_m"] == pytest.approx(100 / 6)
    assert p.populations["mf"].nest_model == "spike_train_injector"


def test_clamp_at_rest_under_inhibition_is_refused():
    d = network_dict(joints=1, fibers=2, per_joint=4)
    d["populations"]["dcn"]["neuron"] = {**d["populations"]["dcn"]["neuron"], "clamp_at_rest": True}
    p = plan(NetworkConfig.model_validate(d), static=True, approximate=False)
    assert any("populations.dcn.neuron" in x and "clamp V >= E_L" in x for x in p.problems)


def test_t_ref_is_exported_as_cerebx_rounds_it():
    d = network_dict(joints=1, fibers=2, per_joint=4)
    d["populations"]["pc"]["neuron"] = {**d["populations"]["pc"]["neuron"], "t_ref_ms": 1.2}
    p = plan(NetworkConfig.model_validate(d), static=True, approximate=True)
    assert p.populations["pc"].nest_params["t_ref"] == 1.0
    assert any("t_ref 1.2 ms is exported as 1.0 ms" in n for n in p.notes)


def test_a_kind_is_registered_once():
    with pytest.raises(ValueError, match="already registered"):
        register(NEURONS, "lif_cond", NEURONS["lif_cond"])


def test_the_npz_holds_exactly_cerebx_synapses(tiny, tmp_path):
    topo = build_topology(tiny)
    topo.dense_w[:] = np.random.default_rng(1).uniform(0, 5, topo.dense_w.size)  # distinct weights: orientation
    p = export(tiny, tmp_path, to=("nest", "pynn"), static=True, approximate=True, topo=topo)
    meta, tables = read_npz(tmp_path / "network.npz")
    assert (tmp_path / "nest_network.py").is_file() and (tmp_path / "pynn_network.py").is_file()
    assert set(tables) == set(p.projections) == set(tiny.projections) - {"cf_dcn_nmda"}
    want = count_and_sum(synapse_tables(topo))
    got = count_and_sum(tables)
    assert got == {k: v for k, v in want.items() if k != "cf_dcn_nmda"}
    assert sum(n for n, _ in got.values()) == tiny.n_synapses - tiny.projections["cf_dcn_nmda"].synapses
    d = next(d for d in topo.dense if d.name == "pf_pc")
    np.testing.assert_array_equal(tables["pf_pc"]["w"], topo.dense_block(d))
    # the joint combinations: GC k of the joint takes one MF of each of the 4 signals, in base-2 digits of k
    mf_gc = tables["mf_gc"]
    pairs = set(zip(mf_gc["pre"].tolist(), mf_gc["post"].tolist()))
    assert len(pairs) == 16 * 4
    assert {pre for pre, post in pairs if post == 0b1011} == {0 * 2 + 1, 1 * 2 + 0, 2 * 2 + 1, 3 * 2 + 1}
    assert meta["projections"]["pc_dcn"]["sign"] == -1 and meta["projections"]["pf_pc"]["layout"] == "dense"
    assert meta["resolution_ms"] == 0.5 and meta["t_offset_ms"] == 0.5


def test_seeded_inputs_are_box_coded_on_the_step_grid(tiny):
    a = seeded_inputs(tiny, 200.0, seed=3)
    b = seeded_inputs(tiny, 200.0, seed=3)
    for pop in a:
        np.testing.assert_array_equal(a[pop][0], b[pop][0])
        np.testing.assert_array_equal(a[pop][1], b[pop][1])
    idx, t = a["mf"]
    assert t.min() == 2.0 and t.max() == 198.0 and np.all(t % 2.0 == 0)
    for step in np.unique(t):  # one active fibre in each group of two, every step
        assert sorted(idx[t == step] // 2) == list(range(4))


def test_a_layer_keeps_its_populations_and_their_inputs(tiny):
    lay = layer_config(tiny, ["pc", "dcn"])
    assert [n for n, p in lay.populations.items() if p.neuron.kind != "input"] == ["pc", "dcn"]
    assert "mf_gc" not in lay.projections and "pf_pc" in lay.projections


def test_the_command_writes_or_refuses_in_one_line(tiny, tmp_path, capsys):
    src = tmp_path / "tiny.yaml"
    src.write_text(yaml.safe_dump(tiny.model_dump()))
    assert main(["export", str(src), "--out", str(tmp_path / "a")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "kernel_stdp" in err and "nmda" in err
    assert main(["export", str(src), "--out", str(tmp_path / "b"), "--static", "--approximate", "--to", "nest,pynn",
                 "--inputs-ms", "20"]) == 0
    out = capsys.readouterr().out
    assert "36 neurons" in out and "left out: projections.cf_dcn_nmda" in out
    meta, _ = read_npz(tmp_path / "b" / "network.npz")
    assert meta["inputs"] == ["cf", "mf"]
    assert main(["export", str(src), "--out", str(tmp_path / "c"), "--to", "brian"]) == 2
    assert "--to: unknown target 'brian'" in capsys.readouterr().err
    assert main(["export", str(tmp_path / "none.yaml"), "--out", str(tmp_path / "d")]) == 2
    assert "cannot be read" in capsys.readouterr().err


def test_crosscheck_without_nest_is_one_line(monkeypatch, tmp_path, capsys):
    import importlib.util

    monkeypatch.delenv("CEREBX_NEST_PYTHON", raising=False)
    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "nest" else real(name, *a))
    assert main(["crosscheck", "small", "--out", str(tmp_path)]) == 2
    assert capsys.readouterr().err.strip() == ("crosscheck: NEST is not importable here: pip install 'cerebx[nest]' "
                                               "or set CEREBX_NEST_PYTHON to a Python that has it")
    assert main(["crosscheck", "small", "--ms", "3"]) == 2
    assert "--ms: must be a positive multiple of 2" in capsys.readouterr().err


def test_drawn_connectors_weights_and_delays_are_exported_as_drawn(tmp_path):
    """A fixed in-degree projection with drawn weights and delays: the npz holds the seed's synapses, each with its
    weight and its delay (the engine's pieces per delay joined), and another seed draws other synapses."""
    d = network_dict(joints=1, fibers=2, per_joint=4)
    d["projections"]["mf_dcn"].update(
        rule={"kind": "fixed_indegree", "indegree": 3}, synapses=3 * d["populations"]["dcn"]["size"],
        weight_nS={"dist": "uniform", "low": 0.1, "high": 0.9}, delay_ms={"dist": "uniform", "low": 0.5, "high": 3.0})
    cfg = NetworkConfig.model_validate(d)
    topo = build_topology(cfg, seed=7)
    export(cfg, tmp_path, to=("nest", "pynn"), static=True, approximate=True, topo=topo)
    meta, tables = read_npz(tmp_path / "network.npz")
    t = tables["mf_dcn"]
    pieces = [s for s in topo.sparse if s.name == "mf_dcn"]
    assert len(pieces) > 1  # several delays: one CSR table per delay in the engine
    assert len(t["w"]) == 3 * cfg.populations["dcn"].size == sum(len(s.w) for s in pieces)
    assert np.bincount(t["post"]).tolist() == [3] * cfg.populations["dcn"].size
    assert float(t["w"].sum(dtype=np.float64)) == pytest.approx(sum(float(s.w.sum(dtype=np.float64)) for s in pieces))
    engine = sorted(x for s in pieces for x in [s.delay * topo.dt_ms] * len(s.w))
    assert sorted(t["d"].tolist()) == engine
    assert meta["projections"]["mf_dcn"]["delay_ms"] == min(engine)
    assert meta["projections"]["mf_dcn"]["max_delay_ms"] == max(engine)
    other = synapse_tables(build_topology(cfg, seed=8))["mf_dcn"]
    assert not np.array_equal(np.sort(other["w"]), np.sort(t["w"]))
