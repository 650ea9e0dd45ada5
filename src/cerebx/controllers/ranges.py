"""Input ranges of the cerebellar encoders (MF box coding, ANN state bins), shared by the
spiking and rate-based controllers. Each ranges kind (``given``, ``from_task``) computes its own
bounds (``schema/controller.py``)."""

from __future__ import annotations

from typing import Any

import numpy as np

from cerebx.schema.controller import GivenRanges, TaskRanges


def mf_ranges(ranges: GivenRanges | TaskRanges, n_joints: int, task: Any = None) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi), each (n_joints, 4), for the signals q_d, q, qd_d, qd: the ranges a mossy-fibre encoder
    spans.

    Parameters
    ----------
    ranges : GivenRanges or TaskRanges
        The controller's ``ranges``: given, or derived from the task's envelope.
    n_joints : int
        Joints encoded.
    task : Task, optional
        The task (needed by ``TaskRanges``).
    """
    return ranges.bounds(n_joints, task)
