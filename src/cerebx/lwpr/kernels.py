"""numba kernels of LWPR (Vijayakumar, D'Souza & Schaal 2005; update order of the reference
library, docs/provenance.md#lwpr-algorithm). One output dimension = one sub-model. A whole model
lives in one flat float64 buffer (:func:`regions` gives the offsets); RF ``k`` of output ``d`` is row
``[d, k]`` of the views of its :class:`Store`:

- ``mat[d, k, f, :, :]`` (n_in x n_in): ``M`` (upper triangular, D = M^T M), ``D``, ``ALPHA`` (learning
  rates of M), and per PLS direction ``j`` (row ``j``): ``U`` regression axes, ``P`` projection axes,
  ``SXY`` (sum of w t z), ``SZ`` (sum of w s z);
- ``vec[d, k, f, :]`` (n_in): ``C`` centre, ``X0`` weighted input mean, and per direction ``BETA``,
  ``SS`` (sum w s^2), ``SY`` (sum w t s), ``SUMW``, ``NDATA``, ``LAM`` (forgetting), ``ECV2`` (sum w
  e_cv^2), ``H`` and ``RR`` (distance-metric gradient traces);
- ``sca[d, k, f]``: ``BETA0``, ``SUME2`` (sum w e^2), ``SSP``, ``TRUST`` (0/1), ``NREG`` (directions in use);
- ``count[d, f]``: ``N_RF`` (RFs in use), ``N_CREATED``, ``N_PRUNED``, ``N_SEEN`` (training pairs).

Before them in the buffer: ``cfg`` (``HP_*``: sizes and hyper-parameters, then ``norm_in``, ``norm_out``),
``count``, ``pred`` (the last ``update`` or ``predict``, per output) and the scratch of one update
(:class:`Work`).

Speed: the entry points are compiled per model shape (:func:`entry_point`), with n_in and n_out as constants,
so that the loops over inputs, directions and outputs have fixed lengths (unrolled: 1.8 x the updates per
second on the 2-D cross, 2.5 x in 1-D). A call from Python costs about 100 ns per array argument (numba wraps
each in a new reference-counted object), hence the model is passed as its buffer's address and a sample's
prediction left in the buffer. Inside, the kernels pass named tuples of views without a reference count
(:func:`_view`, :func:`_borrow`) to helpers that numba inlines: numba counts references to every array value a
helper binds with atomic operations, which fold away on such views but on owned arrays cost more than the
arithmetic of an RF update. RFs too far from x for their activation to matter skip the exponential; the entry
points are compiled without LLVM's vectorizers.
The meta learning of the learning rates (IDBD) of the reference library is not implemented.
"""

from __future__ import annotations

import functools
import math
from contextlib import contextmanager
from typing import NamedTuple

import numpy as np
from numba import config, njit, types
from numba.core import cgutils
from numba.core.dispatcher import Dispatcher
from numba.extending import intrinsic

M_, D_, ALPHA, U_, P_, SXY, SZ = 0, 1, 2, 3, 4, 5, 6
N_MAT = 7
C_, X0, BETA, SS, SY, SUMW, NDATA, LAM, ECV2, H_, RR = 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10
N_VEC = 11
BETA0, SUME2, SSP, TRUST, NREG = 0, 1, 2, 3, 4
N_SCA = 5
N_RF, N_CREATED, N_PRUNED, N_SEEN = 0, 1, 2, 3
N_COUNT = 4

H_N_IN, H_N_OUT, H_CAPACITY = 0, 1, 2
HP_W_GEN, HP_W_PRUNE, HP_INIT_LAMBDA, HP_FINAL_LAMBDA, HP_TAU_LAMBDA = 3, 4, 5, 6, 7
HP_PENALTY, HP_DIAG_ONLY, HP_UPDATE_D, HP_ADD_THRESHOLD, HP_INIT_S2, HP_BISQUARE = 8, 9, 10, 11, 12, 13
HP_CUTOFF, HP_INIT_D, HP_INIT_ALPHA, HP_Q_UPDATE, HP_Q_PREDICT = 14, 15, 16, 17, 18
N_HP = 19

