"""Numba kernels of the Luque et al. 2011 corrective cerebellum (120 input cells, 48 IO, 48 PC, 24 DCN).

One call of :func:`tick` advances the network by one 2 ms control step in ``n_sub`` sub-steps. The
membrane equations are integrated with the exponential Euler rule (exact for the conductances frozen
over a sub-step), so the stiff DCN cells (2 pF under up to 60 nS of inhibition) stay stable. A spike
reaches its targets' conductances in the next sub-step. Populations are laid out group by group:

- input cell ``g * n_per + k``: RBF ``k`` of signal ``g`` (g = 0..2 desired q of joints 1-3, 3..5 desired qd);
- IO cell / PC ``8 * g + k`` with g = 2 j + s (joint j, s = 0 the positive, 1 the negative group);
- DCN cell ``4 * g + k`` is inhibited by PCs ``8 g + 2 k`` and ``8 g + 2 k + 1``.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from cerebx.api import KernelStruct

PEAK_X = math.atan(20.0)  # e^-x sin(x)^20 peaks where tan x = 20


class InputCells(NamedTuple):
    """The RBF-driven input cells and their recent spikes (for LTD)."""

    v: np.ndarray  # [n_in]: integrator state (spike at 1)
    drive: np.ndarray  # [n_in]: this tick's drive (Eq. 2.A)
    enc: np.ndarray  # [2, n_in]: RBF centre and 1 / 2 sigma^2 per cell
    hist: np.ndarray  # int64 [n_in, depth]: each cell's recent spike sub-steps, a ring (-1 empty)
    head: np.ndarray  # int64 [n_in]: next ring position per cell


class LIFConstants(NamedTuple):
    """A conductance-LIF population's constants for a sub-step of ``dt`` ms."""

    capacitance_pF: float
    rest_conductance_nS: float
    rest_mV: float
    threshold_mV: float
    refractory_steps: int
    decay_exc: float  # exp(-dt / tau_exc)
    decay_inh: float  # exp(-dt / tau_inh)
    e_exc_mV: float
    e_inh_mV: float


class LIFCells(NamedTuple):
    """State and parameters of a conductance-LIF population (PC or DCN)."""

    v: np.ndarray  # membrane potential (mV)
    ge: np.ndarray  # excitatory conductance (nS)
    gi: np.ndarray  # inhibitory conductance (nS)
    refr: np.ndarray  # int64: refractory sub-steps left
    par: LIFConstants


class Constants(NamedTuple):
    """The network's constants."""

    n_sub: int  # sub-steps of a 2 ms tick
    dt_ms: float  # sub-step
    input_decay: float  # exp(-dt / tau) of the input cells' integrator
    drive_at_centre: float  # input drive of a signal at an RBF's centre
    n_per: int  # input cells per signal
    w_max_nS: float  # PF-PC weight bound
    ltp_nS: float  # PF-PC increase per PF spike
    ltd_nS: float  # PF-PC decrease per IO spike and unit of kernel
    learn: bool  # plasticity on
    w_dcn_nS: float  # input cell -> DCN weight
    w_inh_nS: float  # PC -> DCN weight
    eps_full_scale: float  # error at which the IO fires at its highest rate
    io_p_max: float  # IO spike probability per tick at that rate


class Circuit(NamedTuple):
    """Everything :func:`tick` reads and writes besides the step's own inputs and output (it gets
    them as one :class:`CircuitState`)."""

    pars: Constants
    clock: np.ndarray  # int64: sub-step index, tick index, IO spike count
    inputs: InputCells
    pc: LIFCells
    dcn: LIFCells
    w: np.ndarray  # [n_pc, n_in]: PF-PC weights (nS)
    kern: np.ndarray  # LTD kernel by age in sub-steps
    io_spike: np.ndarray  # bool [n_io]: IO cells that fired this tick
    counts: np.ndarray  # int64 [ticks, n_dcn]: DCN spikes per buffered tick
    gain: np.ndarray  # [n_joints]: torque per DCN rate difference (N m / Hz)


class CircuitState(KernelStruct, fields=Circuit):
    """A :class:`Circuit` as one numba object, the form :func:`tick` takes (make it with
    :func:`circuit_state`). Pickles as its circuit."""


