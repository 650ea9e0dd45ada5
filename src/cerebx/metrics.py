"""Per-trial metrics (docs/models.md#metrics): position MAE per joint and mean (Eq. 2.21-2.22 with |.|),
velocity MAE, torque variability (Eq. 3.14-3.15, absolute step differences, N·m/ms; per trial here,
over the trial-averaged torque in :func:`torque_variability_of_mean`, Eq. 3.13),
end-effector Cartesian error; and learning-curve summaries over trial windows."""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np


@dataclass(frozen=True)
class TrialMetrics:
    trial: int
    mae: float
    mae_per_joint: tuple[float, ...]
    vel_mae: float
    torque_variability_Nm_per_ms: float
    ee_error_m: float | None


@numba.njit(cache=True, boundscheck=False)
def _put_row(q_des, q, qd_des, qd, tau, pos_err, vel_err, taus, i):  # pragma: no cover - numba
    """Row ``i`` of the errors (``q_des - q``, ``qd_des - qd``) and the command, in one compiled call."""
    for j in range(pos_err.shape[1]):
        pos_err[i, j] = q_des[j] - q[j]
        vel_err[i, j] = qd_des[j] - qd[j]
    for j in range(taus.shape[1]):
        taus[i, j] = tau[j]


_F64 = np.dtype(np.float64)


class TrialAccumulator:
    """Collects one trial's rows (preallocated) and reduces them once at the end of the trial."""

    def __init__(self, n_joints: int, steps: int, step_ms: float = 2.0, n_command: int | None = None):
        self.n, self.step_ms = n_joints, step_ms
        self.pos_err = np.zeros((steps, n_joints))
        self.vel_err = np.zeros((steps, n_joints))
        self.tau = np.zeros((steps, n_joints if n_command is None else n_command))  # the applied command
        self.ee_err = np.full(steps, np.nan)
        self.i = 0
        self._row = (n_joints,)

    def add(self, q_des, q, qd_des, qd, tau, ee_des=None, ee=None) -> None:
        i = self.i
        row = self._row
        try:
            fits = (i < len(self.tau) and q_des.shape == q.shape == qd_des.shape == qd.shape == row
                    and tau.shape == self.tau.shape[1:])
        except AttributeError:  # not arrays
            fits = False
        if fits:
            _put_row(q_des, q, qd_des, qd, tau, self.pos_err, self.vel_err, self.tau, i)
        else:  # numpy's broadcasting and errors
            np.subtract(q_des, q, out=self.pos_err[i])
            np.subtract(qd_des, qd, out=self.vel_err[i])
            self.tau[i] = tau
        if ee_des is not None and ee is not None:
            f64 = getattr(ee_des, "dtype", None) is _F64 is getattr(ee, "dtype", None)
            if f64 and ee_des.shape == ee.shape == (3,):  # Python floats: the same doubles, a third of numpy's time
                (a0, a1, a2), (b0, b1, b2) = ee_des.tolist(), ee.tolist()
                d0, d1, d2 = a0 - b0, a1 - b1, a2 - b2
            else:
                d = ee_des - ee
                d0, d1, d2 = d[0], d[1], d[2]
            self.ee_err[i] = (d0 * d0 + d1 * d1 + d2 * d2) ** 0.5
        self.i = i + 1

    def finish(self, trial: int) -> TrialMetrics:
        k = self.i
        per_joint = np.abs(self.pos_err[:k]).mean(0) if k else np.zeros(self.n)
        dtau = np.abs(np.diff(self.tau[:k], axis=0)).mean() / self.step_ms if k > 1 else 0.0
        ee = self.ee_err[:k]
        return TrialMetrics(
            trial=trial,
            mae=float(per_joint.mean()),
            mae_per_joint=tuple(float(x) for x in per_joint),
            vel_mae=float(np.abs(self.vel_err[:k]).mean()) if k else 0.0,
            torque_variability_Nm_per_ms=float(dtau),
            ee_error_m=float(np.nanmean(ee)) if k and np.isfinite(ee).any() else None,
        )


