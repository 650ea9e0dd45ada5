"""Analog-to-spike encoders (docs/models.md#mf-box-coding, docs/models.md#cf-error-coding).

MF box coding: per joint and signal (q_d, q, qd_d, qd), ``F`` fibres with centres evenly spaced
over [r_min, r_max] and half-width step * width_factor; the input is clipped to the range and
the fibre whose box contains it fires once per 2 ms step. MF local index = 4F j + F s + bin.

CF coding: e = kpos (q_d - q) + kvel (qd_d - qd); e > 0 drives the 50 agonist fibres of the
joint (input e), otherwise the antagonist ones (input |e|). Fibre k of a side has centre
c_k = c_min + k (c_max - c_min)/(n - 1) and width = centre step; rate = r_min + (r_max - r_min)
(tanh((x - c_k)/width) + 1)/2. Each step a fibre fires with probability rate * 2 ms; an event is
a burst of floor(x / c_k) spikes (clipped to 1..max_burst), one per step.
"""

from __future__ import annotations

from itertools import chain
from typing import NamedTuple

import numba
import numpy as np

from cerebx.kernel_struct import KernelStruct
from cerebx.snn.schema import BoxEncoder, CFEncoder, PoissonEncoder

STEP_S = 0.002


@numba.njit(cache=True)
def _mf_active(q_des, q, qd_des, qd, lo, hi, step, half_width, F, out):  # pragma: no cover - numba
    """Box coding of the four signals of the first n_joints = ``lo.shape[0]`` joints into ``out``; returns the
    number of active fibres."""
    n = 0
    nj = lo.shape[0]
    for j in range(nj):
        for s in range(4):
            x = q_des[j] if s == 0 else q[j] if s == 1 else qd_des[j] if s == 2 else qd[j]
            v = min(max(x, lo[j, s]), hi[j, s])
            b = int(np.rint((v - lo[j, s]) / step[j, s]))
            b = min(max(b, 0), F - 1)
            base = (j * 4 + s) * F
            # a neighbour is inside its box too only at an exact midpoint (0.5 step + 1e-12)
            if b > 0 and abs(v - (lo[j, s] + (b - 1) * step[j, s])) < half_width[j, s]:
                out[n] = base + b - 1
                n += 1
            out[n] = base + b
            n += 1
            if b < F - 1 and abs(v - (lo[j, s] + (b + 1) * step[j, s])) < half_width[j, s]:
                out[n] = base + b + 1
                n += 1
    return n


@numba.njit(cache=True)
def _cf_error(q_des, q, qd_des, qd, kpos, kvel):  # pragma: no cover - numba
    """kpos (q_des - q) + kvel (qd_des - qd) over the first kpos.size joints, the array form's operations in
    its order (the same doubles)."""
    e = np.empty(kpos.size)
    for j in range(kpos.size):
        e[j] = kpos[j] * (q_des[j] - q[j]) + kvel[j] * (qd_des[j] - qd[j])
    return e


@numba.njit(cache=True)
def _cf_step(e, u, centres, width, r_min, r_max, max_burst, half, burst_left, out):  # pragma: no cover
    """One 2 ms step of the CF encoder: new events (u < rate * dt) on the side the error's sign
    selects, bursts of floor(|e| / c_k) spikes; returns the number of fibres spiking now."""
    per_joint = 2 * half
    # no rate the formula can give exceeds r_min + (r_max - r_min) (rounding is monotone and the tanh term is
    # at most 1): a draw at or above that rate's probability makes no event, whatever the error
    u_never = max(r_min, r_min + (r_max - r_min)) * 0.002
    n = 0
    for j in range(e.shape[0]):
        x = abs(e[j])
        side = 0 if e[j] > 0 else half
        for k in range(half):
            i = j * per_joint + side + k
            if burst_left[i] == 0 and u[i] < u_never:
                rate = r_min + (r_max - r_min) * (np.tanh((x - centres[k]) / width) + 1.0) / 2.0
                if u[i] < rate * 0.002:
                    b = int(np.floor(x / centres[k]))
                    burst_left[i] = min(max(b, 1), max_burst)
        for k in range(per_joint):
            i = j * per_joint + k
            if burst_left[i] > 0:
                out[n] = i
                n += 1
                burst_left[i] -= 1
    return n


