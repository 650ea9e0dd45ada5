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


def _with_plasticity(d: dict, name: str, rule: dict, w_range: tuple[float, float] = (0.0, 1.0)) -> None:
    d["projections"][name].update(plasticity=rule, weight_range_nS=list(w_range))


PAIR = {"kind": "pair_stdp", "lam": 0.02, "alpha": 1.1, "mu_plus": 0.0, "mu_minus": 1.0, "tau_plus_ms": 15.0,
        "tau_minus_ms": 30.0}


def test_pair_stdp_with_a_dendritic_delay_is_nest_stdp_synapse():
    d = network_dict(joints=1, fibers=2, per_joint=4)
    _with_plasticity(d, "pc_dcn", dict(PAIR, delay="dendritic"))
    p = plan(NetworkConfig.model_validate(d), static=True, approximate=True)
    pp = p.projections["pc_dcn"]
    assert pp.synapse == "stdp_synapse" and not pp.plastic
    assert pp.synapse_params == {"lambda": 0.02, "alpha": 1.1, "mu_plus": 0.0, "mu_minus": 1.0, "tau_plus": 15.0,
                                 "Wmax": -1.0}  # GABA: NEST's weights and their bound are negative
    assert p.populations["dcn"].nest_params["tau_minus"] == 30.0
    assert "tau_minus" not in p.populations["pc"].nest_params


def test_rules_nest_cannot_express_are_refused_in_one_line_naming_them(tmp_path):
    """kernel_stdp, symmetric_cos, symmetric_cos_stdp and pair_stdp with the axonal delay: each named, one line."""
    d = network_dict(joints=1, fibers=2, per_joint=4)
    d["projections"]["mf_dcn"].update(rule={"kind": "fixed_indegree", "indegree": 2}, synapses=8)
    _with_plasticity(d, "mf_dcn", {"kind": "symmetric_cos", "teacher": "pc_dcn"})
    _with_plasticity(d, "pc_dcn", {"kind": "symmetric_cos_stdp"})
    _with_plasticity(d, "cf_dcn_ampa", dict(PAIR))
    cfg = NetworkConfig.model_validate(d)
    with pytest.raises(Exception) as err:
        export(cfg, tmp_path / "x")
    msg = str(err.value)
    assert "\n" not in msg
    for kind in ("kernel_stdp", "symmetric_cos'", "symmetric_cos_stdp", "pair_stdp", "nmda"):
        assert kind in msg, kind
    assert "set delay: dendritic" in msg
    assert [p.split(":")[0] for p in plan(cfg, static=True).problems] == ["projections.cf_dcn_nmda"]
    assert any("pair_stdp" in n and "approximated" in n for n in plan(cfg, approximate=True).notes)


def test_stdp_synapse_bounds_and_its_post_neuron_trace_are_checked():
    d = network_dict(joints=1, fibers=2, per_joint=4)
    _with_plasticity(d, "cf_dcn_ampa", dict(PAIR, delay="dendritic"), (0.1, 1.0))
    d["projections"]["cf_dcn_ampa"]["weight_nS"] = 0.5
    problems = plan(NetworkConfig.model_validate(d)).problems
    assert any("cf_dcn_ampa.plasticity: kind 'pair_stdp'" in p and "bounds weights at 0" in p for p in problems)
    d = network_dict(joints=1, fibers=2, per_joint=4)
    _with_plasticity(d, "cf_dcn_ampa", dict(PAIR, delay="dendritic"))
    _with_plasticity(d, "pc_dcn", dict(PAIR, delay="dendritic", tau_minus_ms=10.0))
    problems = plan(NetworkConfig.model_validate(d)).problems
    assert any("cf_dcn_ampa.plasticity: tau_minus 30.0 differs from 10.0 of projections.pc_dcn" in p
               for p in problems)


def test_a_plugin_registers_its_kinds_export_through_the_api():
    import cerebx.api as api
    from cerebx.export import mapping

    with pytest.raises(ValueError, match="already registered"):
        api.register_export("plasticity", "kernel_stdp", api.Refused("no"))
    with pytest.raises(ValueError, match="group 'synapses'"):
        api.register_export("synapses", "x", "y")
    with pytest.raises(TypeError, match="a NeuronMap or Refused"):
        api.register_export("neurons", "my_neuron", "iaf_psc_alpha")
    try:
        api.register_export("connectors", "my_rule", "fixed_total_number / FixedTotalNumberConnector")
        assert mapping.CONNECTORS["my_rule"].startswith("fixed_total_number")
    finally:
        mapping.CONNECTORS.pop("my_rule", None)