def torque_variability_of_mean(tau: np.ndarray, step_ms: float = 2.0) -> float:
    """Eq. 3.13-3.15: average the torque over trials step by step (``tau``: trials x steps x joints,
    each trial one period of a periodic task), then mean |tau(t) - tau(t - step)| / step over the steps and
    the joints, N·m/ms. Averaging removes the trial-to-trial part (spike noise, sensor noise), so for a
    controller whose output is not deterministic this is well below the per-trial value; for a
    deterministic one on a repeating task the two agree."""
    tau = np.asarray(tau, float)
    if tau.ndim != 3 or tau.shape[1] < 2:
        raise ValueError(f"torque_variability_of_mean: need trials x steps x joints with >= 2 steps, got {tau.shape}")
    return float(np.abs(np.diff(tau.mean(axis=0), axis=0)).mean() / step_ms)


def final_mae(mae_per_trial: list[float]) -> float | None:
    """Mean of the last 10 % of trials (at least one); None for no trials.

    Parameters
    ----------
    mae_per_trial : list of float
        The mean absolute joint error of each trial, rad.
    """
    if not mae_per_trial:
        return None
    k = max(1, int(round(0.1 * len(mae_per_trial))))
    return float(np.mean(mae_per_trial[-k:]))


def window_stats(mae_per_trial: list[float], start: int, stop: int) -> tuple[float, float] | None:
    """Mean and std of trials [start, stop) (docs/models.md#learning-curve-summaries)."""
    w = np.asarray(mae_per_trial[start:stop])
    if w.size == 0:
        return None
    return float(w.mean()), float(w.std())


def trials_to_threshold(mae_per_trial: list[float], threshold: float) -> int | None:
    """First trial whose MAE is at or below ``threshold`` (docs/models.md#learning-curve-summaries)."""
    for i, v in enumerate(mae_per_trial):
        if v <= threshold:
            return i
    return None


# ---- learning estimators over a MAE curve (one value per trial; docs/models.md#learning-estimators) ----------

def final_error(mae_per_trial: list[float], n: int = 30) -> float:
    """Eq. 9: mean MAE of the last ``n`` trials.

    Parameters
    ----------
    mae_per_trial : list of float
        The mean absolute joint error of each trial, rad (a summary's ``mae_per_trial``).
    n : int
        Trials at the end of the curve that make the final error (Luque et al. 2011 use 30).
    """
    return float(np.mean(np.asarray(mae_per_trial, float)[-n:]))


def accuracy_gain(mae_per_trial: list[float], n: int = 30) -> float:
    """Eq. 8: MAE of the first trial minus the final error (same unit as the MAE).

    Parameters
    ----------
    mae_per_trial : list of float
        The mean absolute joint error of each trial, rad (a summary's ``mae_per_trial``).
    n : int
        Trials at the end of the curve that make the final error (Luque et al. 2011 use 30).
    """
    return float(mae_per_trial[0]) - final_error(mae_per_trial, n)


def final_error_stability(mae_per_trial: list[float], n: int = 30) -> float:
    """Eq. 10: standard deviation of the MAE over the last ``n`` trials (lower = more stable).

    Parameters
    ----------
    mae_per_trial : list of float
        The mean absolute joint error of each trial, rad (a summary's ``mae_per_trial``).
    n : int
        Trials at the end of the curve that make the final error (Luque et al. 2011 use 30).
    """
    return float(np.std(np.asarray(mae_per_trial, float)[-n:]))


def convergence_speed(mae_per_trial: list[float], n: int = 30) -> int:
    """Eq. 11: the first trial whose MAE is at or below the final error (trials to converge).

    Parameters
    ----------
    mae_per_trial : list of float
        The mean absolute joint error of each trial, rad (a summary's ``mae_per_trial``).
    n : int
        Trials at the end of the curve that make the final error (Luque et al. 2011 use 30).
    """
    mae = np.asarray(mae_per_trial, float)
    return int(np.argmax(mae <= final_error(mae_per_trial, n)))


def improvement_pct(mae_per_trial: list[float], at_trial: int, n: int = 30) -> float:
    """Error reduction in % by ``at_trial``: 100 (1 - mean MAE of the ``n`` trials before it / MAE of the
    first trial) (docs/models.md#learning-estimators).

    Parameters
    ----------
    mae_per_trial : list of float
        The mean absolute joint error of each trial, rad (a summary's ``mae_per_trial``).
    at_trial : int
        The trial (0-based) the reduction is measured at.
    n : int
        Trials before ``at_trial`` whose mean MAE is compared with the first trial's.
    """
    mae = np.asarray(mae_per_trial, float)
    return float(100.0 * (1.0 - mae[max(0, at_trial - n):at_trial].mean() / mae[0]))