def _require(what: str, n_joints: int, *signals: np.ndarray) -> None:
    """The compiled encoders read the first n_joints values of each signal: fewer is an error."""
    if min(map(len, signals)) < n_joints:
        raise ValueError(f"{what}: {n_joints} joints, got signals of {[len(x) for x in signals]} values")


class MossyEncoder:
    """Box (interval) coding of the four signals of every joint."""

    def __init__(self, cfg: BoxEncoder, lo: np.ndarray, hi: np.ndarray):
        """``lo``/``hi``: shape (n_joints, 4) ranges of q_d, q, qd_d, qd."""
        self.F = cfg.fibers_per_signal
        self.lo = np.asarray(lo, dtype=np.float64)
        self.hi = np.asarray(hi, dtype=np.float64)
        self.step = (self.hi - self.lo) / (self.F - 1)
        self.half_width = self.step * cfg.width_factor
        self.n_joints = self.lo.shape[0]
        self.base = (np.arange(self.n_joints)[:, None] * 4 + np.arange(4)[None, :]) * self.F
        self._out = np.zeros(self.n_joints * 4 * 3, dtype=np.int32)

    @property
    def n_fibers(self) -> int:
        return self.n_joints * 4 * self.F

    def active(self, q_des, q, qd_des, qd) -> np.ndarray:
        """Local indices of the fibres firing this step (one per signal; two only on an exact
        box boundary, as in the original), in increasing order (int32)."""
        _require("mossy encoder", self.n_joints, q_des, q, qd_des, qd)
        n = _mf_active(q_des, q, qd_des, qd, self.lo, self.hi, self.step, self.half_width, self.F, self._out)
        return self._out[:n].copy()


@numba.njit(cache=True)
def _poisson_active(signals, lo, hi, centres, inv_width, rf_rates, u, out):  # pragma: no cover - numba
    """Rate coding of the four signals (q_des, q, qd_des, qd) of the first n_joints = ``lo.shape[0]`` joints:
    fibre i (local index 4F j + F s + k) fires when u[i] < (r_min + r_span RF(z)) x 2 ms, z = (x - centre)
    inv_width, x clipped to the signal's range; rf_rates = (gaussian, r_min, r_span). Returns the number of
    spiking fibres written (in index order) to ``out``."""
    q_des, q, qd_des, qd = signals
    gaussian, r_min, r_span = rf_rates
    n = 0
    F = centres.shape[2]
    for j in range(lo.shape[0]):
        for s in range(4):
            x = q_des[j] if s == 0 else q[j] if s == 1 else qd_des[j] if s == 2 else qd[j]
            x = min(max(x, lo[j, s]), hi[j, s])
            base = (j * 4 + s) * F
            for k in range(F):
                z = (x - centres[j, s, k]) * inv_width[j, s]
                rf = np.exp(-0.5 * z * z) if gaussian else (1.0 if abs(z) < 1.0 else 0.0)
                if u[base + k] < (r_min + r_span * rf) * STEP_S:
                    out[n] = base + k
                    n += 1
    return n