OK, FULL, BAD_X, BAD_Y = 0, 1, 2, 3

_JIT = dict(cache=True, fastmath=False, error_model="numpy", boundscheck=False)
# numba-level inlining of the helpers: a call that is left to LLVM costs tens of ns per array argument
_INLINE = dict(_JIT, inline="always")


class Store(NamedTuple):
    """The RFs of every output (``mat``, ``vec``, ``sca``, ``count`` as in the module docstring; counts are
    stored as floats); indexed by output, the same four arrays of one sub-model."""

    mat: np.ndarray
    vec: np.ndarray
    sca: np.ndarray
    count: np.ndarray


class RF(NamedTuple):
    """Views of one receptive field: ``mat[f]``, ``vec[f]``, ``sca[f]``."""

    mat: np.ndarray
    vec: np.ndarray
    sca: np.ndarray


class Work(NamedTuple):
    """Scratch of one update: normalised input, its offsets from a centre and from a mean, projections,
    residuals and targets per PLS direction, residual inputs and the metric gradient."""

    xn: np.ndarray
    dx: np.ndarray
    z: np.ndarray
    s: np.ndarray
    zu: np.ndarray
    e_cv: np.ndarray
    ytar: np.ndarray
    zres: np.ndarray
    dJdM: np.ndarray


@njit(cache=True)
def regions(n_in, n_out, capacity):
    """Offsets in the model buffer of norm_in, norm_out, count, pred, work, mat, vec, sca, and its size."""
    o_norm_in = N_HP
    o_norm_out = o_norm_in + n_in
    o_count = o_norm_out + n_out
    o_pred = o_count + n_out * N_COUNT
    o_work = o_pred + n_out
    o_mat = o_work + (7 + 2 * n_in) * n_in
    o_vec = o_mat + n_out * capacity * N_MAT * n_in * n_in
    o_sca = o_vec + n_out * capacity * N_VEC * n_in
    return o_norm_in, o_norm_out, o_count, o_pred, o_work, o_mat, o_vec, o_sca, o_sca + n_out * capacity * N_SCA


def far_distance(w_floor: float, bisquare: bool) -> float:
    """The distance q = (x-c)^T D (x-c) beyond which an activation lies below ``w_floor`` (widened by
    1e-9 so that rounding never places a skipped RF above it)."""
    if w_floor <= 0.0:
        return math.inf
    q = 4.0 * (1.0 - math.sqrt(w_floor)) if bisquare else -2.0 * math.log(w_floor)
    return q + 1e-9 * abs(q)


@intrinsic
def _borrow(typingctx, arr):
    """A view of ``arr`` without a reference count, valid while ``arr`` lives (here: an argument of the
    entry point, owned by its Python caller for the whole call)."""

    def codegen(context, builder, sig, args):
        src = context.make_array(arr)(context, builder, value=args[0])
        view = context.make_array(arr)(context, builder)
        context.populate_array(view, data=src.data, shape=src.shape, strides=src.strides,
                               itemsize=src.itemsize, meminfo=None)
        return view._getvalue()

    return arr(arr), codegen


@intrinsic
def _view(typingctx, addr, offset, shape):
    """C-contiguous float64 view, with the given shape, of the memory from ``offset`` values after address
    ``addr``; no reference count (the model's buffer, owned by its ``LWPR`` for the whole call)."""
    ndim = len(shape)
    view_t = types.Array(types.float64, ndim, "C")

    def codegen(context, builder, sig, args):
        dims = [context.cast(builder, v, t, types.intp)
                for v, t in zip(cgutils.unpack_tuple(builder, args[2], ndim), shape.types)]
        ll_item = context.get_data_type(types.float64)
        itemsize = context.get_constant(types.intp, context.get_abi_sizeof(ll_item))
        strides, step = [], itemsize
        for dim in reversed(dims):
            strides.insert(0, step)
            step = builder.mul(step, dim)
        base = builder.inttoptr(context.cast(builder, args[0], sig.args[0], types.intp), ll_item.as_pointer())
        data = builder.gep(base, [context.cast(builder, args[1], sig.args[1], types.intp)])
        view = context.make_array(view_t)(context, builder)
        context.populate_array(view, data=data, shape=dims, strides=strides, itemsize=itemsize, meminfo=None)
        return view._getvalue()

    return view_t(addr, offset, shape), codegen


