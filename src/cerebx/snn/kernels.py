"""numba kernels: one call advances the whole network by one 2 ms control step.

Integration (thesis Eq. 2.2-2.8): conductances decay exactly (g <- g e^(-dt/tau)); the membrane
equation is integrated with classical RK4 over each dt substep, feeding RK4 the exact
conductance at the start, middle and end of the substep (and the NMDA Mg block at the stage
voltage). A spike is emitted when V >= V_thr at the end of a substep; V is then reset to E_L and
held there for t_ref. Synaptic events arrive at substep boundaries, exactly ``delay`` substeps
after the presynaptic spike.

Spike times are integers in substeps (t = 0 is the start of the run). Spikes produced while
integrating substep t carry time t + 1 and live in ring slot (t + 1) % R until every projection
has read them.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from cerebx.snn.topology import (
    KIND_INPUT,
    KIND_LIF_AMPA,
    P_CLAMP,
    P_CM,
    P_DA,
    P_DAH,
    P_DG,
    P_DGH,
    P_DN,
    P_DNH,
    P_EA,
    P_EG,
    P_EL,
    P_GL,
    P_H,
    P_NREF,
    P_VTH,
)

G_FLOOR = np.float32(1e-12)  # conductances below this (nS) become exactly 0 (avoids denormals)


@njit(cache=True, parallel=True, fastmath=True, error_model="numpy", boundscheck=False)
def _lif_ampa(V, gA, ref, flag, p):
    """Neurons with a single (AMPA) conductance: vectorised RK4 substep. Arguments are the
    population's slices (a loop over an array's own length lets LLVM vectorise it)."""
    f32 = np.float32
    h, half, sixth = f32(p[P_H]), f32(0.5), f32(1.0 / 6.0)
    gL, EL, EA, invC = f32(p[P_GL]), f32(p[P_EL]), f32(p[P_EA]), f32(1.0 / p[P_CM])
    dA, dAh, Vth, nref = f32(p[P_DA]), f32(p[P_DAH]), f32(p[P_VTH]), f32(p[P_NREF])
    floor = EL if p[P_CLAMP] > 0.5 else f32(-1e30)
    zero, one, two = f32(0.0), f32(1.0), f32(2.0)
    cnt = 0
    for i in prange(V.shape[0]):
        v = V[i]
        g0 = gA[i]
        r = ref[i]
        gh = g0 * dAh
        g1 = g0 * dA
        k1 = (gL * (EL - v) + g0 * (EA - v)) * invC
        v2 = v + half * h * k1
        k2 = (gL * (EL - v2) + gh * (EA - v2)) * invC
        v3 = v + half * h * k2
        k3 = (gL * (EL - v3) + gh * (EA - v3)) * invC
        v4 = v + h * k3
        k4 = (gL * (EL - v4) + g1 * (EA - v4)) * invC
        vn = v + h * sixth * (k1 + two * k2 + two * k3 + k4)
        vn = vn if vn > floor else floor
        refr = r > zero
        s = (vn >= Vth) and not refr
        V[i] = EL if (refr or s) else vn
        ref[i] = nref if s else (r - one if refr else zero)
        gA[i] = g1 if g1 > G_FLOOR else zero
        flag[i] = s
        cnt += s
    return cnt


@njit(cache=True, fastmath=True, error_model="numpy", boundscheck=False, inline="always")
def _dvdt(v, gA, gN, gG, gL, EL, EA, EG, invC):
    mg = 1.0 / (1.0 + np.exp(-0.062 * v) * (1.2 / 3.57))
    return (gL * (EL - v) + (gA + gN * mg) * (EA - v) + gG * (EG - v)) * invC


@njit(cache=True, fastmath=True, error_model="numpy", boundscheck=False)
def _lif_full(V, gA, gN, gG, ref, flag, p):
    """Neurons with AMPA, NMDA (Mg block, Eq. 2.8) and GABA conductances: RK4 substep in float64."""
    h = p[P_H]
    gL, EL, EA, EG, invC = p[P_GL], p[P_EL], p[P_EA], p[P_EG], 1.0 / p[P_CM]
    Vth, nref = p[P_VTH], p[P_NREF]
    clamp = p[P_CLAMP] > 0.5
    cnt = 0
    for i in range(V.shape[0]):
        v = np.float64(V[i])
        a0, n0, b0 = np.float64(gA[i]), np.float64(gN[i]), np.float64(gG[i])
        ah, nh, bh = a0 * p[P_DAH], n0 * p[P_DNH], b0 * p[P_DGH]
        a1, n1, b1 = a0 * p[P_DA], n0 * p[P_DN], b0 * p[P_DG]
        k1 = _dvdt(v, a0, n0, b0, gL, EL, EA, EG, invC)
        k2 = _dvdt(v + 0.5 * h * k1, ah, nh, bh, gL, EL, EA, EG, invC)
        k3 = _dvdt(v + 0.5 * h * k2, ah, nh, bh, gL, EL, EA, EG, invC)
        k4 = _dvdt(v + h * k3, a1, n1, b1, gL, EL, EA, EG, invC)
        vn = v + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        if clamp and vn < EL:
            vn = EL
        r = ref[i]
        s = False
        if r > 0:
            vn = EL
            ref[i] = r - 1
        elif vn >= Vth:
            s = True
            vn = EL
            ref[i] = nref
        V[i] = vn
        gA[i] = a1 if a1 > G_FLOOR else 0.0
        gN[i] = n1 if n1 > G_FLOOR else 0.0
        gG[i] = b1 if b1 > G_FLOOR else 0.0
        flag[i] = s
        cnt += s
    return cnt


@njit(cache=True, boundscheck=False)
def _collect(flag, lo, ring_idx, slot, ring_n, out_idx, out_t, n_out, stamp):
    """Append the flagged neurons of a population (flag = its slice, lo = its first global index)
    to the ring slot and the step's output list, scanning 8 flags per word."""
    m = ring_n[slot]
    n = flag.shape[0]
    n8 = n // 8
    words = flag[: n8 * 8].view(np.uint64)
    for wi in range(n8):
        if words[wi] == 0:
            continue
        for i in range(wi * 8, wi * 8 + 8):
            if flag[i]:
                ring_idx[slot, m] = lo + i
                m += 1
                out_idx[n_out] = lo + i
                out_t[n_out] = stamp
                n_out += 1
    for i in range(n8 * 8, n):
        if flag[i]:
            ring_idx[slot, m] = lo + i
            m += 1
            out_idx[n_out] = lo + i
            out_t[n_out] = stamp
            n_out += 1
    ring_n[slot] = m
    return n_out


