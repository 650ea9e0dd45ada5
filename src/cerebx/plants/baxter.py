"""MuJoCo model of the Baxter robot's left arm, built from its URDF (docs/provenance.md#baxter-left-arm; what differs
from the URDF and why: docs/provenance.md#baxter-model-differences).

The MJCF beside this file (``baxter.xml``) is the robot: URDF kinematics and inertias, seven joints.
The simulation removes w2 (the wrist and hand become rigid children of the lower forearm at w2 = 0)
and applies the plant config with ``mujoco.MjSpec`` (:func:`baxter_spec`). The end-effector is the
origin of the URDF ``left_hand`` frame (site ``end_effector``); tasks use the same point.

=====================  =====================================================================
gravity_compensation   MuJoCo ``gravcomp`` on every arm body (a passive force, like the
                       Gazebo "links without gravity"); payloads are not compensated
sea                    a rotor joint per link (world-mounted, armature = rotor inertia) tied to
                       its link joint by a fixed tendon with stiffness/damping (Spong model);
                       the motor drives the rotor, sensors read the link
s1_spring              polynomial joint spring on s1 (MuJoCo ``jnt_stiffnesspoly``)
torque_lag_ms          first-order lag from the commanded to the produced torque, per physics step
events                 attach/detach_payload, elastic_band/remove_band, force_pulse, finger_push
                       and grab, from ``plants/interaction.py``
=====================  =====================================================================

=============  ======================  ========================================
signal         meaning                 unit
=============  ======================  ========================================
joint.q        s0, s1, e0, e1, w0, w1  rad (the link joints, also with SEA)
joint.qd       their velocity          rad/s
joint.torque   motor torque            N·m (saturated at ``torque_limit_Nm``)
=============  ======================  ========================================
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np

from cerebx.builders import BuildContext
from cerebx.plants.interaction import HandInteractions, add_to_spec
from cerebx.plants.interaction import grab_anchor as grab_anchor  # re-exported for importers of this module
from cerebx.plants.interaction import half_sine as half_sine
from cerebx.plants.mujoco_arm import MujocoArm
from cerebx.schema.plant import BaxterConfig

MJCF = Path(__file__).with_name("baxter.xml")
JOINTS = ("s0", "s1", "e0", "e1", "w0", "w1")
CONTROL_DT_S = 0.002
_INTEGRATORS = {
    "euler": mujoco.mjtIntegrator.mjINT_EULER,
    "implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
    "rk4": mujoco.mjtIntegrator.mjINT_RK4,
}


def _arm_spec(w2: bool) -> mujoco.MjSpec:
    """The robot of ``baxter.xml``; without ``w2`` the wrist roll joint is removed (a rigid wrist)."""
    spec = mujoco.MjSpec.from_file(str(MJCF))
    if not w2:
        spec.delete(spec.joint("w2"))
    return spec


_RANGES = {j.name: (float(j.range[0]), float(j.range[1])) for j in _arm_spec(w2=True).joints}
JOINT_RANGE = tuple(_RANGES[j] for j in JOINTS)  # (lower, upper) rad of s0..w1, as the MJCF gives them
W2_RANGE = _RANGES["w2"]


def kinematic_model(w2: bool = False) -> mujoco.MjModel:
    """The bare kinematic chain (no actuators; options unused): what inverse kinematics needs; ``w2``
    keeps the wrist roll joint (7 joints, as the original's MoveIt planning chain)."""
    return _arm_spec(w2).compile()


def baxter_spec(cfg: BaxterConfig, pendulum: bool = True) -> mujoco.MjSpec:
    """The simulation model for ``cfg``; ``pendulum`` adds the (idle) conical-pendulum payload body
    with its ball joint, which costs ~25 % of the physics time when no experiment needs it.

    Elements are added in a fixed order (joints, bodies, tendons, actuators keep their indices).
    """
    spec = _arm_spec(w2=False)
    spec.option.timestep = cfg.physics_dt_ms / 1000.0
    spec.option.integrator = _INTEGRATORS[cfg.integrator]
    for i, name in enumerate(JOINTS):
        joint = spec.joint(name)
        joint.damping = [cfg.damping_Nms_per_rad[i], 0.0, 0.0]  # damping and stiffness are polynomials
        joint.frictionloss = cfg.frictionloss_Nm[i]
        joint.armature = cfg.armature_kgm2[i]
    if cfg.s1_spring.enabled:
        sp, s1 = cfg.s1_spring, spec.joint("s1")
        s1.stiffness = [sp.stiffness_Nm_per_rad, sp.quadratic_Nm_per_rad2, sp.cubic_Nm_per_rad3]
        s1.springref = sp.rest_rad
    gravcomp = 1.0 if cfg.gravity_compensation else 0.0
    for body in spec.body("left_arm_mount").find_all(mujoco.mjtObj.mjOBJ_BODY):
        body.gravcomp = gravcomp
    if cfg.gripper_mass_kg > 0:
        spec.body("left_hand").add_body(
            name="gripper_base",
            pos=[0.0, 0.0, 0.025],
            ipos=[0.0] * 3,
            mass=cfg.gripper_mass_kg,
            inertia=[1e-4] * 3,
            explicitinertial=1,
            gravcomp=gravcomp,
        )
    _add_motors(spec, cfg)
    add_to_spec(spec, "end_effector", pendulum)
    return spec


def _add_motors(spec: mujoco.MjSpec, cfg: BaxterConfig) -> None:
    """One motor per joint, saturating at the torque limit; with ``sea`` it drives a rotor joint
    (a world-mounted body whose armature is the rotor inertia) coupled to the link by a spring tendon."""
    sea = cfg.sea
    for i, j in enumerate(JOINTS):
        target = j
        if sea.enabled:
            target = f"rotor_{j}"
            rotor = spec.worldbody.add_body(
                name=target, ipos=[0.0] * 3, mass=1e-3, inertia=[1e-6] * 3, explicitinertial=1
            )
            rotor.add_joint(name=target, axis=[0.0, 0.0, 1.0], armature=sea.rotor_inertia_kgm2[i])
            tendon = spec.add_tendon(
                name=f"sea_{j}",
                stiffness=[sea.stiffness_Nm_per_rad[i], 0.0, 0.0],
                damping=[sea.damping_Nms_per_rad[i], 0.0, 0.0],
                springlength=[0.0, 0.0],
            )
            tendon.wrap_joint(j, 1.0)
            tendon.wrap_joint(target, -1.0)
        limit = cfg.torque_limit_Nm[i]
        spec.add_actuator(
            name=j,
            target=target,
            trntype=mujoco.mjtTrn.mjTRN_JOINT,
            ctrllimited=mujoco.mjtLimited.mjLIMITED_TRUE,
            ctrlrange=[-limit, limit],
        )


def baxter_model(cfg: BaxterConfig, pendulum: bool = True) -> mujoco.MjModel:
    """:func:`baxter_spec` compiled."""
    return baxter_spec(cfg, pendulum).compile()


class BaxterArm(MujocoArm):
    """The Baxter left arm as a torque-driven plant (see the module docstring)."""

    joint_names = JOINTS
    control_dt_s = CONTROL_DT_S

    def __init__(self, cfg: BaxterConfig | None = None, ctx: BuildContext | None = None):
        cfg = cfg if cfg is not None else BaxterConfig()
        # the pendulum payload is built only when the experiment schedules one (or, without an
        # experiment, always: contract checks apply every event kind)
        events = getattr(getattr(ctx, "cfg", None), "events", None)
        self.has_pendulum = events is None or any(
            e.action.kind == "attach_payload" and e.action.rod_length_m > 0 for e in events
        )
        rotors = [f"rotor_{j}" for j in JOINTS] if cfg.sea.enabled else []
        self._attach(cfg, baxter_model(cfg, self.has_pendulum), rotors=rotors)
        self.hand_interactions = HandInteractions(self.model, self.data)
        self.interactions = self.hand_interactions.all()
        self._scratch = mujoco.MjData(self.model)
        self._ee_start = np.zeros(3)
        self.reset(np.zeros(6), np.random.default_rng(0))

    def reset(self, q0: np.ndarray, rng: np.random.Generator) -> None:
        super().reset(q0, rng)
        self._ee_start = self.end_effector()

    # ---- model queries --------------------------------------------------------------------
    def gravity_torque(self, q: np.ndarray) -> np.ndarray:
        """Joint torques (s0..w1) the actuators must supply to hold the arm still at ``q``.

        Includes an attached payload (a hanging pendulum acts at its pivot) and subtracts what
        the plant already provides passively (body gravcomp, the s1 spring).
        """
        m, s = self.model, self._scratch
        s.qpos[:] = self.data.qpos
        s.qpos[:6] = q
        s.qvel[:] = 0.0
        mujoco.mj_kinematics(m, s)
        self.hand_interactions.payload.hang(s)
        mujoco.mj_fwdPosition(m, s)
        mujoco.mj_fwdVelocity(m, s)
        out = s.qfrc_bias[:6] - s.qfrc_gravcomp[:6]
        out[1] -= self.s1_spring_torque(float(q[1]))
        return out

    def s1_spring_torque(self, q_s1: float) -> float:
        """Torque of the s1 spring assist at ``q_s1`` (0 when disabled)."""
        sp = self.cfg.s1_spring
        if not sp.enabled:
            return 0.0
        z = q_s1 - sp.rest_rad
        return -(sp.stiffness_Nm_per_rad * z + sp.quadratic_Nm_per_rad2 * z**2 + sp.cubic_Nm_per_rad3 * z**3)

    def cartesian_pose(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """End-effector position and 3x3 orientation for joint positions ``q`` (forward kinematics)."""
        s = self._scratch
        s.qpos[:6] = q
        mujoco.mj_kinematics(self.model, s)
        return s.site_xpos[self._site].copy(), s.site_xmat[self._site].reshape(3, 3).copy()

    def payload_mass_kg(self) -> float:
        return self.hand_interactions.payload.mass_kg()

    # ---- events (bound to event kinds in plants/events.py) --------------------------------
    def attach_payload(self, mass: float, rod: float = 0.0) -> None:
        """A point mass at the end-effector, or hanging from a rod of ``rod`` m (conical pendulum)."""
        self.hand_interactions.payload.attach(mass, rod)

    def detach_payload(self) -> None:
        """Back to the arm's own masses."""
        self.hand_interactions.payload.detach()

    def elastic_band(self, stiffness_N_per_m: float, anchor_offset_m: np.ndarray, rest_length_m: float) -> None:
        """A spring from the end-effector to an anchor offset from the run's start position."""
        self.hand_interactions.band.stretch(self._ee_start + anchor_offset_m, stiffness_N_per_m, rest_length_m)

    def remove_band(self) -> None:
        self.hand_interactions.band.release()

    def force_pulse(self, force_N: np.ndarray, duration_ms: float, body: str = "end_effector") -> None:
        """A force on a body (at the end-effector point by default) for ``duration_ms``."""
        self.hand_interactions.pulse.start(force_N, float(duration_ms), str(body))

    def finger_push(self, force_N: np.ndarray, duration_ms: float) -> None:
        """A push with one finger: a force at the end-effector rising and falling as a half sine
        over ``duration_ms`` (peak ``force_N``)."""
        self.hand_interactions.pulse.start(force_N, float(duration_ms), half_sine_shape=True)

    def grab(self, stiffness_N_per_m: float, displacement_m: np.ndarray, drag_ms: float, hold_ms: float) -> None:
        """A hand grabs the end-effector through a soft spring and drags it along ``displacement_m``
        over ``drag_ms``, holds it for ``hold_ms``, then lets go (it replaces an elastic band)."""
        self.hand_interactions.grab.start(stiffness_N_per_m, displacement_m, drag_ms, hold_ms)