@njit(**_INLINE)
def _unpack(addr, n, n_out):
    """Views of the model buffer at ``addr`` (n and n_out: the compile-time constants of an entry point):
    cfg, the Store, the Work and pred."""
    cap = int(_view(addr, 0, (N_HP,))[H_CAPACITY])
    _, _, o_count, o_pred, o_work, o_mat, o_vec, o_sca, _ = regions(n, n_out, cap)
    st = Store(_view(addr, o_mat, (n_out, cap, N_MAT, n, n)), _view(addr, o_vec, (n_out, cap, N_VEC, n)),
               _view(addr, o_sca, (n_out, cap, N_SCA)), _view(addr, o_count, (n_out, N_COUNT)))
    w = _view(addr, o_work, (7 + 2 * n, n))
    wk = Work(w[0], w[1], w[2], w[3], w[4], w[5], w[6], w[7:7 + n], w[7 + n:])
    return _view(addr, 0, (o_count,)), st, wk, _view(addr, o_pred, (n_out,))


@njit(**_INLINE)
def _rf(sub, k):
    return RF(sub.mat[k], sub.vec[k], sub.sca[k])


@njit(**_INLINE)
def _sub(st, d):
    return Store(st.mat[d], st.vec[d], st.sca[d], st.count[d])


@njit(**_INLINE)
def _has_room(st):
    for d in range(st.count.shape[0]):
        if st.count[d, N_RF] >= st.mat.shape[1]:
            return False
    return True


@njit(**_INLINE)
def _distance(rf, x, dx):
    """q = (x - c)^T D (x - c); fills dx = x - c. (One loop nest with the sum in it: LLVM does not vectorize
    it, which for n_in of a few saves the vector loop's entry checks, run for every RF and sample.)"""
    n = x.shape[0]
    c, D = rf.vec[C_], rf.mat[D_]
    q = 0.0
    for i in range(n):
        dx[i] = x[i] - c[i]
        acc = 0.0
        for j in range(n):
            acc += D[i, j] * (x[j] - c[j])
        q += dx[i] * acc
    return q


@njit(**_INLINE)
def _weight(q, bisquare):
    """Kernel weight w at distance q and dw/dq."""
    if bisquare:
        a = 1.0 - 0.25 * q
        if a <= 0.0:
            return 0.0, 0.0
        return a * a, -0.5 * a
    w = math.exp(-0.5 * q)
    return w, -0.5 * w


@njit(**_INLINE)
def _project(rf, n_reg, z, s, zu):
    """s_j = u_j . z_j with z_{j+1} = z_j - p_j s_j (z_1 = z)."""
    n = z.shape[0]
    for i in range(n):
        zu[i] = z[i]
    for j in range(n_reg):
        sj = 0.0
        for i in range(n):
            sj += rf.mat[U_, j, i] * zu[i]
        s[j] = sj
        for i in range(n):
            zu[i] -= rf.mat[P_, j, i] * sj