class PoissonMossyEncoder:
    """Rate (Poisson) coding of the four signals of every joint: the same fibre layout as :class:`MossyEncoder`
    (local index 4F j + F s + k, centres evenly spaced over [lo, hi]), each fibre a Bernoulli draw per 2 ms step
    with its receptive field's rate. ``rng``: the generator (the controller gives one from the run's seed)."""

    def __init__(self, cfg: PoissonEncoder, lo: np.ndarray, hi: np.ndarray, rng: np.random.Generator | None = None):
        self.cfg = cfg
        self.F = F = cfg.fibers_per_signal
        self.lo = np.asarray(lo, dtype=np.float64)
        self.hi = np.asarray(hi, dtype=np.float64)
        self.n_joints = self.lo.shape[0]
        step = (self.hi - self.lo) / (F - 1)
        self.centres = self.lo[:, :, None] + step[:, :, None] * np.arange(F)
        self.inv_width = 1.0 / (step * cfg.width_factor)
        self.rng = rng if rng is not None else np.random.default_rng(0)
        self._u = np.zeros(self.n_fibers)
        self._out = np.zeros(self.n_fibers, dtype=np.int32)

    @property
    def n_fibers(self) -> int:
        return self.n_joints * 4 * self.F

    def rates(self, q_des, q, qd_des, qd) -> np.ndarray:
        """Rate (Hz) of every fibre, by local index."""
        x = np.stack([q_des, q, qd_des, qd], axis=1)[: self.n_joints]
        x = np.clip(x, self.lo, self.hi)
        z = (x[:, :, None] - self.centres) * self.inv_width[:, :, None]
        rf = np.exp(-0.5 * z * z) if self.cfg.field == "gaussian" else (np.abs(z) < 1.0).astype(float)
        c = self.cfg
        return (c.rate_min_hz + (c.rate_max_hz - c.rate_min_hz) * rf).ravel()

    def active(self, q_des, q, qd_des, qd) -> np.ndarray:
        """Local indices of the fibres firing this step, in increasing order (int32); one uniform draw per fibre
        per step, so the random stream does not depend on the signals."""
        _require("mossy encoder", self.n_joints, q_des, q, qd_des, qd)
        c = self.cfg
        u = self.rng.random(out=self._u)
        signals = tuple(np.ascontiguousarray(x, dtype=np.float64) for x in (q_des, q, qd_des, qd))
        n = _poisson_active(signals, self.lo, self.hi, self.centres, self.inv_width,
                            (c.field == "gaussian", float(c.rate_min_hz), float(c.rate_max_hz - c.rate_min_hz)), u,
                            self._out)
        return self._out[:n].copy()


class ClimbingEncoder:
    """Stochastic error coding on agonist/antagonist climbing fibres."""

    def __init__(self, cfg: CFEncoder, n_joints: int, per_joint: int, kpos, kvel, rng: np.random.Generator):
        if per_joint % 2:
            raise ValueError(f"climbing fibres per joint ({per_joint}) must be even (agonist/antagonist)")
        self.cfg = cfg
        self.n_joints, self.per_joint, self.half = n_joints, per_joint, per_joint // 2
        self.kpos = np.asarray(kpos, dtype=np.float64)[:n_joints]
        self.kvel = np.asarray(kvel, dtype=np.float64)[:n_joints]
        n = self.half
        self.centres = cfg.center_min + np.arange(n) * (cfg.center_max - cfg.center_min) / max(n - 1, 1)
        self.width = (cfg.center_max - cfg.center_min) / max(n - 1, 1)
        self.rng = rng
        self.burst_left = np.zeros(n_joints * per_joint, dtype=np.int64)
        self._out = np.zeros(n_joints * per_joint, dtype=np.int32)
        self._u = np.zeros(n_joints * per_joint)

    def error(self, q_des, q, qd_des, qd) -> np.ndarray:
        """kpos (q_des - q) + kvel (qd_des - qd) of the first n_joints joints."""
        _require("climbing encoder", self.n_joints, q_des, q, qd_des, qd)
        return _cf_error(q_des, q, qd_des, qd, self.kpos, self.kvel)

    def rates(self, e: np.ndarray) -> np.ndarray:
        """Firing rate (Hz) of every fibre, shape (n_joints, per_joint); the silent side is 0."""
        c = self.cfg
        x = np.abs(e)[:, None]
        r = c.rate_min_hz + (c.rate_max_hz - c.rate_min_hz) * (np.tanh((x - self.centres) / self.width) + 1) / 2
        out = np.zeros((self.n_joints, self.per_joint))
        pos = e > 0
        out[pos, : self.half] = r[pos]
        out[~pos, self.half :] = r[~pos]
        return out

    def bursts(self, e: np.ndarray) -> np.ndarray:
        """Spikes per event for every fibre: floor(|e| / c_k) clipped to 1..max_burst."""
        n = np.floor(np.abs(e)[:, None] / self.centres).astype(np.int64)
        n = np.clip(n, 1, self.cfg.max_burst)
        return np.concatenate([n, n], axis=1)

    def active(self, e: np.ndarray) -> np.ndarray:
        """Local indices of the fibres spiking this step (new events plus ongoing bursts).

        Same rule as :meth:`rates` and :meth:`bursts`, in one numba pass; one uniform per fibre
        per step keeps the random stream independent of the error.
        """
        c = self.cfg
        u = self.rng.random(out=self._u)  # the same draws as rng.random(n), into one array kept
        n = _cf_step(np.ascontiguousarray(e, dtype=np.float64), u, self.centres, self.width, c.rate_min_hz,
                     c.rate_max_hz, c.max_burst, self.half, self.burst_left, self._out)
        return self._out[:n].copy()

    def reset(self) -> None:
        self.burst_left[:] = 0

    def __setstate__(self, state: dict) -> None:
        """A checkpoint of the code before the draws' array was kept has none."""
        self.__dict__.update(state)
        if "_u" not in state:
            self._u = np.zeros(self.burst_left.shape[0])