def _named(circuit: Circuit) -> Circuit:
    """``circuit`` with its constants named: a checkpoint made before they were carries them as arrays (the
    fields' order)."""
    if not isinstance(circuit.pars, np.ndarray):
        return circuit

    def lif(cells: LIFCells) -> LIFCells:
        p = [float(x) for x in cells.par]
        p[4] = int(p[4])
        return cells._replace(par=LIFConstants(*p))

    p = [float(x) for x in circuit.pars]
    p[0], p[4], p[8] = int(p[0]), int(p[4]), p[8] > 0.0
    return circuit._replace(pars=Constants(*p), pc=lif(circuit.pc), dcn=lif(circuit.dcn))


def circuit_state(circuit: Circuit) -> CircuitState:
    """The kernel's handle on ``circuit`` (the same array objects)."""
    return CircuitState.of(_named(circuit))


def ltd_kernel(age_ms: np.ndarray, peak_ms: float) -> np.ndarray:
    """k(s) = e^-x sin(x)^20 with x = s atan(20) / peak_ms, normalised to 1 at s = peak_ms (Eq. 5).
    Its second bump, e^-pi (4.3 %) of the first, lies pi peak_ms / atan(20) later."""
    x = np.asarray(age_ms, float) * PEAK_X / peak_ms
    k = np.exp(-x) * np.sin(x) ** 20 / (math.exp(-PEAK_X) * math.sin(PEAK_X) ** 20)
    return np.where(x >= 0, k, 0.0)


def kernel_table(peak_ms: float, dt_ms: float) -> np.ndarray:
    """The kernel at ages 0, dt, 2 dt, ... up to the end of its second bump (x = atan(20) + 2 pi)."""
    span_ms = (PEAK_X + 2 * math.pi) * peak_ms / PEAK_X
    return ltd_kernel(np.arange(int(span_ms / dt_ms) + 1) * dt_ms, peak_ms)


def rbf_currents(x: np.ndarray, centres: np.ndarray, sigma: np.ndarray, n_per: int) -> np.ndarray:
    """Eq. 2.A: I_i = exp(-(x_g - mu_i)^2 / 2 sigma_g^2) for every cell i of signal g."""
    xg = np.repeat(np.asarray(x, float), n_per)
    return np.exp(-((xg - centres) ** 2) / (2.0 * np.repeat(sigma, n_per) ** 2))


def io_probability(eps: np.ndarray, full_scale: float, rate_max_hz: float, dt_s: float) -> np.ndarray:
    """Spike probability per step of the + and - IO groups of each joint, shape (2 n_joints,):
    rate_max dt min(1, max(0, +-eps) / full_scale) (the paper's "spike when eps > eta", scaled to 0-10 Hz)."""
    e = np.clip(np.stack([eps, -eps], 1).ravel() / full_scale, 0.0, 1.0)
    return rate_max_hz * dt_s * e


@njit(cache=True, fastmath=False)
def _lif(cells, dt):
    """One sub-step of conductance LIF cells (:class:`LIFCells`); returns the indices that spiked."""
    v, ge, gi, refr, p = cells.v, cells.ge, cells.gi, cells.refr, cells.par
    n = v.shape[0]
    spiked = np.empty(n, np.int64)
    ns = 0
    c, gl, el, th, nref = p.capacitance_pF, p.rest_conductance_nS, p.rest_mV, p.threshold_mV, p.refractory_steps
    de, di, ee, ei = p.decay_exc, p.decay_inh, p.e_exc_mV, p.e_inh_mV
    for i in range(n):
        if refr[i] > 0:
            refr[i] -= 1
        else:
            g = gl + ge[i] + gi[i]
            vinf = (gl * el + ge[i] * ee + gi[i] * ei) / g
            v[i] = vinf + (v[i] - vinf) * math.exp(-g * dt / c)  # nS * ms / pF = dimensionless
            if v[i] >= th:
                v[i] = el
                refr[i] = nref
                spiked[ns] = i
                ns += 1
        ge[i] *= de
        gi[i] *= di
    return spiked[:ns]