@njit(**_INLINE)
def _init_rf(rf, template, x, y, cfg):
    """A new RF at centre x: a copy of ``template``'s metric, rates, beta0 and PLS count, or the
    initial ones (D = init_D I, M = sqrt(init_D) I, every rate init_alpha) when ``template`` is None."""
    n = x.shape[0]
    rf.mat[:] = 0.0
    rf.vec[:] = 0.0
    rf.sca[:] = 0.0
    if template is not None:
        rf.mat[M_] = template.mat[M_]
        rf.mat[D_] = template.mat[D_]
        rf.mat[ALPHA] = template.mat[ALPHA]
        rf.sca[BETA0] = template.sca[BETA0]
        n_reg = int(template.sca[NREG])
    else:
        m0 = math.sqrt(cfg[HP_INIT_D])
        for i in range(n):
            rf.mat[M_, i, i] = m0
            rf.mat[D_, i, i] = cfg[HP_INIT_D]
        rf.mat[ALPHA] = cfg[HP_INIT_ALPHA]
        rf.sca[BETA0] = y
        n_reg = 2 if n > 1 else 1
    rf.sca[NREG] = n_reg
    for i in range(n):
        rf.vec[C_, i] = x[i]
    for j in range(n_reg):
        rf.vec[SS, j] = cfg[HP_INIT_S2]
        rf.mat[U_, j, j] = 1.0
        rf.mat[P_, j, j] = 1.0
        rf.vec[SUMW, j] = 1e-10
        rf.vec[NDATA, j] = 1e-10
        rf.vec[LAM, j] = cfg[HP_INIT_LAMBDA]


@njit(**_INLINE)
def _update_regression(rf, y, w, wk):
    """PLS update of an RF with centred input wk.z and target y. Returns (local prediction, e_cv_R, e)."""
    z, s, zres, e_cv, ytar = wk.z, wk.s, wk.zres, wk.e_cv, wk.ytar
    mat, vec, sca = rf.mat, rf.vec, rf.sca
    n = z.shape[0]
    R = int(sca[NREG])
    # projections with the old axes, keeping every residual input
    for i in range(n):
        zres[0, i] = z[i]
    for j in range(R):
        sj = 0.0
        for i in range(n):
            sj += mat[U_, j, i] * zres[j, i]
        s[j] = sj
        if j + 1 < R:
            for i in range(n):
                zres[j + 1, i] = zres[j, i] - mat[P_, j, i] * sj
    acc = 0.0
    for j in range(R):
        acc += vec[BETA, j] * s[j]
        vec[SUMW, j] = vec[SUMW, j] * vec[LAM, j] + w
        e_cv[j] = y - acc
    ytar[0] = y
    for j in range(1, R):
        ytar[j] = e_cv[j - 1]
    ws2 = 0.0
    for j in range(R):
        lam = vec[LAM, j]
        slow = 0.9 + 0.1 * lam
        norm2 = 0.0
        for i in range(n):
            v = mat[SXY, j, i] * slow + w * ytar[j] * zres[j, i]
            mat[SXY, j, i] = v
            norm2 += v * v
        if norm2 > 1e-24:
            inv = 1.0 / math.sqrt(norm2)
            for i in range(n):
                mat[U_, j, i] = mat[SXY, j, i] * inv
        wsj = w * s[j]
        vec[SS, j] = lam * vec[SS, j] + wsj * s[j]
        vec[SY, j] = lam * vec[SY, j] + wsj * ytar[j]
        inv_ss = 1.0 / vec[SS, j]
        for i in range(n):
            mat[SZ, j, i] = lam * mat[SZ, j, i] + wsj * zres[j, i]
            mat[P_, j, i] = mat[SZ, j, i] * inv_ss
        vec[BETA, j] = vec[SY, j] * inv_ss
        ws2 += wsj * wsj * inv_ss
    sca[SSP] = vec[LAM, R - 1] * sca[SSP] + ws2
    _project(rf, R, z, s, wk.zu)
    # the last direction joins the prediction only once it has seen enough data
    n_used = R if vec[NDATA, R - 1] > 2.0 * n else R - 1
    yp = 0.0
    for j in range(n_used):
        yp += vec[BETA, j] * s[j]
    e_cv_r = e_cv[n_used - 1] if n_used > 0 else y
    e = y - yp
    if vec[NDATA, 0] * (1.0 - vec[LAM, 0]) > 0.1:
        sca[SUME2] = sca[SUME2] * vec[LAM, R - 1] + w * e * e
        for j in range(R):
            vec[ECV2, j] = vec[ECV2, j] * vec[LAM, j] + w * e_cv[j] * e_cv[j]
    if vec[NDATA, 0] > 2.0 * n:
        sca[TRUST] = 1.0
    return yp + sca[BETA0], e_cv_r, e