class BoxCoding(NamedTuple):
    """What :func:`_both_active` reads of a :class:`MossyEncoder` (its arrays, not copies)."""

    lo: np.ndarray  # (n_joints, 4): the signals' ranges
    hi: np.ndarray
    step: np.ndarray  # (n_joints, 4): centre spacing
    half_width: np.ndarray  # (n_joints, 4): half-width of a box
    fibers: int  # fibres per signal
    first: int  # global index of local fibre 0
    out: np.ndarray  # int32 scratch of the active local indices


class ErrorCoding(NamedTuple):
    """What :func:`_both_active` reads of a :class:`ClimbingEncoder` (its arrays, not copies)."""

    n_joints: int
    kpos: np.ndarray  # error gains per joint
    kvel: np.ndarray
    centres: np.ndarray  # a side's fibre centres
    width: float
    rate_min_hz: float
    rate_max_hz: float
    max_burst: int
    half: int  # fibres per side of a joint
    burst_left: np.ndarray  # int64: spikes left in each fibre's burst
    first: int  # global index of local fibre 0
    out: np.ndarray  # int32 scratch of the spiking local indices


class Coders(NamedTuple):
    """Both encoders of an :class:`EncoderPair`."""

    mf: BoxCoding
    cf: ErrorCoding


class CodersState(KernelStruct, fields=Coders):
    """:class:`Coders` as the one numba object :func:`_both_active` takes."""


@numba.njit(cache=True)
def _both_active(q_des, qd_des, q_des_cf, qd_des_cf, q, qd, u, coders):  # pragma: no cover
    """:meth:`MossyEncoder.active` on (q_des, q, qd_des, qd), :meth:`ClimbingEncoder.error` on (q_des_cf, q,
    qd_des_cf, qd) and :meth:`ClimbingEncoder.active` on that error with the draws ``u``, in one call
    (``coders``: a :class:`CodersState`): the MF and CF fibres' global indices (local + ``first``, int32) and
    the error; three empty arrays and False when a signal has fewer values than the encoders read."""
    b, c = coders.mf, coders.cf
    nj = b.lo.shape[0]
    if min(q_des.size, q.size, qd_des.size, qd.size) < nj or min(q_des_cf.size, qd_des_cf.size, q.size,
                                                                 qd.size) < c.n_joints:
        return np.zeros(0, np.int32), np.zeros(0, np.int32), np.zeros(0), False
    # the scratch arrays take the global indices in place (each local index is read before it is replaced)
    n_mf, n_cf, e = _encode_tick(b, c, q_des, qd_des, q_des_cf, qd_des_cf, q, qd, u, b.out, c.out)
    return b.out[:n_mf].copy(), c.out[:n_cf].copy(), e, True


