"""What every MuJoCo arm whose joints are the model's degrees of freedom shares.

``qpos``/``qvel`` are the joint positions and velocities, ``ctrl`` holds one command per actuator and
an ``end_effector`` site (when the model has one) gives the hand. A subclass builds its model and
calls :meth:`MujocoArm._attach`; torque-driven arms (one motor per joint, saturating at the
config's ``torque_limit_Nm``) take :meth:`apply` as it is.
"""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np

from cerebx.plants.base import Plant


class MujocoArm(Plant):
    cfg: Any
    model: mujoco.MjModel
    data: mujoco.MjData

    def _attach(self, cfg: Any, model: mujoco.MjModel, site: str | None = "end_effector") -> None:
        """Keep ``model`` and its data; the physics step from ``cfg.physics_dt_ms``."""
        self.cfg = cfg
        self.model, self.data = model, mujoco.MjData(model)
        self.physics_dt_s = cfg.physics_dt_ms / 1000.0
        self._site = model.site(site).id if site is not None else None
        limit = getattr(cfg, "torque_limit_Nm", None)
        self._limit = np.asarray(limit, float) if limit is not None else None
        self._rng = np.random.default_rng(0)
        self._n = self.substeps

    def reset(self, q0: np.ndarray, rng: np.random.Generator) -> None:
        mujoco.mj_resetData(self.model, self.data)
        self.data.qpos[:] = q0
        mujoco.mj_forward(self.model, self.data)
        self._rng = rng

    def sensors(self) -> tuple[np.ndarray, np.ndarray]:
        """Joint state with Gaussian position noise of ``cfg.sensor_noise_rad`` (when the config has it)."""
        q, qd = self.data.qpos.copy(), self.data.qvel.copy()
        noise = getattr(self.cfg, "sensor_noise_rad", 0.0)
        if noise > 0:
            q += self._rng.normal(0.0, noise, q.shape)
        return q, qd

    def true_state(self) -> tuple[np.ndarray, np.ndarray]:
        return self.data.qpos.copy(), self.data.qvel.copy()

    def apply(self, tau: np.ndarray) -> np.ndarray:
        applied = np.minimum(np.maximum(tau, -self._limit), self._limit)
        self.data.ctrl[:] = applied
        return applied

    def step(self) -> None:
        mujoco.mj_step(self.model, self.data, nstep=self._n)

    @property
    def time_s(self) -> float:
        return float(self.data.time)

    def joint_limits(self) -> tuple[np.ndarray, np.ndarray]:
        r = self.model.jnt_range
        return r[:, 0].copy(), r[:, 1].copy()

    def torque_limits(self) -> np.ndarray | None:
        return None if self._limit is None else self._limit.copy()

    def end_effector(self) -> np.ndarray | None:
        return None if self._site is None else self.data.site_xpos[self._site].copy()