def _learned_state(tmp_path, seed: int, layout: bool, pc_dcn_weight=None):
    """A small network with pair STDP on MF-DCN, its weights drawn at random (as if learned), saved as a run's
    ``controller_state.npz`` in ``tmp_path`` (``layout``: with the populations' and projections' order, as
    states are saved now; without: as before it was recorded)."""
    from cerebx.persistence.state import save_state_npz
    from cerebx.snn.network import Network

    d = network_dict(joints=1, fibers=2, per_joint=4)
    d["projections"]["mf_dcn"].update(rule={"kind": "fixed_indegree", "indegree": 2}, synapses=8)
    if pc_dcn_weight is not None:
        d["projections"]["pc_dcn"].update(weight_nS=pc_dcn_weight)
    _with_plasticity(d, "mf_dcn", dict(PAIR, delay="dendritic"))
    cfg = NetworkConfig.model_validate(d)
    net = Network(cfg, parallel=False)
    rng = np.random.default_rng(seed)
    net.dense_w[:] = rng.uniform(0, 5, net.dense_w.size)
    net.sp_w[:] = rng.uniform(0, 1, net.sp_w.size)
    meta = {"fingerprint": cfg.fingerprint(), "network": cfg.name, **({"layout": cfg.layout()} if layout else {})}
    save_state_npz(tmp_path / "controller_state.npz", meta, **{f"net_{k}": v for k, v in net.state_arrays().items()})
    return cfg, net


