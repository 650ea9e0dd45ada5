"""Luque et al. 2011's figures from fabricated run summaries: Fig. 11's error reduction and stability improvement
per object mass over seeds, and the checks of Figs. 7c, 8, 10 and 12."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from cerebx.report.explain import explain, load_explanations
from cerebx.report.registry import Figure
from cerebx.report.runs import Run, RunSet
from cerebx_luque2011 import report

pytestmark = pytest.mark.unit


def _run(tmp: Path, name: str, mae_sum, mass: float = 1.0, seed: int = 0, ltd: float = 0.075, ltp: float = 0.01,
         peak: float = 100.0, delay: float = 100.0) -> Run:
    """A Luque eight run (one warm-up trial) whose MAE summed over the 3 joints is ``mae_sum`` after it."""
    cer = {"kind": "luque2011_cerebellum",
           "plasticity": {"ltd_nS": ltd, "ltp_nS": ltp, "kernel_peak_ms": peak, "arm_lag_ms": 70.0}}
    cfg = {"controller": {"parts": [{"kind": "crude_inverse_dynamics"}, cer]}, "plant": {"object_mass_kg": mass},
           "delay": {"total_ms": delay}, "events": [], "init_from": None}
    mae = [1.0, *(np.asarray(mae_sum, float) / 3)]
    summary = {"task": "luque_eight", "controller": "composite", "delay": "constant", "status": "completed",
               "seed": seed, "warmup_trials": 1, "trials_completed": len(mae), "mae_per_trial": mae,
               "sim_seconds": float(len(mae))}
    return Run(tmp / name, summary, cfg)


def _learning(start: float, end: float, n: int = 400, tau: float = 40.0, noise: float = 0.0, seed: int = 0):
    k = np.arange(n)
    wiggle = noise * np.random.default_rng(seed).standard_normal(n) * np.exp(-k / 150)
    return end + (start - end) * np.exp(-k / tau) + wiggle


def test_error_reduction_and_stability_improvement_of_one_run():
    m = np.r_[np.full(30, 1.0) + np.tile([0.1, -0.1], 15), np.full(370, 0.4) + np.tile([0.02, -0.02], 185)]
    assert report.stability_improvement_pct(list(m), 200) == pytest.approx(80.0)
    run = _run(Path("/nonexistent"), "r", m, mass=0.5)
    h = report.headline(run)
    assert h["0.5 kg: error reduction by trial 200"] == pytest.approx(100 * (1 - 0.4 / 1.1))
    assert h["0.5 kg: stability improvement, trials 370–400 vs 0–30"] == pytest.approx(80.0)
    # what the two are made of: the mean and the spread of the MAE over the first 30 trials and the 30 before t
    assert h["0.5 kg: MAE over trials 170–200 (rad)"] == pytest.approx(0.4)
    assert h["0.5 kg: std of the MAE over trials 0–30 (rad)"] == pytest.approx(0.1)
    assert h["0.5 kg: std of the MAE over trials 370–400 (rad)"] == pytest.approx(0.02)


def test_fig12_gives_the_error_reduction_over_seeds_and_checks_fig11s_numbers(tmp_path):
    runs = RunSet()
    for seed in range(3):
        for i, mass in enumerate((0.5, 1.0, 1.5, 2.0)):
            start = 1.0 + mass
            curve = _learning(start, start * (0.6 - 0.12 * i), noise=0.05 * (4 - i) / 4 + 0.01, seed=seed)
            runs.append(_run(tmp_path, f"m{mass}s{seed}", curve, mass=mass, seed=seed))
    ivs = report.fig12_intervals(runs)
    iv = ivs["2 kg: error reduction by trial 400"]
    assert iv.n == 3 and iv.paper == (79.3, 79.3) and iv.has_interval
    assert ivs["0.5 kg: stability improvement, trials 170–200 vs 0–30"].paper == (82.0, 82.0)
    fig = report.fig12(runs, tmp_path / "fig12")
    assert fig.intervals == ivs
    row = next(r for r in fig.table if r[0] == "2 kg: error reduction by trial 400")
    assert row[1] == "79.3 %" and "; over seeds " in row[2] and "(3 seeds)" in row[2]
    row = next(r for r in fig.table if r[0] == "2 kg: MAE over trials 170–200 (rad)")
    assert row[1] == "–" and "; over seeds " in row[2] and ivs[row[0]].paper is None
    holds = {c.claim.split(" (")[0]: c.holds for c in fig.checks}
    assert holds["accuracy gain grows with the mass"] and holds["heavier objects start with a higher error"]
    assert holds["the error is significantly reduced for every mass: by at least 30 % by trial 400"]
    short = RunSet(_run(tmp_path, f"q{mass}", _learning(1 + mass, 0.5, n=199), mass=mass) for mass in (0.5, 1.0))
    claims = [c.claim for c in report.fig12(short, tmp_path / "short").checks]
    assert any(c.startswith("the error is significantly reduced for every mass") and "by trial 200" in c
               for c in claims)
    assert holds["the error reduction by trial 400 grows with the mass"]
    assert holds["the MAE varies less between trials 370–400 than in the first 30 for every mass"]


def test_fig10_checks_follow_the_papers_words(tmp_path):
    learns = {d: _learning(3.0, 0.5 + 0.05 * abs(d) / 70) for d in (-70, -50, 0, 50, 70)}
    unstable = {d: np.r_[_learning(3.0, 0.5, 300), np.linspace(0.5, 1.0, 100)] for d in (100, 150)}
    runs = RunSet(_run(tmp_path, f"d{d}", m, peak=100.0 + d) for d, m in {**learns, **unstable}.items())
    checks = report._fig10_checks(runs.by(lambda r: report._cer(r, "plasticity.kernel_peak_ms") - 100.0))
    assert [c.claim.split(" (")[0] for c in checks] == ["50-70 ms of mismatch still learns",
                                                       "the final error keeps constant up to 70 ms of mismatch",
                                                       "beyond 70 ms of mismatch learning is unstable"]
    assert all(c.holds for c in checks)


def test_fig8_checks_compare_the_dominated_corners_with_the_balanced_points():
    def est(final, stability, gain):
        return {"final error (rad)": final, "final error stability (rad)": stability, "accuracy gain (rad)": gain,
                "convergence (trials)": 100.0}

    grid = {(ltd, ltp): est(0.5, 0.02, 2.0) for ltd in (0.025, 0.075, 0.2) for ltp in (0.001, 0.005, 0.015, 0.05)}
    grid[0.025, 0.05] = est(2.0, 0.001, 0.5)  # LTP dominating: saturated
    grid[0.2, 0.001] = est(0.45, 0.2, 2.1)  # LTD dominating: good but unstable
    grid[0.075, 0.015] = grid[0.075, 0.05] = est(1.5, 0.005, 1.0)
    grid[0.075, 0.001] = grid[0.075, 0.005] = est(0.4, 0.01, 2.2)
    checks = report._fig8_checks(grid)
    assert len(checks) == 6 and all(c.holds for c in checks), [c for c in checks if not c.holds]
    grid[0.075, 0.015] = est(0.3, 0.005, 2.5)  # LTD 0.075 with LTP 0.015 as good as below it
    assert not report._fig8_checks(grid)[-1].holds


def test_fig7c_checks_read_the_block_pattern():
    rng = np.random.default_rng(1)
    w = np.full((48, 120), 20.0) + rng.uniform(-0.2, 0.2, (48, 120))
    for j in range(3):  # + rows dark at the left side of each block, - rows dark at the right side
        for c in range(6):
            w[16 * j: 16 * j + 8, 20 * c: 20 * c + 2] = 2.0 + 3 * j
            w[16 * j + 8: 16 * j + 16, 20 * c + 18: 20 * c + 20] = 3.0 + 3 * j
    assert [c.holds for c in report.fig7c_checks(w)] == [True, True, True]
    assert [c.holds for c in report.fig7c_checks(np.full((48, 120), 20.0))] == [False, False, False]


def test_each_explanation_links_the_failing_check_it_names(tmp_path):
    """Every entry of the plugin's explanations file starts a claim that its figure makes: when that check fails
    in the full profile it carries the link; in the quick profile, and when it holds, it carries none."""
    known = load_explanations(Path(report.__file__).with_name("explanations.yaml"))
    grid = {(ltd, ltp): {"final error (rad)": 0.1, "final error stability (rad)": 0.003, "accuracy gain (rad)": 0.4,
                         "convergence (trials)": 100.0}
            for ltd in (0.025, 0.075, 0.2) for ltp in (0.001, 0.005, 0.01, 0.05)}
    grid[0.025, 0.05] = grid[0.2, 0.001] = {"final error (rad)": 0.46, "final error stability (rad)": 0.0,
                                            "accuracy gain (rad)": 0.005, "convergence (trials)": 1.0}
    same = _learning(0.5, 0.06)  # the same curve for every point: nothing grows or falls with the mass
    figures = {
        "luque2011_fig7c": report.fig7c_checks(np.full((48, 120), 20.0)),
        "luque2011_fig8": report._fig8_checks(grid),
        "luque2011_fig9": report.fig9(RunSet(_run(tmp_path, f"d{d}", _learning(0.5, f), peak=d, delay=d)
                                             for d, f in ((100.0, 0.06), (150.0, 0.124))), tmp_path / "f9").checks,
        "luque2011_fig10": report._fig10_checks({d: _run(tmp_path, f"p{d}", _learning(0.5, f), peak=100.0 + d)
                                                 for d, f in ((-70.0, 0.117), (0.0, 0.06), (70.0, 0.161))}),
        "luque2011_fig12": report.fig12(RunSet(_run(tmp_path, f"m{m}", same, mass=m) for m in (0.5, 1.0, 2.0)),
                                        tmp_path / "f12").checks,
    }
    used = set()
    for name, checks in figures.items():
        for profile, linked in (("full", True), ("quick", False)):
            fig = Figure([], "", checks=checks)
            explain(name, fig, profile, known)
            for c in fig.checks:
                hit = [e for e in known if e.figure == name and c.claim.startswith(e.claim)]
                assert (c.explained_at is not None) == (linked and c.holds is False and bool(hit)), c.claim
                if c.explained_at:
                    assert c.explained_at == f"docs/{hit[0].at}"
                    used.add((name, hit[0].claim))
    assert used == {(e.figure, e.claim) for e in known}, "an explanation names no claim its figure makes"
