"""Fig. 4.5 from run summaries: run selection by content, trials to 0.1 rad, perturbation deviation."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from cerebx.config import compose
from cerebx.report.runs import Run, RunSet
from cerebx_thesis.report.upper_limb import PATHWAY_MS, fig4_5, learning_runs, perturbation_runs, trials_to

pytestmark = pytest.mark.integration


def _run(tmp: Path, name: str, task: str, period: float, spinal: str, mae, vel, events=(), warmup=0,
         pathway=PATHWAY_MS) -> Run:
    cfg = {"plant": {"kind": "upper_limb"}, "controller": {"kind": "snn", "pathway_delay_ms": pathway},
           "spinal": {"kind": spinal},
           "task": {"kind": task, "period_s": period}, "events": list(events), "init_from": None,
           "warmup_trials": warmup}
    summary = {"task": task, "controller": "snn", "status": "completed", "trials_completed": len(mae),
               "mae_per_trial": list(mae), "vel_mae_per_trial": list(vel), "warmup_trials": warmup,
               "sim_seconds": period * len(mae)}
    return Run(tmp / name, summary, cfg)


def test_fig4_5_selects_runs_and_measures(tmp_path):
    decay = 0.3 * np.exp(-np.arange(50) / 10.0) + 0.03
    runs = RunSet()
    for spinal, scale in (("spinal_cord", 1.0), ("direct_muscles", 1.5)):
        for task, period in (("flexion_extension", 3.0), ("vertical_circle", 3.0), ("vertical_circle", 1.5)):
            runs.append(_run(tmp_path, f"{spinal}{task}{period}", task, period, spinal, decay * scale, decay * 3))
        for k in range(8):
            a = np.radians(45 * k)
            ev = [{"at_s": 5.25, "action": {"kind": "force_pulse", "force_N": [20 * np.cos(a), 0.0, 20 * np.sin(a)]}}]
            mae = [0, 0, 0.05, 0.05 + 0.01 * scale]  # 2 warm-up, nominal, perturbed
            runs.append(_run(tmp_path, f"p{spinal}{k}", "vertical_circle", 1.5, spinal, mae, [0.1] * 4, ev, warmup=2))
        ev0 = [{"at_s": 5.25, "action": {"kind": "force_pulse", "force_N": [0.0, 0.0, 0.0]}}]
        runs.append(_run(tmp_path, f"z{spinal}", "vertical_circle", 1.5, spinal, [0, 0, 0.05, 0.045], [0.1] * 4, ev0,
                         warmup=2))
    learn, pert = learning_runs(RunSet(runs)), perturbation_runs(RunSet(runs))
    assert set(learn) == {(t, s) for t in ("flexion_extension", "circle_slow", "circle_fast")
                          for s in ("spinal_cord", "direct_muscles")}
    assert sorted(a for s, a in pert if s == "spinal_cord" and a is not None) == [0, 45, 90, 135, 180, 225, 270, 315]
    assert ("spinal_cord", None) in pert  # the zero-force reference
    # first trial at or below 0.1 rad: 0.3 e^(-k/10) + 0.03 <= 0.1  ->  k = 15 (trial 16)
    assert trials_to(learn[("circle_fast", "spinal_cord")]) == 16
    out = fig4_5(RunSet(runs), tmp_path / "fig4_5")
    assert out.files[0].exists()
    rows = {r[0]: r for r in out.table}
    assert rows["position MAE (rad), fast circle, with SC"][1] == "0.020 ± 0.003"
    assert rows["trials to 0.1 rad, slow circle, with SC"][2] == "16"
    assert rows["MAE deviation under 20 N pulses, with SC (rad; mean over directions)"][2] == "0.015"
    assert rows["MAE deviation under 20 N pulses, without SC (rad; mean over directions)"][2] == "0.020"


def test_other_pathways_are_sensitivity_rows_not_panels(tmp_path):
    """Runs with chapter 2's 2 x 50 ms pathway (study fig4_5_learn_d50) never replace the preset's runs in the
    panels; they are listed in the table as sensitivity rows."""
    decay = 0.3 * np.exp(-np.arange(50) / 10.0) + 0.03
    runs = RunSet()
    for spinal in ("spinal_cord", "direct_muscles"):
        runs.append(_run(tmp_path, f"a{spinal}", "vertical_circle", 1.5, spinal, decay, decay * 3))
        # longer, so the "longest run" rule would pick it if the pathway were not checked
        runs.append(_run(tmp_path, f"b{spinal}", "vertical_circle", 1.5, spinal, np.full(80, 0.07), np.full(80, 0.8),
                         pathway=50.0))
    learn = learning_runs(runs)
    assert learn[("circle_fast", "spinal_cord")].n_measured == 50
    out = fig4_5(runs, tmp_path / "fig4_5")
    rows = {r[0]: r for r in out.table}
    assert rows["position MAE (rad), fast circle, with SC"][2] == "0.033 ± 0.000"  # last 5 of 0.3 e^(-k/10) + 0.03
    assert rows["sensitivity, pathway 2 × 50 ms: position MAE (rad), fast circle, with SC"][2] == "0.070 ± 0.000"
    assert rows["sensitivity, pathway 2 × 50 ms: trials to 0.1 rad, fast circle, with / without SC"][2] == "1 / 1"


def test_preset_pathway_is_the_reports():
    cfg = compose(["+experiment=upper_limb", "+task=vertical_circle_fast"])
    assert cfg.controller.pathway_delay_ms == PATHWAY_MS
    plast = cfg.controller.network.projections.pf_pc.plasticity
    assert (plast.kernel_peak_ms, plast.kernel_onset_ms) == (2 * PATHWAY_MS + 50, 2 * PATHWAY_MS + 20)
