"""The pendulum plant: its MJCF beside this file, parametrised from the config, on cerebx's MuJoCo arm base.

=============  ==========================  ======
signal         meaning                     unit
=============  ==========================  ======
joint.q        pivot angle (0: hanging)    rad
joint.qd       its velocity                rad/s
joint.torque   motor torque (saturated)    N·m
=============  ==========================  ======
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np

from cerebx.api import BuildContext, MujocoArm
from my_lab.schema import PendulumConfig

MJCF = Path(__file__).with_name("pendulum.xml")
BOB_RADIUS_M = 0.04


def pendulum_model(cfg: PendulumConfig) -> mujoco.MjModel:
    """The MuJoCo model of ``cfg``: the MJCF with the config's timestep, damping, bob and motor range."""
    model = mujoco.MjModel.from_xml_path(str(MJCF))
    model.opt.timestep = cfg.physics_dt_ms / 1000.0
    model.dof_damping[:] = cfg.damping_Nms_per_rad
    limit = cfg.torque_limit_Nm[0]
    model.actuator_ctrlrange[:] = [-limit, limit]
    set_bob(model, cfg.bob_mass_kg)
    return model


def set_bob(model: mujoco.MjModel, mass_kg: float) -> None:
    """Give the bob ``mass_kg`` (a solid sphere); MuJoCo reads body masses every step."""
    bob = model.body("bob").id
    model.body_mass[bob] = mass_kg
    model.body_inertia[bob] = 0.4 * mass_kg * BOB_RADIUS_M**2


class Pendulum(MujocoArm):
    joint_names = ("pivot",)
    control_dt_s = 0.002

    def __init__(self, cfg: PendulumConfig, ctx: BuildContext | None = None):
        self._attach(cfg, pendulum_model(cfg))  # sensing, saturation, stepping and the end effector: MujocoArm

    def reset(self, q0: np.ndarray, rng: np.random.Generator) -> None:
        set_bob(self.model, self.cfg.bob_mass_kg)  # a payload of the last run is gone
        super().reset(q0, rng)

    # plant events: a plant supports an event kind by having the method the event names
    def attach_payload(self, mass: float, rod: float = 0.0) -> None:
        """An object of ``mass`` kg picked up by the bob (``rod`` must be 0: it is held, not hung)."""
        if rod != 0.0:
            raise ValueError("pendulum attach_payload needs rod_length_m = 0 (the bob holds the object)")
        set_bob(self.model, self.cfg.bob_mass_kg + mass)

    def detach_payload(self) -> None:
        set_bob(self.model, self.cfg.bob_mass_kg)
