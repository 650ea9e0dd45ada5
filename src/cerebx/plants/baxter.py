"""MuJoCo model of the Baxter robot's left arm (SPEC §3.1), built from facts/baxter_left_arm.md.

World = the URDF ``base`` frame (x forward, y left, z up). Six torque-controlled joints
s0, s1, e0, e1, w0, w1; w2 is removed and the wrist and hand are rigid children of the lower
forearm at w2 = 0 (MuJoCo simulates joint-less children as one rigid body with their parent).
The end-effector is the origin of the URDF ``left_hand`` frame (site ``end_effector``); tasks use
the same point.

Options (``BaxterConfig``):

=====================  =====================================================================
gravity_compensation   MuJoCo ``gravcomp="1"`` on every arm body (a passive force, like the
                       Gazebo "links without gravity"); payloads are not compensated
sea                    a rotor joint per link (world-mounted, armature = rotor inertia) tied to
                       its link joint by a fixed tendon with stiffness/damping (Spong model);
                       the actuator drives the rotor, sensors read the link
s1_spring              polynomial joint spring on s1 (MuJoCo ``jnt_stiffnesspoly``)
torque_lag_ms          first-order lag from the commanded to the produced torque, per physics step
events                 attach/detach_payload, elastic_band/remove_band, force_pulse, and human
                       interaction (thesis §2.3.1, Fig. 2.10): finger_push (a half-sine force at
                       the end-effector) and grab (a soft spring whose hand end drags the
                       end-effector along a displacement, then lets go)
=====================  =====================================================================
"""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np

from cerebx.plants.base import Plant
from cerebx.schema.plant import BaxterConfig

JOINTS = ("s0", "s1", "e0", "e1", "w0", "w1")
CONTROL_DT_S = 0.002

_Q_MOUNT = "0.9238792 0 0 0.3826843"
_Q_PITCH = "0.7071068 -0.7071068 0 0"  # rpy(-pi/2, 0, 0)
_Q_A = "0.5 0.5 0.5 0.5"  # rpy(pi/2, 0, pi/2)
_Q_B = "0.5 -0.5 -0.5 -0.5"  # rpy(-pi/2, -pi/2, 0)

# (body, joint, pos, quat, mass, com, fullinertia ixx iyy izz ixy ixz iyz), facts §1-2.
_LINKS = (
    (
        "left_upper_shoulder",
        "s0",
        "0.055695 0 0.011038",
        "1 0 0 0",
        5.70044,
        "0.01783 0.00086 0.19127",
        "0.04709102262 0.03766976455 0.03595988478 0.00012787556 0.00614870039 0.00078086899",
    ),
    (
        "left_lower_shoulder",
        "s1",
        "0.069 0 0.27035",
        _Q_PITCH,
        3.22698,
        "0.06845 0.00269 -0.00529",
        "0.01175209419 0.0278859752 0.02078749298 -0.00030096398 0.00207675762 -0.00018821993",
    ),
    (
        "left_upper_elbow",
        "e0",
        "0.102 0 0",
        _Q_A,
        4.31272,
        "-0.00276 0.00132 0.18086",
        "0.02661733557 0.02844355207 0.01248008322 0.00029270634 0.00392189887 0.0010838933",
    ),
    (
        "left_lower_elbow",
        "e1",
        "0.069 0 0.26242",
        _Q_B,
        2.07206,
        "0.02611 0.00159 -0.01117",
        "0.00711582686 0.01318227876 0.00926852064 0.00036036173 0.0007459496 -0.00019663418",
    ),
    (
        "left_upper_forearm",
        "w0",
        "0.10359 0 0",
        _Q_A,
        2.24665,
        "-0.00168 0.0046 0.13952",
        "0.01667742825 0.01675457264 0.0037463115 0.00018403705 0.00018657629 -0.00064732352",
    ),
    (
        "left_lower_forearm",
        "w1",
        "0.01 0 0.2707",
        _Q_B,
        1.60979,
        "0.06041 0.00697 0.006",
        "0.00387607152 0.00700537914 0.0055275524 -0.00044384784 -0.00021115038 0.00015348067",
    ),
)
_WRIST = (
    "left_wrist",
    "0.115975 0 0",
    _Q_A,
    0.35093,
    "0.00198 0.00125 0.01855",
    "0.00025289155 0.0002688601 0.0003074118 5.75311e-6 -1.59345e-6 -5.19818e-6",
)
_HAND = (
    "left_hand",
    "0 0 0.11355",
    "1 0 0 0",
    0.19125,
    "0.01093 0.00042 -0.01532",
    "0.00017588 0.00021166377 0.00023745397 1.47073e-6 2.43633e-5 1.72689e-6",
)
JOINT_RANGE = (
    (-1.70167993878, 1.70167993878),
    (-2.147, 1.047),
    (-3.05417993878, 3.05417993878),
    (-0.05, 2.618),
    (-3.059, 3.059),
    (-1.57079632679, 2.094),
)
W2_RANGE = (-3.059, 3.059)
_PAYLOAD_IDLE_MASS_KG = 1e-6
_PAYLOAD_IDLE_INERTIA = 1e-9


