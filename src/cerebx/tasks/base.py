"""The task contract: a periodic desired trajectory sampled on the control grid."""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class TrialReference:
    """Desired joint positions/velocities for one trial, one row per control step.

    Parameters
    ----------
    q, qd : numpy.ndarray (steps, n_joints)
        Desired joint positions (rad) and velocities (rad/s).
    xyz : numpy.ndarray (steps, 3), optional
        The desired Cartesian path when the task is defined in Cartesian space, m.
    label : str
        The trial's name (e.g. which figure of a task that alternates).
    extra : dict of str to numpy.ndarray (steps, n_joints)
        Further reference arrays by name, e.g. ``{"qdd": ...}``: the loop puts row i into the brain frame as
        ``ref.<name>`` (the task's schema declares them in ``extra_reference``).
    """

    q: np.ndarray
    qd: np.ndarray
    xyz: np.ndarray | None = None
    label: str = ""
    extra: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def steps(self) -> int:
        return self.q.shape[0]


class Task(ABC):
    """A task produces one :class:`TrialReference` per trial; trials are back-to-back periods."""

    period_s: float
    control_dt_s: float

    @property
    def steps_per_trial(self) -> int:
        return int(round(self.period_s / self.control_dt_s))

    @abstractmethod
    def trial(self, index: int, rng: np.random.Generator) -> TrialReference:
        """The reference for trial ``index`` (the rng draws per-trial choices, e.g. a reach target)."""

    @abstractmethod
    def start_position(self) -> np.ndarray:
        """Joint positions where the plant starts (the robot is not moved to the path first)."""

    def first_sample(self) -> np.ndarray:
        """Joint positions of the path's first sample (where ``start_at: path`` puts the plant)."""
        return self.start_position()

    def envelope(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Min/max of desired position and velocity over all trial variants, per joint.

        Encoders derive their ranges from this. The default samples the first trial.
        """
        ref = self.trial(0, np.random.default_rng(0))
        return ref.q.min(0), ref.q.max(0), ref.qd.min(0), ref.qd.max(0)