@numba.njit(cache=True, nogil=True, boundscheck=False)
def _encode_tick(b, c, q_des, qd_des, q_des_cf, qd_des_cf, q, qd, u, mf, cf):  # pragma: no cover - numba
    """One tick of both encoders (``b``: :class:`BoxCoding`, ``c``: :class:`ErrorCoding`): the MF and CF fibres'
    global indices written to the front of ``mf`` and ``cf``; returns their numbers and the error."""
    n_mf = _mf_active(q_des, q, qd_des, qd, b.lo, b.hi, b.step, b.half_width, b.fibers, b.out)
    for i in range(n_mf):
        mf[i] = b.out[i] + b.first
    e = _cf_error(q_des_cf, q, qd_des_cf, qd, c.kpos, c.kvel)
    n_cf = _cf_step(e, u, c.centres, c.width, c.rate_min_hz, c.rate_max_hz, c.max_burst, c.half, c.burst_left,
                    c.out)
    for i in range(n_cf):
        cf[i] = c.out[i] + c.first
    return n_mf, n_cf, e


def _coders(mf: MossyEncoder, cf: ClimbingEncoder, mf_first: int, cf_first: int) -> Coders:
    """What the compiled encoders read of ``mf`` and ``cf`` (their arrays, not copies), with the global index of
    each one's fibre 0."""
    c = cf.cfg
    return Coders(BoxCoding(mf.lo, mf.hi, mf.step, mf.half_width, mf.F, mf_first, mf._out),
                  ErrorCoding(cf.n_joints, cf.kpos, cf.kvel, cf.centres, cf.width, c.rate_min_hz, c.rate_max_hz,
                              c.max_burst, cf.half, cf.burst_left, cf_first, cf._out))


class EncoderPair:
    """The built-in MF and CF encoders of one controller stepped together: one compiled call a tick instead of
    three and their array handling (~6 us a tick of the loop's thread), the same indices, error and draws.

    ``EncoderPair.of(mf, cf, ...)`` is None unless both are the built-in classes (a plugin's encoders are
    stepped one by one). The pair keeps the encoders' arrays, not copies: make a new one when an encoder is
    replaced (a checkpoint restored); its state (bursts, random generator) stays the encoder's."""

    __slots__ = ("cf", "_coders")

    def __init__(self, mf: MossyEncoder, cf: ClimbingEncoder, mf_first: int, cf_first: int):
        self.cf = cf
        self._coders = CodersState.of(_coders(mf, cf, mf_first, cf_first))

    @classmethod
    def of(cls, mf: object, cf: object, mf_first: int, cf_first: int) -> EncoderPair | None:
        if type(mf) is MossyEncoder and type(cf) is ClimbingEncoder:
            return cls(mf, cf, mf_first, cf_first)
        return None

    def active(self, q_des, qd_des, q_des_cf, qd_des_cf, q, qd) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """(MF global indices, CF global indices, error) of this tick (draws the CF encoder's uniforms); None
        when a signal has fewer values than the encoders read (stepping the encoders one by one then says
        which)."""
        cf = self.cf
        u = cf.rng.random(out=cf._u)
        mf, cfi, e, ok = _both_active(q_des, qd_des, q_des_cf, qd_des_cf, q, qd, u, self._coders)
        return (mf, cfi, e) if ok else None


class Afferents(NamedTuple):
    """The built-in encoders' fibres of each tick kept for the network thread (:class:`AfferentRing`): the
    encoders (:class:`Coders`), a ring of the last ``R`` ticks' MF and CF fibres (global indices) and their
    counts, the newest error, and ``rows[0]``, the next tick to encode. Tick t of the ring is tick t - ``shift``
    of the controller: network step n takes the MF fibres of ring tick n - k_mf + shift (ticks before the
    controller's first are kept as ticks without fibres, :meth:`AfferentRing.from_fifos`)."""

    coders: Coders
    mf: np.ndarray  # int32 (R, n_mf): tick t's MF fibres in row t % R
    mf_n: np.ndarray  # int64 (R,)
    cf: np.ndarray  # int32 (R, n_cf)
    cf_n: np.ndarray  # int64 (R,)
    err: np.ndarray  # float64 (n_joints,): the error of the newest tick encoded with a sensor sample
    rows: np.ndarray  # int64 (1,)
    k_mf: int  # network step n takes the MF fibres of tick n - k_mf
    k_cf: int  # and the CF fibres of tick n - k_cf
    shift: int  # max(k_mf, k_cf): no step reads a ring tick before 0


