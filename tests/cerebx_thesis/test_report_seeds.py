"""Headline numbers of the thesis's figures over independently learned seeds, from fabricated run summaries:
Tables 2.3 / 2.4 per stage, Fig. 3.6's slope, Fig. 4.6 A per cocontraction; and the checks of their claims."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from cerebx.report.runs import Run, RunSet
from cerebx_thesis.report import stages
from cerebx_thesis.report.learning import table2_3

pytestmark = pytest.mark.unit


def _learner(tmp: Path, name: str, task: str, mae, seed: int = 0, kernel_ms: float = 100.0) -> Run:
    """An snn run learning ``task`` from scratch with one PF-PC kernel peaking at ``kernel_ms``."""
    cfg = {"init_from": None, "events": [], "controller": {"network": {"projections": {
        "pf_pc": {"plasticity": {"kind": "kernel_stdp", "kernel_peak_ms": kernel_ms}}}}}}
    summary = {"task": task, "controller": "snn", "delay": "none", "status": "completed", "seed": seed,
               "trials_completed": len(mae), "mae_per_trial": list(mae), "sim_seconds": 2.0 * len(mae)}
    return Run(tmp / name, summary, cfg)


def _factory(tmp: Path, task: str, level: float) -> Run:
    summary = {"task": task, "controller": "position", "delay": "none", "status": "completed", "seed": 0,
               "presets": {"controller": "position_factory"}, "trials_completed": 5, "mae_per_trial": [level] * 5,
               "sim_seconds": 10.0}
    return Run(tmp / f"factory_{task}", summary, {"events": []})


def _curve(n: int, start: float, end: float, tau: float) -> np.ndarray:
    return end + (start - end) * np.exp(-np.arange(n) / tau)


def test_stage_intervals_take_each_seeds_stage_means_with_the_thesis_mean(tmp_path):
    runs = [_learner(tmp_path, f"s{k}", "circle", np.full(500, 0.02 + 0.001 * k), seed=k) for k in range(3)]
    ivs = stages.stage_intervals(runs, "circle")
    assert [iv.n for iv in ivs] == [3, 3, 3]
    assert ivs[2].mean == pytest.approx(0.021) and ivs[2].values == pytest.approx((0.020, 0.021, 0.022))
    assert [iv.paper for iv in ivs] == [(0.115, 0.115), (0.036, 0.036), (0.019, 0.019)]
    assert ivs[2].paper_in_ci == "yes"  # 0.021 ± 4.303 · 0.001 / √3 holds 0.019
    # a 300-trial run's windows are the thesis's scaled by 300 / 500
    short = _learner(tmp_path, "short", "circle", np.r_[np.full(60, 0.1), np.full(240, 0.02)])
    assert stages.stage_means(short, "circle") == pytest.approx([0.1, 0.02, 0.02])


def test_table2_3_gives_every_stage_over_seeds_and_checks_the_tables_claims(tmp_path):
    runs = RunSet()
    for k in range(3):
        runs.append(_learner(tmp_path, f"c{k}", "circle", _curve(500, 0.12, 0.019 + 0.001 * k, 40), seed=k))
        runs.append(_learner(tmp_path, f"e{k}", "eight", _curve(500, 0.11, 0.017, 80), seed=k))
    runs.append(_learner(tmp_path, "e_short", "eight", _curve(400, 0.11, 0.017, 80), seed=3))  # still learning
    runs.append(_learner(tmp_path, "other_kernel", "circle", np.full(500, 0.5), seed=1, kernel_ms=150.0))
    runs += [_factory(tmp_path, "circle", 0.077), _factory(tmp_path, "eight", 0.063)]
    fig = table2_3(RunSet(runs), tmp_path / "t")
    key = "circle: SNN MAE (rad), trials 400–500"
    assert fig.intervals[key].n == 3 and fig.intervals[key].mean == pytest.approx(0.020, abs=1e-4)
    assert fig.intervals["eight: SNN MAE (rad), trials 400–500"].n == 3  # the 400-trial seed is left out
    row = next(r for r in fig.table if r[0] == key)
    assert row[1] == "0.019 ± 0.003" and "; over seeds 0.020 [" in row[2] and "(3 seeds)" in row[2]
    holds = {c.claim.split(" (")[0]: c.holds for c in fig.checks}
    assert holds["circle: SNN MAE falls from stage to stage"]
    assert holds["eight: SNN MAE of the final stage below the factory position controller's"]
    # the eight learns with twice the circle's time constant: further from done at the intermediate stage
    assert holds["the eight converges more slowly than the circle: intermediate / initial stage MAE higher"]


def test_reaching_is_checked_for_its_spread_and_the_trials_it_needs(tmp_path):
    rng = np.random.default_rng(0)
    reach = _curve(1000, 0.15, 0.02, 150) + rng.uniform(-0.005, 0.005, 1000)
    runs = RunSet([_learner(tmp_path, "c", "circle", _curve(500, 0.12, 0.02, 30)),
                   _learner(tmp_path, "e", "eight", _curve(500, 0.11, 0.02, 30)),
                   _learner(tmp_path, "r", "reaching", reach)])
    fig = table2_3(runs, tmp_path / "t")
    holds = {c.claim.split(" (")[0]: c.holds for c in fig.checks}
    assert holds["reaching: higher std between trials at the final stage than circle and eight"]
    assert holds["reaching needs more trials to reach stability than circle and eight"]
    assert holds["reaching: SNN MAE of the final stage below the factory position controller's"] is None  # no run


def _kernel_run(tmp: Path, peak: float, seed: int, slope: float, pathway_ms: float | None = None) -> Run:
    """A kernel-sweep run: MAE = slope · peak + 0.004 (plus a little noise), pathway delay (peak - 50) / 2."""
    d = (peak - 50) / 2 if pathway_ms is None else pathway_ms
    cfg = {"init_from": None, "events": [], "controller": {"pathway_delay_ms": d, "network": {"projections": {
        "pf_pc": {"plasticity": {"kind": "kernel_stdp", "ltp_nS": 0.002, "ltd_nS": -0.0008, "kernel_peak_ms": peak,
                                 "kernel_onset_ms": peak - 30, "teacher": "cf_pc"}}}}}}
    mae = slope * peak + 0.004 + 0.0002 * np.sin(np.arange(120) + peak)
    summary = {"task": "circle", "controller": "snn", "delay": "none", "status": "completed", "seed": seed,
               "trials_completed": 120, "mae_per_trial": list(mae), "sim_seconds": 240.0}
    return Run(tmp / f"k{peak:g}s{seed}", summary, cfg)


def test_fig3_6_fits_a_slope_per_seed_and_keeps_other_designs_out(tmp_path):
    from cerebx_thesis.report.kernels import fig3_6, fig3_6_intervals, kernel_fit, kernel_runs

    peaks = [90.0, 130.0, 170.0, 210.0, 250.0]
    runs = RunSet(_kernel_run(tmp_path, p, k, 0.0001 * (1 + 0.1 * k)) for k in range(3) for p in peaks)
    runs.append(_kernel_run(tmp_path, 100.0, 0, 0.01, pathway_ms=50.0))  # chapter 2's circle: not a sweep point
    runs.append(_kernel_run(tmp_path, 90.0, 3, 0.0001))  # a seed that learned one kernel so far
    by_peak = kernel_runs(runs.seeds()[0])
    assert sorted(by_peak) == peaks
    assert kernel_fit(by_peak)[0] == pytest.approx(0.0001, rel=0.02)
    ivs = fig3_6_intervals(runs, peaks)
    slope = ivs["slope (rad/ms)"]
    assert slope.n == 3 and slope.mean == pytest.approx(0.00011, rel=0.02) and slope.paper == (0.000106, 0.000106)
    assert ivs["intercept (rad)"].mean == pytest.approx(0.004, abs=3e-4)
    fig = fig3_6(runs, tmp_path / "fig3_6")
    assert fig.intervals["slope (rad/ms)"].n == 3
    assert "; over seeds 0.000110 [" in next(r for r in fig.table if r[0] == "slope (rad/ms)")[2]


def test_fig3_6_checks_the_thesis_line_on_the_seed_mean(tmp_path):
    from cerebx_thesis.report.kernels import _fig3_6_shape, fig3_6_intervals, kernel_fit, kernel_runs

    peaks = [90.0, 130.0, 170.0, 210.0, 250.0]
    for slope, size in ((0.0001, True), (0.0004, False)):
        runs = RunSet(_kernel_run(tmp_path / str(slope), p, k, slope) for k in range(2) for p in peaks)
        by_peak = kernel_runs(runs.seeds()[0])
        checks, _ = _fig3_6_shape(runs, by_peak, {}, kernel_fit(by_peak), fig3_6_intervals(runs, peaks))
        holds = {c.claim.split(":")[0].split(" (")[0]: c.holds for c in checks}
        assert holds["MAE rises with the kernel peak"] and holds["the MAE evolves linearly with the kernel peak"]
        assert holds["the slope of the thesis's size"] is size
        assert holds["the shortest kernel peak gives the lowest MAE"]


def _muscle_run(tmp: Path, k: float, seed: int, level: float) -> Run:
    """An SNN run of the eight with the Table 4.1 muscle at cocontraction ``k``, evaluated from a learned state."""
    from cerebx.schema.muscles import EkebergConfig

    muscle = {**EkebergConfig().model_dump(mode="json"), "kind": "ekeberg", "cocontraction": k}
    cfg = {"init_from": f"learn/{k:g}", "events": [], "muscle": muscle}
    mae = level + 0.001 * np.sin(np.arange(100))
    summary = {"task": "eight", "controller": "snn", "delay": "none", "status": "completed", "seed": seed,
               "trials_completed": 100, "mae_per_trial": list(mae), "sim_seconds": 200.0}
    return Run(tmp / f"m{k:g}s{seed}", summary, cfg)


def test_fig4_6_gives_each_cocontractions_mae_over_seeds_and_checks_panel_a(tmp_path):
    from cerebx_thesis.report.baxter_muscles import RATIO_ROW, fig4_6, fig4_6_intervals, mae_row

    level = {0: 0.019, 1: 0.019, 5: 0.018, 9: 0.019, 10: 0.024, 12: 0.05}
    runs = RunSet(_muscle_run(tmp_path, float(k), s, v + 0.0005 * s) for s in range(3) for k, v in level.items())
    ivs = fig4_6_intervals(runs)
    assert ivs[mae_row(12)].n == 3 and ivs[mae_row(12)].mean == pytest.approx(0.0505, abs=1e-4)
    assert ivs[mae_row(0)].paper == (0.0189, 0.0189) and ivs[mae_row(0)].paper_in_ci == "yes"
    assert ivs[RATIO_ROW].mean == pytest.approx(0.0505 / 0.01925, rel=0.01)
    fig = fig4_6(runs, tmp_path / "fig4_6")
    assert "; over seeds 0.0505 [" in next(r for r in fig.table if r[0] == mae_row(12))[2]
    holds = {c.claim.split(":")[1].strip().split(" (")[0]: c.holds for c in fig.checks}
    assert holds == {"MAE flat up to x9": True, "x10 starts to degrade": True, "x12 degraded significantly": True,
                     "x12 the least accurate": True}
    # x10 no worse than the flat range: it has not started to degrade
    runs = RunSet(_muscle_run(tmp_path, float(k), 0, 0.019 if k == 10 else v) for k, v in level.items())
    holds = {c.claim.split(":")[1].strip(): c.holds for c in fig4_6(runs, tmp_path / "f2").checks}
    assert holds["x10 starts to degrade"] is False


def test_fig4_6_b_sag_values_within_the_constructed_tolerance_of_the_thesis():
    from cerebx_thesis.report.baxter_muscles import SAG_TOLERANCE, THESIS_SAG_CM, _sag_values

    near = {float(k): v * (1 + 0.9 * SAG_TOLERANCE) for k, v in THESIS_SAG_CM.items()}
    assert [c.holds for c in _sag_values(near)] == [True]
    assert [c.holds for c in _sag_values({**near, 0.0: 9.9 * (1 + 1.1 * SAG_TOLERANCE)})] == [False]
    assert _sag_values({}) == []
