"""Muscles between the cerebellum's commands and the joints (docs/models.md#ekeberg).

:class:`Ekeberg` is one antagonist muscle pair per joint (Eq. 4.6): an active torque set by the
agonist/antagonist commands, and a passive spring towards the resting pose, whose stiffness grows
with the commands and the cocontraction baseline c, plus damping. :class:`MuscleRest` is the
brain-side controller that commands no activity (M_ag = M_at = 0).
"""

from __future__ import annotations

from typing import Any

import numba
import numpy as np

from cerebx.builders import BuildContext
from cerebx.schema.muscles import EkebergConfig, MuscleRestController
from cerebx.signals import Frame
from cerebx.stages.base import Stage


def ekeberg_torque(ag: np.ndarray, at: np.ndarray, q: np.ndarray, qd: np.ndarray, p: dict[str, np.ndarray]
                   ) -> tuple[np.ndarray, np.ndarray]:
    """(active, passive) joint torques of Eq. 4.6; their sum is the muscle torque. ``p`` holds the per-joint
    alpha, beta, gamma, delta, c and q_rest."""
    active = p["alpha"] * (ag - at)
    passive = p["beta"] * (ag + at + 2.0 * p["c"] + p["gamma"]) * (p["q_rest"] - q) + p["delta"] * qd
    return active, passive


@numba.njit(cache=True, boundscheck=False)
def _ekeberg(ag, at, q, qd, params, out):  # pragma: no cover - numba
    """:func:`ekeberg_torque` and the sum joint by joint into ``out`` = (active, passive, total); ``params``:
    (alpha, beta, gamma, delta, c, q_rest). The array form's operations in its order, so the same doubles (one
    compiled call instead of eleven array operations, ~9 us a tick; returning three new arrays instead cost it
    ~0.9 us more, numba boxing them through Python)."""
    alpha, beta, gamma, delta, c, q_rest = params
    active, passive, total = out
    for j in range(alpha.size):
        a = alpha[j] * (ag[j] - at[j])
        b = beta[j] * (ag[j] + at[j] + 2.0 * c[j] + gamma[j]) * (q_rest[j] - q[j]) + delta[j] * qd[j]
        active[j], passive[j], total[j] = a, b, a + b


class Ekeberg(Stage):
    """Robot side: muscle.ag, muscle.at (link) and joint.q, joint.qd (the plant) -> joint.torque."""

    name = "ekeberg"

    def __init__(self, cfg: EkebergConfig, n_joints: int):
        self.params = {
            "alpha": np.asarray(cfg.alpha_Nm, float), "beta": np.asarray(cfg.beta_Nm_per_rad, float),
            "gamma": np.asarray(cfg.gamma, float), "delta": np.asarray(cfg.delta_Nms_per_rad, float),
            "c": cfg.cocontraction * np.asarray(cfg.cocontraction_base, float),
            "q_rest": np.asarray(cfg.rest_pose_rad, float),
        }
        io = cfg.io(n_joints)
        self.reads, self.writes = io.reads, io.writes
        self.active = self.passive = np.zeros(n_joints)
        self._params = tuple(self.params[k] for k in ("alpha", "beta", "gamma", "delta", "c", "q_rest"))

    def step(self, frame: Frame) -> None:
        sig = frame.signals
        ag, at, q, qd = sig["muscle.ag"], sig["muscle.at"], sig["joint.q"], sig["joint.qd"]
        n = self._params[0].size
        if ag.shape == at.shape == q.shape == qd.shape == (n,):  # every tick: one compiled call, new arrays
            out = self.active, self.passive, total = np.empty(n), np.empty(n), np.empty(n)
            _ekeberg(ag, at, q, qd, self._params, out)
        else:
            self.active, self.passive = ekeberg_torque(ag, at, q, qd, self.params)
            total = self.active + self.passive
        self.emit(frame, "joint.torque", total)

    def record(self) -> dict[str, Any]:
        return {"tau_muscle_active": self.active, "tau_muscle_passive": self.passive}

    def describe(self) -> dict[str, Any]:
        return {"cocontraction_c": self.params["c"].tolist()}


def build_ekeberg(cfg: EkebergConfig, ctx: BuildContext) -> Ekeberg:
    return Ekeberg(cfg, ctx.plant.n_joints)


class MuscleRest(Stage):
    """Brain side: M_ag = M_at = 0 for every joint."""

    name = "muscle_rest"

    def __init__(self, n_joints: int):
        self.zero = np.zeros(n_joints)

    def step(self, frame: Frame) -> None:
        self.emit(frame, "muscle.ag", self.zero)
        self.emit(frame, "muscle.at", self.zero)


def build_muscle_rest(cfg: MuscleRestController, ctx: BuildContext) -> MuscleRest:
    return MuscleRest(ctx.plant.n_joints)