def half_sine(t_s: np.ndarray | float, duration_s: float) -> np.ndarray:
    """Profile of a finger push: sin(pi t / T) on [0, T], else 0."""
    t = np.asarray(t_s, dtype=float)
    return np.where((t >= 0) & (t <= duration_s), np.sin(np.pi * np.clip(t / duration_s, 0.0, 1.0)), 0.0)


def grab_anchor(t_s: np.ndarray | float, start_m: np.ndarray, displacement_m: np.ndarray, drag_s: float) -> np.ndarray:
    """Where the grabbing hand holds the spring, ``t_s`` after the grab: from ``start_m`` along
    ``displacement_m`` with a minimum-jerk profile over ``drag_s``, then still (shape (..., 3))."""
    s = np.clip(np.asarray(t_s, dtype=float) / drag_s, 0.0, 1.0)[..., None]
    return np.asarray(start_m) + (s**3 * (10 - 15 * s + 6 * s**2)) * np.asarray(displacement_m)


def _f(values: Any) -> str:
    return " ".join(f"{float(v):.10g}" for v in values)


def _chain_xml(link_attrs: list[str], body_attrs: str, hand_children: str, w2: bool = False) -> str:
    """The nested arm bodies; ``link_attrs[i]`` are extra joint attributes of joint i; ``w2`` adds
    the wrist roll joint (kinematics only: the simulated arm holds w2 at 0 as a rigid wrist)."""
    open_tags = []
    for (body, joint, pos, quat, mass, com, inertia), extra in zip(_LINKS, link_attrs, strict=True):
        lo, hi = JOINT_RANGE[JOINTS.index(joint)]
        open_tags.append(
            f'<body name="{body}" pos="{pos}" quat="{quat}"{body_attrs}>'
            f'<inertial pos="{com}" mass="{mass}" fullinertia="{inertia}"/>'
            f'<joint name="{joint}" axis="0 0 1" range="{lo} {hi}"{extra}/>'
        )
    wrist, hand = _WRIST, _HAND
    w2_joint = f'<joint name="w2" axis="0 0 1" range="{W2_RANGE[0]} {W2_RANGE[1]}"/>' if w2 else ""
    tail = (
        f'<body name="{wrist[0]}" pos="{wrist[1]}" quat="{wrist[2]}"{body_attrs}>'
        f'<inertial pos="{wrist[4]}" mass="{wrist[3]}" fullinertia="{wrist[5]}"/>{w2_joint}'
        f'<body name="{hand[0]}" pos="{hand[1]}" quat="{hand[2]}"{body_attrs}>'
        f'<inertial pos="{hand[4]}" mass="{hand[3]}" fullinertia="{hand[5]}"/>'
        f'<site name="end_effector" pos="0 0 0"/>{hand_children}</body></body>'
    )
    return (
        f'<body name="left_arm_mount" pos="0.024645 0.219645 0.118588" quat="{_Q_MOUNT}">'
        + "".join(open_tags)
        + tail
        + "</body>" * len(open_tags)
        + "</body>"
    )


def kinematic_mjcf(w2: bool = False) -> str:
    """The bare kinematic chain (no actuators or options): what inverse kinematics needs; ``w2``
    adds the wrist roll joint (7 joints, as the original's MoveIt planning chain).

    Its text is part of the IK cache key, so any change to the arm geometry invalidates caches.
    """
    chain = _chain_xml([""] * 6, "", "", w2)
    return (
        '<mujoco model="baxter_left_arm_kinematics"><compiler angle="radian"/>'
        f"<worldbody>{chain}</worldbody></mujoco>"
    )