@njit(cache=True, fastmath=True, boundscheck=False)
def _ltd(w, n_post, col, n_col, lo_w, ltd, kern, pf_t, pf_j, pf_head, t):
    """LTD for CF arrivals at time t on the PCs in col[:n_col]: for every buffered PF arrival
    (t_pf, j) with k(t - t_pf) > 0, w[j, i] += ltd * k, clipped at lo_w."""
    cap = pf_t.shape[0]
    klen = kern.shape[0]
    h = pf_head
    stop = max(0, pf_head - cap)
    while h > stop:
        h -= 1
        e = h % cap
        m = t - pf_t[e]
        if m >= klen:
            break
        kv = kern[m]
        if kv == 0.0:
            continue
        dw = np.float32(ltd * kv)
        base = pf_j[e] * n_post
        for q in range(n_col):
            k = base + col[q]
            x = w[k] + dw
            w[k] = x if x > lo_w else lo_w


@njit(cache=True, fastmath=True, boundscheck=False)
def run_step(t0, n_sub, inputs, learn, V, g, ref, flag, pop_lo, pop_hi, pop_kind, pop_par,
             ring_idx, ring_n, sp_i, sp_ptr, sp_post, sp_w, de_i, dense_w,
             pl_i, pl_f, kern, pf_t, pf_j, pf_head, pf_lost, col_buf, out_idx, out_t):
    """Advance the network by one control step of ``n_sub`` substeps starting at substep t0.

    ``inputs`` are global indices of input fibres spiking at t0. Returns the number of spikes
    written to out_idx/out_t (out_t = substep 1..n_sub at whose end the spike happened).
    """
    R = ring_idx.shape[0]
    slot0 = t0 % R
    m = ring_n[slot0]
    for k in range(inputs.shape[0]):
        ring_idx[slot0, m] = inputs[k]
        m += 1
    ring_n[slot0] = m
    n_out = 0
    for s in range(n_sub):
        t = t0 + s
        # sparse projections (CSR by presynaptic neuron); teaching ones carry no current
        for p in range(sp_i.shape[0]):
            if sp_i[p, 5] != 0:
                continue
            pre_lo, n_pre, off, rec, delay = sp_i[p, 0], sp_i[p, 1], sp_i[p, 2], sp_i[p, 3], sp_i[p, 4]
            if t - delay < 0:
                continue
            sl = (t - delay) % R
            for k in range(ring_n[sl]):
                j = ring_idx[sl, k] - pre_lo
                if j < 0 or j >= n_pre:
                    continue
                for q in range(sp_ptr[off + j], sp_ptr[off + j + 1]):
                    g[rec, sp_post[q]] += sp_w[q]
        # dense (all-to-all) projections: a spike adds its weight row; plastic rows get LTP
        for d in range(de_i.shape[0]):
            pre_lo, n_pre, post_lo, n_post = de_i[d, 0], de_i[d, 1], de_i[d, 2], de_i[d, 3]
            w_off, rec, delay, pl = de_i[d, 4], de_i[d, 5], de_i[d, 6], de_i[d, 7]
            if t - delay < 0:
                continue
            sl = (t - delay) % R
            for k in range(ring_n[sl]):
                j = ring_idx[sl, k] - pre_lo
                if j < 0 or j >= n_pre:
                    continue
                row = w_off + j * n_post
                for q in range(n_post):
                    g[rec, post_lo + q] += dense_w[row + q]
                if pl >= 0 and learn:
                    ltp, hi_w = np.float32(pl_f[pl, 0]), np.float32(pl_f[pl, 3])
                    for q in range(n_post):
                        x = dense_w[row + q] + ltp
                        dense_w[row + q] = x if x < hi_w else hi_w
                if pl >= 0:
                    cap = pf_t.shape[1]
                    e = pf_head[pl] % cap
                    if pf_head[pl] >= cap and t - pf_t[pl, e] < pl_i[pl, 3]:
                        pf_lost[pl] += 1
                    pf_t[pl, e] = t
                    pf_j[pl, e] = j
                    pf_head[pl] += 1
        # LTD: teacher (CF) spikes arriving now at PCs of each plastic projection
        if learn:
            for pl in range(pl_i.shape[0]):
                d, tp = pl_i[pl, 0], pl_i[pl, 1]
                delay = sp_i[tp, 4]
                if t - delay < 0:
                    continue
                sl = (t - delay) % R
                pre_lo, n_pre, off = sp_i[tp, 0], sp_i[tp, 1], sp_i[tp, 2]
                post_lo, n_post = de_i[d, 2], de_i[d, 3]
                n_col = 0
                for k in range(ring_n[sl]):
                    j = ring_idx[sl, k] - pre_lo
                    if j < 0 or j >= n_pre:
                        continue
                    for q in range(sp_ptr[off + j], sp_ptr[off + j + 1]):
                        col_buf[n_col] = sp_post[q] - post_lo
                        n_col += 1
                if n_col > 0:
                    w_off = de_i[d, 4]
                    k_off, k_len = pl_i[pl, 2], pl_i[pl, 3]
                    _ltd(dense_w[w_off : w_off + de_i[d, 1] * n_post], n_post, col_buf, n_col,
                         np.float32(pl_f[pl, 2]), pl_f[pl, 1], kern[k_off : k_off + k_len],
                         pf_t[pl], pf_j[pl], pf_head[pl], t)
        # integrate every LIF population over [t, t+1); spikes are stamped t + 1
        nxt = (t + 1) % R
        ring_n[nxt] = 0
        for pi in range(pop_lo.shape[0]):
            kind = pop_kind[pi]
            if kind == KIND_INPUT:
                continue
            lo, hi = pop_lo[pi], pop_hi[pi]
            if kind == KIND_LIF_AMPA:
                cnt = _lif_ampa(V[lo:hi], g[0, lo:hi], ref[lo:hi], flag[lo:hi], pop_par[pi])
            else:
                cnt = _lif_full(V[lo:hi], g[0, lo:hi], g[1, lo:hi], g[2, lo:hi], ref[lo:hi], flag[lo:hi],
                                pop_par[pi])
            if cnt > 0:
                n_out = _collect(flag[lo:hi], lo, ring_idx, nxt, ring_n, out_idx, out_t, n_out, s + 1)
    return n_out
