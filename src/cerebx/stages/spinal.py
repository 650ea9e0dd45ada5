"""The upper limb's stages between the cerebellum and the muscles (docs/models.md#spinal-cord).

``spinal_cord``: one motor neuron (MN) and one Ia interneuron (Ia IN) per muscle, leaky rate neurons
(Eq. 4.1-4.2) updated exactly for an input held over the 2 ms step: r <- s + (r - s) exp(-dt / tau_m),
s = sigma(input). The Ia afferent (Eq. 4.3) reads the muscle length and velocity from a FIFO on the 2 ms grid
(the spinal afferent link): the sample measured exactly ``afferent_delay_ms`` earlier; before the run has
lasted that long, the first sample (the arm at rest before t = 0). Its rate is normalised to [0, 1]:

    r = a sign(v) |v|^p + b l + c,   v clipped to +-V,
    r_norm = clip((r - r_lo) / (r_hi - r_lo), 0, 1),   r_lo = r(l_min, -V),  r_hi = r(l_max, +V),

with [l_min, l_max] each muscle's length range over the joint range (the plant's ``muscle.length`` bounds)
and V = ``velocity_range_mm_per_s``; by default (``normalise: peak``) r_lo = 0, i.e. the rate over its peak.
Both are constructed (the source only says "normalised to [0, 1]"): the default keeps the 30 ms-delayed
reflex loop of this strong arm from turning into clonus (with 'range' and V = 100 mm/s the resting arm
oscillates at ~3 Hz; v^0.6 has an infinite slope at v = 0, so some small limit cycle always remains).
Shortening (v < 0) lowers the rate (odd extension of v^0.6; the source gives the law only for lengthening).
The MN rates are the muscle excitations: the plant's MuJoCo muscles integrate the activation dynamics
(Eq. 4.4-4.5) once.

``direct_muscles``: without the spinal cord the commands are the excitations directly
(docs/models.md#direct-muscles).
``split_pairs``: brain side, a joint torque as agonist/antagonist commands.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numba
import numpy as np

from cerebx.builders import BuildContext
from cerebx.errors import ConfigError
from cerebx.kernel_struct import KernelStruct
from cerebx.schema.base import CONTROL_DT_MS
from cerebx.schema.spinal import DirectMusclesConfig, SpinalCordConfig, SplitPairsConfig, _MuscleMap
from cerebx.signals import Frame
from cerebx.stages.base import Stage

CONTROL_DT_S = CONTROL_DT_MS / 1000.0


def command_matrix(cfg: _MuscleMap, n_joints: int) -> np.ndarray:
    """(n_muscles, 2 n_joints) matrix from [ag, at] to each muscle's command (mean over its joints)."""
    out = np.zeros((len(cfg.muscles), 2 * n_joints))
    for i, m in enumerate(cfg.muscles):
        joints = cfg.joints[m]
        if any(j >= n_joints for j in joints):
            raise ConfigError(f"{cfg.kind}: muscle {m} names joint {max(joints)} but the plant has {n_joints}")
        col = 0 if m in cfg.flexors else n_joints
        for j in joints:
            out[i, col + j] = 1.0 / len(joints)
    return out


def _declare(stage: Stage, cfg: Any, ctx: BuildContext) -> None:
    io = cfg.io(ctx.plant.n_joints)
    stage.name, stage.reads, stage.writes = cfg.kind, io.reads, io.writes


def _check_muscles(cfg: _MuscleMap, ctx: BuildContext) -> None:
    have = tuple(getattr(ctx.plant, "muscle_names", ()))
    if have != tuple(cfg.muscles):
        raise ConfigError(f"{cfg.kind}: muscles {', '.join(cfg.muscles)} differ from plant "
                          f"{type(ctx.plant).__name__}'s ({', '.join(have) or 'none'})")


class DirectMuscles(Stage):
    def __init__(self, cfg: DirectMusclesConfig, ctx: BuildContext):
        _check_muscles(cfg, ctx)
        _declare(self, cfg, ctx)
        self.cmd = command_matrix(cfg, ctx.plant.n_joints)

    def step(self, frame: Frame) -> None:
        s = frame.signals
        u = self.cmd @ np.concatenate([s["muscle.ag"], s["muscle.at"]])
        self.emit(frame, "muscle.activation", np.clip(u, 0.0, 1.0))


