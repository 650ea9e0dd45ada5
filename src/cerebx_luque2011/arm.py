"""Three moving joints of a KUKA LWR 4+ (A1, A2, A4), torque-driven, with an object at the hand.

The MJCF beside this file (``lwr3.xml``) carries the URDF kinematics and inertias of the LWR 4+ of
kuka-isir/rtt_lwr (docs/provenance.md#lightweight-arm: 0.102 m base, 0.2085/0.1915 m segments, 2.3 kg
links); the DLR LWR-III of Luque et al. 2011 has the same layout but its parameters are not
published. Constructed here: which three joints move (A1 yaw, A2 shoulder pitch, A4 elbow pitch;
A3, A5-A7 are fixed at 0), the object's place (a sphere whose centre is 4 cm beyond the flange) and
the joint damping (1 N·m·s/rad, the Gazebo URDF's value).

=========  ==============  ========
signal     meaning         unit
=========  ==============  ========
joint.q    A1, A2, A4      rad
joint.qd   their velocity  rad/s
joint.torque  motor torque  N·m (saturated at 176, 176, 100)
=========  ==============  ========
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np

from cerebx.api import BuildContext, MujocoArm
from cerebx_luque2011.schema import LWR3Config

MJCF = Path(__file__).with_name("lwr3.xml")
OBJECT_RADIUS_M = 0.04


def lwr3_model(cfg: LWR3Config, object_mass_kg: float | None = None) -> mujoco.MjModel:
    """The arm's MuJoCo model for ``cfg``; ``object_mass_kg`` overrides the configured object (0 = none)."""
    model = mujoco.MjModel.from_xml_path(str(MJCF))
    model.opt.timestep = cfg.physics_dt_ms / 1000.0
    model.dof_damping[:] = cfg.damping_Nms_per_rad
    model.jnt_stiffness[:] = cfg.stiffness_Nm_per_rad
    model.qpos_spring[:] = cfg.spring_ref_rad
    model.actuator_ctrlrange[:] = np.stack([-np.asarray(cfg.torque_limit_Nm), np.asarray(cfg.torque_limit_Nm)], 1)
    set_object(model, cfg.object_mass_kg if object_mass_kg is None else object_mass_kg)
    return model


def set_object(model: mujoco.MjModel, mass_kg: float) -> None:
    """Give the object body ``mass_kg`` (a solid sphere of radius 4 cm; 0 removes it). The dynamics read
    body masses every step, so no model constants need recomputing."""
    b = model.body("object").id
    model.body_mass[b] = mass_kg
    model.body_inertia[b] = 0.4 * mass_kg * OBJECT_RADIUS_M**2


class LWR3Arm(MujocoArm):
    joint_names = ("a1", "a2", "a4")
    control_dt_s = 0.002

    def __init__(self, cfg: LWR3Config, ctx: BuildContext | None = None):
        self._attach(cfg, lwr3_model(cfg))

    def nominal_model(self) -> mujoco.MjModel:
        """A copy of the arm's model without any object (what a crude inverse dynamics model knows)."""
        return lwr3_model(self.cfg, object_mass_kg=0.0)

    def reset(self, q0: np.ndarray, rng: np.random.Generator) -> None:
        set_object(self.model, self.cfg.object_mass_kg)
        super().reset(q0, rng)

    def object_mass_kg(self) -> float:
        return float(self.model.body_mass[self.model.body("object").id])

    # ---- plant events ----------------------------------------------------------------------
    def attach_payload(self, mass: float, rod: float = 0.0) -> None:
        """Hold an object of ``mass`` kg at the end of the last segment instead of the configured one (no rod:
        ``rod`` must be 0)."""
        if mass <= 0 or rod != 0:
            raise ValueError("lwr3 attach_payload needs mass_kg > 0 and rod_length_m = 0 (the object is held)")
        set_object(self.model, mass)
        mujoco.mj_forward(self.model, self.data)

    def detach_payload(self) -> None:
        """Back to the configured arm (its ``object_mass_kg``, 0 = empty hand)."""
        set_object(self.model, self.cfg.object_mass_kg)
        mujoco.mj_forward(self.model, self.data)
