"""Fig. 3.4's headline numbers over seeds: each seed's SNN sweep against the ANN of its seed, else the first
seed's (the ANN draws nothing at random), and PD's; the checks of the paper's 3-4x headline."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pytest

from cerebx.report.runs import Run, RunSet
from cerebx_thesis.report.constant_delays import _fig3_4_shape, _seed_band, fig3_4_intervals

pytestmark = pytest.mark.unit
KERNEL = {"pf_pc": {"plasticity": {"kind": "kernel_stdp", "kernel_peak_ms": 150.0}}}


def _run(tmp_path: Path, controller: str, seed: int, delay_ms: float, mae: float, origin: str | None) -> Run:
    d = tmp_path / f"{controller}_{seed}_{delay_ms:g}"
    d.mkdir(parents=True)
    summary = {"task": "circle", "controller": controller, "delay": "constant", "seed": seed, "status": "completed",
               "trials_completed": 4, "mae_per_trial": [mae] * 4, "sim_seconds": 8.0}
    config = {"delay": {"total_ms": delay_ms}, "init_from": origin,
              "controller": {"network": {"projections": KERNEL}} if controller == "snn" else {}}
    return Run(d, summary, config)


def _runs(tmp_path: Path) -> RunSet:
    runs = RunSet()
    for d, m in ((0.0, 0.08), (50.0, 0.10), (80.0, 0.14)):
        runs.append(_run(tmp_path, "pd", 0, d, m, None))
        runs.append(_run(tmp_path, "ann", 0, d, 0.02 if d < 80 else 0.08, "learn_ann"))
    for seed, base in ((0, 0.015), (1, 0.017), (2, 0.016)):
        for d, k in ((0.0, 1.0), (50.0, 1.1), (80.0, 1.25)):
            runs.append(_run(tmp_path, "snn", seed, d, base * k, f"learn_ch3_{seed}"))
    return runs


def test_each_seed_is_measured_against_the_deterministic_controllers(tmp_path):
    iv = fig3_4_intervals(_runs(tmp_path))
    pd = iv["PD average MAE ÷ SNN average MAE"]
    assert pd.n == 3 and pd.has_interval and pd.paper == (3.0, 4.0)
    # seed 0: PD's 0-50 ms mean 0.09 over the SNN's 0-80 ms mean
    assert pd.values[0] == pytest.approx(0.09 / np.mean([0.015, 0.0165, 0.01875]))
    assert iv["ANN average MAE ÷ SNN average MAE"].n == 3  # the first seed's ANN for seeds 1 and 2
    assert iv["SNN MAE ratio 80 / 0 ms"].values == pytest.approx((1.25, 1.25, 1.25))
    assert iv["PD MAE at δT = 0 ms (rad)"].n == 1 and iv["ANN average MAE over δT ≤ 50 ms (rad)"].n == 1


def test_the_headline_checks_decide_on_the_mean_over_seeds(tmp_path, monkeypatch):
    monkeypatch.setattr("cerebx_thesis.report.constant_delays.tv_as_paper", lambda run, controller: None)  # no logs
    runs = _runs(tmp_path)
    sweeps = {c: {r.delay_total_ms: r for r in runs.where(controller=c, seed=0)} for c in ("pd", "ann", "snn")}
    checks, _ = _fig3_4_shape(runs, sweeps, fig3_4_intervals(runs))
    by = {c.claim.split(" (")[0]: c for c in checks}
    assert by["PD mean MAE over 0–50 ms at least 2× the SNN's over 0–80 ms"].holds is True
    assert by["ANN mean MAE over 0–50 ms at least 2× the SNN's over 0–80 ms"].holds is False  # 0.02 / 0.0167
    assert by["the SNN's MAE barely deviates up to 80 ms"].holds is True


def test_the_seed_band_is_drawn_only_with_two_seeds_or_more(tmp_path):
    fig, ax = plt.subplots()
    assert "mean MAE over 3 independently learned" in _seed_band(ax, _runs(tmp_path))
    assert len(ax.containers) == 1
    plt.close(fig)
    fig, ax = plt.subplots()
    assert _seed_band(ax, RunSet(r for r in _runs(tmp_path / "x") if r.seed == 0)) == ""
    plt.close(fig)
