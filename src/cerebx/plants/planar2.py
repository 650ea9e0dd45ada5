"""A planar two-link arm (shoulder, elbow) in a vertical plane, driven by joint torques.

A real, small MuJoCo plant for fast tests and demos: two capsule links with point-like masses,
joint damping and armature, motors saturating at ``torque_limit_Nm``. Joint 0 at q = 0 points the
upper arm horizontally along +x; gravity acts along -z when enabled.
"""

from __future__ import annotations

import mujoco

from cerebx.builders import BuildContext
from cerebx.plants.mujoco_arm import MujocoArm
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


class Planar2Arm(MujocoArm):
    joint_names = ("shoulder", "elbow")
    control_dt_s = 0.002

    def __init__(self, cfg: Planar2Config, ctx: BuildContext | None = None):
        self._attach(cfg, mujoco.MjModel.from_xml_string(planar2_mjcf(cfg)))