def baxter_mjcf(cfg: BaxterConfig, pendulum: bool = True) -> str:
    """The full simulation model for ``cfg``; ``pendulum`` adds the (idle) conical-pendulum payload
    body with its ball joint, which costs ~25 % of the physics time when no experiment needs it."""
    link_attrs = []
    for i in range(6):
        attrs = (
            f' limited="true" damping="{cfg.damping_Nms_per_rad[i]}"'
            f' frictionloss="{cfg.frictionloss_Nm[i]}" armature="{cfg.armature_kgm2[i]}"'
        )
        if i == 1 and cfg.s1_spring.enabled:
            sp = cfg.s1_spring
            coefs = _f((sp.stiffness_Nm_per_rad, sp.quadratic_Nm_per_rad2, sp.cubic_Nm_per_rad3))
            attrs += f' stiffness="{coefs}" springref="{sp.rest_rad}"'
        link_attrs.append(attrs)
    gravcomp = ' gravcomp="1"' if cfg.gravity_compensation else ""
    gripper = ""
    if cfg.gripper_mass_kg > 0:
        gripper = (
            f'<body name="gripper_base" pos="0 0 0.025"{gravcomp}>'
            f'<inertial pos="0 0 0" mass="{cfg.gripper_mass_kg}" diaginertia="1e-4 1e-4 1e-4"/></body>'
        )
    payload = (
        gripper
        + '<body name="payload_point"><inertial pos="0 0 0" mass="0" diaginertia="0 0 0"/></body>'
        + (f'<body name="payload_pendulum"><inertial pos="0 0 0" mass="{_PAYLOAD_IDLE_MASS_KG}"'
           f' diaginertia="{_PAYLOAD_IDLE_INERTIA} {_PAYLOAD_IDLE_INERTIA} {_PAYLOAD_IDLE_INERTIA}"/>'
           '<joint name="payload_ball" type="ball" armature="1e-5" damping="1e-5"/></body>' if pendulum else "")
        + '<site name="band_hand" pos="0 0 0"/>'
    )
    chain = _chain_xml(link_attrs, gravcomp, payload)

    rotors, tendons, actuators = "", "", ""
    for i, j in enumerate(JOINTS):
        lo, hi = cfg.torque_limit_Nm[i] * -1.0, cfg.torque_limit_Nm[i]
        if cfg.sea.enabled:
            sea = cfg.sea
            rotors += (
                f'<body name="rotor_{j}"><inertial pos="0 0 0" mass="1e-3" diaginertia="1e-6 1e-6 1e-6"/>'
                f'<joint name="rotor_{j}" axis="0 0 1" armature="{sea.rotor_inertia_kgm2[i]}"/></body>'
            )
            tendons += (
                f'<fixed name="sea_{j}" stiffness="{sea.stiffness_Nm_per_rad[i]}" '
                f'damping="{sea.damping_Nms_per_rad[i]}" springlength="0">'
                f'<joint joint="{j}" coef="1"/><joint joint="rotor_{j}" coef="-1"/></fixed>'
            )
            target = f"rotor_{j}"
        else:
            target = j
        actuators += f'<motor name="{j}" joint="{target}" ctrllimited="true" ctrlrange="{lo} {hi}"/>'
    tendons += (
        '<spatial name="band" stiffness="0" springlength="0 0">'
        '<site site="band_anchor"/><site site="band_hand"/></spatial>'
    )
    return (
        '<mujoco model="baxter_left_arm"><compiler angle="radian" autolimits="true"/>'
        f'<option timestep="{cfg.physics_dt_ms / 1000.0}" integrator="{_INTEGRATORS[cfg.integrator]}"'
        ' gravity="0 0 -9.81"><flag contact="disable"/></option>'
        f'<worldbody>{chain}<site name="band_anchor" pos="0 0 -1"/>{rotors}</worldbody>'
        f"<tendon>{tendons}</tendon><actuator>{actuators}</actuator></mujoco>"
    )


_INTEGRATORS = {"euler": "Euler", "implicitfast": "implicitfast", "rk4": "RK4"}


