"""Flatten a :class:`~cerebx.snn.schema.NetworkConfig` into the arrays the kernels use.

All neurons share one global index space (populations concatenated in config order, input
fibres included). Small projections (one-to-one, joint combinations) become CSR tables keyed
by the global presynaptic index; all-to-all projections become dense float32 blocks
``[n_pre, n_post]`` stored in one flat buffer, so a presynaptic spike adds one contiguous row.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.polynomial import Polynomial as Pn

from cerebx import registry
from cerebx.snn.connectors import Synapses, projection_rng
from cerebx.snn.plasticity import PairingSpec, TraceSpec
from cerebx.snn.schema import (
    AdExNeuron,
    AllToAll,
    Integration,
    JointCombinations,
    KernelSTDP,
    LIFNeuron,
    NetworkConfig,
    OneToOne,
)

RECEPTORS = {"ampa": 0, "nmda": 1, "gaba": 2}

# Columns of the per-population parameter table (float64; kernels cast to float32 where hot).
# P_DA/P_DAH etc. are the conductance decays over one integration step h of the population and
# over h/2; P_D1A etc. over one network dt (used to decay input that arrives between two steps of a
# population integrated with a longer step); P_DFA over one bifixed sub-step.
(P_CM, P_GL, P_EL, P_EA, P_EG, P_DA, P_DAH, P_DN, P_DNH, P_DG, P_DGH, P_VTH, P_NREF, P_CLAMP, P_H,
 P_D1A, P_D1N, P_D1G, P_DFA, P_UFINE, P_METHOD) = range(21)
# P_DFAH .. P_DFGH: the other decays over one bifixed sub-step hf and hf/2 (P_DFA: AMPA over hf). AdEx rows
# (KIND_ADEX) use AMPA's columns for g_ex, GABA's for g_in, P_VTH for the spike threshold (V_peak, or V_th
# without the exponential term), and: P_DT Delta_T, P_INVDT 1/Delta_T (0 without the term), P_VT V_th - E_L,
# P_UPK V_peak - E_L, P_URST V_reset - E_L, P_A a, P_B b, P_ITW 1/tau_w, P_IE I_e.
(P_DFAH, P_DFN, P_DFNH, P_DFG, P_DFGH, P_DT, P_INVDT, P_VT, P_UPK, P_URST, P_A, P_B, P_ITW,
 P_IE) = range(21, 35)
N_PAR = 35

KIND_INPUT, KIND_LIF_AMPA, KIND_LIF_FULL, KIND_ADEX = 0, 1, 2, 3
KIND_NAMES = {KIND_INPUT: "input", KIND_LIF_AMPA: "lif_cond", KIND_LIF_FULL: "lif_cond", KIND_ADEX: "adex_cond"}
INTEGRATOR_PATHS = {KIND_LIF_AMPA: "ampa_polynomial", KIND_LIF_FULL: "rk_stages", KIND_ADEX: "rk_stages"}
"""How each kind's step is computed (docs/models.md#lif-integration): the AMPA-only polynomial form, or the
Runge-Kutta stages evaluated neuron by neuron. Both honour method, dt_ms and bifixed_substeps."""
METHODS = {"euler": 0, "rk2": 1, "rk4": 2}

# Columns of the per-population integer table.
I_LO, I_HI, I_KIND, I_RATIO, I_COMPACT, I_NFINE = range(6)
N_IPAR = 6
# Columns of the sparse projections' integer table (``Delivery.sp_i``, one row per projection): the first
# presynaptic neuron and their count, the projection's first row in sp_ptr, receptor, delay (substeps),
# teaching (1: a pairing rule's partner, delivered by the rule, not as current), the post population.
S_PRE_LO, S_N_PRE, S_ROW, S_RECEPTOR, S_DELAY, S_TEACHING, S_POST_POP = range(7)
N_SPAR = 7
N_COEF = 7  # polynomial coefficients (degree <= 6 in g) of a one-step update of an AMPA-only LIF
ORDER = {"euler": 1, "rk2": 2, "rk4": 4}  # degree in g0 of one step of each method


def step_polynomials(method: str, h: float, C: float, gL: float, E: float, d: float, dh: float,
                     n: int = 1):
    """One integration step of C du/dt = -gL u + g(t) (E - u), u = V - E_L, g(t) = g0 e^(-t/tau),
    with the stage conductances g0, g0*dh (h/2), g0*d (h) exact, is u' = P(g0) u + Q(g0): the
    stage values are linear in u with coefficients polynomial in g0. Returns the coefficient arrays
    (lowest order first, length N_COEF) of P and Q, computed exactly in float64. With n > 1 the
    step is n sub-steps of h/n (d, dh are then the decays over h/n and h/2n), composed into one
    pair: P = prod_k P1(g0 d^k), Q accordingly."""
    gp = Pn([0.0, 1.0])
    one, zero = Pn([1.0]), Pn([0.0])

    def f(x, gs):  # x = (A, B): the stage state A u + B
        a = (gL + gs) / C
        return (-a * x[0], -a * x[1] + gs * (E / C))

    def lin(x, k, s):
        return (x[0] + s * k[0], x[1] + s * k[1])

    u0 = (one, zero)
    if method == "euler":
        out = lin(u0, f(u0, gp), h)
    elif method == "rk2":  # Heun: slopes at the start and at the Euler-predicted end
        k1 = f(u0, gp)
        k2 = f(lin(u0, k1, h), gp * d)
        out = (u0[0] + h / 2 * (k1[0] + k2[0]), u0[1] + h / 2 * (k1[1] + k2[1]))
    else:
        k1 = f(u0, gp)
        k2 = f(lin(u0, k1, h / 2), gp * dh)
        k3 = f(lin(u0, k2, h / 2), gp * dh)
        k4 = f(lin(u0, k3, h), gp * d)
        out = (u0[0] + h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0]),
               u0[1] + h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1]))
    P, Q = Pn([1.0]), Pn([0.0])
    for k in range(n):
        Pk, Qk = (x(Pn([0.0, d**k])) for x in out)  # the k-th sub-step sees g0 d^k
        P, Q = Pk * P, Pk * Q + Qk
    res = np.zeros((2, N_COEF))
    for r, poly in enumerate((P, Q)):
        c = poly.coef
        res[r, : len(c)] = c
    return res


LAZY_MARGIN = 0.25  # a lazily kept GABA conductance leaves the step's rest result at least this share of its lead term


def lazy_gaba_nS(nrn: LIFNeuron, h: float) -> float:
    """The largest GABA conductance (nS) under which a ``lif_cond`` neuron at rest with no other input (V = E_L,
    no AMPA or NMDA conductance, not refractory) stays exactly at rest, step after step, while the conductance
    decays: 0 when there is none (the neuron then leaves rest under any GABA).

    With ``clamp_at_rest`` and E_GABA < E_L, the step from rest is u' = Q(g) (``step_polynomials`` with GABA's
    reversal and decay), which is negative, and so clamped to exactly 0, while Q(g) keeps at least
    :data:`LAZY_MARGIN` of its lead term g (E_GABA - E_L) h / C (float32 rounding, ~1e-6 of it, cannot change
    the sign). Beyond that bound the explicit step overshoots (it goes unstable near (g_L + g) h / C = 2). The
    kernels keep such a neuron out of their integration loop and decay its conductance only when it is next
    touched, by the same float32 products the loop would have applied (kernels, lazy GABA)."""
    if not nrn.clamp_at_rest or nrn.V_thr_mV <= nrn.E_L_mV:
        return 0.0
    E = nrn.E_GABA_mV - nrn.E_L_mV
    if E > 0:
        return 0.0
    C, gL, tau = nrn.C_m_pF, nrn.g_L_nS, nrn.tau_GABA_ms
    top = 4.0 * C / h + gL  # past the stability limit of every method
    if E == 0:
        return top  # GABA then never moves V at rest
    Q = Pn(step_polynomials(nrn.integration.method, h, C, gL, E, np.exp(-h / tau), np.exp(-0.5 * h / tau))[1])
    g = np.linspace(0.0, top, 200_001)[1:]
    ratio = Q(g) / (g * E * h / C)
    bad = np.flatnonzero(ratio < LAZY_MARGIN)
    return float(top if not len(bad) else (g[bad[0] - 1] if bad[0] > 0 else 0.0))


def _step_ratio(integ: Integration, name: str, dt: float, n_sub: int) -> tuple[int, float]:
    """(network steps per integration step, the step h in ms) of a population, checked."""
    h = integ.dt_ms if integ.dt_ms is not None else dt
    ratio = int(round(h / dt))
    if abs(h / dt - ratio) > 1e-9 or ratio < 1 or n_sub % ratio:
        raise ValueError(f"populations.{name}.neuron.integration.dt_ms: {h} must be a multiple of the "
                         f"network dt_ms ({dt}) that divides 2 ms")
    return ratio, ratio * dt


def _adex_row(nrn: AdExNeuron, name: str, dt: float, n_sub: int, par: np.ndarray, ipar: np.ndarray) -> None:
    """Fill one population's parameter rows for ``adex_cond`` (column meanings at N_PAR); g_ex lives in the
    AMPA conductance, g_in in the GABA one."""
    integ = nrn.integration
    ratio, h = _step_ratio(integ, name, dt, n_sub)
    nf = integ.bifixed_substeps
    hf = h / nf
    ipar[I_KIND], ipar[I_RATIO], ipar[I_NFINE] = KIND_ADEX, ratio, nf
    el = nrn.E_L_mV
    par[P_CM], par[P_GL], par[P_EL], par[P_EA], par[P_EG] = nrn.C_m_pF, nrn.g_L_nS, el, nrn.E_ex_mV, nrn.E_in_mV
    te, ti = nrn.tau_syn_ex_ms, nrn.tau_syn_in_ms
    for tau, cols in ((te, (P_DA, P_DAH, P_D1A, P_DFA, P_DFAH)), (te, (P_DN, P_DNH, P_D1N, P_DFN, P_DFNH)),
                      (ti, (P_DG, P_DGH, P_D1G, P_DFG, P_DFGH))):
        for col, span in zip(cols, (h, h / 2, dt, hf, hf / 2), strict=True):
            par[col] = np.exp(-span / tau)
    exp_term = nrn.Delta_T_mV > 0
    par[P_VTH] = nrn.V_peak_mV if exp_term else nrn.V_th_mV
    par[P_NREF] = round(nrn.t_ref_ms / h)
    par[P_H] = h
    par[P_METHOD] = METHODS[integ.method]
    par[P_UFINE] = 0.5 * (nrn.V_th_mV - el) if nf > 1 else np.inf
    par[P_DT], par[P_INVDT] = nrn.Delta_T_mV, (1.0 / nrn.Delta_T_mV if exp_term else 0.0)
    par[P_VT], par[P_UPK], par[P_URST] = nrn.V_th_mV - el, par[P_VTH] - el, nrn.V_reset_mV - el
    par[P_A], par[P_B], par[P_ITW], par[P_IE] = nrn.a_nS, nrn.b_pA, 1.0 / nrn.tau_w_ms, nrn.I_e_pA


def integrators(topo: Topology) -> dict[str, dict]:
    """The integrator each non-input population actually uses (recorded in a run's summary.json):
    model kind, computation path, method, step and bifixed sub-steps."""
    out = {}
    for i, name in enumerate(topo.names):
        k = int(topo.kind[i])
        if k == KIND_INPUT:
            continue
        nrn = topo.cfg.populations[name].neuron
        out[name] = {"kind": KIND_NAMES[k], "path": INTEGRATOR_PATHS[k], "method": nrn.integration.method,
                     "dt_ms": float(topo.par[i, P_H]), "bifixed_substeps": int(topo.ipar[i, I_NFINE])}
    return out


@dataclass
class SparseProj:
    name: str
    pre_lo: int
    n_pre: int
    ptr: np.ndarray  # int64 [n_pre + 1]
    post: np.ndarray  # int32 global post index
    w: np.ndarray  # float32
    receptor: int
    delay: int  # in substeps
    teaching: bool


@dataclass
class DenseProj:
    name: str
    pre_lo: int
    n_pre: int
    post_lo: int
    n_post: int
    w_off: int  # offset into Topology.dense_w
    receptor: int
    delay: int
    plastic: int  # index into Topology.plastic, -1 if static


@dataclass
class PlasticRule:
    proj: str
    dense: int  # index of the DenseProj
    teacher: int  # index of the SparseProj whose spikes trigger LTD (teacher must be sparse)
    ltp: float
    ltd: float
    w_lo: float
    w_hi: float
    kernel: np.ndarray  # float32 k(m * dt) for m = 0 .. len-1


@dataclass
class SparseRule:
    """A learning rule on one piece (one delay) of a sparse projection (:mod:`cerebx.snn.plasticity`)."""

    proj: str
    piece: int  # index of the SparseProj
    teachers: tuple[int, int]  # SparseProj index range of the teaching projection's pieces; (-1, -1): post spikes
    spec: TraceSpec | PairingSpec
    w_lo: float
    w_hi: float
    csc_ptr: np.ndarray  # int64 [n_post + 1]: the piece's synapses by post neuron (local)
    csc_q: np.ndarray  # int64: synapse index within the piece
    csc_j: np.ndarray  # int64: its presynaptic (local) index


@dataclass
class Topology:
    cfg: NetworkConfig
    n_sub: int  # integration substeps per 2 ms control step
    dt_ms: float
    names: list[str]
    lo: np.ndarray  # int64 first global index per population
    hi: np.ndarray
    kind: np.ndarray  # int64 KIND_* per population
    par: np.ndarray  # float64 [n_pop, N_PAR]
    ipar: np.ndarray  # int64 [n_pop, N_IPAR]
    poly: np.ndarray  # float32 [n_pop, 2 (step, bifixed sub-step), 2 (P, Q), N_COEF]
    sparse: list[SparseProj]
    dense: list[DenseProj]
    dense_w: np.ndarray  # float32 flat buffer of all dense blocks
    plastic: list[PlasticRule]
    max_delay: int
    index: dict[str, int] = field(default_factory=dict)
    sparse_rules: list[SparseRule] = field(default_factory=list)
    built: dict[str, int] = field(default_factory=dict)  # synapses built per projection
    dense_init: dict[str, np.ndarray] = field(default_factory=dict)  # drawn initial weights of dense blocks
    lazy_gaba: np.ndarray | None = None  # float64 [n_pop]: lazy_gaba_nS of lif_cond populations with GABA input
    nmda_in: np.ndarray | None = None  # uint8 [n_pop]: 1 where a projection carries NMDA to the population

    @property
    def n_neurons(self) -> int:
        return int(self.hi[-1])

    def slice(self, pop: str) -> slice:
        i = self.index[pop]
        return slice(int(self.lo[i]), int(self.hi[i]))

    def dense_block(self, d: DenseProj) -> np.ndarray:
        """View of one dense projection's weights as [n_pre, n_post]."""
        return self.dense_w[d.w_off : d.w_off + d.n_pre * d.n_post].reshape(d.n_pre, d.n_post)


def ltd_kernel_table(peak_ms: float, onset_ms: float, cutoff: float, dt_ms: float) -> np.ndarray:
    """k(t) = (t'/tau) e^(1 - t'/tau), t' = t - onset, tau = peak - onset, zero before the onset,
    sampled exactly at the integration grid m*dt and cut after the peak where k < cutoff."""
    tau = peak_ms - onset_ms
    # past the peak, x e^(1-x) falls monotonically; find where it drops below the cutoff
    x = np.linspace(1.0, 200.0, 400_000)
    x_cut = x[np.argmax(x * np.exp(1.0 - x) < cutoff)]
    t_end = onset_ms + x_cut * tau
    m = np.arange(int(np.ceil(t_end / dt_ms)) + 1)
    tp = m * dt_ms - onset_ms
    k = np.where(tp > 0, (tp / tau) * np.exp(1.0 - tp / tau), 0.0)
    k[(m * dt_ms > peak_ms) & (k < cutoff)] = 0.0
    return k.astype(np.float32)


def _pairs(rule, n_pre: int, n_post: int) -> tuple[np.ndarray, np.ndarray]:
    """(pre_local, post_local) synapse pairs of a sparse rule."""
    if isinstance(rule, OneToOne):
        i = np.arange(n_pre)
        return i, i
    r: JointCombinations = rule
    F, S = r.fibers_per_signal, r.signals
    per_joint = F**S
    post = np.arange(n_post)
    joint, rem = post // per_joint, post % per_joint
    pres, posts = [], []
    for k in range(S):
        digit = (rem // F ** (S - 1 - k)) % F
        pres.append(joint * S * F + k * F + digit)
        posts.append(post)
    return np.concatenate(pres), np.concatenate(posts)


def all_to_all(rule: AllToAll, n_pre: int, n_post: int, same: bool, rng: np.random.Generator) -> Synapses:
    return Synapses(np.repeat(np.arange(n_pre), n_post), np.tile(np.arange(n_post), n_pre))


def one_to_one(rule: OneToOne, n_pre: int, n_post: int, same: bool, rng: np.random.Generator) -> Synapses:
    return Synapses(*_pairs(rule, n_pre, n_post))


def joint_combinations(rule: JointCombinations, n_pre: int, n_post: int, same: bool,
                       rng: np.random.Generator) -> Synapses:
    return Synapses(*_pairs(rule, n_pre, n_post))


def kernel_stdp(rule: KernelSTDP, dt_ms: float) -> KernelSTDP:
    """The PF–PC rule runs on its own dense path (:class:`PlasticRule`): its builder hands it back."""
    return rule


def _weights(p, n: int, rng: np.random.Generator, given: np.ndarray | None) -> np.ndarray:
    """float32 initial weights of ``n`` synapses of projection ``p``: listed, drawn (clipped to the weight range,
    else to >= 0) or constant."""
    if given is not None:
        w = given
    elif isinstance(p.weight_nS, float):
        return np.full(n, p.weight_nS, dtype=np.float32)
    else:
        w = p.weight_nS.draw(rng, n)
    lo, hi = p.weight_range_nS if p.weight_range_nS is not None else (0.0, np.inf)
    return np.clip(w, lo, hi).astype(np.float32)


def _delays(p, n: int, dt: float, rng: np.random.Generator, given: np.ndarray | None) -> np.ndarray:
    """Per-synapse delays in steps of dt (rounded, at least one step)."""
    if given is None and isinstance(p.delay_ms, float):
        return np.full(n, int(round(p.delay_ms / dt)), dtype=np.int64)
    d = given if given is not None else p.delay_ms.draw(rng, n)
    return np.maximum(np.round(np.asarray(d) / dt), 1).astype(np.int64)


def _csr(name: str, pre_l, post_l, w, n_pre: int, pre_lo: int, post_lo: int, rec: int, delay: int,
         teaching: bool) -> SparseProj:
    order = np.argsort(pre_l, kind="stable")
    pre_l, post_l = pre_l[order], post_l[order]
    ptr = np.zeros(n_pre + 1, dtype=np.int64)
    np.cumsum(np.bincount(pre_l, minlength=n_pre), out=ptr[1:])
    return SparseProj(name, pre_lo, n_pre, ptr, (post_l + post_lo).astype(np.int32), w[order], rec, delay, teaching)


def _csc(s: SparseProj, post_lo: int, n_post: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A piece's synapses grouped by post neuron: (pointers, synapse indices, pre indices)."""
    post_l = s.post.astype(np.int64) - post_lo
    pre_l = np.repeat(np.arange(s.n_pre), np.diff(s.ptr))
    order = np.argsort(post_l, kind="stable")
    ptr = np.zeros(n_post + 1, dtype=np.int64)
    np.cumsum(np.bincount(post_l, minlength=n_post), out=ptr[1:])
    return ptr, order.astype(np.int64), pre_l[order]


def fill_dense(topo: Topology) -> None:
    """Write the dense blocks' initial weights (``weight_nS``) into ``topo.dense_w``. On the full network that
    is the first touch of ~145 MB, 50-350 ms on a VM whose page faults are slow; numpy lets go of the
    interpreter lock meanwhile, so :class:`~cerebx.snn.network.Network` runs it beside its own set-up."""
    for d in topo.dense:
        drawn = topo.dense_init.get(d.name)
        w = topo.cfg.projections[d.name].weight_nS if drawn is None else drawn
        topo.dense_w[d.w_off : d.w_off + d.n_pre * d.n_post] = w


def build_topology(cfg: NetworkConfig, fill: bool = True, seed: int = 0) -> Topology:
    """Lay out populations and build every projection (a few seconds for the full network): ``cfg`` flattened;
    without ``fill`` the dense weights are left unwritten (:func:`fill_dense` writes them). Random connectors,
    weights and delays of projection P draw from :func:`~cerebx.snn.connectors.projection_rng` (seed, P).

    A projection is a dense block when it is all_to_all, carries current, has one delay and a dense rule (none or
    kernel_stdp) and teaches no sparse rule; every other one is CSR, split into one SparseProj per distinct delay
    (its pieces, consecutive in ``sparse``), so the kernels deliver each piece with one delay."""
    dt = cfg.dt_ms
    n_sub = int(round(2.0 / dt))
    names = list(cfg.populations)
    index = {n: i for i, n in enumerate(names)}
    sizes = np.array([cfg.populations[n].size for n in names], dtype=np.int64)
    hi = np.cumsum(sizes)
    lo = hi - sizes

    targeted: dict[str, set[int]] = {n: set() for n in names}
    for p in cfg.projections.values():
        if not p.teaching:
            targeted[p.post].add(RECEPTORS[p.receptor])

    kind = np.zeros(len(names), dtype=np.int64)
    par = np.zeros((len(names), N_PAR))
    ipar = np.zeros((len(names), N_IPAR), dtype=np.int64)
    poly = np.zeros((len(names), 2, 2, N_COEF), dtype=np.float32)
    lazy = np.zeros(len(names))
    nmda_in = np.array([RECEPTORS["nmda"] in targeted[n] for n in names], dtype=np.uint8)
    ipar[:, I_LO], ipar[:, I_HI], ipar[:, I_RATIO], ipar[:, I_NFINE] = lo, hi, 1, 1
    for i, n in enumerate(names):
        nrn = cfg.populations[n].neuron
        if isinstance(nrn, AdExNeuron):
            kind[i] = KIND_ADEX
            _adex_row(nrn, n, dt, n_sub, par[i], ipar[i])
            continue
        if not isinstance(nrn, LIFNeuron):
            kind[i] = KIND_INPUT
            continue
        kind[i] = KIND_LIF_AMPA if targeted[n] <= {RECEPTORS["ampa"]} else KIND_LIF_FULL
        integ = nrn.integration
        h = integ.dt_ms if integ.dt_ms is not None else dt
        ratio = int(round(h / dt))
        if abs(h / dt - ratio) > 1e-9 or ratio < 1 or n_sub % ratio:
            raise ValueError(f"populations.{n}.neuron.integration.dt_ms: {h} must be a multiple of the "
                             f"network dt_ms ({dt}) that divides 2 ms")
        h = ratio * dt
        if ORDER[integ.method] * integ.bifixed_substeps > N_COEF - 1:
            raise ValueError(f"populations.{n}.neuron.integration: {integ.method} with bifixed_substeps = "
                             f"{integ.bifixed_substeps} is not supported (order x sub-steps must be <= "
                             f"{N_COEF - 1})")
        ipar[i, I_KIND], ipar[i, I_RATIO], ipar[i, I_NFINE] = kind[i], ratio, integ.bifixed_substeps
        par[i, P_CM], par[i, P_GL], par[i, P_EL] = nrn.C_m_pF, nrn.g_L_nS, nrn.E_L_mV
        par[i, P_EA], par[i, P_EG] = nrn.E_AMPA_mV, nrn.E_GABA_mV
        for col, tau in ((P_DA, nrn.tau_AMPA_ms), (P_DN, nrn.tau_NMDA_ms), (P_DG, nrn.tau_GABA_ms)):
            par[i, col] = np.exp(-h / tau)
            par[i, col + 1] = np.exp(-0.5 * h / tau)
        par[i, P_D1A], par[i, P_D1N], par[i, P_D1G] = (np.exp(-dt / tau) for tau in
                                                       (nrn.tau_AMPA_ms, nrn.tau_NMDA_ms, nrn.tau_GABA_ms))
        hf = h / integ.bifixed_substeps
        par[i, P_DFA] = np.exp(-hf / nrn.tau_AMPA_ms)
        par[i, P_DFAH] = np.exp(-0.5 * hf / nrn.tau_AMPA_ms)
        par[i, P_DFN], par[i, P_DFNH] = np.exp(-hf / nrn.tau_NMDA_ms), np.exp(-0.5 * hf / nrn.tau_NMDA_ms)
        par[i, P_DFG], par[i, P_DFGH] = np.exp(-hf / nrn.tau_GABA_ms), np.exp(-0.5 * hf / nrn.tau_GABA_ms)
        par[i, P_UFINE] = 0.5 * (nrn.V_thr_mV - nrn.E_L_mV) if integ.bifixed_substeps > 1 else np.inf
        par[i, P_METHOD] = METHODS[integ.method]
        par[i, P_VTH] = nrn.V_thr_mV
        par[i, P_NREF] = round(nrn.t_ref_ms / h)
        par[i, P_CLAMP] = 1.0 if nrn.clamp_at_rest else 0.0
        par[i, P_H] = h
        E = nrn.E_AMPA_mV - nrn.E_L_mV
        tau = nrn.tau_AMPA_ms
        poly[i, 0] = step_polynomials(integ.method, h, nrn.C_m_pF, nrn.g_L_nS, E, np.exp(-h / tau),
                                      np.exp(-0.5 * h / tau))
        poly[i, 1] = step_polynomials(integ.method, hf, nrn.C_m_pF, nrn.g_L_nS, E, np.exp(-hf / tau),
                                      np.exp(-0.5 * hf / tau), integ.bifixed_substeps)
        if RECEPTORS["gaba"] in targeted[n]:
            lazy[i] = lazy_gaba_nS(nrn, h)

    sparse: list[SparseProj] = []
    dense: list[DenseProj] = []
    pieces: dict[str, tuple[int, int]] = {}
    built: dict[str, int] = {}
    dense_init: dict[str, np.ndarray] = {}
    sparse_rule = {n for n, p in cfg.projections.items()
                   if p.plasticity is not None and not isinstance(p.plasticity, KernelSTDP)}
    teachers = {getattr(cfg.projections[n].plasticity, "teacher", None) for n in sparse_rule}
    w_off = 0
    for name, p in cfg.projections.items():
        a, b = index[p.pre], index[p.post]
        n_pre, n_post = int(sizes[a]), int(sizes[b])
        rec = RECEPTORS[p.receptor]
        rng = projection_rng(seed, name)
        if (isinstance(p.rule, AllToAll) and not p.teaching and isinstance(p.delay_ms, float)
                and name not in sparse_rule and name not in teachers):
            delay = int(round(p.delay_ms / dt))
            d = DenseProj(name, int(lo[a]), n_pre, int(lo[b]), n_post, w_off, rec, delay, -1)
            dense.append(d)
            if not isinstance(p.weight_nS, float):
                dense_init[name] = _weights(p, n_pre * n_post, rng, None)
            w_off += n_pre * n_post
            built[name] = n_pre * n_post
            continue
        syn = registry.connectors[p.rule.kind].resolve()(p.rule, n_pre, n_post, p.pre == p.post, rng)
        pre_l, post_l = np.asarray(syn.pre, dtype=np.int64), np.asarray(syn.post, dtype=np.int64)
        w = _weights(p, len(pre_l), rng, syn.weight_nS)
        steps = _delays(p, len(pre_l), dt, rng, syn.delay_ms)
        built[name] = len(pre_l)
        first = len(sparse)
        for delay in np.unique(steps) if len(steps) else [int(round(1.0 / dt))]:
            keep = steps == delay
            sparse.append(_csr(name, pre_l[keep], post_l[keep], w[keep], n_pre, int(lo[a]), int(lo[b]), rec,
                               int(delay), p.teaching))
        pieces[name] = (first, len(sparse))

    dense_w = np.empty(w_off, dtype=np.float32)

    sparse_index = {n: i for n, (i, _) in pieces.items()}
    plastic: list[PlasticRule] = []
    for di, d in enumerate(dense):
        p = cfg.projections[d.name]
        if p.plasticity is None:
            continue
        rule = p.plasticity
        if rule.teacher not in sparse_index:
            raise ValueError(f"projections.{d.name}.plasticity.teacher: {rule.teacher!r} must be a "
                             "one_to_one or joint_combinations projection")
        lo_w, hi_w = p.weight_range_nS
        d.plastic = len(plastic)
        plastic.append(
            PlasticRule(
                d.name, di, sparse_index[rule.teacher], rule.ltp_nS, rule.ltd_nS, lo_w, hi_w,
                ltd_kernel_table(rule.kernel_peak_ms, rule.kernel_onset_ms, rule.kernel_cutoff, dt),
            )
        )
    for name, p in cfg.projections.items():
        if isinstance(p.plasticity, KernelSTDP) and name not in {d.name for d in dense}:
            raise ValueError(f"projections.{name}: plasticity is supported on all_to_all projections only")

    sparse_rules: list[SparseRule] = []
    for name, p in cfg.projections.items():
        if name not in sparse_rule:
            continue
        spec = registry.plasticity_rules[p.plasticity.kind].resolve()(p.plasticity, dt)
        if not isinstance(spec, (TraceSpec, PairingSpec)):
            raise ValueError(f"projections.{name}.plasticity: the builder of kind {p.plasticity.kind!r} returned "
                             f"{type(spec).__name__}, not a TraceSpec or PairingSpec")
        teacher = getattr(spec, "teacher", None)
        span = pieces[teacher] if teacher is not None else (-1, -1)
        w_lo, w_hi = p.weight_range_nS
        b = index[p.post]
        for k in range(*pieces[name]):
            ptr, q, j = _csc(sparse[k], int(lo[b]), int(sizes[b]))
            sparse_rules.append(SparseRule(name, k, span, spec, w_lo, w_hi, ptr, q, j))

    dendritic = [2 * sparse[r.piece].delay for r in sparse_rules if getattr(r.spec, "dendritic", False)]
    max_delay = max([s.delay for s in sparse] + [d.delay for d in dense] + dendritic + [1])  # the ring's reach
    topo = Topology(cfg, n_sub, dt, names, lo, hi, kind, par, ipar, poly, sparse, dense, dense_w, plastic,
                    max_delay, index, sparse_rules, built, dense_init, lazy, nmda_in)
    if fill:
        fill_dense(topo)
    return topo
