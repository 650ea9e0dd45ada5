"""Things that act on a MuJoCo arm's hand: a payload (a point mass, or a bob on a rod: a conical
pendulum), an elastic band, force pulses, a finger push and a grab.

They need a few model elements, which :func:`add_to_spec` adds to the arm's ``mujoco.MjSpec`` before it
is compiled; :class:`HandInteractions` then binds them to the compiled model and data. Each is an
:class:`Interaction`: the arm (``plants/mujoco_arm.py``) resets it with itself and, while it is
``active``, calls it before and after every physics step.
"""

from __future__ import annotations

import mujoco
import numpy as np

POINT, PENDULUM, BALL = "payload_point", "payload_pendulum", "payload_ball"
BAND, BAND_HAND, BAND_ANCHOR = "band", "band_hand", "band_anchor"
IDLE_MASS_KG, IDLE_INERTIA_KGM2 = 1e-6, 1e-9  # the pendulum bob when nothing hangs there
BOB_RADIUS_M = 0.02  # a hanging payload is a solid sphere of this radius
_EPS_S = 1e-9  # an interaction ends on the first physics step at or after its end time


def half_sine(t_s: np.ndarray | float, duration_s: float) -> np.ndarray:
    """Profile of a finger push: sin(pi t / T) on [0, T], else 0.

    Parameters
    ----------
    t_s : float or array
        Time since the push began, s.
    duration_s : float
        The push's duration T, s.
    """
    t = np.asarray(t_s, dtype=float)
    return np.where((t >= 0) & (t <= duration_s), np.sin(np.pi * np.clip(t / duration_s, 0.0, 1.0)), 0.0)


def grab_anchor(t_s: np.ndarray | float, start_m: np.ndarray, displacement_m: np.ndarray, drag_s: float) -> np.ndarray:
    """Where the grabbing hand holds the spring, ``t_s`` after the grab: from ``start_m`` along
    ``displacement_m`` with a minimum-jerk profile over ``drag_s``, then still (shape (..., 3)).

    Parameters
    ----------
    t_s : float or array
        Time since the grab, s.
    start_m : array (3,)
        Where the hand grabs, m.
    displacement_m : array (3,)
        How far the hand drags, m.
    drag_s : float
        How long the drag lasts, s.
    """
    s = np.clip(np.asarray(t_s, dtype=float) / drag_s, 0.0, 1.0)[..., None]
    return np.asarray(start_m) + (s**3 * (10 - 15 * s + 6 * s**2)) * np.asarray(displacement_m)


def add_to_spec(spec: mujoco.MjSpec, site: str = "end_effector", pendulum: bool = True) -> None:
    """Add to ``spec``, at the body holding ``site`` and at the site's position: a massless payload
    point, with ``pendulum`` an idle bob on a ball joint (it costs physics time, so only when needed),
    and a slack band (a spatial tendon from a world anchor to the site)."""
    ee = spec.site(site)
    hand, pos = ee.parent, list(ee.pos)
    hand.add_body(name=POINT, pos=pos, ipos=[0.0] * 3, mass=0.0, inertia=[0.0] * 3, explicitinertial=1)
    if pendulum:
        bob = hand.add_body(
            name=PENDULUM,
            pos=pos,
            ipos=[0.0] * 3,
            mass=IDLE_MASS_KG,
            inertia=[IDLE_INERTIA_KGM2] * 3,
            explicitinertial=1,
        )
        bob.add_joint(name=BALL, type=mujoco.mjtJoint.mjJNT_BALL, armature=1e-5, damping=1e-5)
    hand.add_site(name=BAND_HAND, pos=pos)
    spec.worldbody.add_site(name=BAND_ANCHOR, pos=[0.0, 0.0, -1.0])
    band = spec.add_tendon(name=BAND, springlength=[0.0, 0.0])
    band.wrap_site(BAND_ANCHOR)
    band.wrap_site(BAND_HAND)


class Interaction:
    """Something acting on an arm; the hooks default to doing nothing."""

    active = False  # the arm calls before_substep/after_substep only while this is true

    def reset(self) -> None:
        """Called by the arm's reset, right after MuJoCo's data is reset."""

    def before_substep(self) -> None:
        """Called before each physics step while active."""

    def after_substep(self) -> None:
        """Called after each physics step while active."""


