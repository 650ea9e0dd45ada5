"""Learning-curve summaries with known answers (docs/models.md#learning-curve-summaries)."""

from __future__ import annotations

import numpy as np
import pytest

from cerebx.metrics import TrialAccumulator, final_mae, torque_variability_of_mean, trials_to_threshold, window_stats


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


def test_torque_variability_of_the_trial_averaged_torque():
    """Eq. 3.13-3.15: the torque is averaged over trials before differencing, so trial-to-trial noise
    drops out: a ramp of 0.1 N·m per 2 ms step (0.05 N·m/ms) plus +-1 N·m noise that flips sign from
    one trial to the next gives 0.05 exactly, where the per-trial value is dominated by the noise."""
    steps, joints = 50, 2
    ramp = 0.1 * np.arange(steps)[:, None] * np.ones(joints)
    noise = np.where(np.arange(steps) % 2, 1.0, -1.0)[:, None] * np.ones(joints)
    tau = np.stack([ramp + noise, ramp - noise, ramp + noise, ramp - noise])
    assert torque_variability_of_mean(tau) == pytest.approx(0.05)
    per_trial = np.mean([np.abs(np.diff(t, axis=0)).mean() / 2.0 for t in tau])
    assert per_trial == pytest.approx((2.1 + 1.9) / 2 / 2.0)
    with pytest.raises(ValueError):
        torque_variability_of_mean(ramp)


def test_accumulated_rows_are_the_array_differences_bit_for_bit():
    rng = np.random.default_rng(3)
    acc = TrialAccumulator(3, steps=50, n_command=4)
    rows = [rng.normal(size=(4, 3)) for _ in range(50)]
    taus = rng.normal(size=(50, 4))
    for (q_des, q, qd_des, qd), tau in zip(rows, taus):
        acc.add(q_des, q, qd_des, qd, tau)
    want_pos = np.array([r[0] - r[1] for r in rows])
    want_vel = np.array([r[2] - r[3] for r in rows])
    assert acc.pos_err.tobytes() == want_pos.tobytes() and acc.vel_err.tobytes() == want_vel.tobytes()
    assert acc.tau.tobytes() == taus.tobytes()
    with pytest.raises(IndexError):  # a trial's rows are full: numpy's error, no write past the end
        acc.add(*rows[0], taus[0])
    other = TrialAccumulator(3, steps=2)
    other.add(np.ones(3), 0.5, np.ones(3), np.zeros(3), np.ones(3))  # a scalar broadcasts, as with numpy
    assert other.pos_err[0].tolist() == [0.5, 0.5, 0.5]
