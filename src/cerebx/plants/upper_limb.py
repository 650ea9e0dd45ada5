"""A musculoskeletal upper limb: shoulder and elbow flexion-extension in a vertical plane, moved by
seven Hill-type muscles, built from ``upper_limb.xml`` (OpenSim Arm26 after
Holzbaur et al. 2005, plus the MoBL-ARMS anterior deltoid; the sources are named in the MJCF header).

Command: ``muscle.activation[7]`` is each muscle's neural excitation u in [0, 1] (the motor-neuron rate).
It is MuJoCo's actuator control; MuJoCo's muscle activation state integrates Eq. 4.4-4.5 itself
(``timeconst`` = t_act, t_deact), so nothing in cerebx integrates it again.

Sensors: ``joint.q``/``joint.qd`` and ``muscle.length``/``muscle.velocity`` in mm and mm/s: the
musculotendon length and its rate (MuJoCo actuator length/velocity). MuJoCo tendons are inelastic, so the
fibre length is this minus the tendon slack length and the fibre velocity equals it. The length signal's
bounds are each muscle's length range over the joint range.

Muscle parameters: each muscle's OpenSim numbers (max isometric force, optimal fibre length, tendon
slack length, pennation) sit in the MJCF's ``<custom>`` block; :func:`set_muscle_parameters` turns them
into MuJoCo's (force = Fmax cos(pennation); lengthrange from an exact sweep of the joint range; range =
(lengthrange - slack) / lopt so the fibre's optimal length is lopt).
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np

from cerebx.builders import BuildContext
from cerebx.plants.mujoco_arm import MujocoArm
from cerebx.schema.plant import MUSCLES_UPPER_LIMB, UpperLimbConfig
from cerebx.signals import Signal

MJCF = Path(__file__).with_name("upper_limb.xml")
SWEEP_POINTS = 61  # per joint: the length range is taken over a 61 x 61 grid of the joint range


def set_muscle_parameters(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """Set force, lengthrange and range of every muscle from its OpenSim numbers; return the
    (n_muscles, 2) lengthrange (m)."""
    lo, hi = model.jnt_range[:, 0], model.jnt_range[:, 1]
    grid = np.stack(np.meshgrid(*[np.linspace(a, b, SWEEP_POINTS) for a, b in zip(lo, hi)]), -1).reshape(-1, 2)
    lengths = np.empty((len(grid), model.nu))
    for i, q in enumerate(grid):
        data.qpos[:] = q
        mujoco.mj_fwdPosition(model, data)
        lengths[i] = data.actuator_length
    lr = np.stack([lengths.min(0), lengths.max(0)], 1)
    for a in range(model.nu):
        fmax, lopt, slack, pennation = model.numeric(model.actuator(a).name).data
        rng = (lr[a] - slack) / lopt
        model.actuator_lengthrange[a] = lr[a]
        for prm in (model.actuator_gainprm, model.actuator_biasprm):
            prm[a, 0:2] = rng
            prm[a, 2] = fmax * np.cos(pennation)
    return lr


def moment_arms(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """d(length)/dq per muscle and joint (m) at the current pose (negative: the muscle flexes the joint)."""
    out = np.zeros((model.nu, model.nv))
    mujoco.mju_sparse2dense(out, data.actuator_moment, data.moment_rownnz, data.moment_rowadr, data.moment_colind)
    return out


class UpperLimb(MujocoArm):
    joint_names = ("shoulder", "elbow")
    muscle_names = MUSCLES_UPPER_LIMB
    control_dt_s = 0.002

    def __init__(self, cfg: UpperLimbConfig, ctx: BuildContext | None = None):
        model = mujoco.MjModel.from_xml_path(str(MJCF))
        names = tuple(model.actuator(i).name for i in range(model.nu))
        if names != MUSCLES_UPPER_LIMB:
            raise ValueError(f"{MJCF.name}: muscles {names} differ from {MUSCLES_UPPER_LIMB}")
        model.opt.timestep = cfg.physics_dt_ms / 1000.0
        model.opt.gravity[:] = (0.0, 0.0, -9.80665 if cfg.gravity else 0.0)
        model.dof_damping[:] = cfg.joint_damping_Nms_per_rad
        model.actuator_dynprm[:, 0:2] = cfg.activation_time_constants_s
        self._attach(cfg, model, site="hand")
        self.length_range_m = set_muscle_parameters(model, self.data)
        self._forearm = model.body("r_ulna_radius_hand").id
        self._pulse_end_s = -1.0
        self._pulse = np.zeros(3)

    # ---- plant contract -------------------------------------------------------------------
    def reset(self, q0: np.ndarray, rng: np.random.Generator) -> None:
        super().reset(q0, rng)
        self._pulse_end_s = -1.0

    def apply(self, excitation: np.ndarray) -> np.ndarray:
        """Set the 7 muscle excitations (clipped to [0, 1]) as MuJoCo's controls; returns them."""
        u = np.clip(np.asarray(excitation, float), 0.0, 1.0)
        self.data.ctrl[:] = u
        return u

    def step(self) -> None:
        for _ in range(self._n):  # a force pulse starts and ends on a physics step
            if self._pulse_end_s >= 0 and self.data.time >= self._pulse_end_s - 1e-9:
                self.data.xfrc_applied[self._forearm] = 0.0
                self._pulse_end_s = -1.0
            elif self._pulse_end_s >= 0:
                self._set_pulse_wrench()
            mujoco.mj_step(self.model, self.data)
        if self._pulse_end_s >= 0 and self.data.time >= self._pulse_end_s - 1e-9:
            self.data.xfrc_applied[self._forearm] = 0.0
            self._pulse_end_s = -1.0

    # ---- signals --------------------------------------------------------------------------
    def sensor_signals(self) -> dict[str, Signal]:
        n = len(self.muscle_names)
        lo, hi = (tuple(float(v) for v in 1000.0 * self.length_range_m[:, k]) for k in (0, 1))
        return {**super().sensor_signals(), "muscle.length": Signal("muscle.length", n, "mm", lo, hi),
                "muscle.velocity": Signal("muscle.velocity", n, "mm/s")}

    def command_signals(self) -> dict[str, Signal]:
        return {"muscle.activation": Signal("muscle.activation", len(self.muscle_names), "", 0.0, 1.0)}

    def sense(self) -> dict[str, np.ndarray]:
        q, qd = self.sensors()
        d = self.data
        return {"joint.q": q, "joint.qd": qd, "muscle.length": 1000.0 * d.actuator_length,
                "muscle.velocity": 1000.0 * d.actuator_velocity}

    def actuate(self, command: dict[str, np.ndarray]) -> np.ndarray:
        return self.apply(command["muscle.activation"])

    # ---- extras ---------------------------------------------------------------------------
    def hand(self) -> np.ndarray:
        """World position (m) of the hand point (Arm26's radius-styloid marker, at the wrist)."""
        return self.data.site_xpos[self._site].copy()

    def activation(self) -> np.ndarray:
        """MuJoCo's muscle activation state (Eq. 4.4-4.5 integrated by MuJoCo)."""
        return self.data.act.copy()

    def force_pulse(self, force_N: np.ndarray, duration_ms: float, body: str = "end_effector") -> None:
        """A force (N, world frame) on the hand point for ``duration_ms``; ``body`` must name the hand."""
        if body not in ("end_effector", "hand"):
            raise ValueError(f"force_pulse: the upper limb takes forces on the hand, not {body!r}")
        self._pulse = np.asarray(force_N, float)
        self._pulse_end_s = self.data.time + duration_ms / 1000.0
        self._set_pulse_wrench()

    def _set_pulse_wrench(self) -> None:
        d = self.data
        arm = d.site_xpos[self._site] - d.xipos[self._forearm]  # xfrc_applied acts at the body's centre of mass
        d.xfrc_applied[self._forearm, :3] = self._pulse
        d.xfrc_applied[self._forearm, 3:] = np.cross(arm, self._pulse)
