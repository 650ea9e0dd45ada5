"""Input ranges of the cerebellar encoders (MF box coding, ANN state bins), shared by the
spiking and rate-based controllers. Each ranges kind (``given``, ``from_task``) computes its own
bounds (``schema/controller.py``)."""

from __future__ import annotations

from typing import Any

import numpy as np

from cerebx.schema.controller import GivenRanges, TaskRanges


def mf_ranges(ranges: GivenRanges | TaskRanges, n_joints: int, task: Any = None) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi), each (n_joints, 4), for the signals q_d, q, qd_d, qd."""
    return ranges.bounds(n_joints, task)
