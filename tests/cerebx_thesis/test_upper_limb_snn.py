"""The 2-joint cerebellum on the upper limb (thesis ch. 4): the network keeps Table 2.1's synaptic drive per
cell, its PCs act on the DCN from the first trial, and (slow) it learns the fast circle with the spinal cord."""

from __future__ import annotations

import numpy as np
import pytest

from cerebx.loop.runner import run_experiment
from cerebx.recording.reader import read_messages

pytestmark = pytest.mark.integration

FAST = ["+experiment=upper_limb", "+task=vertical_circle_fast", "spinal=cord", "recording.joint_states=false"]


def _per_post(net, name):
    p = net.projections[name]
    return p.synapses / net.populations[p.post].size


def test_the_2_joint_network_keeps_the_table_2_1_drive_per_cell(load):
    """PF-PC and MF-DCN are all-to-all: 2 joints instead of 6 give each PC / DCN a third of the inputs (and a
    third of them active per step), so the weights are 3 x Table 2.1's: synapses per cell x weight agree."""
    ul = load([*FAST]).controller.network
    ch2 = load(["+task=circle", "network=thesis_ch2"]).controller.network
    assert ul.name == "upper_limb" and ch2.name == "thesis_ch2"
    assert _per_post(ch2, "pf_pc") == 3 * _per_post(ul, "pf_pc") == 60000
    assert _per_post(ch2, "mf_dcn") == 3 * _per_post(ul, "mf_dcn") == 240
    for name, key in (("mf_dcn", "weight_nS"), ("pf_pc", "weight_range_nS")):
        a, b = np.asarray(getattr(ul.projections[name], key)), np.asarray(getattr(ch2.projections[name], key))
        np.testing.assert_allclose(_per_post(ul, name) * a, _per_post(ch2, name) * b)
    ltp, ltd = ul.projections["pf_pc"].plasticity.ltp_nS, ul.projections["pf_pc"].plasticity.ltd_nS
    ch2_rule = ch2.projections["pf_pc"].plasticity
    assert ltp / ltd == pytest.approx(ch2_rule.ltp_nS / ch2_rule.ltd_nS)  # LTP:LTD as Table 2.1


def _dcn_rate(load, tmp, extra):
    s = run_experiment(load([*FAST, "trials=1", "controller.plasticity=false", *extra]), tmp)
    assert s["status"] == "completed", s
    rates = [m["dcn_rate_hz"] for _, _, m in read_messages(tmp) if "dcn_rate_hz" in m]
    assert len(rates) == 1
    return rates[0]


def test_the_pcs_hold_the_dcn_below_their_mf_drive_from_the_start(load, tmp_path):
    """With the PCs silenced (PF-PC 0) the DCN fire at their MF/CF drive; at the preset's initial PF-PC weight
    the PCs fire and inhibit them, so PF-PC learning can move the output both ways. (At Table 2.1's
    unscaled weights both rates were the same, ~108 Hz: the PCs never fired and nothing was learned.)"""
    silent = _dcn_rate(load, tmp_path / "silent", ["controller.network.projections.pf_pc.weight_nS=0.0"])
    preset = _dcn_rate(load, tmp_path / "preset", [])
    assert silent > 200.0  # ~260 Hz: up to 26 spikes of 50 cells per 2 ms, M up to ~0.65 at full scale 40
    assert 30.0 < preset < 0.5 * silent  # ~80 Hz


@pytest.mark.slow
def test_the_cerebellum_learns_the_fast_circle_through_the_spinal_cord(load, tmp_path):
    s = run_experiment(load([*FAST, "trials=100"]), tmp_path)
    mae = np.asarray(s["mae_per_trial"])
    assert s["status"] == "completed" and len(mae) == 100
    first, last = mae[:10].mean(), mae[-10:].mean()
    assert last < 0.6 * first, (first, last)
    assert last < 0.2, last
