"""What every MuJoCo arm whose first ``n_joints`` degrees of freedom are its controlled joints shares.

``qpos[:n]``/``qvel[:n]`` are the joint positions and velocities (further degrees of freedom, such as
series-elastic rotors or a hanging payload, are not sensed), ``ctrl`` holds one command per actuator
and an ``end_effector`` site (when the model has one) gives the hand. A subclass builds its model and
calls :meth:`MujocoArm._attach`; torque-driven arms (one motor per joint, saturating at the config's
``torque_limit_Nm``) take :meth:`apply` as it is.

Optional, from the config or the subclass: a first-order lag between the commanded and the produced
torque (``cfg.torque_lag_ms``), velocity noise (``cfg.sensor_noise_rad_per_s``), rotor joints that
start where their link joints do, and interactions (``plants/interaction.py``) the arm resets with
itself and calls around each physics step while they are active.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from typing import Any

import mujoco
import numba
import numpy as np

from cerebx.plants.base import Plant
from cerebx.plants.interaction import Interaction


@numba.njit(cache=True)
def _saturate(tau, limit, out):  # pragma: no cover - numba
    """``minimum(maximum(tau, -limit), limit)`` into ``out``, a NaN kept as numpy's keeps it."""
    for j in range(out.size):
        x = tau[j]
        lo = -limit[j]
        if x < lo:
            x = lo
        if x > limit[j]:
            x = limit[j]
        out[j] = x


@functools.cache
def _no_time() -> Any:
    """A compiled ``double (*)(void)`` returning 0, made on first use (~0.03 s once numba has compiled or loaded
    anything; not cached on disk: as a kernel of the run's own it would count toward the first run's compile
    notice at a kernel's ~0.9 s)."""

    @numba.cfunc(numba.float64())
    def zero() -> float:  # pragma: no cover - numba
        return 0.0

    return zero


def without_step_timers() -> None:
    """Turn MuJoCo's per-stage step timers off, unless a timer callback is installed already.

    With no ``mjcb_time`` MuJoCo times every stage of every step by the system clock (``MjData.timer``): on the
    development machine ~12 % of a plain ``mj_step`` loop's samples were in the clock. A callback that returns 0
    leaves the timers at zero and the trajectory bit for bit the same; the Baxter's 2 ms control step (four
    physics steps) took 32-35 instead of 37-40 µs (docs/guide/speed.md#mujoco-timers). The callback is global to
    the process; ``mujoco.set_mjcb_time(None)`` brings the timers back."""
    if mujoco.get_mjcb_time() is None:
        mujoco.set_mjcb_time(_no_time().ctypes)


class MujocoArm(Plant):
    cfg: Any
    model: mujoco.MjModel
    data: mujoco.MjData
    interactions: tuple[Interaction, ...] = ()

    def _attach(
        self, cfg: Any, model: mujoco.MjModel, site: str | None = "end_effector", rotors: Sequence[str] = ()
    ) -> None:
        """Keep ``model`` and its data; the physics step from ``cfg.physics_dt_ms``; ``rotors`` name one
        rotor joint per controlled joint (series-elastic actuators), placed at the joint's position by reset."""
        self.cfg = cfg
        self.model, self.data = model, mujoco.MjData(model)
        without_step_timers()
        self.physics_dt_s = cfg.physics_dt_ms / 1000.0
        self._n = self.substeps
        if self._n < 1 or abs(self._n * self.physics_dt_s - self.control_dt_s) > 1e-12:
            raise ValueError(
                f"physics_dt_ms {cfg.physics_dt_ms} does not divide the {self.control_dt_s * 1e3:g} ms control step"
            )
        self._site = model.site(site).id if site is not None else None
        limit = getattr(cfg, "torque_limit_Nm", None)
        self._limit = np.asarray(limit, float) if limit is not None else None
        self._noise = (getattr(cfg, "sensor_noise_rad", 0.0), getattr(cfg, "sensor_noise_rad_per_s", 0.0))
        self._rotor_q = np.array([model.jnt_qposadr[model.joint(r).id] for r in rotors], dtype=int)
        self._cmd = np.zeros(model.nu)
        self._nj = self.n_joints
        lag_s = getattr(cfg, "torque_lag_ms", 0.0) / 1000.0
        self._lag_gain = 1.0 - np.exp(-self.physics_dt_s / lag_s) if lag_s > 0 else 1.0
        self._rng = np.random.default_rng(0)

    def __setstate__(self, state: dict[str, Any]) -> None:
        """Unpickled (a resumed run's checkpoint): the step timers off in this process too."""
        self.__dict__.update(state)
        without_step_timers()

    def reset(self, q0: np.ndarray, rng: np.random.Generator) -> None:
        mujoco.mj_resetData(self.model, self.data)
        for interaction in self.interactions:
            interaction.reset()
        q0 = np.asarray(q0, dtype=float)
        self.data.qpos[: self.n_joints] = q0
        if len(self._rotor_q):
            self.data.qpos[self._rotor_q] = q0
        self._cmd[:] = 0.0
        mujoco.mj_forward(self.model, self.data)
        self._rng = rng

    def sensors(self) -> tuple[np.ndarray, np.ndarray]:
        """Joint state with Gaussian noise of ``cfg.sensor_noise_rad`` and ``cfg.sensor_noise_rad_per_s``
        (when the config has them)."""
        n = self._nj
        q, qd = self.data.qpos[:n].copy(), self.data.qvel[:n].copy()
        noise_q, noise_qd = self._noise
        if noise_q > 0:
            q += self._rng.normal(0.0, noise_q, q.shape)
        if noise_qd > 0:
            qd += self._rng.normal(0.0, noise_qd, qd.shape)
        return q, qd

    def true_state(self) -> tuple[np.ndarray, np.ndarray]:
        n = self._nj
        return self.data.qpos[:n].copy(), self.data.qvel[:n].copy()

    def apply(self, tau: np.ndarray) -> np.ndarray:
        """Saturate ``tau``; without a torque lag it is the motors' control at once, with one
        :meth:`step` moves the control towards it."""
        if tau.shape == self._cmd.shape == self._limit.shape:  # every tick: one compiled call
            _saturate(tau, self._limit, self._cmd)
        else:
            np.minimum(np.maximum(tau, -self._limit, out=self._cmd), self._limit, out=self._cmd)
        if self._lag_gain == 1.0:
            self.data.ctrl[:] = self._cmd
        return self._cmd.copy()

    def step(self) -> None:
        m, d = self.model, self.data
        lagged = self._lag_gain < 1.0
        if not lagged:
            for interaction in self.interactions:
                if interaction.active:
                    break
            else:  # nothing to do between physics steps: MuJoCo steps on its own
                mujoco.mj_step(m, d, nstep=self._n)
                return
        for _ in range(self._n):
            if lagged:  # the produced torque approaches the command with the lag's time constant
                d.ctrl[:] += self._lag_gain * (self._cmd - d.ctrl)
            for interaction in self.interactions:
                if interaction.active:
                    interaction.before_substep()
            mujoco.mj_step(m, d)
            for interaction in self.interactions:
                if interaction.active:
                    interaction.after_substep()

    @property
    def time_s(self) -> float:
        return float(self.data.time)

    def joint_limits(self) -> tuple[np.ndarray, np.ndarray]:
        r = self.model.jnt_range[: self.n_joints]
        return r[:, 0].copy(), r[:, 1].copy()

    def torque_limits(self) -> np.ndarray | None:
        return None if self._limit is None else self._limit.copy()

    def end_effector(self) -> np.ndarray | None:
        return None if self._site is None else self.data.site_xpos[self._site].copy()