@njit(**_INLINE)
def _deriv_ok(vec, j):
    return vec[NDATA, j] * (1.0 - vec[LAM, 0]) > 0.1


@njit(**_INLINE)
def _update_metric(rf, w, dwdq, e_cv, e, cfg, wk):
    """One gradient step on M (leave-one-out cost plus penalty on D)."""
    mat, vec, sca, s, dx, dJdM = rf.mat, rf.vec, rf.sca, wk.s, wk.dx, wk.dJdM
    n = dx.shape[0]
    R = int(sca[NREG])
    if not _deriv_ok(vec, 0):
        return
    h = 0.0
    for j in range(R):
        if _deriv_ok(vec, j):
            h += s[j] * s[j] / vec[SS, j]
    h *= w
    W = vec[SUMW, 0]
    if R == 1 or vec[NDATA, R - 1] > 2.0 * n:
        E = vec[ECV2, R - 1]
    else:
        E = vec[ECV2, R - 2]
    T = sca[SUME2] / (E + 1e-10)
    T = min(1.0, T * T * T * T)
    dJ1dw = -E / W + e_cv * e_cv
    for j in range(R):
        if _deriv_ok(vec, j):
            ps = s[j] / vec[SS, j]
            dJ1dw -= 2.0 * e * ps * vec[H_, j] + 2.0 * ps * ps * vec[RR, j]
    dJ1dw /= W
    wW = w / W
    pen = cfg[HP_PENALTY] / n
    diag = cfg[HP_DIAG_ONLY] != 0.0
    max_m = 0.0
    for a in range(n):
        for b in range(a, n):
            if diag and b != a:
                continue
            m_ab = abs(mat[M_, a, b])
            if m_ab > max_m:
                max_m = m_ab
    # dq/dM_ab = 2 dx_b (M dx)_a; dJ2/dM = 4 (gamma/n) (M D)_ab
    for a in range(n):
        mdx = 0.0
        for i in range(a, n):
            mdx += mat[M_, a, i] * dx[i]
        for b in range(a, n):
            if diag and b != a:
                continue
            md = 0.0
            for i in range(a, n):
                md += mat[M_, a, i] * mat[D_, i, b]
            dJdM[a, b] = wW * 4.0 * pen * md + 2.0 * dx[b] * mdx * dwdq * dJ1dw
    for a in range(n):
        for b in range(a, n):
            if diag and b != a:
                continue
            delta = mat[ALPHA, a, b] * T * dJdM[a, b]
            if delta > 0.1 * max_m:
                mat[ALPHA, a, b] *= 0.5
            else:
                mat[M_, a, b] -= delta
    for a in range(n):
        for b in range(n):
            acc = 0.0
            for i in range(min(a, b) + 1):
                acc += mat[M_, i, a] * mat[M_, i, b]
            mat[D_, a, b] = acc
    for j in range(R):
        if _deriv_ok(vec, j):
            vec[H_, j] = vec[LAM, j] * vec[H_, j] + (w / (1.0 - h)) * s[j] * e_cv * T
            vec[RR, j] = vec[LAM, j] * vec[RR, j] + (w * w * e_cv * e_cv / (1.0 - h)) * s[j] * s[j] * T


@njit(**_INLINE)
def _check_add_direction(rf, n, cfg):
    vec, R = rf.vec, int(rf.sca[NREG])
    if R >= n:
        return
    mse_r = vec[ECV2, R - 1] / vec[SUMW, R - 1] + 1e-10
    mse_r1 = vec[ECV2, R - 2] / vec[SUMW, R - 2] + 1e-10
    if (mse_r < cfg[HP_ADD_THRESHOLD] * mse_r1 and vec[NDATA, R - 1] > 0.99 * vec[NDATA, 0]
            and vec[NDATA, R - 1] * (1.0 - vec[LAM, R - 1]) > 0.5):
        vec[SS, R] = cfg[HP_INIT_S2]
        rf.mat[U_, R, R] = 1.0
        rf.mat[P_, R, R] = 1.0
        vec[SUMW, R] = 1e-10
        vec[LAM, R] = cfg[HP_INIT_LAMBDA]
        rf.sca[NREG] = R + 1
        rf.sca[SSP] = 0.0


