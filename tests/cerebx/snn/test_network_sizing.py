"""A network sized from the plant's joint count (``per_joint``, cerebx.snn.sizing): the same preset gives the
6-joint `full` network on Baxter and a 2-joint one on the planar arm, with every synapse count derived; and
(slow) the planar arm learns the joint sinusoid from scratch with it, with box-coded and with Poisson mossy
fibres on a random granular layer."""

from __future__ import annotations

import numpy as np
import pytest

from cerebx.errors import ConfigError
from cerebx.loop.runner import run_experiment
from cerebx.snn.sizing import sized_network

PLANAR = ["+experiment=snn_planar2"]


def test_per_joint_on_baxter_is_the_full_network(load):
    sized = load(["+task=circle", "network=per_joint"]).controller.network
    full = load(["+task=circle", "network=full"]).controller.network
    assert sized.model_dump(exclude={"name"}) == full.model_dump(exclude={"name"})


def test_per_joint_on_the_planar_arm_has_two_joints_of_everything(load):
    exp = load(PLANAR)
    net = exp.controller.network
    sizes = {k: (p.size, p.microcomplexes) for k, p in net.populations.items()}
    assert sizes == {"mf": (80, 2), "cf": (200, 2), "gc": (20000, 2), "pc": (200, 2), "dcn": (200, 2)}
    assert net.projections["mf_gc"].rule.joints == 2
    assert net.projections["pf_pc"].synapses == 20000 * 200 and net.projections["mf_dcn"].synapses == 80 * 200
    # each PC sees a third of full's PFs (2 joints, not 6): weights, range and steps x 3 keep its drive (the
    # experiment gives the steps 0.0133333 / -0.0066667, so upper_limb's 0.04 / -0.02 after the x 3)
    pf = net.projections["pf_pc"]
    assert pf.weight_nS == pytest.approx(6.0) and pf.weight_range_nS == pytest.approx((0.0, 15.0))
    assert pf.plasticity.ltp_nS == pytest.approx(0.04, rel=1e-5)
    assert pf.plasticity.ltd_nS == pytest.approx(-0.02, rel=1e-4)
    assert net.projections["mf_dcn"].weight_nS == pytest.approx(0.3)
    assert net.projections["pc_dcn"].weight_nS == 1.0  # one_to_one: not scaled
    # one-entry gains are given to both joints
    assert exp.controller.error.kpos == (2.0, 2.0) and exp.controller.error.kvel == (0.25, 0.25)


def test_a_random_rule_gets_its_expected_count_and_a_bad_population_is_left_to_validation():
    net = {"per_joint": {"a": 10, "b": 20}, "populations": {"a": {"size": 1}, "b": {"size": 1}},
           "projections": {"ab": {"pre": "a", "post": "b", "rule": {"kind": "fixed_probability", "p": 0.1}},
                           "zz": {"pre": "a", "post": "nowhere", "rule": {"kind": "all_to_all"}, "synapses": 7}}}
    out = sized_network(net, 3)
    assert out["populations"]["a"] == {"size": 30, "microcomplexes": 3}
    assert out["projections"]["ab"]["synapses"] == 180  # 30 x 60 x 0.1
    assert out["projections"]["zz"]["synapses"] == 7
    assert "per_joint" not in out and "per_joint" in net  # the input is not changed


@pytest.mark.parametrize("override, problem", [
    ("+controller.network.per_joint.gcc=100", "controller.network.per_joint.gcc: no population 'gcc'"),
    ("controller.network.per_joint.gc=0", "controller.network.per_joint.gc: 0 is not a positive")])
def test_a_bad_per_joint_entry_is_one_line(load, override, problem):
    with pytest.raises(ConfigError, match=problem):
        load([*PLANAR, override])


def test_a_composite_part_is_sized_too(load):
    """The distributed-plasticity network of the Luque LWR task is the snn part of a composite controller."""
    exp = load(["+experiment=luque2011_distributed"])
    net = exp.controller.parts[1].network
    assert net.populations["gc"].size == 30000 and net.projections["mf_gc"].rule.joints == 3
    assert exp.controller.parts[1].decoder.alpha_Nm_per_spike == (1.0, 1.0, 1.0)


def _learns(load, tmp_path, overrides, trials):
    s = run_experiment(load([*overrides, f"trials={trials}"]), tmp_path)
    assert s["status"] == "completed", s
    mae = np.asarray(s["mae_per_trial"])
    return mae[0], mae[-3:].mean()


@pytest.mark.slow
def test_the_planar_arm_learns_the_sine_from_scratch(load, tmp_path):
    first, last = _learns(load, tmp_path, PLANAR, 15)
    assert last < 0.6 * first, (first, last)  # measured: 0.272 -> 0.09 at trial 12


@pytest.mark.slow
def test_poisson_mossy_fibres_on_a_random_granular_layer_learn(load, tmp_path):
    first, last = _learns(load, tmp_path, ["+experiment=snn_planar2_poisson"], 30)
    assert last < 0.7 * first, (first, last)  # measured: 0.296 -> ~0.1 at trial 24
