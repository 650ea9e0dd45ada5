"""numba kernels of LWPR (Vijayakumar, D'Souza & Schaal 2005; update order of the reference
library, facts ``luque2011_capolei2020.md`` §3). One output dimension = one sub-model whose
receptive fields (RFs) live in three flat preallocated arrays; RF ``k`` is row ``k``:

- ``mat[k, f, :, :]`` (n_in x n_in): ``M`` (upper triangular, D = M^T M), ``D``, ``ALPHA`` (learning
  rates of M), and per PLS direction ``j`` (row ``j``): ``U`` regression axes, ``P`` projection axes,
  ``SXY`` (sum of w t z), ``SZ`` (sum of w s z);
- ``vec[k, f, :]`` (n_in): ``C`` centre, ``X0`` weighted input mean, and per direction ``BETA``,
  ``SS`` (sum w s^2), ``SY`` (sum w t s), ``SUMW``, ``NDATA``, ``LAM`` (forgetting), ``ECV2`` (sum w
  e_cv^2), ``H`` and ``RR`` (distance-metric gradient traces);
- ``sca[k, f]``: ``BETA0``, ``SUME2`` (sum w e^2), ``SSP``, ``TRUST`` (0/1), ``NREG`` (directions in use).

The meta learning of the learning rates (IDBD) of the reference library is not implemented.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

M_, D_, ALPHA, U_, P_, SXY, SZ = 0, 1, 2, 3, 4, 5, 6
N_MAT = 7
C_, X0, BETA, SS, SY, SUMW, NDATA, LAM, ECV2, H_, RR = 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10
N_VEC = 11
BETA0, SUME2, SSP, TRUST, NREG = 0, 1, 2, 3, 4
N_SCA = 5

# hyper-parameter vector (one float array so the kernels take a fixed argument list)
HP_W_GEN, HP_W_PRUNE, HP_INIT_LAMBDA, HP_FINAL_LAMBDA, HP_TAU_LAMBDA = 0, 1, 2, 3, 4
HP_PENALTY, HP_DIAG_ONLY, HP_UPDATE_D, HP_ADD_THRESHOLD, HP_INIT_S2, HP_BISQUARE, HP_CUTOFF = 5, 6, 7, 8, 9, 10, 11
N_HP = 12

_JIT = dict(cache=True, fastmath=False, error_model="numpy", boundscheck=False)


@njit(**_JIT)
def _activation(mat, vec, k, x, bisquare, dx):
    """Kernel weight w of RF k at x and dw/dq; fills dx = x - c."""
    n = x.shape[0]
    for i in range(n):
        dx[i] = x[i] - vec[k, C_, i]
    q = 0.0
    for i in range(n):
        acc = 0.0
        for j in range(n):
            acc += mat[k, D_, i, j] * dx[j]
        q += dx[i] * acc
    if bisquare:
        a = 1.0 - 0.25 * q
        if a <= 0.0:
            return 0.0, 0.0
        return a * a, -0.5 * a
    w = math.exp(-0.5 * q)
    return w, -0.5 * w


@njit(**_JIT)
def _project(mat, k, n_reg, z, s, zu):
    """s_j = u_j . z_j with z_{j+1} = z_j - p_j s_j (z_1 = z)."""
    n = z.shape[0]
    for i in range(n):
        zu[i] = z[i]
    for j in range(n_reg):
        sj = 0.0
        for i in range(n):
            sj += mat[k, U_, j, i] * zu[i]
        s[j] = sj
        for i in range(n):
            zu[i] -= mat[k, P_, j, i] * sj


@njit(**_JIT)
def init_rf(mat, vec, sca, k, template, x, y, init_M, init_D, init_alpha, hp):
    """RF k at centre x: a copy of ``template``'s metric, rates, beta0 and PLS count, or the
    initial ones when ``template`` < 0."""
    n = x.shape[0]
    mat[k] = 0.0
    vec[k] = 0.0
    sca[k] = 0.0
    if template >= 0:
        mat[k, M_] = mat[template, M_]
        mat[k, D_] = mat[template, D_]
        mat[k, ALPHA] = mat[template, ALPHA]
        sca[k, BETA0] = sca[template, BETA0]
        n_reg = int(sca[template, NREG])
    else:
        mat[k, M_] = init_M
        mat[k, D_] = init_D
        mat[k, ALPHA] = init_alpha
        sca[k, BETA0] = y
        n_reg = 2 if n > 1 else 1
    sca[k, NREG] = n_reg
    for i in range(n):
        vec[k, C_, i] = x[i]
    for j in range(n_reg):
        vec[k, SS, j] = hp[HP_INIT_S2]
        mat[k, U_, j, j] = 1.0
        mat[k, P_, j, j] = 1.0
        vec[k, SUMW, j] = 1e-10
        vec[k, NDATA, j] = 1e-10
        vec[k, LAM, j] = hp[HP_INIT_LAMBDA]


@njit(**_JIT)
def _update_regression(mat, vec, sca, k, z, y, w, s, zres, e_cv, ytar, zu, out):
    """PLS update of RF k with centred input z and target y. out = (y_pred local, e_cv_R, e)."""
    n = z.shape[0]
    R = int(sca[k, NREG])
    # projections with the old axes, keeping every residual input
    for i in range(n):
        zres[0, i] = z[i]
    for j in range(R):
        sj = 0.0
        for i in range(n):
            sj += mat[k, U_, j, i] * zres[j, i]
        s[j] = sj
        if j + 1 < R:
            for i in range(n):
                zres[j + 1, i] = zres[j, i] - mat[k, P_, j, i] * sj
    acc = 0.0
    for j in range(R):
        acc += vec[k, BETA, j] * s[j]
        vec[k, SUMW, j] = vec[k, SUMW, j] * vec[k, LAM, j] + w
        e_cv[j] = y - acc
    ytar[0] = y
    for j in range(1, R):
        ytar[j] = e_cv[j - 1]
    ws2 = 0.0
    for j in range(R):
        lam = vec[k, LAM, j]
        slow = 0.9 + 0.1 * lam
        norm2 = 0.0
        for i in range(n):
            v = mat[k, SXY, j, i] * slow + w * ytar[j] * zres[j, i]
            mat[k, SXY, j, i] = v
            norm2 += v * v
        if norm2 > 1e-24:
            inv = 1.0 / math.sqrt(norm2)
            for i in range(n):
                mat[k, U_, j, i] = mat[k, SXY, j, i] * inv
        wsj = w * s[j]
        vec[k, SS, j] = lam * vec[k, SS, j] + wsj * s[j]
        vec[k, SY, j] = lam * vec[k, SY, j] + wsj * ytar[j]
        inv_ss = 1.0 / vec[k, SS, j]
        for i in range(n):
            mat[k, SZ, j, i] = lam * mat[k, SZ, j, i] + wsj * zres[j, i]
            mat[k, P_, j, i] = mat[k, SZ, j, i] * inv_ss
        vec[k, BETA, j] = vec[k, SY, j] * inv_ss
        ws2 += wsj * wsj * inv_ss
    sca[k, SSP] = vec[k, LAM, R - 1] * sca[k, SSP] + ws2
    _project(mat, k, R, z, s, zu)
    # the last direction joins the prediction only once it has seen enough data
    n_used = R if vec[k, NDATA, R - 1] > 2.0 * n else R - 1
    yp = 0.0
    for j in range(n_used):
        yp += vec[k, BETA, j] * s[j]
    e_cv_r = e_cv[n_used - 1] if n_used > 0 else y
    e = y - yp
    if vec[k, NDATA, 0] * (1.0 - vec[k, LAM, 0]) > 0.1:
        sca[k, SUME2] = sca[k, SUME2] * vec[k, LAM, R - 1] + w * e * e
        for j in range(R):
            vec[k, ECV2, j] = vec[k, ECV2, j] * vec[k, LAM, j] + w * e_cv[j] * e_cv[j]
    if vec[k, NDATA, 0] > 2.0 * n:
        sca[k, TRUST] = 1.0
    out[0] = yp + sca[k, BETA0]
    out[1] = e_cv_r
    out[2] = e


@njit(**_JIT)
def _update_metric(mat, vec, sca, k, w, dwdq, e_cv, e, dx, s, hp, dJdM, ok):
    """One gradient step on M (leave-one-out cost plus penalty on D)."""
    n = dx.shape[0]
    R = int(sca[k, NREG])
    for j in range(R):
        ok[j] = vec[k, NDATA, j] * (1.0 - vec[k, LAM, 0]) > 0.1
    if not ok[0]:
        return
    h = 0.0
    for j in range(R):
        if ok[j]:
            h += s[j] * s[j] / vec[k, SS, j]
    h *= w
    W = vec[k, SUMW, 0]
    if R == 1 or vec[k, NDATA, R - 1] > 2.0 * n:
        E = vec[k, ECV2, R - 1]
    else:
        E = vec[k, ECV2, R - 2]
    T = sca[k, SUME2] / (E + 1e-10)
    T = min(1.0, T * T * T * T)
    dJ1dw = -E / W + e_cv * e_cv
    for j in range(R):
        if ok[j]:
            ps = s[j] / vec[k, SS, j]
            dJ1dw -= 2.0 * e * ps * vec[k, H_, j] + 2.0 * ps * ps * vec[k, RR, j]
    dJ1dw /= W
    wW = w / W
    pen = hp[HP_PENALTY] / n
    diag = hp[HP_DIAG_ONLY] != 0.0
    max_m = 0.0
    for a in range(n):
        for b in range(a, n):
            if diag and b != a:
                continue
            dJdM[a, b] = 0.0
            m_ab = abs(mat[k, M_, a, b])
            if m_ab > max_m:
                max_m = m_ab
    # dq/dM_ab = 2 dx_b (M dx)_a; dJ2/dM = 4 (gamma/n) (M D)_ab
    for a in range(n):
        mdx = 0.0
        for i in range(a, n):
            mdx += mat[k, M_, a, i] * dx[i]
        for b in range(a, n):
            if diag and b != a:
                continue
            md = 0.0
            for i in range(a, n):
                md += mat[k, M_, a, i] * mat[k, D_, i, b]
            dJdM[a, b] = wW * 4.0 * pen * md + 2.0 * dx[b] * mdx * dwdq * dJ1dw
    for a in range(n):
        for b in range(a, n):
            if diag and b != a:
                continue
            delta = mat[k, ALPHA, a, b] * T * dJdM[a, b]
            if delta > 0.1 * max_m:
                mat[k, ALPHA, a, b] *= 0.5
            else:
                mat[k, M_, a, b] -= delta
    for a in range(n):
        for b in range(n):
            acc = 0.0
            for i in range(min(a, b) + 1):
                acc += mat[k, M_, i, a] * mat[k, M_, i, b]
            mat[k, D_, a, b] = acc
    for j in range(R):
        if ok[j]:
            vec[k, H_, j] = vec[k, LAM, j] * vec[k, H_, j] + (w / (1.0 - h)) * s[j] * e_cv * T
            vec[k, RR, j] = vec[k, LAM, j] * vec[k, RR, j] + (w * w * e_cv * e_cv / (1.0 - h)) * s[j] * s[j] * T


@njit(**_JIT)
def _check_add_direction(mat, vec, sca, k, n, hp):
    R = int(sca[k, NREG])
    if R >= n:
        return
    mse_r = vec[k, ECV2, R - 1] / vec[k, SUMW, R - 1] + 1e-10
    mse_r1 = vec[k, ECV2, R - 2] / vec[k, SUMW, R - 2] + 1e-10
    if (mse_r < hp[HP_ADD_THRESHOLD] * mse_r1 and vec[k, NDATA, R - 1] > 0.99 * vec[k, NDATA, 0]
            and vec[k, NDATA, R - 1] * (1.0 - vec[k, LAM, R - 1]) > 0.5):
        vec[k, SS, R] = hp[HP_INIT_S2]
        mat[k, U_, R, R] = 1.0
        mat[k, P_, R, R] = 1.0
        vec[k, SUMW, R] = 1e-10
        vec[k, LAM, R] = hp[HP_INIT_LAMBDA]
        sca[k, NREG] = R + 1
        sca[k, SSP] = 0.0


@njit(**_JIT)
def update(mat, vec, sca, n_rf, x, y, init_M, init_D, init_alpha, hp):
    """One training pair (normalised x, scalar y) for a sub-model with ``n_rf`` RFs; the arrays must
    hold one free slot. Returns (prediction before the update's RF changes, new n_rf, max activation)."""
    n = x.shape[0]
    dx = np.empty(n)
    z = np.empty(n)
    s = np.empty(n)
    zu = np.empty(n)
    zres = np.empty((n, n))
    e_cv = np.empty(n)
    ytar = np.empty(n)
    dJdM = np.zeros((n, n))
    ok = np.zeros(n, np.bool_)
    out = np.empty(3)
    bisquare = hp[HP_BISQUARE] != 0.0
    w_max, w_sec, i_max, i_sec = 0.0, 0.0, -1, -1
    yp_sum, w_sum = 0.0, 0.0
    for k in range(n_rf):
        w, dwdq = _activation(mat, vec, k, x, bisquare, dx)
        if w > w_sec:
            if w > w_max:
                w_sec, i_sec = w_max, i_max
                w_max, i_max = w, k
            else:
                w_sec, i_sec = w, k
        if w <= 0.001:
            continue
        # weighted means with the forgetting of the first direction
        swl = vec[k, SUMW, 0] * vec[k, LAM, 0]
        inv = 1.0 / (swl + w)
        for i in range(n):
            vec[k, X0, i] = (swl * vec[k, X0, i] + w * x[i]) * inv
            z[i] = x[i] - vec[k, X0, i]
        sca[k, BETA0] = (swl * sca[k, BETA0] + w * y) * inv
        _update_regression(mat, vec, sca, k, z, y - sca[k, BETA0], w, s, zres, e_cv, ytar, zu, out)
        if sca[k, TRUST] != 0.0:
            yp_sum += w * out[0]
            w_sum += w
        if hp[HP_UPDATE_D] != 0.0:
            _update_metric(mat, vec, sca, k, w, dwdq, out[1], out[2], dx, s, hp, dJdM, ok)
        _check_add_direction(mat, vec, sca, k, n, hp)
        lam_f, tau = hp[HP_FINAL_LAMBDA], hp[HP_TAU_LAMBDA]
        for j in range(int(sca[k, NREG])):
            vec[k, NDATA, j] = vec[k, NDATA, j] * vec[k, LAM, j] + 1.0
            vec[k, LAM, j] = tau * vec[k, LAM, j] + lam_f * (1.0 - tau)
    y_pred = yp_sum / w_sum if w_sum > 0.0 else 0.0
    if w_max <= hp[HP_W_GEN]:
        template = i_max if (w_max > 0.1 * hp[HP_W_GEN] and sca[i_max, TRUST] != 0.0) else -1
        init_rf(mat, vec, sca, n_rf, template, x, y, init_M, init_D, init_alpha, hp)
        n_rf += 1
    elif w_sec > hp[HP_W_PRUNE]:
        tr_max, tr_sec = 0.0, 0.0
        for i in range(n):
            tr_max += mat[i_max, D_, i, i]
            tr_sec += mat[i_sec, D_, i, i]
        gone = i_max if tr_max > tr_sec else i_sec  # the narrower RF goes (MATLAB library, lwpr_doc)
        last = n_rf - 1
        if gone != last:
            mat[gone] = mat[last]
            vec[gone] = vec[last]
            sca[gone] = sca[last]
        n_rf -= 1
    return y_pred, n_rf, w_max


@njit(**_JIT)
def predict(mat, vec, sca, n_rf, x, cutoff, bisquare, act):
    """Weighted mean of the trustworthy RFs' local models at normalised x; ``act[k]`` gets RF k's
    activation if it took part (w > cutoff and trustworthy), else 0."""
    n = x.shape[0]
    dx = np.empty(n)
    z = np.empty(n)
    s = np.empty(n)
    zu = np.empty(n)
    yp, ws = 0.0, 0.0
    for k in range(n_rf):
        act[k] = 0.0
        if sca[k, TRUST] == 0.0:
            continue
        w, _ = _activation(mat, vec, k, x, bisquare, dx)
        if w <= cutoff:
            continue
        act[k] = w
        R = int(sca[k, NREG])
        n_used = R if vec[k, NDATA, R - 1] > 2.0 * n else R - 1
        for i in range(n):
            z[i] = x[i] - vec[k, X0, i]
        _project(mat, k, n_used, z, s, zu)
        yk = sca[k, BETA0]
        for j in range(n_used):
            yk += vec[k, BETA, j] * s[j]
        yp += w * yk
        ws += w
    return yp / ws if ws > 0.0 else 0.0


@njit(**_JIT)
def activations(mat, vec, n_rf, x, bisquare, act):
    """Raw kernel weight of every RF at normalised x (trustworthy or not)."""
    dx = np.empty(x.shape[0])
    for k in range(n_rf):
        act[k], _ = _activation(mat, vec, k, x, bisquare, dx)