@njit(**_INLINE)
def _update_rf(rf, x, y, w, dwdq, cfg, wk):
    """Means, PLS regression, distance metric, PLS growth and forgetting of one active RF; returns its
    local prediction."""
    n = x.shape[0]
    vec, sca = rf.vec, rf.sca
    # weighted means with the forgetting of the first direction
    swl = vec[SUMW, 0] * vec[LAM, 0]
    inv = 1.0 / (swl + w)
    for i in range(n):
        vec[X0, i] = (swl * vec[X0, i] + w * x[i]) * inv
        wk.z[i] = x[i] - vec[X0, i]
    sca[BETA0] = (swl * sca[BETA0] + w * y) * inv
    yp, e_cv, e = _update_regression(rf, y - sca[BETA0], w, wk)
    if cfg[HP_UPDATE_D] != 0.0:
        _update_metric(rf, w, dwdq, e_cv, e, cfg, wk)
    _check_add_direction(rf, n, cfg)
    lam_f, tau = cfg[HP_FINAL_LAMBDA], cfg[HP_TAU_LAMBDA]
    for j in range(int(sca[NREG])):
        vec[NDATA, j] = vec[NDATA, j] * vec[LAM, j] + 1.0
        vec[LAM, j] = tau * vec[LAM, j] + lam_f * (1.0 - tau)
    return yp


@njit(**_INLINE)
def _update_output(sub, cfg, wk, y):
    """One training pair (normalised x in wk.xn, scalar y) for one sub-model with a free slot. Returns the
    weighted prediction of its trustworthy RFs, made with their updated local models."""
    x = wk.xn
    n = x.shape[0]
    n_rf = int(sub.count[N_RF])
    bisquare = cfg[HP_BISQUARE] != 0.0
    q_far = cfg[HP_Q_UPDATE]
    w_max, w_sec, i_max, i_sec = 0.0, 0.0, -1, -1
    yp_sum, w_sum = 0.0, 0.0
    for k in range(n_rf):
        rf = _rf(sub, k)
        q = _distance(rf, x, wk.dx)
        if q > q_far:  # w is below every threshold a decision compares it with: no exp needed
            continue
        w, dwdq = _weight(q, bisquare)
        if w > w_sec:
            if w > w_max:
                w_sec, i_sec = w_max, i_max
                w_max, i_max = w, k
            else:
                w_sec, i_sec = w, k
        if w <= 0.001:
            continue
        yp = _update_rf(rf, x, y, w, dwdq, cfg, wk)
        if rf.sca[TRUST] != 0.0:
            yp_sum += w * yp
            w_sum += w
    y_pred = yp_sum / w_sum if w_sum > 0.0 else 0.0
    sub.count[N_SEEN] += 1.0
    if w_max <= cfg[HP_W_GEN]:
        new = _rf(sub, n_rf)
        if w_max > 0.1 * cfg[HP_W_GEN] and sub.sca[i_max, TRUST] != 0.0:
            _init_rf(new, _rf(sub, i_max), x, y, cfg)
        else:
            _init_rf(new, None, x, y, cfg)
        sub.count[N_RF] = n_rf + 1
        sub.count[N_CREATED] += 1.0
    elif w_sec > cfg[HP_W_PRUNE]:
        tr_max, tr_sec = 0.0, 0.0
        for i in range(n):
            tr_max += sub.mat[i_max, D_, i, i]
            tr_sec += sub.mat[i_sec, D_, i, i]
        gone = i_max if tr_max > tr_sec else i_sec  # the narrower RF goes (MATLAB library, lwpr_doc)
        last = n_rf - 1
        if gone != last:
            sub.mat[gone] = sub.mat[last]
            sub.vec[gone] = sub.vec[last]
            sub.sca[gone] = sub.sca[last]
        sub.count[N_RF] = last
        sub.count[N_PRUNED] += 1.0
    return y_pred