class AfferentState(KernelStruct, fields=Afferents):
    """:class:`Afferents` as the one numba object :func:`encode_ticks` and :func:`compose_steps` take."""


@numba.njit(cache=True, nogil=True, boundscheck=False)
def encode_ticks(aff, signals, sensed, u):  # pragma: no cover - numba
    """Encode the next ``sensed.size`` ticks into the ring, in order: tick i with ``sensed[i] = r >= 0`` from
    ``signals[r]`` = (q_des, qd_des, q_des_cf, qd_des_cf, q, qd), each (n_joints,), with the CF fibres'
    uniforms ``u[r]``; a tick without a sensor sample (-1) has no fibres and draws nothing. The same operations
    as :func:`_both_active` (:func:`_encode_tick`), so the same fibres, error and bursts."""
    R = aff.mf_n.shape[0]
    for i in range(sensed.shape[0]):
        slot = aff.rows[0] % R
        r = sensed[i]
        if r < 0:
            aff.mf_n[slot] = 0
            aff.cf_n[slot] = 0
        else:
            x = signals[r]
            aff.mf_n[slot], aff.cf_n[slot], e = _encode_tick(aff.coders.mf, aff.coders.cf, x[0], x[1], x[2], x[3],
                                                             x[4], x[5], u[r], aff.mf[slot], aff.cf[slot])
            aff.err[:] = e
        aff.rows[0] += 1


@numba.njit(cache=True, nogil=True, boundscheck=False)
def compose_steps(aff, first, steps):  # pragma: no cover - numba
    """The network's inputs of steps ``first`` .. ``first + steps - 1`` packed as
    :func:`~cerebx.snn.network.pack` packs them: step n's MF fibres of tick n - k_mf, then its CF fibres of
    tick n - k_cf (ring ticks, shifted by ``shift``)."""
    R = aff.mf_n.shape[0]
    mf0 = aff.shift - aff.k_mf
    cf0 = aff.shift - aff.k_cf
    total = 0
    for n in range(first, first + steps):
        total += aff.mf_n[(n + mf0) % R] + aff.cf_n[(n + cf0) % R]
    flat = np.empty(total, np.int32)
    off = np.zeros(steps + 1, np.int64)
    p = 0
    for i in range(steps):
        s = (first + i + mf0) % R
        for k in range(aff.mf_n[s]):
            flat[p] = aff.mf[s, k]
            p += 1
        s = (first + i + cf0) % R
        for k in range(aff.cf_n[s]):
            flat[p] = aff.cf[s, k]
            p += 1
        off[i + 1] = p
    return flat, off