@numba.njit(cache=True)
def _sigmoid(x: float, k: float, x0: float) -> float:
    return 1.0 / (1.0 + math.exp(-k * (x - x0)))


class IaLaw(NamedTuple):
    """Eq. 4.3's constants: r = velocity_gain sign(v) |v|^exponent + length_gain l + offset, |v| <= v_max."""

    velocity_gain: float
    exponent: float
    length_gain: float
    offset: float
    v_max: float  # mm/s


class RateNeurons(NamedTuple):
    """The leaky rate neurons' constants (Eq. 4.1-4.2): the decay exp(-dt / tau_m) of a 2 ms step, the input
    weights and the sigmoid's slope and centre."""

    decay: float
    w_exc: float
    w_inh: float
    slope: float
    centre: float


class Cord(NamedTuple):
    """Everything :func:`cord_tick` reads and writes besides the step's signals (the stage's arrays)."""

    cmd_map: np.ndarray  # (n_muscles, 2 n_joints): [ag, at] -> command
    ant: np.ndarray  # (n_muscles, n_muscles): antagonists' weights
    fifo: np.ndarray  # (delay, 2, n_muscles): delayed length and velocity
    delay: int  # afferent delay in ticks
    r_lo: np.ndarray  # Ia rate normalisation per muscle
    r_hi: np.ndarray
    ia_law: IaLaw
    neurons: RateNeurons
    ia: np.ndarray  # outputs: Ia rates, Ia IN and MN rates
    ia_in: np.ndarray
    mn: np.ndarray


class CordState(KernelStruct, fields=Cord):
    """:class:`Cord` as the one numba object :func:`cord_tick` takes."""


@numba.njit(cache=True)
def ia_rate(length, velocity, law):  # pragma: no cover - numba
    """Eq. 4.3 before normalisation (``law``: an :class:`IaLaw`): velocity clipped to +-v_max, odd power for
    shortening."""
    v = min(max(velocity, -law.v_max), law.v_max)
    sv = law.velocity_gain * abs(v) ** law.exponent
    return (sv if v >= 0 else -sv) + law.length_gain * length + law.offset


@numba.njit(cache=True)
def cord_tick(ag, at, length, velocity, cord, head):  # pragma: no cover - numba
    """One 2 ms step in place (``cord``: a :class:`CordState`): the Ia afferents of the sample pushed
    ``cord.delay`` ticks ago (this one stored), then the Ia INs, then the MNs. Returns the FIFO's new head."""
    fifo, delay, ia, ia_in, mn = cord.fifo, cord.delay, cord.ia, cord.ia_in, cord.mn
    n = mn.shape[0]
    nj = ag.shape[0]
    if head < 0:  # first sample: the history before t = 0 is the arm at rest as it is now
        for s in range(fifo.shape[0]):
            for i in range(n):
                fifo[s, 0, i] = length[i]
                fifo[s, 1, i] = velocity[i]
        head = 0
    for i in range(n):
        if delay > 0:
            l_del, v_del = fifo[head, 0, i], fifo[head, 1, i]
            fifo[head, 0, i], fifo[head, 1, i] = length[i], velocity[i]
        else:
            l_del, v_del = length[i], velocity[i]
        r = (ia_rate(l_del, v_del, cord.ia_law) - cord.r_lo[i]) / (cord.r_hi[i] - cord.r_lo[i])
        ia[i] = min(max(r, 0.0), 1.0)
    if delay > 0:
        head = (head + 1) % delay
    nrn = cord.neurons
    decay, w_exc, w_inh, k, x0 = nrn.decay, nrn.w_exc, nrn.w_inh, nrn.slope, nrn.centre
    cmd_map, ant = cord.cmd_map, cord.ant
    for i in range(n):
        s = _sigmoid(w_exc * ia[i], k, x0)
        ia_in[i] = s + (ia_in[i] - s) * decay
    for i in range(n):
        cmd = 0.0
        for j in range(nj):
            cmd += cmd_map[i, j] * ag[j] + cmd_map[i, nj + j] * at[j]
        inh = 0.0
        for j in range(n):
            inh += ant[i, j] * ia_in[j]
        s = _sigmoid(w_exc * (cmd + ia[i]) - w_inh * inh, k, x0)
        mn[i] = s + (mn[i] - s) * decay
    return head


