"""numba kernel of the sparse projections' learning rules (:mod:`cerebx.snn.plasticity`), called by
:func:`cerebx.snn.kernels.run_step` at the start of every substep t, before the spikes arriving at t are
delivered (so a synapse delivers its updated weight, as NEST's do).

Events at substep t: the partner events of a rule (the post neuron's own spikes stamped t, or the arrivals at
t of the teaching projection at the post neuron) and the pre arrivals (spikes of the piece's pre population
stamped t − delay). Order within t: partner events update the weights from the pre side's past (arrivals
before t); for the pairing family they then join the partner history; pre arrivals update the weights from the
partner side (pairing: events up to and including t; traces: before t); then every event joins its trace or
history. So a pre arrival and a post spike in the same substep do not pair under pair STDP (NEST's
``stdp_synapse`` does not pair simultaneous spikes either) and pair once under the pairing family.

With a dendritic delay (``TraceSpec.dendritic``, NEST's convention) a post spike reaches the synapse one delay d
after it happened, and the pre arrival is d after the pre spike reaches the synapse: the partner events at t are
the post spikes stamped t − 2d (``R_PDELAY``), and a pair then has NEST's Δt = t_post − t_pre + d.

Traces are exact: a trace keeps its value and the substep of its last update and is decayed on read,
x(t) = x(t_last) exp(−(t − t_last) dt / tau). Histories keep each neuron's last HISTORY_MAX spike times (a ring).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit, types
from numba.extending import overload

from cerebx.snn.topology import S_DELAY, S_N_PRE, S_PRE_LO, S_ROW

FAM_TRACE, FAM_PAIRING = 0, 1

# columns of sr_i (int64 per rule)
(R_FAM, R_PIECE, R_TLO, R_THI, R_POST_LO, R_NPOST, R_CSC, R_KOFF, R_KLEN, R_PRE_ROW, R_POST_ROW, R_PDELAY) = range(12)
N_RI = 12
# columns of sr_f (float64 per rule)
(R_WLO, R_WHI, R_FIXED, R_LAM, R_ALPHA, R_MUP, R_MUM, R_RATEP, R_RATEM) = range(9)
N_RF = 9


class SparseLearning(NamedTuple):
    """The sparse projections' rules and their state (rows of tr_*/hs_*: per rule, its pre neurons then its post
    neurons, from R_PRE_ROW / R_POST_ROW)."""

    sr_i: np.ndarray  # int64 [rule, N_RI]
    sr_f: np.ndarray  # float64 [rule, N_RF]
    csc_ptr: np.ndarray  # int64: per rule (from R_CSC) n_post + 1 pointers into csc_q/csc_j
    csc_q: np.ndarray  # int64: global synapse index (into sp_w)
    csc_j: np.ndarray  # int64: its presynaptic local index
    kern: np.ndarray  # float64: pairing tables, k_pre then k_post (R_KLEN each, from R_KOFF)
    tr_v: np.ndarray  # float64 [rows]: trace value at its last update
    tr_t: np.ndarray  # int64 [rows]: substep of the last update
    hs_t: np.ndarray  # int64 [rows, H]: spike times (ring)
    hs_n: np.ndarray  # int64 [rows]: spikes recorded so far
    lost: np.ndarray  # int64 [rule]: history entries overwritten while still inside the kernel window
    ev: np.ndarray  # int64: scratch, the partner events of one substep (local post index)


class NoLearning(NamedTuple):
    """What the kernels get for a network without sparse rules: a type of its own, so :func:`run_rules` compiles to
    nothing and the step kernel is the same code as without this module."""

    none: np.ndarray


NO_LEARNING = NoLearning(np.zeros(0, np.int64))


def empty() -> SparseLearning:
    """The arrays of a network without sparse rules."""
    z = np.zeros
    return SparseLearning(z((0, N_RI), np.int64), z((0, N_RF)), z(1, np.int64), z(0, np.int64), z(0, np.int64),
                          z(1), z(0), z(0, np.int64), z((0, 1), np.int64), z(0, np.int64), z(0, np.int64),
                          z(1, np.int64))


@njit(cache=True, boundscheck=False, inline="always")
def _remember(sl, r, row, t, klen):
    hs_t, hs_n = sl.hs_t, sl.hs_n
    H = hs_t.shape[1]
    n = hs_n[row]
    e = n % H
    if n >= H and t - hs_t[row, e] < klen:
        sl.lost[r] += 1
    hs_t[row, e] = t
    hs_n[row] = n + 1


@njit(cache=True, boundscheck=False, inline="always")
def _kernel_sum(sl, row, t, k0, klen):
    """Σ kern[k0 + (t − s)] over the recorded spikes s of ``row`` with t − s < klen."""
    hs_t, kern = sl.hs_t, sl.kern
    H = hs_t.shape[1]
    n = sl.hs_n[row]
    acc = 0.0
    for h in range(min(n, H)):
        m = t - hs_t[row, (n - 1 - h) % H]
        if m >= klen:
            break
        acc += kern[k0 + m]
    return acc


@njit(cache=True, boundscheck=False, inline="always")
def _trace(sl, row, t, rate):
    return sl.tr_v[row] * np.exp(-(t - sl.tr_t[row]) * rate)


@njit(cache=True, boundscheck=False)
def sparse_learning(t, learn, sl, dl):
    """Apply every sparse rule's events of substep t (``sl``: :class:`SparseLearning`, ``dl``: the kernels'
    ``Delivery``). ``learn`` False: traces and histories go on, weights stay."""
    ring_idx, ring_n = dl.ring_idx, dl.ring_n
    sp_i, sp_ptr, sp_post, w = dl.sp_i, dl.sp_ptr, dl.sp_post, dl.sp_w
    sr_i, sr_f, ev = sl.sr_i, sl.sr_f, sl.ev
    csc_ptr, csc_q, csc_j = sl.csc_ptr, sl.csc_q, sl.csc_j
    R = ring_idx.shape[0]
    for r in range(sr_i.shape[0]):
        pc = sr_i[r, R_PIECE]
        pre_lo, n_pre, off, delay = sp_i[pc, S_PRE_LO], sp_i[pc, S_N_PRE], sp_i[pc, S_ROW], sp_i[pc, S_DELAY]
        post_lo, n_post, co = sr_i[r, R_POST_LO], sr_i[r, R_NPOST], sr_i[r, R_CSC]
        pre_row, post_row = sr_i[r, R_PRE_ROW], sr_i[r, R_POST_ROW]
        w_lo, w_hi = sr_f[r, R_WLO], sr_f[r, R_WHI]
        # partner events at t
        ne = 0
        if sr_i[r, R_TLO] < 0:
            td = t - sr_i[r, R_PDELAY]  # the post spikes that reach the synapse now
            s0 = td % R
            for k in range(ring_n[s0] if td >= 0 else 0):
                i = ring_idx[s0, k] - post_lo
                if i >= 0 and i < n_post:
                    ev[ne] = i
                    ne += 1
        else:
            for tp in range(sr_i[r, R_TLO], sr_i[r, R_THI]):
                if t - sp_i[tp, S_DELAY] < 0:
                    continue
                s1 = (t - sp_i[tp, S_DELAY]) % R
                t_lo, t_n, t_off = sp_i[tp, S_PRE_LO], sp_i[tp, S_N_PRE], sp_i[tp, S_ROW]
                for k in range(ring_n[s1]):
                    j = ring_idx[s1, k] - t_lo
                    if j < 0 or j >= t_n:
                        continue
                    for q in range(sp_ptr[t_off + j], sp_ptr[t_off + j + 1]):
                        ev[ne] = sp_post[q] - post_lo
                        ne += 1
        sa = (t - delay) % R
        n_arr = ring_n[sa] if t - delay >= 0 else 0
        if sr_i[r, R_FAM] == FAM_TRACE:
            lam, alpha, mup, mum = sr_f[r, R_LAM], sr_f[r, R_ALPHA], sr_f[r, R_MUP], sr_f[r, R_MUM]
            ratep, ratem = sr_f[r, R_RATEP], sr_f[r, R_RATEM]
            if learn:
                for e in range(ne):  # potentiation: post spike after earlier pre arrivals
                    i = ev[e]
                    for c in range(csc_ptr[co + i], csc_ptr[co + i + 1]):
                        q = csc_q[c]
                        x = _trace(sl, pre_row + csc_j[c], t, ratep)
                        nw = w[q] / w_hi
                        nw = min(nw + lam * (1.0 - nw) ** mup * x, 1.0) * w_hi
                        w[q] = min(max(nw, w_lo), w_hi)
                for k in range(n_arr):  # depression: pre arrival after earlier post spikes
                    j = ring_idx[sa, k] - pre_lo
                    if j < 0 or j >= n_pre:
                        continue
                    for q in range(sp_ptr[off + j], sp_ptr[off + j + 1]):
                        y = _trace(sl, post_row + sp_post[q] - post_lo, t, ratem)
                        nw = w[q] / w_hi
                        nw = max(nw - alpha * lam * nw**mum * y, 0.0) * w_hi
                        w[q] = min(max(nw, w_lo), w_hi)
            for e in range(ne):
                row = post_row + ev[e]
                sl.tr_v[row] = _trace(sl, row, t, ratem) + 1.0
                sl.tr_t[row] = t
            for k in range(n_arr):
                j = ring_idx[sa, k] - pre_lo
                if j >= 0 and j < n_pre:
                    row = pre_row + j
                    sl.tr_v[row] = _trace(sl, row, t, ratep) + 1.0
                    sl.tr_t[row] = t
        else:
            k0, klen = sr_i[r, R_KOFF], sr_i[r, R_KLEN]
            fixed = sr_f[r, R_FIXED]
            for e in range(ne):  # partner event after earlier pre arrivals: k_post
                i = ev[e]
                if learn:
                    for c in range(csc_ptr[co + i], csc_ptr[co + i + 1]):
                        q = csc_q[c]
                        dw = _kernel_sum(sl, pre_row + csc_j[c], t, k0 + klen, klen)
                        w[q] = min(max(w[q] + dw, w_lo), w_hi)
                _remember(sl, r, post_row + i, t, klen)
            for k in range(n_arr):  # pre arrival: fixed + k_pre over partner events up to now
                j = ring_idx[sa, k] - pre_lo
                if j < 0 or j >= n_pre:
                    continue
                if learn:
                    for q in range(sp_ptr[off + j], sp_ptr[off + j + 1]):
                        dw = fixed + _kernel_sum(sl, post_row + sp_post[q] - post_lo, t, k0, klen)
                        w[q] = min(max(w[q] + dw, w_lo), w_hi)
                _remember(sl, r, pre_row + j, t, klen)


def run_rules(t, learn, sl, dl):
    """:func:`sparse_learning` of substep t, for the kernels (compiled away for :class:`NoLearning`)."""
    if len(sl.sr_i):
        sparse_learning(t, learn, sl, dl)


@overload(run_rules)
def _run_rules(t, learn, sl, dl):
    if isinstance(sl, types.BaseNamedTuple) and sl.instance_class is NoLearning:
        return lambda t, learn, sl, dl: None

    def impl(t, learn, sl, dl):
        if sl.sr_i.shape[0] > 0:
            sparse_learning(t, learn, sl, dl)

    return impl