class AfferentRing:
    """The built-in MF and CF encoders of a pipelined controller, stepped on the network thread: the loop's
    thread appends each tick's six signals to :attr:`kept` and, when it hands a chunk over, stacks them
    (:meth:`take`). The CF fibres' uniforms of all the chunk's ticks are drawn in one call (:meth:`draws`:
    numpy's stream, as one draw a tick gives it, filled without the interpreter lock), on the loop's thread
    when it hands the chunk over or on the network thread when the chunk starts, whichever the controller
    chooses (the thread with time to spare); the chunk's one compiled call then encodes them
    (:func:`encode_ticks`) and packs its steps' inputs (:func:`compose_steps`). The loop's thread spends no
    encoder call, array or FIFO operation on a tick. (With numba's ``Generator`` inside the compiled call the
    numbers are the same but a draw costs 55 instructions against numpy's 32, 600 draws a tick.)

    The batches of ticks taken are drawn in the order they were taken, wherever: :meth:`may_draw_now` says
    whether every batch before the newest one is drawn already (a batch handed to the network thread is drawn
    when its chunk starts), so the stream and every result are the same whichever thread draws.

    Ticks count from the controller's reset; network step n takes the MF fibres of tick n - ``k_mf`` and the
    CF fibres of tick n - ``k_cf`` (the pathway delays), as the controller's FIFOs of encoded ticks give them
    (:meth:`from_fifos`, :meth:`to_fifos` convert for checkpoints and saved states)."""

    def __init__(self, mf: MossyEncoder, cf: ClimbingEncoder, mf_first: int, cf_first: int, k_mf: int,
                 k_cf: int, span: int):
        """``span``: ticks the ring must hold at once (from the oldest a step still needs to the newest kept)."""
        self.cf = cf
        self.n_joints = mf.n_joints
        R = span + 1
        self.R = R
        self._mf_range = (mf_first, mf_first + mf.n_fibers)
        n_cf = cf.burst_left.shape[0]
        self.arrays = Afferents(_coders(mf, cf, mf_first, cf_first),
                                mf=np.zeros((R, mf.n_fibers), np.int32), mf_n=np.zeros(R, np.int64),
                                cf=np.zeros((R, n_cf), np.int32), cf_n=np.zeros(R, np.int64),
                                err=np.zeros(cf.n_joints), rows=np.zeros(1, np.int64), k_mf=int(k_mf),
                                k_cf=int(k_cf), shift=int(max(k_mf, k_cf)))
        self.state = AfferentState.of(self.arrays)
        self.kept: list = []  # ticks not yet taken to be encoded: six signals, or None without a sensor sample
        self.taken = 0  # ticks taken (the network thread may still be encoding them): counted here, not read there
        self.batches = 0  # batches of ticks taken (:meth:`take`)
        self.drawn = 0  # batches whose uniforms are drawn (:meth:`draws`, on either thread)

    @classmethod
    def of(cls, mf: object, cf: object, mf_first: int, cf_first: int, k_mf: int, k_cf: int,
           span: int) -> AfferentRing | None:
        """None unless both encoders are the built-in classes (a plugin's encoders run on the loop's thread)."""
        if type(mf) is MossyEncoder and type(cf) is ClimbingEncoder:
            return cls(mf, cf, mf_first, cf_first, k_mf, k_cf, span)
        return None

    @property
    def ticks(self) -> int:
        """Ticks kept since the controller's reset (encoded or not)."""
        return self.taken + len(self.kept)

    def take(self) -> tuple[np.ndarray, np.ndarray]:
        """The ticks kept so far as :func:`encode_ticks` takes them (signals, and per tick its row of them or -1
        without a sensor sample; the CF uniforms are drawn by :meth:`draws`, on the thread that encodes them);
        the kept list starts again."""
        kept, self.kept = self.kept, []
        self.taken += len(kept)
        sensed = np.full(len(kept), -1, np.int64)
        rows = [k for k in kept if k is not None]
        nj = self.n_joints
        if rows:
            flat = list(chain.from_iterable(rows))
            sizes = set(map(len, flat))
            if min(sizes) < nj:
                raise ValueError(f"mossy and climbing encoders: {nj} joints, got signals of "
                                 f"{[len(x) for x in rows[0]]} values")
            if sizes == {nj}:  # one concatenation of the 6 x ticks arrays (np.array of the nested list: ~1.4 x as long)
                signals = np.concatenate(flat, dtype=np.float64).reshape(len(rows), 6, nj)
            else:  # longer signals (a plant with more joints than the controller): the first nj values
                signals = np.array([[np.asarray(x, np.float64)[:nj] for x in r] for r in rows])
            sensed[[i for i, k in enumerate(kept) if k is not None]] = np.arange(len(rows))
        else:
            signals = np.zeros((0, 6, nj))
        self.batches += 1
        return signals, sensed

    def may_draw_now(self) -> bool:
        """Whether the newest batch taken may be drawn now: every batch taken before it is drawn."""
        return self.drawn == self.batches - 1

    def draws(self, ticks: tuple[np.ndarray, ...]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`take`'s ticks with the CF fibres' uniforms of each tick with a sample, drawn now in one call
        (the stream of one draw a tick; numpy fills it without the interpreter lock): what
        :func:`encode_ticks` takes. Ticks drawn already (three arrays) are returned as they are. Batches are
        drawn in the order they were taken (:meth:`may_draw_now`)."""
        if len(ticks) == 3:
            return ticks  # type: ignore[return-value]
        signals, sensed = ticks
        u = self.cf.rng.random((signals.shape[0], self.cf.burst_left.shape[0]))
        self.drawn += 1
        return signals, sensed, u

    def encode_now(self) -> None:
        """Encode the ticks kept, on this thread (nothing may be in flight on the network thread)."""
        if self.kept:
            encode_ticks(self.state, *self.draws(self.take()))

    @property
    def error(self) -> np.ndarray:
        """The newest encoded tick's error (of a sensor sample)."""
        return self.arrays.err.copy()

    def _tick_fibres(self, t: int) -> tuple[np.ndarray, np.ndarray]:
        """MF and CF fibres of ring tick ``t``."""
        a = self.arrays
        s = t % self.R
        return a.mf[s, : a.mf_n[s]].copy(), a.cf[s, : a.cf_n[s]].copy()

    def to_fifos(self, first: int, k_in: int) -> tuple[list[np.ndarray], list[np.ndarray], list[np.ndarray]]:
        """The controller's FIFOs of encoded ticks for network steps from ``first`` on (after :meth:`encode_now`):
        the shared input FIFO (steps ``first`` .. ticks + k_in - 1) and the MF and CF ticks still waiting for
        it (the longer pathway's extra delay)."""
        a, T = self.arrays, int(self.arrays.rows[0])  # ring ticks
        assert not self.kept
        pending = []
        for n in range(first, T - a.shift + k_in):
            mf, _ = self._tick_fibres(n - a.k_mf + a.shift)
            _, cf = self._tick_fibres(n - a.k_cf + a.shift)
            pending.append(np.concatenate([mf, cf]))
        mf_lag = [self._tick_fibres(t)[0] for t in range(T - (a.k_mf - k_in), T)]
        cf_lag = [self._tick_fibres(t)[1] for t in range(T - (a.k_cf - k_in), T)]
        return pending, mf_lag, cf_lag

    def from_fifos(self, first: int, k_in: int, pending: list[np.ndarray], mf_lag: list[np.ndarray],
                   cf_lag: list[np.ndarray]) -> None:
        """The inverse of :meth:`to_fifos`: the ring as the FIFOs say, network step ``first`` next to run."""
        a = self.arrays
        T = first + len(pending) - k_in + a.shift  # ring ticks seen
        self.kept = []
        self.taken = T - a.shift
        self.drawn = self.batches  # nothing in flight: every batch taken is drawn
        a.mf_n[:] = 0
        a.cf_n[:] = 0
        a.rows[0] = T
        lo, hi = self._mf_range

        def put(ring: np.ndarray, counts: np.ndarray, t: int, fibres: np.ndarray) -> None:
            s = t % self.R
            counts[s] = len(fibres)
            ring[s, : len(fibres)] = fibres

        for j, x in enumerate(pending):
            x = np.asarray(x, np.int32)
            is_mf = (x >= lo) & (x < hi)
            n = first + j
            put(a.mf, a.mf_n, n - a.k_mf + a.shift, x[is_mf])
            put(a.cf, a.cf_n, n - a.k_cf + a.shift, x[~is_mf])
        for j, x in enumerate(mf_lag):
            put(a.mf, a.mf_n, T - (a.k_mf - k_in) + j, np.asarray(x, np.int32))
        for j, x in enumerate(cf_lag):
            put(a.cf, a.cf_n, T - (a.k_cf - k_in) + j, np.asarray(x, np.int32))