@njit(cache=True)
def _encode(x, centres, inv2s2, n_per, scale, drive):
    """Eq. 2.A for every input cell, times the drive at a centre (in place into ``drive``)."""
    for j in range(centres.shape[0]):
        d = x[j // n_per] - centres[j]
        drive[j] = scale * math.exp(-d * d * inv2s2[j])


@njit(cache=True)
def _olive(eps, u, full_scale, p_max, per_group, io_spike):
    """IO spikes of this step: cell i of group g = 2 j + s fires when u_i < p_max min(1, max(0, +-eps_j) / full)."""
    any_io = False
    for i in range(io_spike.shape[0]):
        g = i // per_group
        e = eps[g // 2] if g % 2 == 0 else -eps[g // 2]
        p = e / full_scale
        p = 0.0 if p < 0.0 else (1.0 if p > 1.0 else p)
        io_spike[i] = u[i] < p_max * p
        any_io = any_io or io_spike[i]
    return any_io


@njit(cache=True)
def _depress(w, io_spike, ltd, kern, hist, now):
    """Eq. 6.A: each PC whose IO cell fired loses ltd x sum_k kern(now - t_k) on each PF's synapse."""
    n_in, depth, span = hist.shape[0], hist.shape[1], kern.shape[0]
    elig = np.zeros(n_in)
    for j in range(n_in):
        s = 0.0
        for h in range(depth):
            t = hist[j, h]
            if t >= 0 and now - t < span:
                s += kern[now - t]
        elig[j] = s
    for i in range(w.shape[0]):
        if io_spike[i]:
            for j in range(n_in):
                x = w[i, j] - ltd * elig[j]
                w[i, j] = x if x > 0.0 else 0.0


@njit(cache=True)
def tick(x, eps, uniform, circuit, torque):
    """Advance ``circuit`` (a :class:`CircuitState`) one 2 ms control step and write the corrective
    ``torque``.

    ``x``: desired (q1..q3, qd1..qd3); ``eps``: teaching error per joint (NaN: no measurement arrived);
    ``uniform``: a uniform number per IO cell; ``circuit.pars``: the :class:`Constants`."""
    pars, clock, w, io_spike, counts = circuit.pars, circuit.clock, circuit.w, circuit.io_spike, circuit.counts
    cells = circuit.inputs
    v_in, drive, hist, head = cells.v, cells.drive, cells.hist, cells.head
    ge_pc, ge_dcn, gi_dcn = circuit.pc.ge, circuit.dcn.ge, circuit.dcn.gi
    n_sub, dt, in_decay, scale, n_per = pars.n_sub, pars.dt_ms, pars.input_decay, pars.drive_at_centre, pars.n_per
    w_max, ltp, ltd, learn = pars.w_max_nS, pars.ltp_nS, pars.ltd_nS, pars.learn
    w_dcn, w_inh = pars.w_dcn_nS, pars.w_inh_nS
    n_in, n_pc, depth = v_in.shape[0], ge_pc.shape[0], hist.shape[1]
    now = clock[0]
    _encode(x, cells.enc[0], cells.enc[1], n_per, scale, drive)
    if not math.isnan(eps[0]):
        if _olive(eps, uniform, pars.eps_full_scale, pars.io_p_max, n_pc // 6, io_spike):
            for i in range(n_pc):
                clock[2] += io_spike[i]
            if learn and ltd > 0.0:
                _depress(w, io_spike, ltd, circuit.kern, hist, now)
    slot = counts[clock[1] % counts.shape[0]]
    slot[:] = 0
    for _ in range(n_sub):
        for j in range(n_in):
            d = drive[j]
            v_in[j] = d + (v_in[j] - d) * in_decay
            if v_in[j] >= 1.0:
                v_in[j] = 0.0
                hist[j, head[j]] = now
                head[j] = (head[j] + 1) % depth
                for i in range(n_pc):
                    ge_pc[i] += w[i, j]
                    if learn:
                        y = w[i, j] + ltp
                        w[i, j] = y if y < w_max else w_max
                for k in range(ge_dcn.shape[0]):
                    ge_dcn[k] += w_dcn
        for i in _lif(circuit.pc, dt):
            gi_dcn[i // 2] += w_inh
        for k in _lif(circuit.dcn, dt):
            slot[k] += 1
        now += 1
    clock[0] = now
    clock[1] += 1
    # buffered DCN rate per cell (Hz), + group minus - group, per joint
    n_dcn = ge_dcn.shape[0]
    per = n_dcn // 6
    window_s = counts.shape[0] * n_sub * dt / 1000.0
    for j in range(torque.shape[0]):
        pos = 0
        neg = 0
        for b in range(counts.shape[0]):
            for k in range(per):
                pos += counts[b, 2 * j * per + k]
                neg += counts[b, (2 * j + 1) * per + k]
        torque[j] = circuit.gain[j] * (pos - neg) / (per * window_s)