@njit(**_INLINE)
def _update_sample(st, cfg, wk, x, y, out):
    """One training pair for every output (each with a free slot); out gets the predictions.

    The input's normalisation is written out here and in :func:`_predict_sample` rather than shared: as an
    inlined helper that returned the input's dimension it cost 15-35 % of the updates' speed (2-D cross
    870-880 k -> 710-760 k updates/s, 1-D 2.9 -> 1.9-2.0 M)."""
    n = wk.xn.shape[0]
    for i in range(n):
        wk.xn[i] = x[i] / cfg[N_HP + i]
    for d in range(st.count.shape[0]):
        norm = cfg[N_HP + n + d]
        out[d] = _update_output(_sub(st, d), cfg, wk, y[d] / norm) * norm


@njit(**_INLINE)
def _predict_output(sub, cfg, wk, act):
    """Weighted mean of the trustworthy RFs' local models at wk.xn; if ``act`` has room, ``act[k]`` gets RF
    k's activation if it took part (w > cutoff and trustworthy), else 0."""
    x = wk.xn
    n = x.shape[0]
    keep = act.shape[0] > 0
    bisquare = cfg[HP_BISQUARE] != 0.0
    cutoff, q_far = cfg[HP_CUTOFF], cfg[HP_Q_PREDICT]
    yp, ws = 0.0, 0.0
    for k in range(int(sub.count[N_RF])):
        if keep:
            act[k] = 0.0
        rf = _rf(sub, k)
        if rf.sca[TRUST] == 0.0:
            continue
        q = _distance(rf, x, wk.dx)
        if q > q_far:
            continue
        w, _ = _weight(q, bisquare)
        if w <= cutoff:
            continue
        if keep:
            act[k] = w
        R = int(rf.sca[NREG])
        n_used = R if rf.vec[NDATA, R - 1] > 2.0 * n else R - 1
        for i in range(n):
            wk.z[i] = x[i] - rf.vec[X0, i]
        _project(rf, n_used, wk.z, wk.s, wk.zu)
        yk = rf.sca[BETA0]
        for j in range(n_used):
            yk += rf.vec[BETA, j] * wk.s[j]
        yp += w * yk
        ws += w
    return yp / ws if ws > 0.0 else 0.0


@njit(**_INLINE)
def _predict_sample(st, cfg, wk, x, out, act):
    n = wk.xn.shape[0]
    for i in range(n):
        wk.xn[i] = x[i] / cfg[N_HP + i]
    for d in range(st.count.shape[0]):
        out[d] = _predict_output(_sub(st, d), cfg, wk, act[d]) * cfg[N_HP + n + d]


@njit(**_JIT)
def _update_row(addr, x, y, out, n_in, n_out):
    """One training pair (x, y: views of n_in, n_out values in user units) for the model at ``addr``; out
    gets the prediction of each output. Returns FULL, with nothing changed, if some output has no free RF
    slot, else OK. n_in and n_out are literals: numba compiles (and caches) one version per model shape,
    which ``update`` and ``update_many`` share."""
    cfg, st, wk, _ = _unpack(addr, n_in, n_out)
    if not _has_room(st):
        return FULL
    _update_sample(st, cfg, wk, x, y, out)
    return OK


def _update(n_in, n_out):
    @njit(**_JIT)
    def update(addr, x, y):
        """One training pair (x, y in user units) for the model at ``addr``; its pred gets the prediction of
        each output. Returns FULL, with nothing changed, if some output has no free RF slot, BAD_X / BAD_Y
        for wrong lengths, else OK."""
        if x.shape[0] != n_in:
            return BAD_X
        if y.shape[0] != n_out:
            return BAD_Y
        return _update_row(addr, _borrow(x), _borrow(y), _unpack(addr, n_in, n_out)[3], n_in, n_out)

    return update