class Payload(Interaction):
    """A point mass at the end-effector, or a bob hanging from a rod there (a conical pendulum)."""

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, hand: int):
        self.model, self.data, self._hand = model, data, hand
        self._scratch = mujoco.MjData(model)
        self._point = model.body(POINT).id
        self._pend = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, PENDULUM)
        self.has_pendulum = self._pend >= 0
        self._bodies = [self._point, self._pend] if self.has_pendulum else [self._point]
        if self.has_pendulum:
            ball = model.joint(BALL).id
            self._ball_q, self._ball_v = model.jnt_qposadr[ball], model.jnt_dofadr[ball]
        self._idle = (
            model.body_mass[self._bodies].copy(),
            model.body_ipos[self._bodies].copy(),
            model.body_inertia[self._bodies].copy(),
        )

    def reset(self) -> None:
        self.detach()

    def detach(self) -> None:
        """Back to the idle (massless) payload bodies."""
        m = self.model
        m.body_mass[self._bodies], m.body_ipos[self._bodies], m.body_inertia[self._bodies] = self._idle
        self._set_const()

    def attach(self, mass: float, rod: float = 0.0) -> None:
        """``mass`` kg at the end-effector, or (``rod`` > 0 m) a sphere of radius 2 cm hanging from a
        massless rod that pivots freely there, starting straight down and at rest relative to the hand."""
        if mass <= 0 or rod < 0:
            raise ValueError("attach_payload needs mass_kg > 0 and rod_length_m >= 0")
        m, d = self.model, self.data
        self.detach()
        if rod <= 0:
            m.body_mass[self._point] = mass
        elif not self.has_pendulum:
            raise ValueError(
                "attach_payload with rod_length_m > 0: the plant was built without the pendulum body "
                "(it is added when the experiment's events schedule one)"
            )
        else:
            inertia = 0.4 * mass * BOB_RADIUS_M**2
            m.body_mass[self._pend] = mass
            m.body_ipos[self._pend] = (0.0, 0.0, -rod)
            m.body_inertia[self._pend] = (inertia, inertia, inertia)
            self.hang(d)
            d.qvel[self._ball_v : self._ball_v + 3] = 0.0
        self._set_const()
        mujoco.mj_forward(m, d)

    def hang(self, d: mujoco.MjData) -> None:
        """Turn the rod straight down (world -z) in ``d`` (its kinematics must be current)."""
        if self.has_pendulum:
            mujoco.mju_negQuat(d.qpos[self._ball_q : self._ball_q + 4], d.xquat[self._hand])

    def mass_kg(self) -> float:
        return float(self.model.body_mass[self._bodies].sum())

    def _set_const(self) -> None:
        """Recompute the model constants that depend on the masses."""
        self._scratch.qpos[:] = self.data.qpos
        mujoco.mj_setConst(self.model, self._scratch)


class Band(Interaction):
    """A linear spring (the spatial tendon of :func:`add_to_spec`) from a world anchor to the
    end-effector; slack (stiffness 0) until stretched."""

    def __init__(self, model: mujoco.MjModel):
        self.model = model
        self._tendon = model.tendon(BAND).id
        self._anchor = model.site(BAND_ANCHOR).id

    def reset(self) -> None:
        self.release()

    def stretch(self, anchor_m: np.ndarray, stiffness_N_per_m: float, rest_length_m: float = 0.0) -> None:
        """Anchor the spring at ``anchor_m`` (world) with this stiffness and rest length."""
        self.move_anchor(anchor_m)
        self.model.tendon_stiffness[self._tendon] = float(stiffness_N_per_m)
        self.model.tendon_lengthspring[self._tendon] = (0.0, float(rest_length_m))

    def move_anchor(self, anchor_m: np.ndarray) -> None:
        self.model.site_pos[self._anchor] = anchor_m

    def release(self) -> None:
        self.model.tendon_stiffness[self._tendon] = 0.0

    @property
    def stiffness_N_per_m(self) -> float:
        return float(self.model.tendon_stiffness[self._tendon])

    @property
    def anchor_m(self) -> np.ndarray:
        return self.model.site_pos[self._anchor].copy()