class SpinalCord(Stage):
    def __init__(self, cfg: SpinalCordConfig, ctx: BuildContext):
        _check_muscles(cfg, ctx)
        _declare(self, cfg, ctx)
        self.cfg = cfg
        n = len(cfg.muscles)
        self.cmd = command_matrix(cfg, ctx.plant.n_joints)
        self.ant = np.zeros((n, n))
        for i, m in enumerate(cfg.muscles):
            for a in cfg.antagonists[m]:
                self.ant[i, cfg.muscles.index(a)] = 1.0 / len(cfg.antagonists[m])
        l_lo, l_hi = ctx.plant.sensor_signals()["muscle.length"].bounds()
        if not (np.all(np.isfinite(l_lo)) and np.all(np.isfinite(l_hi)) and np.all(l_hi > l_lo)):
            raise ConfigError("spinal_cord: the plant's muscle.length signal must declare each muscle's length range")
        v = cfg.velocity_range_mm_per_s
        self.ia_prm = np.array([cfg.ia_velocity_gain, cfg.ia_velocity_exponent, cfg.ia_length_gain, cfg.ia_offset, v])
        law = IaLaw(*map(float, self.ia_prm))
        self.r_lo = np.array([ia_rate(x, -v, law) for x in l_lo]) if cfg.normalise == "range" else np.zeros(n)
        self.r_hi = np.array([ia_rate(x, v, law) for x in l_hi])
        self.delay_steps = int(round(cfg.afferent_delay_ms / 1000.0 / CONTROL_DT_S))
        decay = math.exp(-CONTROL_DT_S / (cfg.tau_m_ms / 1000.0))
        self.neuron_prm = np.array([decay, cfg.w_exc, cfg.w_inh, cfg.sigmoid_slope, cfg.sigmoid_centre])
        self.mn, self.ia_in, self.ia = np.zeros(n), np.zeros(n), np.zeros(n)
        self._fifo = np.zeros((max(self.delay_steps, 1), 2, n))
        self._head = -1  # -1: empty (the first sample fills it)
        self._cord = self._kernel_state()

    def _kernel_state(self) -> CordState:
        """The kernel's handle on this stage's arrays (``ia_prm`` and ``neuron_prm`` by name)."""
        return CordState.of(Cord(self.cmd, self.ant, self._fifo, self.delay_steps, self.r_lo, self.r_hi,
                                 IaLaw(*map(float, self.ia_prm)), RateNeurons(*map(float, self.neuron_prm)),
                                 self.ia, self.ia_in, self.mn))

    def __getstate__(self) -> dict[str, Any]:
        state = dict(self.__dict__)
        state.pop("_cord", None)  # made again from the arrays restored
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        self._cord = self._kernel_state()

    def afferent(self, length_mm: np.ndarray, velocity_mm_per_s: np.ndarray) -> np.ndarray:
        """Normalised Ia rate in [0, 1] for a length and velocity (no delay)."""
        law = IaLaw(*map(float, self.ia_prm))
        r = np.array([ia_rate(x, v, law) for x, v in zip(length_mm, velocity_mm_per_s)])
        return np.clip((r - self.r_lo) / (self.r_hi - self.r_lo), 0.0, 1.0)

    def reset(self, rng: np.random.Generator) -> None:
        self.mn[:] = 0.0
        self.ia_in[:] = 0.0
        self.ia[:] = 0.0
        self._head = -1

    def step(self, frame: Frame) -> None:
        s = frame.signals
        self._head = cord_tick(s["muscle.ag"], s["muscle.at"], s["muscle.length"], s["muscle.velocity"], self._cord,
                               self._head)
        self.emit(frame, "muscle.activation", self.mn.copy())

    def record(self) -> dict[str, Any]:
        return {"spinal_ia": self.ia.copy(), "spinal_ia_in": self.ia_in.copy()}

    def describe(self) -> dict[str, Any]:
        return {"muscles": list(self.cfg.muscles), "afferent_delay_steps": self.delay_steps}


class SplitPairs(Stage):
    def __init__(self, cfg: SplitPairsConfig, ctx: BuildContext):
        _declare(self, cfg, ctx)
        self.full = np.asarray(cfg.full_command_Nm, float)

    def step(self, frame: Frame) -> None:
        x = frame.signals["joint.torque"] / self.full
        self.emit(frame, "muscle.ag", np.clip(x, 0.0, 1.0))
        self.emit(frame, "muscle.at", np.clip(-x, 0.0, 1.0))
