"""Learning-curve summaries with known answers (docs/models.md#learning-curve-summaries)."""

from __future__ import annotations

import numpy as np
import pytest

from cerebx.metrics import TrialAccumulator, final_mae, trials_to_threshold, window_stats


def test_final_mae_is_mean_of_last_ten_percent():
    assert final_mae(list(range(20))) == pytest.approx(18.5)  # last 2 of 20
    assert final_mae([3.0, 1.0]) == 1.0  # at least one trial
    assert final_mae([]) is None


def test_window_stats_and_threshold():
    mae = [0.2, 0.1, 0.05, 0.03, 0.02]
    assert window_stats(mae, 1, 3) == pytest.approx((0.075, 0.025))
    assert window_stats(mae, 10, 20) is None
    assert trials_to_threshold(mae, 0.05) == 2
    assert trials_to_threshold(mae, 0.001) is None


def test_accumulator_mae_and_torque_variability():
    acc = TrialAccumulator(2, steps=3, step_ms=2.0)
    for k in range(3):
        acc.add(np.array([1.0, 0.0]), np.array([0.5, 0.0]), np.zeros(2), np.array([0.1, -0.1]),
                np.array([2.0 * k, 0.0]))
    m = acc.finish(0)
    assert m.mae_per_joint == pytest.approx((0.5, 0.0)) and m.mae == pytest.approx(0.25)
    assert m.vel_mae == pytest.approx(0.1)
    assert m.torque_variability_Nm_per_ms == pytest.approx(0.5)  # |Δτ| = 2 N·m on one of 2 joints per 2 ms
