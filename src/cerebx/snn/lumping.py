"""Lumped populations: neurons with the same state and the same input stepped once, exactly.

A population whose only input is one sparse projection from an input population, with one weight for all its
synapses and no plasticity (the thesis network's granule layer: each granule cell the conjunction of four mossy
fibres, box-coded, each firing at every 2 ms step while its signal is in its box), is a few hundred distinct
states over tens of thousands of neurons: every neuron's next state is a function of its state and of how many
of its fibres fired (its conductance gets the same float32 additions, ``w`` times the arrival's decay, once per
arriving spike). So its neurons are kept in *classes*: one state (u, g, refractory count) and one input count
per class, and a doubly linked list of members. A step integrates the classes (the population's own integration
kernel, on the class arrays), not the neurons, and a class that spikes spikes for every member.

Input is tracked by change, not by spike: at each arrival window (the population's step that receives the input
population's spikes of one control step) the fibres that fired are compared with those of the previous window,
and only the targets of fibres that started or stopped firing move, each to the class of (its class, its change
in count); members of one class that see the same change move together (``split``). Box coding changes a fibre
every few tens of milliseconds, so a step moves a few hundred neurons instead of delivering to ~25,000 and
integrating ~30,000. A class that comes back to rest with no input dissolves: its members are at rest, in no
class (``cls`` -1), and cost nothing.

Every result is bit for bit the unlumped path's: the class state goes through the same compiled arithmetic as a
listed neuron's (the same additions in the same order, the same integration kernel), and spikes are emitted in
global index order as a compact population's are. Python reads and writes neuron state through
:func:`unlump` / :func:`lump` (the population's compact list is written from the classes, and the classes are
rebuilt from it: neurons with equal state bits share a class, with no input counted yet, which the next arrival
window's comparison against an empty previous window makes exact again).
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
from numba import njit

from cerebx.snn.topology import (
    I_COMPACT,
    I_HI,
    I_KIND,
    I_LO,
    I_RATIO,
    KIND_INPUT,
    KIND_LIF_AMPA,
    S_DELAY,
    S_N_PRE,
    S_POST_POP,
    S_PRE_LO,
    S_ROW,
    S_TEACHING,
)

KMAX = 8  # largest number of a lumped neuron's input synapses (the change of its count in one window is within +-KMAX)
SPLIT_COLS = 2 * KMAX + 1


class Lumps(NamedTuple):
    """Classes of the lumped populations (slots of population ``pi``'s classes: its own index range [lo, hi))."""

    proj: np.ndarray  # int64 [pop]: the sparse projection a lumped population's input comes through (-1: not lumped)
    w: np.ndarray  # float32 [pop]: that projection's one weight (nS)
    cls: np.ndarray  # int32 [n]: class slot of each neuron (-1: at rest, in no class)
    nx: np.ndarray  # int32 [n]: next member of the neuron's class (-1: last)
    pv: np.ndarray  # int32 [n]: previous member (-1: first)
    cu: np.ndarray  # float32 [n]: class state V - E_L (mV)
    cg: np.ndarray  # float32 [n]: class AMPA conductance (nS)
    cref: np.ndarray  # float32 [n]: class refractory steps left
    cflag: np.ndarray  # uint8 [n]: the class spiked in the step just integrated
    ccnt: np.ndarray  # int32 [n]: spikes each member receives per arrival window (its fibres that fire)
    chead: np.ndarray  # int32 [n]: first member (-1: none)
    csize: np.ndarray  # int32 [n]: members (0: a free slot, at rest with no input)
    n_cls: np.ndarray  # int64 [pop]: class slots in use from lo on (free ones among them)
    cfree: np.ndarray  # int32 [n]: stack of free slots below lo + n_cls, from lo on
    n_free: np.ndarray  # int64 [pop]: free slots on that stack
    pc: np.ndarray  # int32 [n]: spikes of each input neuron (global index) in the previous arrival window
    cc: np.ndarray  # int32 [n]: the same for this window (zero between uses)
    plist: np.ndarray  # int32 [n]: the input neurons with pc > 0, in the input population's range (pre_lo on)
    clist: np.ndarray  # int32 [n]: this window's, same range (scratch)
    pn: np.ndarray  # int64 [pop]: length of the lumped population's plist
    dd: np.ndarray  # int32 [n]: change of each neuron's count in this window (zero between uses)
    tm: np.ndarray  # uint8 [n]: neuron touched in this window (zero between uses)
    tl: np.ndarray  # int32 [n]: touched neurons (scratch)
    split: np.ndarray  # int32 [rows, SPLIT_COLS]: 1 + where (class - lo + 1, change + KMAX) moves (0 between uses)
    used: np.ndarray  # int64 [n]: split entries set in this window, hash slots used by a merge (scratch)
    emp: np.ndarray  # int32 [n]: classes emptied in this window (scratch)
    htab: np.ndarray  # int32 [H]: 1 + a class, by the hash of its state and count (0 between uses); H a power of 2


def empty(n: int, n_pop: int) -> Lumps:
    """No lumped population (every array sized for ``n`` neurons, ``split`` one row)."""
    def i32(fill: int = 0) -> np.ndarray:
        return np.full(n, fill, np.int32)

    def per_pop(fill: int = 0) -> np.ndarray:
        return np.full(n_pop, fill, np.int64)

    return Lumps(proj=per_pop(-1), w=np.zeros(n_pop, np.float32), cls=i32(-1), nx=i32(-1), pv=i32(-1),
                 cu=np.zeros(n, np.float32), cg=np.zeros(n, np.float32), cref=np.zeros(n, np.float32),
                 cflag=np.zeros(n, np.uint8), ccnt=i32(), chead=i32(-1), csize=i32(), n_cls=per_pop(), cfree=i32(),
                 n_free=per_pop(), pc=i32(), cc=i32(), plist=i32(), clist=i32(), pn=per_pop(), dd=i32(),
                 tm=np.zeros(n, np.uint8), tl=i32(), split=np.zeros((1, SPLIT_COLS), np.int32),
                 used=np.zeros(SPLIT_COLS, np.int64), emp=i32(), htab=np.zeros(1, np.int32))


@njit(cache=True, boundscheck=False)
def _new_class(lp, pi, lo, src, d):
    """A class slot for the members of class ``src`` (-1: rest) whose count changes by ``d``: src's state,
    count + d, no members."""
    if lp.n_free[pi] > 0:
        lp.n_free[pi] -= 1
        c = lp.cfree[lo + lp.n_free[pi]]
    else:
        c = lo + lp.n_cls[pi]
        lp.n_cls[pi] += 1
    if src >= 0:
        lp.cu[c], lp.cg[c], lp.cref[c] = lp.cu[src], lp.cg[src], lp.cref[src]
        lp.ccnt[c] = lp.ccnt[src] + d
    else:
        lp.cu[c], lp.cg[c], lp.cref[c] = 0.0, 0.0, 0.0
        lp.ccnt[c] = d
    lp.cflag[c] = 0
    lp.chead[c] = -1
    lp.csize[c] = 0
    return c


@njit(cache=True, boundscheck=False)
def _free(lp, pi, lo, c):
    lp.cu[c], lp.cg[c], lp.cref[c] = 0.0, 0.0, 0.0
    lp.ccnt[c] = 0
    lp.cflag[c] = 0
    lp.chead[c] = -1
    lp.csize[c] = 0
    lp.cfree[lo + lp.n_free[pi]] = c
    lp.n_free[pi] += 1


@njit(cache=True, boundscheck=False)
def _touch(lp, q0, q1, sp_post, e, nt):
    """Add ``e`` to the count change of the targets sp_post[q0:q1]."""
    for q in range(q0, q1):
        i = sp_post[q]
        if lp.tm[i] == 0:
            lp.tm[i] = 1
            lp.tl[nt] = i
            nt += 1
        lp.dd[i] += e
    return nt


@njit(cache=True, boundscheck=False)
def _move(lp, pi, lo, n_act, nt):
    """Move each touched neuron whose count changed to the class of (its class, the change)."""
    nu = 0
    ne = 0
    split, cls, nx, pv = lp.split, lp.cls, lp.nx, lp.pv
    for k in range(nt):
        i = lp.tl[k]
        d = lp.dd[i]
        lp.dd[i] = 0
        lp.tm[i] = 0
        if d == 0:
            continue
        c = cls[i]
        row = c - lo + 1 if c >= 0 else 0
        col = d + KMAX
        dst = split[row, col] - 1
        if dst < 0:
            dst = _new_class(lp, pi, lo, c, d)
            split[row, col] = dst + 1
            lp.used[nu] = row * SPLIT_COLS + col
            nu += 1
        if c >= 0:  # unlink from c
            a, b = pv[i], nx[i]
            if a >= 0:
                nx[a] = b
            else:
                lp.chead[c] = b
            if b >= 0:
                pv[b] = a
            lp.csize[c] -= 1
            if lp.csize[c] == 0:
                lp.emp[ne] = c
                ne += 1
        else:
            n_act[pi] += 1
        h = lp.chead[dst]
        nx[i] = h
        pv[i] = -1
        if h >= 0:
            pv[h] = i
        lp.chead[dst] = i
        lp.csize[dst] += 1
        cls[i] = dst
    flat = split.reshape(-1)
    for k in range(nu):
        flat[lp.used[k]] = 0
    for k in range(ne):
        c = lp.emp[k]
        if lp.csize[c] == 0:
            _free(lp, pi, lo, c)


@njit(cache=True, boundscheck=False)
def arrival_window(lp, pi, p, t, n_sub, ratio, dl, nrn, lo, hi):
    """The lumped population ``pi``'s input at its delivery step ``t`` (projection ``p``), an arrival window of the
    input population's spikes of one control step (the caller tests :func:`in_window` first; ``dl``: the kernels'
    ``Delivery``): move the neurons whose count changed since the previous such window and add each class's count
    of spikes to its conductance. The spikes arrive at ``t`` itself (the projection's delay is a multiple of the
    population's step: :func:`eligible`), so each adds the weight unscaled, exactly as the unlumped delivery's
    ``w * 1`` does. Returns 0 when done; 1 when a cell's count would change by more than KMAX (a fibre given
    several times in one step): the population then goes back to its list for good (``nrn``: the kernels'
    ``Neurons``; [lo, hi): its range) and the caller delivers this window's spikes to the list."""
    sp_i, sp_ptr, sp_post, ring_idx, ring_n = dl.sp_i, dl.sp_ptr, dl.sp_post, dl.ring_idx, dl.ring_n
    delay = sp_i[p, S_DELAY]
    a = (t - delay) % n_sub
    pre_lo, n_pre, off = sp_i[p, S_PRE_LO], sp_i[p, S_N_PRE], sp_i[p, S_ROW]
    R = ring_idx.shape[0]
    sl = (t - a - delay) % R
    pc, cc, plist, clist = lp.pc, lp.cc, lp.plist, lp.clist
    ncur = 0
    for k in range(ring_n[sl]):
        j = ring_idx[sl, k] - pre_lo
        if j < 0 or j >= n_pre:
            continue
        if cc[pre_lo + j] == 0:
            clist[pre_lo + ncur] = j
            ncur += 1
        cc[pre_lo + j] += 1
    nt = 0
    for k in range(ncur):
        j = clist[pre_lo + k]
        e = cc[pre_lo + j] - pc[pre_lo + j]
        if e != 0:
            nt = _touch(lp, sp_ptr[off + j], sp_ptr[off + j + 1], sp_post, e, nt)
    npr = lp.pn[pi]
    for k in range(npr):
        j = plist[pre_lo + k]
        if cc[pre_lo + j] == 0:
            nt = _touch(lp, sp_ptr[off + j], sp_ptr[off + j + 1], sp_post, -pc[pre_lo + j], nt)
        pc[pre_lo + j] = 0
    for k in range(ncur):
        j = clist[pre_lo + k]
        pc[pre_lo + j] = cc[pre_lo + j]
        cc[pre_lo + j] = 0
        plist[pre_lo + k] = j
    lp.pn[pi] = ncur
    for k in range(nt):
        if abs(lp.dd[lp.tl[k]]) > KMAX:  # beyond the class table: the list takes over, exactly
            for q in range(nt):
                lp.dd[lp.tl[q]] = 0
                lp.tm[lp.tl[q]] = 0
            release(lp, pi, lo, hi, nrn)
            return 1
    if nt > 0:
        _move(lp, pi, lo, nrn.n_act, nt)
    # each class's spikes: the same float32 additions, one at a time, as a listed neuron's. One pass per spike:
    # this code is inlined into run_step, whose fast-math would let the compiler sum a class's spikes in one
    # loop as count x w, which rounds differently
    ws = lp.w[pi]
    cg, ccnt = lp.cg[lo : lo + lp.n_cls[pi]], lp.ccnt[lo : lo + lp.n_cls[pi]]
    top = 0
    for c in range(cg.shape[0]):
        top = max(top, ccnt[c])
    for k in range(top):
        for c in range(cg.shape[0]):
            if ccnt[c] > k:
                cg[c] += ws
    return 0


@njit(cache=True, boundscheck=False)
def collect(lp, pi, lo, ring_idx, sl, ring_n, out_idx, out_t, n_out, stamp):
    """Append the members of the classes that spiked to ring slot ``sl`` and the step's output, in global index
    order (as a compact population's spikes are)."""
    m0 = m = ring_n[sl]
    for c in range(lo, lo + lp.n_cls[pi]):
        if lp.cflag[c] == 0:
            continue
        i = lp.chead[c]
        while i >= 0:
            ring_idx[sl, m] = i
            m += 1
            i = lp.nx[i]
    blk = ring_idx[sl, m0:m]
    if m - m0 > 1:
        blk.sort()
    for k in range(m - m0):
        out_idx[n_out + k] = blk[k]
        out_t[n_out + k] = stamp
    ring_n[sl] = m
    return n_out + m - m0


@njit(cache=True, boundscheck=False)
def dissolve(lp, pi, lo, n_act):
    """Classes back at rest with no input: their members leave every class (at rest), their slots are freed."""
    for c in range(lo, lo + lp.n_cls[pi]):
        if (lp.csize[c] == 0 or lp.ccnt[c] != 0 or lp.cu[c] != 0.0 or lp.cg[c] != 0.0
                or lp.cref[c] != 0.0):
            continue
        i = lp.chead[c]
        while i >= 0:
            lp.cls[i] = -1
            i = lp.nx[i]
        n_act[pi] -= lp.csize[c]
        _free(lp, pi, lo, c)
    # the free slots at the top of the range are given back (the class arrays integrated stay short)
    top = lp.n_cls[pi]
    while top > 0 and lp.csize[lo + top - 1] == 0:
        top -= 1
    if top < lp.n_cls[pi]:
        k = 0
        for f in range(lp.n_free[pi]):
            c = lp.cfree[lo + f]
            if c < lo + top:
                lp.cfree[lo + k] = c
                k += 1
        lp.n_free[pi] = k
        lp.n_cls[pi] = top


@njit(cache=True, boundscheck=False)
def unlump(lp, pi, lo, hi, nrn):
    """Write population ``pi``'s compact list (the neurons in a class, in index order, with their class's state)
    into ``nrn`` (the kernels' ``Neurons``) from its classes; the classes stay as they are. The list's delivery
    caches are stale (``pop_ep``)."""
    u, g, ref, cid, slot = nrn.u, nrn.g, nrn.ref, nrn.cid, nrn.slot
    k = lo
    for i in range(lo, hi):
        c = lp.cls[i]
        if c < 0:
            slot[i] = -1
            continue
        slot[i] = k
        cid[k] = i
        u[k] = lp.cu[c]
        g[0, k] = lp.cg[c]
        g[1, k] = 0.0
        g[2, k] = 0.0
        ref[k] = lp.cref[c]
        k += 1
    for q in range(k, hi):
        u[q] = 0.0
        g[0, q] = 0.0
        g[1, q] = 0.0
        g[2, q] = 0.0
        ref[q] = 0.0
    nrn.n_act[pi] = k - lo
    nrn.n_rest[pi] = 0
    nrn.pop_ep[pi] += 1


@njit(cache=True, boundscheck=False)
def merge(lp, pi, lo):
    """Classes that have come to the same state bits with the same count are one class from now on (histories
    that differ converge: the periodic steady states of cells with the same count of active fibres are the same
    float32 numbers): the smaller one's members join the larger, its slot is freed."""
    htab = lp.htab
    # a table twice the class slots in use (a power of 2, at most htab's size): probes into all of htab (twice the
    # population) were the network thread's hot spot in samples. Equal keys meet whatever the size
    size = 16
    while size < 2 * lp.n_cls[pi]:
        size *= 2
    mask = min(size, htab.shape[0]) - 1
    cu, cg, cref, ccnt, csize = lp.cu, lp.cg, lp.cref, lp.ccnt, lp.csize
    bu, bg, br = cu.view(np.uint32), cg.view(np.uint32), cref.view(np.uint32)
    nu = 0
    for c in range(lo, lo + lp.n_cls[pi]):
        if csize[c] == 0:
            continue
        h = (np.uint32(bu[c]) * np.uint32(0x9E3779B1)) ^ (np.uint32(bg[c]) * np.uint32(0x85EBCA77))
        h = (h ^ (np.uint32(br[c]) * np.uint32(0xC2B2AE3D)) ^ (np.uint32(ccnt[c]) * np.uint32(0x27D4EB2F)))
        k = int(h ^ (h >> np.uint32(15))) & mask
        while True:
            e = htab[k] - 1
            if e < 0:
                htab[k] = c + 1
                lp.used[nu] = k
                nu += 1
                break
            if bu[e] == bu[c] and bg[e] == bg[c] and br[e] == br[c] and ccnt[e] == ccnt[c]:
                big, small = (e, c) if csize[e] >= csize[c] else (c, e)
                i = lp.chead[small]
                last = i
                while i >= 0:
                    lp.cls[i] = big
                    last = i
                    i = lp.nx[i]
                h0 = lp.chead[big]  # the small list spliced in front of the big one
                lp.nx[last] = h0
                if h0 >= 0:
                    lp.pv[h0] = last
                lp.chead[big] = lp.chead[small]
                csize[big] += csize[small]
                lp.chead[small] = -1
                _free(lp, pi, lo, small)
                htab[k] = big + 1
                break
            k = (k + 1) & mask
    for q in range(nu):
        htab[lp.used[q]] = 0


@njit(cache=True, boundscheck=False)
def release(lp, pi, lo, hi, nrn):
    """Population ``pi`` back to its compact list for good (:func:`unlump`; the same results from then on)."""
    unlump(lp, pi, lo, hi, nrn)
    lp.proj[pi] = -1


LUMP_MAX = 4  # a population whose classes exceed 1/LUMP_MAX of its neurons off rest goes back to its list
LUMP_MIN = 256  # ... once it has this many off rest


@njit(cache=True, boundscheck=False)
def worth_it(n_cls, n_free, pi, n_act):
    """Whether the classes still pay: with input that changes at most spikes (Poisson fibres) nearly every neuron
    off rest has a class of its own, and moving neurons between classes costs more than stepping the list.
    (``n_cls``, ``n_free``: the :class:`Lumps` arrays, not the whole tuple: a compiled call counts a reference to
    every array of a tuple it is passed, 27 here, on entry and again on return, every granule step.)"""
    live = n_cls[pi] - n_free[pi]
    return n_act[pi] < LUMP_MIN or LUMP_MAX * live <= n_act[pi]


@njit(cache=True, inline="always")
def in_window(t, delay, n_sub, ratio):
    """Whether delivery step ``t`` of a projection with ``delay`` (substeps) onto a population stepping every
    ``ratio`` substeps is an arrival window of one control step's spikes (of ``n_sub`` substeps): where
    :func:`arrival_window` is called, made by the caller before the call (which passes three tuples of arrays:
    ~100 reference counts, at every step of the population)."""
    a = (t - delay) % n_sub
    return a < ratio and t - delay - a >= 0


def lump(lp: Lumps, pi: int, lo: int, hi: int, pre: tuple[int, int], nrn: Any) -> None:
    """Rebuild population ``pi``'s classes from its compact list in ``nrn`` (the kernels' ``Neurons``): neurons
    with equal state bits share a class, with no input counted (so the next arrival window counts every fibre that
    fires as a change; ``pre``: the input population's first index and size)."""
    u, g, ref, cid, n_act = nrn.u, nrn.g, nrn.ref, nrn.cid, nrn.n_act
    pre_lo, n_pre = pre
    na = int(n_act[pi])
    idx = cid[lo : lo + na].astype(np.int64)
    st = np.stack([u[lo : lo + na].view(np.int32), g[0, lo : lo + na].view(np.int32),
                   ref[lo : lo + na].view(np.int32)], axis=1)
    live = np.flatnonzero((st != 0).any(axis=1))
    lp.cls[lo:hi] = -1
    lp.nx[lo:hi] = -1
    lp.pv[lo:hi] = -1
    for a in (lp.cu, lp.cg, lp.cref):
        a[lo:hi] = 0
    lp.cflag[lo:hi], lp.ccnt[lo:hi], lp.csize[lo:hi], lp.chead[lo:hi] = 0, 0, 0, -1
    lp.pc[pre_lo : pre_lo + n_pre] = 0
    lp.pn[pi] = 0
    lp.n_free[pi] = 0
    if len(live) == 0:
        lp.n_cls[pi] = 0
        n_act[pi] = 0
        return
    keys, first, inv = np.unique(st[live], axis=0, return_index=True, return_inverse=True)
    inv = inv.reshape(-1)
    nc = len(keys)
    lp.n_cls[pi] = nc
    src = live[first]
    lp.cu[lo : lo + nc] = u[lo + src]
    lp.cg[lo : lo + nc] = g[0, lo + src]
    lp.cref[lo : lo + nc] = ref[lo + src]
    members = idx[live]
    order = np.argsort(inv, kind="stable")
    m, k = members[order], inv[order]
    same = np.r_[k[1:] == k[:-1], False]
    nxt = np.where(same, np.r_[m[1:], 0], -1)
    prv = np.where(np.r_[False, same[:-1]], np.r_[0, m[:-1]], -1)
    lp.nx[m] = nxt
    lp.pv[m] = prv
    lp.cls[m] = lo + k
    starts = np.r_[True, ~same[:-1]]
    lp.chead[lo + k[starts]] = m[starts]
    lp.csize[lo : lo + nc] = np.bincount(k, minlength=nc)
    n_act[pi] = len(live)


def eligible(pop_i: np.ndarray, lazy: np.ndarray, nmda: np.ndarray, sparse: list, sp_i: np.ndarray,
             de_i: np.ndarray, rule_posts: list[tuple[int, int]], n_sub: int) -> tuple[np.ndarray, np.ndarray]:
    """Which populations are lumped, and through which projection: (``proj`` [pop], ``w`` [pop]) of :class:`Lumps`.

    A population is lumped when it is a compact AMPA-only population (``lif_cond`` without NMDA or GABA input)
    whose every input comes through one sparse projection from an input population, with one weight for all its
    synapses, no plasticity rule writing them (``rule_posts``: the (post_lo, n_post) ranges the sparse rules
    write), at most ``KMAX`` synapses onto any neuron, a delay that is a multiple of the population's step (its
    spikes arrive on the step's boundary) and a step that divides the control step; no other lumped population
    takes input from the same input population. Each condition is what makes the classes exact; a population that
    misses one runs unlumped, with the same results."""
    n_pop = pop_i.shape[0]
    proj = np.full(n_pop, -1, np.int64)
    w = np.zeros(n_pop, np.float32)
    pre_taken: set[int] = set()
    for pi in range(n_pop):
        lo, hi, ratio = int(pop_i[pi, I_LO]), int(pop_i[pi, I_HI]), int(pop_i[pi, I_RATIO])
        if (pop_i[pi, I_KIND] != KIND_LIF_AMPA or pop_i[pi, I_COMPACT] == 0 or lazy[pi] > 0 or nmda[pi] != 0
                or n_sub % ratio != 0):
            continue
        if len(de_i) and (de_i[:, 8] == pi).any():
            continue
        into = [k for k in range(len(sp_i)) if sp_i[k, S_POST_POP] == pi]
        if len(into) != 1 or sp_i[into[0], S_TEACHING] != 0:
            continue
        k = into[0]
        s = sparse[k]
        pre_lo = int(sp_i[k, S_PRE_LO])
        pre_pop = int(np.searchsorted(pop_i[:, I_HI], pre_lo, side="right"))
        if pop_i[pre_pop, I_KIND] != KIND_INPUT or pre_lo in pre_taken or int(sp_i[k, S_DELAY]) % ratio != 0:
            continue
        if len(s.w) == 0 or (s.w != s.w[0]).any():
            continue
        if np.bincount(np.asarray(s.post, np.int64) - lo, minlength=hi - lo).max() > KMAX:
            continue
        if any(a < hi and lo < a + n for a, n in rule_posts):
            continue
        proj[pi] = k
        w[pi] = s.w[0]
        pre_taken.add(pre_lo)
    return proj, w


def build(n: int, proj: np.ndarray, w: np.ndarray, pop_i: np.ndarray) -> Lumps:
    """:class:`Lumps` for ``n`` neurons with the lumped populations of :func:`eligible`."""
    lp = empty(n, len(proj))
    rows = max([int(pop_i[pi, I_HI] - pop_i[pi, I_LO]) for pi in np.flatnonzero(proj >= 0)] + [0]) + 1
    h = 1 << int(np.ceil(np.log2(2 * rows)))
    return lp._replace(proj=proj.astype(np.int64), w=w.astype(np.float32),
                       split=np.zeros((rows, SPLIT_COLS), np.int32), used=np.zeros(max(n, 1), np.int64),
                       htab=np.zeros(h, np.int32))