class Pulse(Interaction):
    """A force for a while: on the end-effector point (constant, or rising and falling as a half sine:
    a finger push), or constant on a named body's centre of mass."""

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, site: int):
        self.model, self.data, self._site = model, data, site
        self._hand = int(model.site_bodyid[site])
        self._body, self._at_ee, self._half_sine = -1, False, False
        self._force = np.zeros(3)
        self._start_s = self._end_s = 0.0

    def reset(self) -> None:
        self._body, self.active = -1, False

    def start(
        self, force_N: np.ndarray, duration_ms: float, body: str = "end_effector", half_sine_shape: bool = False
    ) -> None:
        """``force_N`` (world frame) on ``body`` for ``duration_ms``; replaces a pulse still running."""
        force = np.asarray(force_N, dtype=float)
        if force.shape != (3,) or duration_ms <= 0:
            raise ValueError("force_pulse needs a 3-vector force_N and a positive duration_ms")
        d = self.data
        if self._body >= 0:
            d.xfrc_applied[self._body] = 0.0
        if body == "end_effector":
            self._body, self._at_ee = self._hand, True
        else:
            bid = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, body)
            if bid <= 0:
                raise ValueError(f"force_pulse: unknown body {body!r}")
            self._body, self._at_ee = bid, False
            d.xfrc_applied[bid, :3] = force
            d.xfrc_applied[bid, 3:] = 0.0
        self._force = force.copy()
        self._half_sine = half_sine_shape
        self._start_s = float(d.time)
        self._end_s = float(d.time) + duration_ms / 1000.0
        self.active = True
        if self._at_ee:
            self._set_wrench()

    def before_substep(self) -> None:
        if self._at_ee:
            self._set_wrench()

    def after_substep(self) -> None:
        if self.data.time >= self._end_s - _EPS_S:
            self.data.xfrc_applied[self._body] = 0.0
            self._body, self.active = -1, False

    def _set_wrench(self) -> None:
        """Force at the end-effector point = force + moment about the hand's centre of mass."""
        d, b = self.data, self._body
        arm = d.site_xpos[self._site] - d.xipos[b]
        force = self._force
        if self._half_sine:
            force = force * float(half_sine(d.time - self._start_s, self._end_s - self._start_s))
        d.xfrc_applied[b, :3] = force
        d.xfrc_applied[b, 3:] = np.cross(arm, force)


class Grab(Interaction):
    """A hand grabs the end-effector through a soft spring (the band, rest length 0) and drags its end
    along a displacement (:func:`grab_anchor`), holds it, then lets go."""

    def __init__(self, band: Band, data: mujoco.MjData, site: int):
        self.band, self.data, self._site = band, data, site
        self._plan: tuple[float, np.ndarray, np.ndarray, float, float] | None = None  # t0, start, disp, drag, end

    def reset(self) -> None:
        self._plan, self.active = None, False

    def start(self, stiffness_N_per_m: float, displacement_m: np.ndarray, drag_ms: float, hold_ms: float) -> None:
        """Drag over ``drag_ms``, hold for ``hold_ms``, then let go; replaces an elastic band."""
        disp = np.asarray(displacement_m, dtype=float)
        if stiffness_N_per_m <= 0 or drag_ms <= 0 or hold_ms < 0 or disp.shape != (3,):
            raise ValueError("grab needs stiffness_N_per_m > 0, a 3-vector displacement_m, drag_ms > 0, hold_ms >= 0")
        start = self.data.site_xpos[self._site].copy()
        t0 = float(self.data.time)
        self._plan = (t0, start, disp, drag_ms / 1000.0, t0 + (drag_ms + hold_ms) / 1000.0)
        self.active = True
        self.band.stretch(start, stiffness_N_per_m, 0.0)
        self.before_substep()

    def before_substep(self) -> None:
        t0, start, disp, drag, end = self._plan
        t = float(self.data.time)
        if t >= end - _EPS_S:
            self.band.release()
            self.reset()
            return
        self.band.move_anchor(grab_anchor(t - t0, start, disp, drag))


class HandInteractions:
    """The payload, band, pulse and grab at one arm's end-effector ``site``, bound to the model compiled
    from a spec that :func:`add_to_spec` prepared."""

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, site: str = "end_effector"):
        site_id = model.site(site).id
        self.payload = Payload(model, data, int(model.site_bodyid[site_id]))
        self.band = Band(model)
        self.pulse = Pulse(model, data, site_id)
        self.grab = Grab(self.band, data, site_id)

    def all(self) -> tuple[Interaction, ...]:
        """Every interaction, in the order the arm calls them (the pulse before the grab)."""
        return (self.pulse, self.grab, self.payload, self.band)
