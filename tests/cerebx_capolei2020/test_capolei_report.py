"""Capolei et al. 2020's Fig. 5 and Table II from fabricated run summaries: IV's drop against I over the seeds,
receptive-field counts over the repetitions, and the checks of the paper's claims."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from cerebx.report.runs import Run, RunSet
from cerebx_capolei2020 import report

pytestmark = pytest.mark.unit

ARCH = {"I": "capolei_arch1", "II": "capolei_arch2", "III": "capolei_arch3", "IV": "capolei_arch4"}


def _run(tmp: Path, label: str, case: str, seed: int, mae, rfs: dict[str, float] | None = None) -> Run:
    """A repetition of architecture ``label`` in ``case``: MAE per trial and joint (trials x 3)."""
    cfg = {"plant": {"sensor_noise": 0.1 if case == "B" else 0.0},
           "controller": {"parts": [{"kind": "pid"}, {"kind": "capolei_forward", "correct_from_trial": 7}]}}
    summary = {"task": "wrist_oscillation", "plant": "icub_wrist", "controller": "composite", "status": "completed",
               "seed": seed, "presets": {"controller": ARCH[label]}, "trials_completed": len(mae),
               "mae_per_joint_per_trial": np.asarray(mae, float).tolist(), "mae_per_trial": list(np.mean(mae, 1)),
               "rfs": rfs or {}}
    return Run(tmp / f"{label}{case}{seed}", summary, cfg)


def _mae(level, n: int = 20, drop_from: int = 7, to=None) -> np.ndarray:
    m = np.tile(np.asarray(level, float), (n, 1))
    if to is not None:
        m[drop_from + 1:] = to
    return m


def test_ivs_drop_against_i_is_taken_per_seed_with_the_papers_number(tmp_path):
    runs = RunSet()
    for seed in range(4):
        runs.append(_run(tmp_path, "I", "A", seed, _mae([0.10, 0.10, 0.05])))
        ours = [0.10 * (0.80 + 0.005 * seed), 0.10 * (0.12 - 0.01 * seed), 0.04]
        runs.append(_run(tmp_path, "IV", "A", seed, _mae([0.10, 0.10, 0.05], to=ours)))
    runs.append(_run(tmp_path, "IV", "A", 9, _mae([0.1, 0.1, 0.05])))  # no I of its seed: left out
    g = report.groups(runs)
    drops = report.drop_per_seed(g, 1, 12)
    assert drops == pytest.approx([88.0, 89.0, 90.0, 91.0])
    fig = report.fig5(runs, tmp_path / "fig5")
    iv = fig.intervals[report.drop_row(1, 12, 7)]
    assert iv.n == 4 and iv.mean == pytest.approx(89.5) and iv.paper == (90.0, 90.0) and iv.paper_in_ci == "yes"
    assert fig.intervals[report.drop_row(0, 12, 7)].paper_in_ci == "no"  # 19.3 ± 1.0 %: not 12 %
    row = next(r for r in fig.table if r[0] == report.drop_row(1, 12, 7))
    assert row[1] == "90 %" and "; over seeds 90 [" in row[2]
    holds = {c.claim.split(" at trial")[0].split(" (")[0]: c.holds for c in fig.checks}
    assert holds["IV below I on joint 1"] and holds["IV below I on joint 2"]
    assert holds["IV's drop against I larger on joint 2 than on joint 1"]


def test_fig5_checks_iv_faster_than_ii_and_iii_and_the_noise_costing_i_most(tmp_path):
    runs = RunSet()
    for seed in range(2):
        runs.append(_run(tmp_path, "I", "A", seed, _mae([0.1, 0.1, 0.1])))
        runs.append(_run(tmp_path, "I", "B", seed, _mae([0.2, 0.2, 0.2])))
        for label, after in (("II", 0.08), ("III", 0.07), ("IV", 0.05)):
            runs.append(_run(tmp_path, label, "A", seed, _mae([0.1, 0.1, 0.1], to=after)))
            runs.append(_run(tmp_path, label, "B", seed, _mae([0.1, 0.1, 0.1], to=after * 1.1)))
    holds = {c.claim.split(":")[0].split(" (")[0]: c.holds for c in report.fig5(runs, tmp_path / "f").checks}
    assert holds["IV corrects faster than II and III"]
    assert holds["the noise"]


def test_table2_gives_counts_over_repetitions_and_checks_the_papers_claims(tmp_path, monkeypatch):
    monkeypatch.setattr(report, "receptive_fields", lambda r: r.summary["rfs"])
    counts = {("II", "A"): {"inverse": 8}, ("II", "B"): {"inverse": 14}, ("III", "A"): {"forward": 80},
              ("III", "B"): {"forward": 150}, ("IV", "A"): {"inverse": 11, "forward": 430},
              ("IV", "B"): {"inverse": 16, "forward": 500}}
    runs = RunSet(_run(tmp_path, label, case, seed, _mae([0.1, 0.1, 0.1]),
                       {k: v + seed - 1 for k, v in rfs.items()})
                  for (label, case), rfs in counts.items() for seed in range(3))
    fig = report.table2(runs, tmp_path / "t2")
    assert all(len(row) == 3 for row in fig.table)  # quantity, paper, cerebx: the columns of paper_vs_cerebx.csv
    iv = fig.intervals[report.rf_row("IV", "forward", "B")]
    assert iv.n == 3 and iv.mean == 500 and iv.paper == (510, 510)
    assert [c.holds for c in fig.checks] == [True, True, True]
    counts[("IV", "B")]["forward"] = 420  # fewer with noise than without
    runs = RunSet(_run(tmp_path, label, case, 0, _mae([0.1, 0.1, 0.1]), rfs) for (label, case), rfs in counts.items())
    assert [c.holds for c in report.table2(runs, tmp_path / "t3").checks] == [False, True, True]