def _update_many(n_in, n_out):
    @njit(**_JIT)
    def update_many(addr, X, Y, out, start):
        """Training pairs X[t], Y[t] (rows of n_in, n_out values) from row ``start`` on, in order; out[t]
        gets the predictions. Stops before a row when some output has no free RF slot; returns the next row
        to learn."""
        Xb, Yb, ob = _borrow(X), _borrow(Y), _borrow(out)
        for t in range(start, X.shape[0]):
            if _update_row(addr, Xb[t], Yb[t], ob[t], n_in, n_out) == FULL:
                return t
        return X.shape[0]

    return update_many


def _predict(n_in, n_out):
    @njit(**_JIT)
    def predict(addr, x):
        """Prediction at x (user units) into the model's pred. Returns BAD_X for a wrong input length, else OK."""
        cfg, st, wk, pred = _unpack(addr, n_in, n_out)
        if x.shape[0] != n_in:
            return BAD_X
        _predict_sample(st, cfg, wk, _borrow(x), pred, _view(addr, 0, (n_out, 0)))
        return OK

    return predict


def _predict_many(n_in, n_out):
    @njit(**_JIT)
    def predict_many(addr, X, out, act):
        """Predictions at every row of X (n_in values) into the rows of out; act[d, k] as in
        ``_predict_output`` if act has columns (then for a single row)."""
        cfg, st, wk, _ = _unpack(addr, n_in, n_out)
        Xb, ob, ab = _borrow(X), _borrow(out), _borrow(act)
        for t in range(X.shape[0]):
            _predict_sample(st, cfg, wk, Xb[t], ob[t], ab)

    return predict_many


def _activations(n_in, n_out):
    @njit(**_JIT)
    def activations(addr, x, act):
        """Raw kernel weight of every RF at x (n_in values, user units), trustworthy or not: act[d, k]."""
        cfg, st, wk, _ = _unpack(addr, n_in, n_out)
        for i in range(n_in):
            wk.xn[i] = x[i] / cfg[N_HP + i]
        bisquare = cfg[HP_BISQUARE] != 0.0
        for d in range(n_out):
            sub = _sub(st, d)
            for k in range(int(sub.count[N_RF])):
                act[d, k] = _weight(_distance(_rf(sub, k), wk.xn, wk.dx), bisquare)[0]

    return activations


@contextmanager
def _scalar_loops():
    """LLVM's loop and SLP vectorizers off (numba reads these settings whenever it optimizes code)."""
    saved = config.LOOP_VECTORIZE, config.SLP_VECTORIZE
    config.LOOP_VECTORIZE = config.SLP_VECTORIZE = False
    try:
        yield
    finally:
        config.LOOP_VECTORIZE, config.SLP_VECTORIZE = saved


_F1, _F2, _I = types.float64[::1], types.float64[:, ::1], types.int64
_ENTRY_POINTS = {"update": (_update, (_I, _F1, _F1)), "update_many": (_update_many, (_I, _F2, _F2, _F2, _I)),
                 "predict": (_predict, (_I, _F1)), "predict_many": (_predict_many, (_I, _F2, _F2, _F2)),
                 "activations": (_activations, (_I, _F1, _F2))}


@functools.cache
def entry_point(name: str, n_in: int, n_out: int) -> Dispatcher:
    """Entry point ``name`` for models of n_in inputs and n_out outputs, compiled (or loaded from numba's
    cache, which keys a closure on the values it closes over) for the model's address (int) and float64
    C-contiguous writable arrays, without LLVM's vectorizers: the loops here run a few times, and the entry
    checks of vector versions cost about a fifth of an update. It compiles nothing else: other argument
    types raise TypeError."""
    make, signature = _ENTRY_POINTS[name]
    fn = make(int(n_in), int(n_out))
    with _scalar_loops():
        fn.compile(signature)
    fn.disable_compile()
    return fn