class BaxterArm(Plant):
    """The Baxter left arm as a torque-driven :class:`Plant` (see the module docstring)."""

    joint_names = JOINTS
    control_dt_s = CONTROL_DT_S

    def __init__(self, cfg: BaxterConfig | None = None, ctx: Any = None):
        self.cfg = cfg if cfg is not None else BaxterConfig()
        self.physics_dt_s = self.cfg.physics_dt_ms / 1000.0
        n = self.substeps
        if n < 1 or abs(n * self.physics_dt_s - self.control_dt_s) > 1e-12:
            raise ValueError(f"physics_dt_ms {self.cfg.physics_dt_ms} does not divide the 2 ms control step")
        # the pendulum payload is built only when the experiment schedules one (or, without an
        # experiment, always: contract checks apply every event kind)
        events = getattr(getattr(ctx, "cfg", None), "events", None)
        self.has_pendulum = events is None or any(
            e.action.kind == "attach_payload" and e.action.rod_length_m > 0 for e in events)
        self.xml = baxter_mjcf(self.cfg, pendulum=self.has_pendulum)
        self.model = mujoco.MjModel.from_xml_string(self.xml)
        self.data = mujoco.MjData(self.model)
        self._scratch = mujoco.MjData(self.model)
        m = self.model
        self._tau_max = np.asarray(self.cfg.torque_limit_Nm, dtype=float)
        self._tau = np.zeros(6)
        lag_s = self.cfg.torque_lag_ms / 1000.0
        self._lag_gain = 1.0 - np.exp(-self.physics_dt_s / lag_s) if lag_s > 0 else 1.0
        self._lo = np.array([r[0] for r in JOINT_RANGE])
        self._hi = np.array([r[1] for r in JOINT_RANGE])
        self._ee_site = m.site("end_effector").id
        self._hand = m.body("left_hand").id
        self._point = m.body("payload_point").id
        self._pend = m.body("payload_pendulum").id if self.has_pendulum else -1
        self._ball_q = m.jnt_qposadr[m.joint("payload_ball").id] if self.has_pendulum else -1
        self._ball_v = m.jnt_dofadr[m.joint("payload_ball").id] if self.has_pendulum else -1
        self._rotor_q = (
            np.array([m.jnt_qposadr[m.joint(f"rotor_{j}").id] for j in JOINTS])
            if self.cfg.sea.enabled
            else None
        )
        self._rotor_v = (
            np.array([m.jnt_dofadr[m.joint(f"rotor_{j}").id] for j in JOINTS])
            if self.cfg.sea.enabled
            else None
        )
        self._band = m.tendon("band").id
        self._band_anchor = m.site("band_anchor").id
        self._gravcomp = self.cfg.gravity_compensation
        self._noise_q = self.cfg.sensor_noise_rad
        self._noise_qd = self.cfg.sensor_noise_rad_per_s
        self._rng = np.random.default_rng(0)
        self._pulse_body = -1
        self._pulse_end_s = 0.0
        self._pulse_force = np.zeros(3)
        self._pulse_at_ee = False
        self._pulse_start_s = 0.0
        self._pulse_shape = "step"
        self._grab: tuple[float, np.ndarray, np.ndarray, float, float] | None = None  # t0, start, disp, drag, end
        self._ee_start = np.zeros(3)
        self._mass0 = m.body_mass.copy()
        self._ipos0 = m.body_ipos.copy()
        self._inertia0 = m.body_inertia.copy()
        self.reset(np.zeros(6), np.random.default_rng(0))

    # ---- Plant contract -------------------------------------------------------------------
    def reset(self, q0: np.ndarray, rng: np.random.Generator) -> None:
        m, d = self.model, self.data
        mujoco.mj_resetData(m, d)
        self._restore_payload()
        m.tendon_stiffness[self._band] = 0.0
        d.xfrc_applied[:] = 0.0
        self._pulse_body = -1
        self._grab = None
        q0 = np.asarray(q0, dtype=float)
        d.qpos[:6] = q0
        if self._rotor_q is not None:
            d.qpos[self._rotor_q] = q0
        d.ctrl[:] = 0.0
        self._tau[:] = 0.0
        mujoco.mj_forward(m, d)
        self._ee_start = d.site_xpos[self._ee_site].copy()
        self._rng = rng

    def sensors(self) -> tuple[np.ndarray, np.ndarray]:
        q = self.data.qpos[:6].copy()
        qd = self.data.qvel[:6].copy()
        if self._noise_q > 0:
            q += self._rng.normal(0.0, self._noise_q, 6)
        if self._noise_qd > 0:
            qd += self._rng.normal(0.0, self._noise_qd, 6)
        return q, qd

    def true_state(self) -> tuple[np.ndarray, np.ndarray]:
        return self.data.qpos[:6].copy(), self.data.qvel[:6].copy()

    def apply(self, tau: np.ndarray) -> np.ndarray:
        np.minimum(np.maximum(tau, -self._tau_max, out=self._tau), self._tau_max, out=self._tau)
        if self._lag_gain == 1.0:
            self.data.ctrl[:] = self._tau
        return self._tau.copy()

    def step(self) -> None:
        m, d = self.model, self.data
        lagged = self._lag_gain < 1.0
        if self._pulse_body < 0 and self._grab is None and not lagged:
            mujoco.mj_step(m, d, self.substeps)
            return
        for _ in range(self.substeps):
            if lagged:  # the produced torque approaches the command with the lag's time constant
                d.ctrl[:] += self._lag_gain * (self._tau - d.ctrl)
            if self._pulse_body >= 0 and self._pulse_at_ee:
                self._set_pulse_wrench()
            if self._grab is not None:
                self._move_grab()
            mujoco.mj_step(m, d)
            if self._pulse_body >= 0 and d.time >= self._pulse_end_s - 1e-9:
                d.xfrc_applied[self._pulse_body] = 0.0
                self._pulse_body = -1

    @property
    def time_s(self) -> float:
        return float(self.data.time)

    def joint_limits(self) -> tuple[np.ndarray, np.ndarray]:
        return self._lo.copy(), self._hi.copy()

    def torque_limits(self) -> np.ndarray:
        return self._tau_max.copy()

    def end_effector(self) -> np.ndarray:
        return self.data.site_xpos[self._ee_site].copy()

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
        if self.has_pendulum:
            mujoco.mju_negQuat(s.qpos[self._ball_q : self._ball_q + 4], s.xquat[self._hand])
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
        return s.site_xpos[self._ee_site].copy(), s.site_xmat[self._ee_site].reshape(3, 3).copy()

    def payload_mass_kg(self) -> float:
        pend = self.model.body_mass[self._pend] if self.has_pendulum else 0.0
        return float(self.model.body_mass[self._point] + pend)

    # ---- events (bound to event kinds in plants/events.py) --------------------------------
    def detach_payload(self) -> None:
        """Back to the arm's own masses."""
        self._restore_payload()

    def elastic_band(self, stiffness_N_per_m: float, anchor_offset_m: np.ndarray, rest_length_m: float) -> None:
        """A spring from the end-effector to an anchor offset from the run's start position."""
        self.model.site_pos[self._band_anchor] = self._ee_start + anchor_offset_m
        self.model.tendon_stiffness[self._band] = float(stiffness_N_per_m)
        self.model.tendon_lengthspring[self._band] = (0.0, float(rest_length_m))

    def remove_band(self) -> None:
        self.model.tendon_stiffness[self._band] = 0.0

    def force_pulse(self, force_N: np.ndarray, duration_ms: float, body: str = "end_effector") -> None:
        """A force on a body (at the end-effector point by default) for ``duration_ms``."""
        self._start_pulse(np.asarray(force_N, dtype=float), float(duration_ms), str(body))

    def finger_push(self, force_N: np.ndarray, duration_ms: float) -> None:
        """A push with one finger: a force at the end-effector rising and falling as a half sine
        over ``duration_ms`` (peak ``force_N``)."""
        self._start_pulse(np.asarray(force_N, dtype=float), float(duration_ms), "end_effector")
        self._pulse_shape = "half_sine"
        self._set_pulse_wrench()

    def grab(self, stiffness_N_per_m: float, displacement_m: np.ndarray, drag_ms: float, hold_ms: float) -> None:
        """A hand grabs the end-effector through a soft spring (rest length 0) and drags its end along
        ``displacement_m`` (:func:`grab_anchor`) over ``drag_ms``, holds it for ``hold_ms``, then lets go.
        Uses the band spring, so it replaces an elastic band."""
        disp = np.asarray(displacement_m, dtype=float)
        if stiffness_N_per_m <= 0 or drag_ms <= 0 or hold_ms < 0 or disp.shape != (3,):
            raise ValueError("grab needs stiffness_N_per_m > 0, a 3-vector displacement_m, drag_ms > 0, hold_ms >= 0")
        start = self.data.site_xpos[self._ee_site].copy()
        t0 = float(self.data.time)
        self._grab = (t0, start, disp, drag_ms / 1000.0, t0 + (drag_ms + hold_ms) / 1000.0)
        self.model.tendon_stiffness[self._band] = float(stiffness_N_per_m)
        self.model.tendon_lengthspring[self._band] = (0.0, 0.0)
        self._move_grab()

    def _move_grab(self) -> None:
        t0, start, disp, drag, end = self._grab
        t = float(self.data.time)
        if t >= end - 1e-9:
            self.model.tendon_stiffness[self._band] = 0.0
            self._grab = None
            return
        self.model.site_pos[self._band_anchor] = grab_anchor(t - t0, start, disp, drag)

    def _restore_payload(self) -> None:
        m = self.model
        for b in (self._point, self._pend) if self.has_pendulum else (self._point,):
            m.body_mass[b] = self._mass0[b]
            m.body_ipos[b] = self._ipos0[b]
            m.body_inertia[b] = self._inertia0[b]
        self._set_const()

    def attach_payload(self, mass: float, rod: float = 0.0) -> None:
        """A point mass at the end-effector, or hanging from a rod of ``rod`` m (conical pendulum)."""
        if mass <= 0 or rod < 0:
            raise ValueError("attach_payload needs mass_kg > 0 and rod_length_m >= 0")
        m, d = self.model, self.data
        self._restore_payload()
        if rod <= 0:
            m.body_mass[self._point] = mass
        elif not self.has_pendulum:
            raise ValueError("attach_payload with rod_length_m > 0: the plant was built without the pendulum body "
                             "(it is added when the experiment's events schedule one)")
        else:
            # A small sphere (radius 2 cm) on a massless rod, pivoting freely at the end-effector.
            inertia = 0.4 * mass * 0.02**2
            m.body_mass[self._pend] = mass
            m.body_ipos[self._pend] = (0.0, 0.0, -rod)
            m.body_inertia[self._pend] = (inertia, inertia, inertia)
            # Start hanging straight down (world -z) and at rest relative to the hand.
            mujoco.mju_negQuat(d.qpos[self._ball_q : self._ball_q + 4], d.xquat[self._hand])
            d.qvel[self._ball_v : self._ball_v + 3] = 0.0
        self._set_const()
        mujoco.mj_forward(m, d)

    def _set_const(self) -> None:
        s = self._scratch
        s.qpos[:] = self.data.qpos
        mujoco.mj_setConst(self.model, s)

    def _start_pulse(self, force: np.ndarray, duration_ms: float, body: str) -> None:
        if force.shape != (3,) or duration_ms <= 0:
            raise ValueError("force_pulse needs a 3-vector force_N and a positive duration_ms")
        if self._pulse_body >= 0:
            self.data.xfrc_applied[self._pulse_body] = 0.0
        if body == "end_effector":
            self._pulse_body, self._pulse_at_ee = self._hand, True
        else:
            bid = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, body)
            if bid <= 0:
                raise ValueError(f"force_pulse: unknown body {body!r}")
            self._pulse_body, self._pulse_at_ee = bid, False
            self.data.xfrc_applied[bid, :3] = force
            self.data.xfrc_applied[bid, 3:] = 0.0
        self._pulse_force = force.copy()
        self._pulse_shape = "step"
        self._pulse_start_s = float(self.data.time)
        self._pulse_end_s = float(self.data.time) + duration_ms / 1000.0
        if self._pulse_at_ee:
            self._set_pulse_wrench()

    def _set_pulse_wrench(self) -> None:
        """Force at the end-effector point = force + moment about the hand's centre of mass."""
        d, b = self.data, self._hand
        arm = d.site_xpos[self._ee_site] - d.xipos[b]
        force = self._pulse_force
        if self._pulse_shape == "half_sine":
            force = force * float(half_sine(d.time - self._pulse_start_s, self._pulse_end_s - self._pulse_start_s))
        d.xfrc_applied[b, :3] = force
        d.xfrc_applied[b, 3:] = np.cross(arm, force)
