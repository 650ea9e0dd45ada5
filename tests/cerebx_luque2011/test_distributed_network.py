"""Worked network B (docs/networks/distributed.md): distributed plasticity (PF-PC, MF-DCN, PC-DCN) on the Luque
2011 LWR task. The experiment writes the network preset out (a composite part cannot take a preset): the two
stay equal; (slow) a reduced version learns."""

from __future__ import annotations

import numpy as np
import pytest

from cerebx.loop.runner import run_experiment

EXP = ["+experiment=luque2011_distributed"]
PART = "controller.parts.1"


def test_the_experiment_runs_the_luque_distributed_preset(load):
    part = load(EXP).controller.parts[1].network
    preset = load(["+experiment=luque2011_eight", "controller=snn", "network=luque_distributed",
                   "controller.error.kpos=[2.0]", "controller.error.kvel=[0.2]",
                   "controller.decoder.alpha_Nm_per_spike=[1.0]", "robot=[{kind: hold}]"]).controller.network
    assert part.model_dump(exclude={"neurons"}) == preset.model_dump(exclude={"neurons"})  # (named sets, unused)
    rules = {k: p.plasticity.kind for k, p in part.projections.items() if p.plasticity is not None}
    assert rules == {"pf_pc": "kernel_stdp", "mf_dcn": "symmetric_cos", "pc_dcn": "symmetric_cos_stdp"}


REDUCED = [*EXP, f"+{PART}.mf={{kind: box, fibers_per_signal: 5}}",
           f"{PART}.network.per_joint={{mf: 20, gc: 625, pc: 10, cf: 10, dcn: 10}}",
           f"{PART}.network.projections.mf_gc.rule.fibers_per_signal=5", f"{PART}.decoder.alpha_Nm_per_spike=[10.0]"]


@pytest.mark.slow
def test_a_reduced_distributed_network_learns_the_lwr_eight(load, tmp_path):
    s = run_experiment(load([*REDUCED, "trials=12"]), tmp_path)
    mae = np.asarray(s["mae_per_trial"])
    assert s["status"] == "completed" and mae[-3:].mean() < 0.8 * mae[1], mae  # trial 0 is the warm-up
