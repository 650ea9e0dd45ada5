"""Input ranges of the cerebellar encoders (MF box coding, ANN state bins), shared by the
spiking and rate-based controllers."""

from __future__ import annotations

from typing import Any

import numpy as np

from cerebx.schema.controller import GivenRanges, TaskRanges


def mf_ranges(ranges: GivenRanges | TaskRanges, n_joints: int, task: Any = None) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi), each (n_joints, 4), for the signals q_d, q, qd_d, qd.

    ``given``: the ranges as configured (q_d and q share the position range, as in the original).
    ``from_task``: the task's desired envelope widened by ``margin`` (positions) and
    ``velocity_margin`` (velocities) of its span; actual and desired share the range.
    """
    if isinstance(ranges, GivenRanges):
        r = ranges
        if min(len(r.q_min), len(r.qd_min), len(r.qd_des_min)) < n_joints:
            raise ValueError(f"controller ranges: given ranges cover fewer than the {n_joints} controlled joints")
        qlo, qhi = np.asarray(r.q_min, float), np.asarray(r.q_max, float)
        lo = np.stack([qlo, qlo, np.asarray(r.qd_des_min, float), np.asarray(r.qd_min, float)], axis=1)
        hi = np.stack([qhi, qhi, np.asarray(r.qd_des_max, float), np.asarray(r.qd_max, float)], axis=1)
        return lo[:n_joints], hi[:n_joints]
    if task is None:
        raise ValueError("controller ranges: 'from_task' needs a task to derive the encoder ranges")
    q_min, q_max, qd_min, qd_max = (np.asarray(a, dtype=float)[:n_joints] for a in task.envelope())

    def widen(a: np.ndarray, b: np.ndarray, m: float) -> tuple[np.ndarray, np.ndarray]:
        span = np.maximum(b - a, 1e-3)
        return a - m * span, b + m * span

    qlo, qhi = widen(q_min, q_max, ranges.margin)
    vlo, vhi = widen(qd_min, qd_max, ranges.velocity_margin)
    return np.stack([qlo, qlo, vlo, vlo], axis=1), np.stack([qhi, qhi, vhi, vhi], axis=1)