def test_learned_weights_of_a_run_are_exported(tmp_path, capsys):
    """``--weights RUN``: the npz holds the saved state's weights (count and sum per projection), not the initial
    ones; a state of another network is refused in one line."""
    cfg, net = _learned_state(tmp_path, seed=4, layout=False)
    src = tmp_path / "net.yaml"
    src.write_text(yaml.safe_dump(cfg.model_dump(), sort_keys=False))  # the synapses' order is the projections'
    assert main(["export", str(src), "--weights", str(tmp_path / "controller_state.npz"), "--static", "--approximate",
                 "--out", str(tmp_path / "out")]) == 0
    assert "weights: learned, from" in capsys.readouterr().out
    _, tables = read_npz(tmp_path / "out" / "network.npz")
    for name in tables:
        if name in ("mf_dcn", "mf_gc", "pc_dcn", "cf_pc", "cf_dcn_ampa"):
            pre, post, w = net.sparse_weights(name)
            assert len(tables[name]["w"]) == len(w)
            assert float(tables[name]["w"].sum(dtype=np.float64)) == pytest.approx(float(w.sum(dtype=np.float64)))
    block = net.topo.dense_block(next(x for x in net.topo.dense if x.name == "pf_pc"))
    assert tables["pf_pc"]["w"].shape == block.shape
    np.testing.assert_array_equal(tables["pf_pc"]["w"], block)
    assert float(tables["mf_dcn"]["w"].sum()) != pytest.approx(float(build_topology(cfg).sparse[0].w.sum()))
    other = network_dict(joints=1, fibers=2, per_joint=6)
    src.write_text(yaml.safe_dump(NetworkConfig.model_validate(other).model_dump()))
    assert main(["export", str(src), "--weights", str(tmp_path / "controller_state.npz"), "--static",
                 "--approximate", "--out", str(tmp_path / "o2")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "of another structure" in err


def test_a_network_file_takes_overrides_of_its_keys():
    from pathlib import Path

    from cerebx.errors import CerebxError
    from cerebx.export.source import load_network

    vocab = Path(__file__).parents[2] / "configs" / "nest_vocab.yaml"
    cfg = load_network(str(vocab), ["dt_ms=0.1", "projections.pf_pc.plasticity.lam=0.02"])
    assert cfg.dt_ms == 0.1 and cfg.projections["pf_pc"].plasticity.lam == 0.02
    assert cfg.projections["goc_gc"].rule.kind == "fixed_indegree" and cfg.projections["mf_gc"].rule.p == 0.1
    with pytest.raises(CerebxError, match="override 'nope.x=1': not key=value"):
        load_network(str(vocab), ["nope.x=1"])


def test_a_network_written_per_joint_is_sized_for_the_composed_plant(tmp_path):
    """`cerebx export/crosscheck small_golgi` sizes the per-joint preset as a run on its plant would; a bare
    network file written per joint names no plant and is refused in one line."""
    from cerebx.errors import CerebxError
    from cerebx.export.source import load_network

    six = load_network("small_golgi")
    two = load_network("small_golgi", ["plant=planar2"])
    assert six.populations["pc"].size // 6 == two.populations["pc"].size // 2 > 0 and two.populations["pc"].size < 60
    bare = tmp_path / "net.yaml"
    bare.write_text("populations: {}\nprojections: {}\nper_joint: {pc: 10}\n")
    with pytest.raises(CerebxError, match="per_joint: the network is sized from a plant"):
        load_network(str(bare))


def test_a_preset_population_s_integration_is_set_through_its_neuron():
    """A preset's population names its neuron by reference (``neuron: ${...neurons.gc}``). Setting a key inside the
    reference failed with Hydra's contradictory "already set; drop the leading '+'" (or, with '++', replaced the
    neuron by the one key); the line now names the key that works, and that key sets the population's step."""
    from cerebx.errors import CerebxError
    from cerebx.export.source import load_network

    cfg = load_network("small_golgi", ["controller.network.dt_ms=0.1",
                                       "controller.network.neurons.gc.integration={method: rk4, dt_ms: null}"])
    gc = cfg.populations["gc"].neuron
    assert cfg.dt_ms == 0.1 and gc.integration.method == "rk4" and gc.integration.dt_ms is None
    assert gc.clamp_at_rest and load_network("small_golgi").populations["gc"].neuron.integration.dt_ms == 1.0
    for plus in ("", "+", "++"):
        with pytest.raises(CerebxError) as err:
            load_network("small_golgi", [f"{plus}controller.network.populations.gc.neuron.integration.dt_ms=0.1"])
        assert str(err.value) == (
            "controller.network.populations.gc.neuron.integration.dt_ms: controller.network.populations.gc.neuron "
            "is a reference (${...neurons.gc}), and a key inside one cannot be overridden; use "
            "controller.network.neurons.gc.integration.dt_ms=0.1 (it applies to everything that refers to "
            "controller.network.neurons.gc), or replace controller.network.populations.gc.neuron whole")


def test_learned_weights_are_found_by_projection_name(tmp_path, capsys):
    """The saved weights follow the saving network's projection order, which the fingerprint leaves out: with the
    order recorded in the state (``layout``), a network file listing the projections in another order (here
    sorted, as ``yaml.safe_dump`` writes a dict) exports each projection's own weights."""
    cfg, net = _learned_state(tmp_path, seed=5, layout=True,
                              pc_dcn_weight={"dist": "uniform", "low": 0.5, "high": 1.5})
    src = tmp_path / "net.yaml"
    src.write_text(yaml.safe_dump(cfg.model_dump()))  # sorted keys: another projection order, same fingerprint
    assert list(yaml.safe_load(src.read_text())["projections"]) != list(cfg.projections)
    assert main(["export", str(src), "--weights", str(tmp_path / "controller_state.npz"), "--static", "--approximate",
                 "--out", str(tmp_path / "out")]) == 0
    capsys.readouterr()
    _, tables = read_npz(tmp_path / "out" / "network.npz")
    for name in ("mf_gc", "mf_dcn", "pc_dcn", "cf_pc", "cf_dcn_ampa"):
        pre, post, w = net.sparse_weights(name)
        order = np.lexsort((post, pre))
        mine = np.lexsort((tables[name]["post"], tables[name]["pre"]))
        np.testing.assert_array_equal(tables[name]["w"][mine], w[order], err_msg=name)
    block = net.topo.dense_block(next(x for x in net.topo.dense if x.name == "pf_pc"))
    np.testing.assert_array_equal(tables["pf_pc"]["w"], block)
