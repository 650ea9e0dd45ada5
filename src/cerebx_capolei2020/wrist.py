"""iCub right wrist carrying a table with a rolling ball (Capolei et al. 2020), torque-controlled.

Controlled joints, in the paper's order: 1 pronosupination, 2 yaw, 3 pitch (the kinematic chain is
prosup -> pitch -> yaw, as on the robot). The rest of the arm is fixed. The MJCF beside this file
says which numbers are from the NRP iCub model and which are constructed. The encoders are sampled
at ``sample_rate_hz`` and held between samples; ``sensor_noise`` adds U(-a, a) to each sampled
position and velocity. The ball starts at rest ``ball_drop_height_m`` above the table centre when
the plant is reset (it is dropped on the table in the first trial; the drop point is drawn within
``ball_drop_jitter_m`` of the centre from the run's seed, so repetitions differ) and is put back there whenever
it falls ``ball_lost_below_m`` below the table.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np

from cerebx.api import BuildContext, Plant
from cerebx_capolei2020.schema import ICubWristConfig

MJCF = Path(__file__).with_name("icub_wrist.xml")
JOINTS = ("r_wrist_prosup", "r_wrist_yaw", "r_wrist_pitch")


class ICubWrist(Plant):
    joint_names = JOINTS
    control_dt_s = 0.002

    def __init__(self, cfg: ICubWristConfig, ctx: BuildContext | None = None):
        self.cfg = cfg
        spec = mujoco.MjSpec.from_file(str(MJCF))
        if not cfg.ball:
            spec.delete(spec.body("ball"))
        spec.option.timestep = cfg.physics_dt_ms / 1000.0
        self.model = spec.compile()
        m = self.model
        self._dof = np.array([m.jnt_dofadr[m.joint(j).id] for j in JOINTS])
        self._qadr = np.array([m.jnt_qposadr[m.joint(j).id] for j in JOINTS])
        m.dof_damping[self._dof] = cfg.damping_Nms_per_rad
        m.dof_armature[self._dof] = cfg.armature_kgm2
        self._limit = np.asarray(cfg.torque_limit_Nm, float)
        act_joint = m.actuator_trnid[:, 0]
        self._act = np.array([list(act_joint).index(m.joint(j).id) for j in JOINTS])
        m.actuator_ctrlrange[self._act, 0] = -self._limit
        m.actuator_ctrlrange[self._act, 1] = self._limit
        self.data = mujoco.MjData(m)
        self.physics_dt_s = cfg.physics_dt_ms / 1000.0
        self._n = self.substeps
        self._table = m.site("table_centre").id
        self._ball_q = m.jnt_qposadr[m.joint("ball").id] if cfg.ball else None
        self._ball_v = m.jnt_dofadr[m.joint("ball").id] if cfg.ball else None
        self._period_s = 1.0 / cfg.sample_rate_hz
        self._rng = np.random.default_rng(0)
        self._ticks = 0          # control steps since reset
        self._samples = 0        # encoder samples taken since reset
        self._held = (np.zeros(3), np.zeros(3))
        self.balls_dropped = 0

    def reset(self, q0: np.ndarray, rng: np.random.Generator) -> None:
        mujoco.mj_resetData(self.model, self.data)
        self.data.qpos[self._qadr] = q0
        mujoco.mj_forward(self.model, self.data)
        self._rng = rng
        self._ticks = 0
        self._samples = 0
        self.balls_dropped = 0
        self._drop_ball()

    def __setstate__(self, state: dict) -> None:
        # Checkpoints written before the sample counters existed carry the running sum ``_next_sample_s``.
        if "_next_sample_s" in state:
            t = float(state["data"].time)
            state["_ticks"] = int(round(t / self.control_dt_s))
            state["_samples"] = int(round(state.pop("_next_sample_s") * state["cfg"].sample_rate_hz))
        self.__dict__.update(state)

    def _drop_ball(self) -> None:
        if self._ball_q is None:
            return
        a, v = self._ball_q, self._ball_v
        j = self.cfg.ball_drop_jitter_m
        dx, dy = self._rng.uniform(-j, j, 2) if j > 0 else (0.0, 0.0)
        self.data.qpos[a:a + 3] = self.data.site_xpos[self._table] + (dx, dy, self.cfg.ball_drop_height_m)
        self.data.qpos[a + 3:a + 7] = (1.0, 0.0, 0.0, 0.0)
        self.data.qvel[v:v + 6] = 0.0
        mujoco.mj_forward(self.model, self.data)
        self.balls_dropped += 1

    def sensors(self) -> tuple[np.ndarray, np.ndarray]:
        # Sample k is due at k / sample_rate_hz. Both sides are products of whole counts, never running sums:
        # MuJoCo's clock is a sum of 0.5 ms steps and drifts from one by 2e-9 s after about 188 s, which once
        # moved every later sample one control tick late (Capolei's case A stepped at trial 48).
        if self._ticks * self.control_dt_s + 1e-9 >= self._samples * self._period_s:
            q, qd = self.true_state()
            a = self.cfg.sensor_noise
            if a > 0:
                q += self._rng.uniform(-a, a, 3)
                qd += self._rng.uniform(-a, a, 3)
            self._held = (q, qd)
            self._samples += 1
        return self._held[0].copy(), self._held[1].copy()

    def true_state(self) -> tuple[np.ndarray, np.ndarray]:
        return self.data.qpos[self._qadr].copy(), self.data.qvel[self._dof].copy()

    def apply(self, tau: np.ndarray) -> np.ndarray:
        applied = np.minimum(np.maximum(tau, -self._limit), self._limit)
        self.data.ctrl[self._act] = applied
        return applied

    def step(self) -> None:
        mujoco.mj_step(self.model, self.data, nstep=self._n)
        self._ticks += 1
        if self._ball_q is not None and self.cfg.ball_reset:
            if self.data.qpos[self._ball_q + 2] < self.data.site_xpos[self._table][2] - self.cfg.ball_lost_below_m:
                self._drop_ball()

    @property
    def time_s(self) -> float:
        return float(self.data.time)

    def joint_limits(self) -> tuple[np.ndarray, np.ndarray]:
        r = self.model.jnt_range[[self.model.joint(j).id for j in JOINTS]]
        return r[:, 0].copy(), r[:, 1].copy()

    def torque_limits(self) -> np.ndarray:
        return self._limit.copy()

    def end_effector(self) -> np.ndarray:
        """Table centre (world frame)."""
        return self.data.site_xpos[self._table].copy()

    def ball_on_table(self) -> np.ndarray | None:
        """Ball position in the table frame (m), None without a ball."""
        if self._ball_q is None:
            return None
        R = self.data.site_xmat[self._table].reshape(3, 3)
        return R.T @ (self.data.qpos[self._ball_q:self._ball_q + 3] - self.data.site_xpos[self._table])
