"""A planar two-link arm (shoulder, elbow) in a vertical plane, driven by joint torques.

A real, small MuJoCo plant for fast tests and demos: two capsule links with point-like masses,
joint damping and armature, motors saturating at ``torque_limit_Nm``. Joint 0 at q = 0 points the
upper arm horizontally along +x; gravity acts along -z when enabled.
"""

from __future__ import annotations

import mujoco
import numpy as np

from cerebx.plants.base import Plant
from cerebx.schema.plant import Planar2Config


def planar2_mjcf(cfg: Planar2Config) -> str:
    (l1, l2), (m1, m2) = cfg.link_length_m, cfg.link_mass_kg
    g = "0 0 -9.81" if cfg.gravity else "0 0 0"
    return f"""
<mujoco model="planar2">
  <compiler angle="radian"/>
  <option timestep="{cfg.physics_dt_ms / 1000.0}" gravity="{g}" integrator="implicitfast"/>
  <default><joint type="hinge" axis="0 -1 0" damping="{cfg.damping_Nms_per_rad}" armature="{cfg.armature_kgm2}"
    limited="true" range="-3.1 3.1"/><geom type="capsule" size="0.02" contype="0" conaffinity="0"/></default>
  <worldbody>
    <body name="upper" pos="0 0 0">
      <joint name="shoulder"/>
      <geom fromto="0 0 0 {l1} 0 0" mass="0"/>
      <inertial pos="{l1 / 2} 0 0" mass="{m1}" diaginertia="{m1 * l1 ** 2 / 12} {m1 * l1 ** 2 / 12} 1e-4"/>
      <body name="fore" pos="{l1} 0 0">
        <joint name="elbow"/>
        <geom fromto="0 0 0 {l2} 0 0" mass="0"/>
        <inertial pos="{l2 / 2} 0 0" mass="{m2}" diaginertia="{m2 * l2 ** 2 / 12} {m2 * l2 ** 2 / 12} 1e-4"/>
        <site name="end_effector" pos="{l2} 0 0"/>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor joint="shoulder" ctrllimited="true" ctrlrange="-{cfg.torque_limit_Nm[0]} {cfg.torque_limit_Nm[0]}"/>
    <motor joint="elbow" ctrllimited="true" ctrlrange="-{cfg.torque_limit_Nm[1]} {cfg.torque_limit_Nm[1]}"/>
  </actuator>
</mujoco>"""


class Planar2Arm(Plant):
    joint_names = ("shoulder", "elbow")
    control_dt_s = 0.002

    def __init__(self, cfg: Planar2Config, ctx=None):
        self.cfg = cfg
        self.model = mujoco.MjModel.from_xml_string(planar2_mjcf(cfg))
        self.data = mujoco.MjData(self.model)
        self.physics_dt_s = cfg.physics_dt_ms / 1000.0
        self._limit = np.asarray(cfg.torque_limit_Nm, float)
        self._site = self.model.site("end_effector").id
        self._rng = np.random.default_rng(0)
        self._n = self.substeps

    def reset(self, q0: np.ndarray, rng: np.random.Generator) -> None:
        mujoco.mj_resetData(self.model, self.data)
        self.data.qpos[:] = q0
        mujoco.mj_forward(self.model, self.data)
        self._rng = rng

    def sensors(self) -> tuple[np.ndarray, np.ndarray]:
        q, qd = self.data.qpos.copy(), self.data.qvel.copy()
        if self.cfg.sensor_noise_rad > 0:
            q += self._rng.normal(0.0, self.cfg.sensor_noise_rad, q.shape)
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

    def end_effector(self) -> np.ndarray:
        return self.data.site_xpos[self._site].copy()
