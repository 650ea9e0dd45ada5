"""numba kernels: one call advances the whole network by one 2 ms control step.

Time grid: the network dt (``NetworkConfig.dt_ms``, 0.5 ms) is the substep; synaptic events arrive
at substep boundaries, exactly ``delay`` substeps after the presynaptic spike. Spike times are
integers in substeps (t = 0 is the start of the run). Spikes produced while integrating the
substep t carry time t + 1 and live in ring slot (t + 1) % R until every projection has read them.

Integration (docs/models.md#lif-integration): conductances decay exactly (g <- g e^(-h/tau)). Each LIF
population has its own step h = ratio * dt and method (``LIFNeuron.integration``: RK4, RK2 = Heun,
or Euler; default RK4 at dt). A population integrated with ratio > 1 advances at the end of the
substeps t with (t + 1) % ratio == 0; input that arrives in the middle of one of its steps takes
effect at the next step boundary with its conductance decayed exactly over the time in between
(until then it waits in the spike ring, so ``Network.g`` read between two control steps does not
show it yet).
A spike is emitted when V >= V_thr at the end of a step; V is then reset to E_L and held there
for t_ref (rounded to whole steps).

State is stored as u = V - E_L (float32). For populations with only AMPA input the step is
u' = P(g0) u + Q(g0) with P, Q polynomials of degree <= 4 in the conductance at the step start
(exactly the RK stages with the exact stage conductances; ``topology.step_polynomials``), so the
update is a few FMAs per neuron and vectorises. EDLUT's Bifixed refinement (a step that starts
with V above (E_L + V_thr)/2 is done as n equal sub-steps) is a second coefficient set; here a
step is also refined when its one-step estimate ends above (E_L + V_thr)/2, so a fast rise from
below the midpoint is not integrated with the coarse step alone (both pairs are evaluated for
every neuron in one vectorised loop: ~12% of the active GCs need the bifixed pair, and picking
them out costs about what it saves).
Populations with NMDA/GABA input (DCN) run the RK stages in float32 with a branch-free Mg block
(max abs error 1e-6 against the exact expression), so that loop vectorises too.

Resting neurons are skipped exactly: a neuron with u == 0, g == 0 and not refractory stays so
until input arrives (every RK stage is exactly 0). Large lif_cond populations ("compact") keep
their non-resting neurons packed in the front of the population's slice of u/g/ref, with
``cid`` (compact position -> global index) and ``slot`` (global index -> compact position, -1 at
rest); delivered input activates a resting neuron by appending it, and neurons that came back
to rest are dropped by a compaction at the end of a step, which also puts the list back in global
index order. The order of the list never changes a result (per-neuron updates are independent,
each neuron's inputs are added in spike order, collected spikes are sorted). Sparse projections
onto a compact population deliver through per-presynaptic-neuron caches of the targets' compact
positions as runs of consecutive positions (index order makes e.g. one MF's 1000 GCs a single
run), rebuilt after each compaction; each target receives exactly the same float32 additions in
the same order as without the cache. Conductances below 1e-12 nS and
|u| below 1e-6 mV become exactly 0 (V itself is only resolved to 7.6e-6 mV in float32 near -65
mV), so a neuron returns to rest a few tens of ms after its last input.

A compact population whose input makes equal neurons stay equal (the thesis granule layer: AMPA from box-coded
mossy fibres, one weight) is *lumped* instead (``snn/lumping.py``): its neurons are kept in classes of equal state
and input count, each class integrated once by the same kernel, and only the neurons whose input changed move
between classes; ``Lumps`` holds them, and the compact list is written from them when Python reads the state.

Rest under GABA (the granule layer under Golgi inhibition): in a compact population with
``clamp_at_rest`` and E_GABA <= E_L, a neuron at rest whose only input is a GABA conductance up to
``Populations.lazy`` (``topology.lazy_gaba_nS``: the step from rest is then negative and clamped to
exactly 0) stays unlisted. The GABA conductance of every neuron of such a population, listed or not, lives in
``g_gaba`` (global index order): a GABA spike adds its weight there (a plain scatter-add; the rare sum that leaves
[0, lazy] lists an unlisted neuron), and each step of the population gathers the listed neurons' values into
their compact slots, then decays the whole array in one vectorised pass by the integration loop's own product
(flushed below G_FLOOR), so the copies the loop decays and the array stay the same bits. Activation and
compaction move no GABA value. The listed
neurons of a population without NMDA input are stepped in one vectorised pass that computes the step and its
bifixed sub-steps for every neuron and selects one (``_lif_gaba``; bit for bit ``_lif_full_fine``, for the
methods and sub-step counts in ``FUSED``; the others compute their one-step estimates in a vectorised pass and
the sub-steps neuron by neuron, ``_lif_full_listed``).
"""

from __future__ import annotations

import time
from typing import NamedTuple

import numpy as np
from numba import njit, prange
from numba.cpython.unsafe.numbers import trailing_zeros

from cerebx.kernel_struct import KernelStruct
from cerebx.snn import lumping
from cerebx.snn.learning import NoLearning, SparseLearning, run_rules
from cerebx.snn.lumping import Lumps
from cerebx.snn.sync import clock_ns_intrinsic
from cerebx.snn.topology import (
    I_COMPACT,
    I_HI,
    I_KIND,
    I_LO,
    I_NFINE,
    I_RATIO,
    KIND_ADEX,
    KIND_INPUT,
    KIND_LIF_AMPA,
    P_A,
    P_B,
    P_CLAMP,
    P_CM,
    P_D1A,
    P_DA,
    P_DAH,
    P_DFA,
    P_DFAH,
    P_DFG,
    P_DFGH,
    P_DFN,
    P_DFNH,
    P_DG,
    P_DGH,
    P_DN,
    P_DNH,
    P_DT,
    P_EA,
    P_EG,
    P_EL,
    P_GL,
    P_H,
    P_IE,
    P_INVDT,
    P_ITW,
    P_METHOD,
    P_NREF,
    P_UFINE,
    P_UPK,
    P_URST,
    P_VT,
    P_VTH,
    S_DELAY,
    S_N_PRE,
    S_POST_POP,
    S_PRE_LO,
    S_RECEPTOR,
    S_ROW,
    S_TEACHING,
)

FAST = {"nnan", "ninf", "nsz", "contract", "afn", "reassoc"}
"""The fast-math flags of :func:`_lif_full` (the DCN's step): numba's ``fastmath=True`` without ``arcp``, so that
its Mg block's ``1 / (1 + e)`` stays a division. With ``arcp`` it became the CPU's reciprocal estimate refined
once, whose bits may depend on the vector width (``vrcpps`` on 8 lanes, ``vrcp14ps`` on 16) and on the CPU maker,
while the loop's scalar remainder divided exactly; without it the step's results do not depend on the width
(:mod:`cerebx.vectors`; tests/cerebx/test_vectors.py), and it was not slower (docs/guide/speed.md#wide-vectors).
The other kernels keep ``fastmath=True`` (inlined helpers take their caller's flags): the granule layer's fused
step equals the listed and the sub-stepped ones bit for bit only as the compiler arranges all three with it
(:data:`FUSED`), and in the networks shipped every population with NMDA input takes :func:`_lif_full` (a
population with NMDA input and bifixed sub-steps, :func:`_lif_full_fine`, still takes the estimate)."""

G_FLOOR = np.float32(1e-12)  # conductances below this (nS) become exactly 0 (avoids denormals)
U_FLOOR = np.float32(1e-6)  # |V - E_L| below this (mV) becomes exactly 0 (neuron back at rest)
COMPACT_FRACTION = 4  # compact a population when at least 1/4 of its listed neurons are at rest
RUN_MIN = 4  # targets at consecutive compact positions delivered as one vector add from this many on
PAR_MIN = 4096  # neurons below which a population is integrated serially even when parallel

MG_LN = float(np.log(1.2 / 3.57))  # NMDA Mg block g_inf(V) = 1 / (1 + e^(-0.062 V + MG_LN)), V in mV


PROF_PARTS = ("delivery", "plasticity", "bookkeeping", "outputs")
DELIVERY, PLASTICITY, BOOKKEEPING, OUTPUTS = range(len(PROF_PARTS))
"""The network thread's parts that a cost profile times besides each population's integration. A profile
(``prof`` of the step kernels, :meth:`cerebx.snn.network.Network.start_profile`) is an int64 array of
nanoseconds: one entry per population (its integration: neuron updates, threshold, decay), then one per part:
spike delivery (the synaptic currents, the sparse delivery caches' rebuilds and the activation of resting
neurons), plasticity (sparse rules, LTP, the PF buffer, LTD), bookkeeping (the spike ring, collecting the
spikes, compacting the lists of active neurons) and the chunk's outputs (decoding, spike messages). Without a
profile ``prof`` is :data:`NO_PROF`, an empty array: the same compiled code, whose timing calls then read no clock
(one branch each). (``prof`` None used to compile the timing away, but as a second version of every step kernel:
~30 s more of compiling on a new machine, for what the branch costs, well under 0.1 µs a step.)"""
NO_PROF = np.zeros(0, dtype=np.int64)
_CLOCK = time.CLOCK_MONOTONIC


_clock_ns = clock_ns_intrinsic(_CLOCK, "The monotonic clock in ns.")


# Not inline="always": after inlining, numba (0.68) runs a typed dead-code elimination whose alias analysis does not
# follow arrays taken out of a tuple (the KernelState's NamedTuples): a store into such an array that is not read
# again in the function is dropped as dead. run_step lost the LTP's row mark (plast.dirty[pl, j] = 1) when these
# were inlined overloads, so checkpoints missed rows that only LTP had changed and resumed runs diverged.
# Called, they compile to a few instructions that LLVM inlines.
@njit(cache=True, nogil=True)
def prof_now(prof):
    """The clock (ns) when ``prof`` is a profile (not :data:`NO_PROF`), else 0."""
    if prof.shape[0] == 0:
        return 0
    return _clock_ns()


@njit(cache=True, nogil=True)
def prof_lap(prof, k, t0):
    """Charge the time since ``t0`` to ``prof[k]`` and return the clock now; without a profile (:data:`NO_PROF`),
    nothing (returns t0)."""
    if prof.shape[0] == 0:
        return t0
    t = _clock_ns()
    prof[k] += t - t0
    return t


class Neurons(NamedTuple):
    """Per-neuron state (compact slices in front, see the module docstring) and the bookkeeping of
    the compact lists, one entry per population where marked."""

    u: np.ndarray  # float32 [n]: V - E_L (mV)
    g: np.ndarray  # float32 [3, n]: AMPA, NMDA, GABA conductance (nS)
    ref: np.ndarray  # float32 [n]: refractory steps left
    flag: np.ndarray  # uint8 [n]: spiked in the step just integrated
    cid: np.ndarray  # int32 [n]: compact position -> global index
    slot: np.ndarray  # int32 [n]: global index -> compact position (-1 at rest)
    n_act: np.ndarray  # int64 [pop]: listed (non-resting) neurons
    n_rest: np.ndarray  # int64 [pop]: listed neurons found at rest by the last step
    pop_ep: np.ndarray  # int64 [pop]: version of the compact list (every compaction increments it)
    w: np.ndarray  # float32 [n]: adaptation current of adex_cond neurons (pA; 0 elsewhere), global index order
    g_gaba: np.ndarray  # float32 [n]: GABA conductance (nS) of every neuron of lazy-GABA populations (listed or
    # not), global index order, decayed with every step of the population; their listed neurons' g[2] is a copy
    # gathered before each step (0 elsewhere)


class Populations(NamedTuple):
    """Fixed parameters of each population (rows: populations, columns: ``topology`` I_*/P_*)."""

    pop_i: np.ndarray  # int64 [pop, I_*]: kind, bounds, step ratio, compact, bifixed sub-steps
    pop_par: np.ndarray  # float64 [pop, P_*]: membrane, synapse and step constants
    poly: np.ndarray  # float32 [pop, 2, 2, N_COEF]: step polynomials of AMPA-only populations
    lazy: np.ndarray  # float64 [pop]: largest GABA conductance an unlisted neuron at rest holds (nS; 0: none)
    nmda: np.ndarray  # uint8 [pop]: 1 where the population has NMDA input


class Delivery(NamedTuple):
    """Spikes in flight and the synapses that deliver them."""

    ring_idx: np.ndarray  # int32 [R, n]: spiking neurons per substep slot (t % R)
    ring_n: np.ndarray  # int64 [R]: spikes in each slot
    sp_i: np.ndarray  # int64 [proj, N_SPAR]: columns S_PRE_LO .. S_POST_POP (topology.py)
    sp_ptr: np.ndarray  # int64: CSR row pointers by presynaptic neuron, all sparse projections
    sp_post: np.ndarray  # int32: postsynaptic global index per synapse
    sp_w: np.ndarray  # float32: weight per synapse (nS)
    sp_c: np.ndarray  # int64 [rows, 2]: delivery cache (epoch, runs) per presynaptic neuron
    c_k: np.ndarray  # int64: cached run start (compact position)
    c_q: np.ndarray  # int64: cached run first synapse
    c_l: np.ndarray  # int64: cached run length
    de_i: np.ndarray  # int64 [proj, 9]: pre_lo, n_pre, post_lo, n_post, w_off, receptor, delay, rule, post pop
    dense_w: np.ndarray  # float32: all-to-all weights, [n_pre, n_post] blocks (nS)


class Plasticity(NamedTuple):
    """PF-PC rules and the buffered PF arrivals LTD pairs with teacher spikes."""

    pl_i: np.ndarray  # int64 [rule, 4]: dense projection, teaching projection, kernel offset, kernel length
    pl_f: np.ndarray  # float64 [rule, 4]: LTP, LTD, w_lo, w_hi (nS)
    kern: np.ndarray  # float32: LTD kernels by substep age, all rules
    pf_t: np.ndarray  # int64 [rule, cap]: arrival substep of each buffered PF spike (ring)
    pf_j: np.ndarray  # int32 [rule, cap]: its presynaptic index
    pf_head: np.ndarray  # int64 [rule]: PF spikes buffered so far
    pf_lost: np.ndarray  # int64 [rule]: overwritten while still inside the kernel window
    dirty: np.ndarray  # uint8 [rule, n_pre]: rows (presynaptic neurons) whose weights changed (checkpoints)


class Buffers(NamedTuple):
    """Scratch space and the step's spike output."""

    col_buf: np.ndarray  # int64 [n]: PCs hit by teacher spikes
    acc: np.ndarray  # float64 [n]: summed kernel values per PF (zero between uses)
    acc_j: np.ndarray  # int64 [n]: PFs with a nonzero acc
    out_idx: np.ndarray  # int32 [n * n_sub]: spiking neurons of the step
    out_t: np.ndarray  # int32 [n * n_sub]: their substep (1..n_sub)
    scr_f: np.ndarray  # float32 [5, n]: compaction scratch (u, g_AMPA, ref, g_NMDA, g_GABA)
    bits: np.ndarray  # uint64 [n // 64 + 2]: compaction scratch, a bitmap of neurons (zero between uses)


class NetworkArrays(NamedTuple):
    """Everything the step kernels read and write, by meaning; the arrays are the ``Network``'s own.
    The entry points get it as one :class:`KernelState`; the helpers they call take the groups
    (named tuples cost nothing inside numba)."""

    neurons: Neurons
    populations: Populations
    delivery: Delivery
    plasticity: Plasticity
    buffers: Buffers
    learning: SparseLearning | NoLearning  # the sparse projections' rules (snn/learning.py), if any
    lumps: Lumps  # the lumped populations' classes (snn/lumping.py)


class KernelState(KernelStruct, fields=NetworkArrays):
    """A network's :class:`NetworkArrays` as one numba object, the form :func:`run_step` and
    :func:`run_chunk` take (make it with :func:`kernel_state`). numba passes it as one pointer, so a
    call costs the same whatever the number of arrays: an empty step costs about half as much as
    with the 38 arrays as arguments and a quarter as much as with the named tuples, whose arrays and
    field names numba checks one by one on every call. Pickles as its arrays."""

    @property
    def arrays(self) -> NetworkArrays:
        """The :class:`NetworkArrays` it was made of."""
        return self.source


def kernel_state(arrays: NetworkArrays) -> KernelState:
    """The kernels' handle on ``arrays`` (the same array objects: writes either way are seen both ways)."""
    return KernelState.of(arrays)


def mg_block(v: np.ndarray) -> np.ndarray:
    """The kernel's Mg block (float32), for tests."""
    return _mg_vec(np.ascontiguousarray(v, dtype=np.float32))


# --------------------------------------------------------------------------- AMPA-only populations
@njit(cache=True, fastmath=True, error_model="numpy", boundscheck=False, inline="always")
def _decay(g, d):
    """g <- g d in place, values below G_FLOOR flushed to 0."""
    zero = np.float32(0.0)
    for i in range(g.shape[0]):
        x = g[i] * d
        g[i] = x if x > G_FLOOR else zero


@njit(cache=True, fastmath=True, error_model="numpy", boundscheck=False, inline="always")
def _at_rest(u, a, n, r, b, gmax):
    """Whether a neuron of a compact lif_cond population with NMDA/GABA may leave the list: at rest (u, the AMPA
    and NMDA conductances a, n and the refractory count r 0) with a GABA conductance b in [0, gmax] (gmax 0:
    none), which stays in ``g_gaba``. Branch-free, so the loops that count it vectorise."""
    zero = np.float32(0.0)
    return (u == zero) & (a == zero) & (n == zero) & (r == zero) & (b >= zero) & (b <= gmax)


@njit(cache=True, fastmath=True, error_model="numpy", boundscheck=False)
def _rest_full(u, gA, gN, gG, ref, gmax):
    """Listed neurons of a compact lif_cond population with NMDA/GABA that a compaction may drop
    (:func:`_at_rest`)."""
    zero, one = np.float32(0.0), np.float32(1.0)
    cnt = zero
    for i in range(u.shape[0]):
        cnt += one if _at_rest(u[i], gA[i], gN[i], ref[i], gG[i], gmax) else zero
    return int(cnt)


@njit(cache=True, fastmath=True, error_model="numpy", boundscheck=False, inline="always")
def _finish(un, r, g0, lo_u, uth, nref, dwin):
    """Clamp, flush, threshold, reset and refractory of a step's result un (refractory count r at
    the step start) and the decayed conductance: (u, ref, spike, g)."""
    zero, one = np.float32(0.0), np.float32(1.0)
    un = max(un, lo_u)
    un = un if abs(un) >= U_FLOOR else zero
    spk = (un >= uth) & (r <= zero)
    un = zero if (r > zero) | spk else un
    rn = nref if spk else max(r - one, zero)
    gn = g0 * dwin
    gn = gn if gn > G_FLOOR else zero
    return un, rn, spk, gn


@njit(cache=True, fastmath=True, error_model="numpy", boundscheck=False, inline="always")
def _coarse(cf, x, g0):
    """P(g0) x + Q(g0) of the coarse step; cf: the coefficients as a tuple (loaded once per call,
    not per neuron: the arrays stored to in a loop could alias the coefficient array)."""
    p0, p1, p2, p3, p4 = cf[0], cf[1], cf[2], cf[3], cf[4]
    q0, q1, q2, q3, q4 = cf[5], cf[6], cf[7], cf[8], cf[9]
    return (p0 + g0 * (p1 + g0 * (p2 + g0 * (p3 + g0 * p4)))) * x + (
        q0 + g0 * (q1 + g0 * (q2 + g0 * (q3 + g0 * q4))))


@njit(cache=True, fastmath=True, error_model="numpy", boundscheck=False, inline="always")
def _fine(cf, x, g0):
    r0, r1, r2, r3, r4, r5, r6 = cf[10], cf[11], cf[12], cf[13], cf[14], cf[15], cf[16]
    s0, s1, s2, s3, s4, s5, s6 = cf[17], cf[18], cf[19], cf[20], cf[21], cf[22], cf[23]
    return (r0 + g0 * (r1 + g0 * (r2 + g0 * (r3 + g0 * (r4 + g0 * (r5 + g0 * r6)))))) * x + (
        s0 + g0 * (s1 + g0 * (s2 + g0 * (s3 + g0 * (s4 + g0 * (s5 + g0 * s6))))))


@njit(cache=True, fastmath=True, error_model="numpy", boundscheck=False, inline="always")
def _coefs(c):
    return (c[0, 0, 0], c[0, 0, 1], c[0, 0, 2], c[0, 0, 3], c[0, 0, 4],
            c[0, 1, 0], c[0, 1, 1], c[0, 1, 2], c[0, 1, 3], c[0, 1, 4],
            c[1, 0, 0], c[1, 0, 1], c[1, 0, 2], c[1, 0, 3], c[1, 0, 4], c[1, 0, 5], c[1, 0, 6],
            c[1, 1, 0], c[1, 1, 1], c[1, 1, 2], c[1, 1, 3], c[1, 1, 4], c[1, 1, 5], c[1, 1, 6])


@njit(cache=True, fastmath=True, error_model="numpy", boundscheck=False)
def _lif_poly(u, g, ref, flag, pops, pi):
    """One step of the AMPA-only population ``pi`` (u, g, ref, flag: its slices; pops:
    :class:`Populations`): u' = P(g0) u + Q(g0), or, when the population has bifixed sub-steps and
    the step starts above u_fine or its one-step estimate ends above it, the bifixed pair (the n
    sub-steps composed). ``pops.poly[pi]``: float32 [2, 2, N_COEF] coefficients (lowest order
    first) of (P, Q) for the step and for the bifixed sub-steps composed.
    Integration, threshold, reset, refractory count, conductance decay and the count of neurons
    at rest are one fused loop per variant (LLVM vectorises it; ~25% faster than separate passes).
    With bifixed sub-steps both polynomials are evaluated for every neuron: the bifixed one is
    needed by ~12% of the active GCs (all those with two or more active inputs), and evaluating
    it only where needed (a coarse pre-pass per block, then the bifixed one for the blocks that
    need it) costs as much as it saves. Returns (spikes, neurons at rest after the step); both
    are counted in floats (integer reductions of booleans defeat the vectoriser)."""
    f32 = np.float32
    pp = pops.pop_par[pi]
    dwin, ufine = f32(pp[P_DA]), f32(pp[P_UFINE])
    uth, nref = f32(pp[P_VTH] - pp[P_EL]), f32(pp[P_NREF])
    lo_u = f32(0.0) if pp[P_CLAMP] > 0.5 else f32(-3.0e38)
    cf = _coefs(pops.poly[pi])
    zero, one = f32(0.0), f32(1.0)
    cnt = zero
    nrest = zero
    if pops.pop_i[pi, I_NFINE] > 1:
        for i in range(u.shape[0]):
            x = u[i]
            g0 = g[i]
            r = ref[i]
            un = _coarse(cf, x, g0)
            uf = _fine(cf, x, g0)
            un = uf if (x > ufine) | (un > ufine) else un
            un, rn, spk, gn = _finish(un, r, g0, lo_u, uth, nref, dwin)
            u[i] = un
            ref[i] = rn
            flag[i] = np.uint8(spk)
            cnt += one if spk else zero
            g[i] = gn
            nrest += one if (abs(un) + gn + rn) == zero else zero
    else:
        for i in range(u.shape[0]):
            x = u[i]
            g0 = g[i]
            r = ref[i]
            un, rn, spk, gn = _finish(_coarse(cf, x, g0), r, g0, lo_u, uth, nref, dwin)
            u[i] = un
            ref[i] = rn
            flag[i] = np.uint8(spk)
            cnt += one if spk else zero
            g[i] = gn
            nrest += one if (abs(un) + gn + rn) == zero else zero
    return int(cnt), int(nrest)


@njit(cache=True, parallel=True, fastmath=True, error_model="numpy", boundscheck=False)
def _lif_poly_par(u, g, ref, flag, pops, pi, nch):
    """:func:`_lif_poly` on numba threads: ``nch`` contiguous chunks."""
    n = u.shape[0]
    cnt = 0
    nrest = 0
    for ch in prange(nch):
        a = ch * n // nch
        b = (ch + 1) * n // nch
        c1, r1 = _lif_poly(u[a:b], g[a:b], ref[a:b], flag[a:b], pops, pi)
        cnt += c1
        nrest += r1
    return cnt, nrest


# --------------------------------------------------------------------------- AMPA + NMDA + GABA
@njit(cache=True, fastmath=True, error_model="numpy", boundscheck=False, inline="always")
def _mg(v):
    """Mg block 1 / (1 + e^(-0.062 v) 1.2/3.57) at v (mV), branch-free so the loop vectorises:
    e^y = (e^(y/64))^64 with a degree-5 Taylor polynomial for e^(y/64), v clamped to [-150, 50] mV
    (the DCN voltage stays within [E_GABA, E_AMPA]). Max abs error 1e-6 (float32 rounding of
    the six squarings; see tests)."""
    f32 = np.float32
    v = min(max(v, f32(-150.0)), f32(50.0))
    y = (f32(-0.062) * v + f32(MG_LN)) * f32(1.0 / 64.0)
    e = f32(1.0) + y * (f32(1.0) + y * (f32(0.5) + y * (f32(1.0 / 6.0) + y * (
        f32(1.0 / 24.0) + y * f32(1.0 / 120.0)))))
    e = e * e
    e = e * e
    e = e * e
    e = e * e
    e = e * e
    e = e * e
    return f32(1.0) / (f32(1.0) + e)


@njit(cache=True, fastmath=True, error_model="numpy", boundscheck=False, inline="always")
def _du(x, a, n, b, gL, EL, EAL, EGL, invC):
    mg = _mg(EL + x)
    return (-gL * x + (a + n * mg) * (EAL - x) + b * (EGL - x)) * invC


@njit(cache=True, fastmath=True, error_model="numpy", boundscheck=False, inline="always")
def _end_full(u, ref, flag, gs, p):
    """The end of a step of :func:`_lif_full` and :func:`_lif_full_fine` once u holds the integrated values, in
    one pass: threshold, reset and refractory count, and the conductances ``gs`` (AMPA, NMDA, GABA) decayed over
    the step, values below G_FLOOR flushed to 0 (p: the population's parameters). Returns the spike count (a
    float accumulator: integer reductions of booleans defeat the vectoriser). Kept apart from the integration
    loop: there the decayed AMPA conductance is a product the RK stages compute too, and sharing it changes how
    the compiler contracts the stages' multiply-adds (the last bit of V moves)."""
    f32 = np.float32
    uth, nref = f32(p[P_VTH] - p[P_EL]), f32(p[P_NREF])
    dA, dN, dG = f32(p[P_DA]), f32(p[P_DN]), f32(p[P_DG])
    gA, gN, gG = gs
    zero, one = f32(0.0), f32(1.0)
    cnt = zero
    for i in range(u.shape[0]):
        un = u[i]
        r = ref[i]
        spk = (un >= uth) & (r <= zero)
        u[i] = zero if (r > zero) | spk else un
        ref[i] = nref if spk else max(r - one, zero)
        flag[i] = np.uint8(spk)
        cnt += one if spk else zero
        x = gA[i] * dA
        gA[i] = x if x > G_FLOOR else zero
        x = gN[i] * dN
        gN[i] = x if x > G_FLOOR else zero
        x = gG[i] * dG
        gG[i] = x if x > G_FLOOR else zero
    return int(cnt)


@njit(cache=True, fastmath=FAST, error_model="numpy", boundscheck=False)
def _lif_full(u, gA, gN, gG, ref, flag, p):
    """One step of a population with AMPA, NMDA (Mg block, Eq. 2.8) and GABA conductances
    (float32; vectorised passes as in :func:`_lif_poly`)."""
    f32 = np.float32
    h = f32(p[P_H])
    gL, EL, invC = f32(p[P_GL]), f32(p[P_EL]), f32(1.0 / p[P_CM])
    EAL, EGL = f32(p[P_EA] - p[P_EL]), f32(p[P_EG] - p[P_EL])
    dA, dAh, dN, dNh = f32(p[P_DA]), f32(p[P_DAH]), f32(p[P_DN]), f32(p[P_DNH])
    dG, dGh = f32(p[P_DG]), f32(p[P_DGH])
    method = int(p[P_METHOD])
    lo_u = f32(0.0) if p[P_CLAMP] > 0.5 else f32(-3.0e38)
    half, sixth, two, zero = f32(0.5), f32(1.0 / 6.0), f32(2.0), f32(0.0)
    hh = half * h
    n = u.shape[0]
    if method == 2:
        for i in range(n):
            x = u[i]
            a0, n0, b0 = gA[i], gN[i], gG[i]
            k1 = _du(x, a0, n0, b0, gL, EL, EAL, EGL, invC)
            k2 = _du(x + hh * k1, a0 * dAh, n0 * dNh, b0 * dGh, gL, EL, EAL, EGL, invC)
            k3 = _du(x + hh * k2, a0 * dAh, n0 * dNh, b0 * dGh, gL, EL, EAL, EGL, invC)
            k4 = _du(x + h * k3, a0 * dA, n0 * dN, b0 * dG, gL, EL, EAL, EGL, invC)
            un = max(x + h * sixth * (k1 + two * k2 + two * k3 + k4), lo_u)
            u[i] = un if abs(un) >= U_FLOOR else zero
    elif method == 1:
        for i in range(n):
            x = u[i]
            a0, n0, b0 = gA[i], gN[i], gG[i]
            k1 = _du(x, a0, n0, b0, gL, EL, EAL, EGL, invC)
            k2 = _du(x + h * k1, a0 * dA, n0 * dN, b0 * dG, gL, EL, EAL, EGL, invC)
            un = max(x + hh * (k1 + k2), lo_u)
            u[i] = un if abs(un) >= U_FLOOR else zero
    else:
        for i in range(n):
            x = u[i]
            un = max(x + h * _du(x, gA[i], gN[i], gG[i], gL, EL, EAL, EGL, invC), lo_u)
            u[i] = un if abs(un) >= U_FLOOR else zero
    return _end_full(u, ref, flag, (gA, gN, gG), p)


@njit(cache=True, fastmath=True, error_model="numpy", boundscheck=False, inline="always")
def _full_rk(x, g0, h, dec, method, m):
    """One step of :func:`_lif_full`'s method from u = x with conductances g0 = (AMPA, NMDA, GABA) at its start;
    dec: their decays over h and h/2 (dA, dAh, dN, dNh, dG, dGh); m: (gL, EL, EAL, EGL, invC)."""
    a0, n0, b0 = g0
    dA, dAh, dN, dNh, dG, dGh = dec
    gL, EL, EAL, EGL, invC = m
    if method == 2:
        k1 = _du(x, a0, n0, b0, gL, EL, EAL, EGL, invC)
        k2 = _du(x + np.float32(0.5) * h * k1, a0 * dAh, n0 * dNh, b0 * dGh, gL, EL, EAL, EGL, invC)
        k3 = _du(x + np.float32(0.5) * h * k2, a0 * dAh, n0 * dNh, b0 * dGh, gL, EL, EAL, EGL, invC)
        k4 = _du(x + h * k3, a0 * dA, n0 * dN, b0 * dG, gL, EL, EAL, EGL, invC)
        return x + h * np.float32(1.0 / 6.0) * (k1 + np.float32(2.0) * k2 + np.float32(2.0) * k3 + k4)
    if method == 1:
        k1 = _du(x, a0, n0, b0, gL, EL, EAL, EGL, invC)
        k2 = _du(x + h * k1, a0 * dA, n0 * dN, b0 * dG, gL, EL, EAL, EGL, invC)
        return x + np.float32(0.5) * h * (k1 + k2)
    return x + h * _du(x, a0, n0, b0, gL, EL, EAL, EGL, invC)


@njit(cache=True, fastmath=True, error_model="numpy", boundscheck=False)
def _lif_full_fine(u, gA, gN, gG, ref, flag, p, nf):
    """:func:`_lif_full` with ``nf`` > 1 bifixed sub-steps: a step that starts above u_fine, or whose one-step
    estimate ends above it, is redone as nf sub-steps (the conductances exact at every stage), with the same
    rule and the same single clamp at the step's end as the AMPA-only path (:func:`_lif_poly`), so a
    population integrates alike whichever receptors reach it."""
    f32 = np.float32
    h = f32(p[P_H])
    hf = h / f32(nf)
    gL, EL, invC = f32(p[P_GL]), f32(p[P_EL]), f32(1.0 / p[P_CM])
    EAL, EGL = f32(p[P_EA] - p[P_EL]), f32(p[P_EG] - p[P_EL])
    dA, dAh, dN, dNh = f32(p[P_DA]), f32(p[P_DAH]), f32(p[P_DN]), f32(p[P_DNH])
    dG, dGh = f32(p[P_DG]), f32(p[P_DGH])
    fA, fAh, fN, fNh = f32(p[P_DFA]), f32(p[P_DFAH]), f32(p[P_DFN]), f32(p[P_DFNH])
    fG, fGh = f32(p[P_DFG]), f32(p[P_DFGH])
    ufine = f32(p[P_UFINE])
    method = int(p[P_METHOD])
    lo_u = f32(0.0) if p[P_CLAMP] > 0.5 else f32(-3.0e38)
    zero = f32(0.0)
    m = (gL, EL, EAL, EGL, invC)
    dec, fdec = (dA, dAh, dN, dNh, dG, dGh), (fA, fAh, fN, fNh, fG, fGh)
    for i in range(u.shape[0]):
        x = u[i]
        a0, n0, b0 = gA[i], gN[i], gG[i]
        un = _full_rk(x, (a0, n0, b0), h, dec, method, m)
        if (x > ufine) | (un > ufine):
            un = x
            for _ in range(nf):
                un = _full_rk(un, (a0, n0, b0), hf, fdec, method, m)
                a0, n0, b0 = a0 * fA, n0 * fN, b0 * fG
        un = max(un, lo_u)
        u[i] = un if abs(un) >= U_FLOOR else zero
    return _end_full(u, ref, flag, (gA, gN, gG), p)


@njit(cache=True, fastmath=True, error_model="numpy", boundscheck=False, inline="always")
def _du_no_nmda(x, a, n, b, gL, EL, EAL, EGL, invC):
    """:func:`_du` for n = 0 (no NMDA input), bit for bit: the Mg block, which then multiplies 0, is replaced by
    a cheap stand-in of the same form 1 / (1 + e), e = x^2 (finite and positive, so n times it is exactly 0), and
    the compiler builds the same arithmetic around it (it folds n / (1 + e) into one division and contracts the
    rest alike: a formula without the term, or with a stand-in that is no division, is contracted differently and
    moves the last bits). Tests compare it with :func:`_du` on random states."""
    mg = np.float32(1.0) / (np.float32(1.0) + x * x)
    return (-gL * x + (a + n * mg) * (EAL - x) + b * (EGL - x)) * invC


@njit(cache=True, fastmath=True, error_model="numpy", boundscheck=False, inline="always")
def _no_nmda_rk(x, g0, h, dec, method, m):
    """:func:`_full_rk` with :func:`_du_no_nmda`."""
    a0, n0, b0 = g0
    dA, dAh, dN, dNh, dG, dGh = dec
    gL, EL, EAL, EGL, invC = m
    if method == 2:
        k1 = _du_no_nmda(x, a0, n0, b0, gL, EL, EAL, EGL, invC)
        k2 = _du_no_nmda(x + np.float32(0.5) * h * k1, a0 * dAh, n0 * dNh, b0 * dGh, gL, EL, EAL, EGL, invC)
        k3 = _du_no_nmda(x + np.float32(0.5) * h * k2, a0 * dAh, n0 * dNh, b0 * dGh, gL, EL, EAL, EGL, invC)
        k4 = _du_no_nmda(x + h * k3, a0 * dA, n0 * dN, b0 * dG, gL, EL, EAL, EGL, invC)
        return x + h * np.float32(1.0 / 6.0) * (k1 + np.float32(2.0) * k2 + np.float32(2.0) * k3 + k4)
    if method == 1:
        k1 = _du_no_nmda(x, a0, n0, b0, gL, EL, EAL, EGL, invC)
        k2 = _du_no_nmda(x + h * k1, a0 * dA, n0 * dN, b0 * dG, gL, EL, EAL, EGL, invC)
        return x + np.float32(0.5) * h * (k1 + k2)
    return x + h * _du_no_nmda(x, a0, n0, b0, gL, EL, EAL, EGL, invC)


@njit(cache=True, fastmath=True, error_model="numpy", boundscheck=False, inline="always")
def _full_estimates(u, gA, gN, gG, out, h, dec, method, m):
    """The one-step estimate of every neuron of a population without NMDA input into ``out``
    (:func:`_no_nmda_rk`, equal to :func:`_full_rk`); inlined with a constant ``method`` the loop has no branch and
    vectorises."""
    for i in range(u.shape[0]):
        out[i] = _no_nmda_rk(u[i], (gA[i], gN[i], gG[i]), h, dec, method, m)


@njit(cache=True, fastmath=True, error_model="numpy", boundscheck=False)
def _lif_full_listed(u, gA, gN, gG, ref, flag, out, p, nf):
    """:func:`_lif_full_fine` in two passes for a population without NMDA input, with the same result bit for
    bit (tests): the one-step estimates of all neurons first, in a loop that vectorises without the Mg block
    (about five times faster), then the bifixed sub-steps for the neurons that need them. ``out``: scratch at
    least as long as u. For the listed neurons of a compact population (whose list may be long: the granule layer
    under Golgi inhibition). Populations with NMDA input keep :func:`_lif_full_fine` (the vectorised Mg block
    may differ from the per-neuron one in the last bit)."""
    f32 = np.float32
    h = f32(p[P_H])
    hf = h / f32(nf)
    gL, EL, invC = f32(p[P_GL]), f32(p[P_EL]), f32(1.0 / p[P_CM])
    EAL, EGL = f32(p[P_EA] - p[P_EL]), f32(p[P_EG] - p[P_EL])
    dec = (f32(p[P_DA]), f32(p[P_DAH]), f32(p[P_DN]), f32(p[P_DNH]), f32(p[P_DG]), f32(p[P_DGH]))
    fA, fN, fG = f32(p[P_DFA]), f32(p[P_DFN]), f32(p[P_DFG])
    fdec = (fA, f32(p[P_DFAH]), fN, f32(p[P_DFNH]), fG, f32(p[P_DFGH]))
    ufine = f32(p[P_UFINE])
    method = int(p[P_METHOD])
    lo_u = f32(0.0) if p[P_CLAMP] > 0.5 else f32(-3.0e38)
    zero = f32(0.0)
    m = (gL, EL, EAL, EGL, invC)
    n = u.shape[0]
    est = out[:n]
    if method == 2:
        _full_estimates(u, gA, gN, gG, est, h, dec, 2, m)
    elif method == 1:
        _full_estimates(u, gA, gN, gG, est, h, dec, 1, m)
    else:
        _full_estimates(u, gA, gN, gG, est, h, dec, 0, m)
    for i in range(n):
        x = u[i]
        un = est[i]
        if nf > 1 and ((x > ufine) | (un > ufine)):
            a0, n0, b0 = gA[i], gN[i], gG[i]
            un = x
            for _ in range(nf):
                un = _full_rk(un, (a0, n0, b0), hf, fdec, method, m)
                a0, n0, b0 = a0 * fA, n0 * fN, b0 * fG
        un = max(un, lo_u)
        u[i] = un if abs(un) >= U_FLOOR else zero
    return _end_full(u, ref, flag, (gA, gN, gG), p)


@njit(cache=True, parallel=True, fastmath=True, error_model="numpy", boundscheck=False)
def _lif_full_listed_par(u, gA, gN, gG, ref, flag, out, p, nf, nch):
    """:func:`_lif_full_listed` on numba threads: ``nch`` contiguous chunks."""
    n = u.shape[0]
    cnt = 0
    for ch in prange(nch):
        a = ch * n // nch
        b = (ch + 1) * n // nch
        cnt += _lif_full_listed(u[a:b], gA[a:b], gN[a:b], gG[a:b], ref[a:b], flag[a:b], out[a:b], p, nf)
    return cnt


FUSED = ((1, 3), (0, 2))
"""(method, bifixed sub-steps) for which :func:`_lif_gaba` has a fused loop: those whose result the tests prove
bit for bit equal to :func:`_lif_full_listed`'s (RK2 with 3 sub-steps is the granule cell's; with 2 sub-steps, and
Euler with 4 or more, the compiler rearranges the unrolled sub-steps' products and the last bit of V moves; Euler
with 3 differed on an AVX-512 host, 71,403 of 1.2 million V values, though it had matched on the development
host). The others keep :func:`_lif_full_listed`."""


@njit(cache=True, inline="always")
def _fusable(method, nf):
    return (method == 1 and nf == 3) or (method == 0 and nf == 2)


@njit(cache=True, fastmath=True, error_model="numpy", boundscheck=False, inline="always")
def _gaba_loop(u, gA, gG, ref, flag, p, gmax, method, nf):
    """The loop of :func:`_lif_gaba` for a constant ``method`` and ``nf`` (inlined: the sub-steps unroll and the
    loop, free of branches, vectorises)."""
    f32 = np.float32
    h = f32(p[P_H])
    hf = h / f32(nf)
    gL, EL, invC = f32(p[P_GL]), f32(p[P_EL]), f32(1.0 / p[P_CM])
    EAL, EGL = f32(p[P_EA] - p[P_EL]), f32(p[P_EG] - p[P_EL])
    dA, dG = f32(p[P_DA]), f32(p[P_DG])
    dec = (dA, f32(p[P_DAH]), f32(p[P_DN]), f32(p[P_DNH]), dG, f32(p[P_DGH]))
    fA, fG = f32(p[P_DFA]), f32(p[P_DFG])
    fdec = (fA, f32(p[P_DFAH]), f32(p[P_DFN]), f32(p[P_DFNH]), fG, f32(p[P_DFGH]))
    ufine = f32(p[P_UFINE])
    uth, nref = f32(p[P_VTH] - p[P_EL]), f32(p[P_NREF])
    lo_u = f32(0.0) if p[P_CLAMP] > 0.5 else f32(-3.0e38)
    zero, one = f32(0.0), f32(1.0)
    # the NMDA conductance, 0 as a value the compiler cannot see through (h > 0): the NMDA term then stays in the
    # stages' arithmetic, which the compiler contracts exactly as in _lif_full_fine (a literal 0 folds it away)
    nz = f32(min(p[P_H], 0.0))
    m = (gL, EL, EAL, EGL, invC)
    cnt = zero
    nrest = zero
    for i in range(u.shape[0]):
        x = u[i]
        a0, b0 = gA[i], gG[i]
        r = ref[i]
        un = _no_nmda_rk(x, (a0, nz, b0), h, dec, method, m)
        uf = x
        a, n, b = a0, nz, b0
        for _ in range(nf):
            uf = _no_nmda_rk(uf, (a, n, b), hf, fdec, method, m)
            a, n, b = a * fA, n * fdec[2], b * fG
        un = uf if (x > ufine) | (un > ufine) else un
        un, rn, spk, ga = _finish(un, r, a0, lo_u, uth, nref, dA)
        gb = b0 * dG
        gb = gb if gb > G_FLOOR else zero
        u[i] = un
        ref[i] = rn
        flag[i] = np.uint8(spk)
        gA[i] = ga
        gG[i] = gb
        cnt += one if spk else zero
        nrest += one if _at_rest(un, ga, nz, rn, gb, gmax) else zero
    return int(cnt), int(nrest)


@njit(cache=True, fastmath=True, error_model="numpy", boundscheck=False)
def _lif_gaba(u, gA, gG, ref, flag, p, nf, gmax):
    """One step of a compact lif_cond population with AMPA and GABA input and no NMDA input (the granule layer
    under Golgi inhibition) in one pass per neuron: the step, its ``nf`` bifixed sub-steps (both computed for
    every neuron and one selected by the rule of :func:`_lif_full_fine`, as :func:`_lif_poly` does, so the loop
    vectorises), threshold, reset and refractory count, the AMPA and GABA decays and the count of neurons a
    compaction may drop (:func:`_rest_full` with ``gmax``), touching no NMDA array (its conductances stay 0).
    Bit for bit :func:`_lif_full_listed` followed by :func:`_rest_full` (tests), in about a quarter of their time
    on the granule layer of thesis_golgi (its ~7 % of steps that need the sub-steps are branches there).
    (method, ``nf``): one of :data:`FUSED`. Returns (spikes, neurons at rest after the step)."""
    if int(p[P_METHOD]) == 1:
        return _gaba_loop(u, gA, gG, ref, flag, p, gmax, 1, 3)
    if nf == 2:
        return _gaba_loop(u, gA, gG, ref, flag, p, gmax, 0, 2)
    return _gaba_loop(u, gA, gG, ref, flag, p, gmax, 0, 3)


@njit(cache=True, parallel=True, fastmath=True, error_model="numpy", boundscheck=False)
def _lif_gaba_par(u, gA, gG, ref, flag, p, nf, gmax, nch):
    """:func:`_lif_gaba` on numba threads: ``nch`` contiguous chunks."""
    n = u.shape[0]
    cnt = 0
    nrest = 0
    for ch in prange(nch):
        a = ch * n // nch
        b = (ch + 1) * n // nch
        c1, r1 = _lif_gaba(u[a:b], gA[a:b], gG[a:b], ref[a:b], flag[a:b], p, nf, gmax)
        cnt += c1
        nrest += r1
    return cnt, nrest


def lif_gaba_step(u, gA, gG, ref, p, nf, gmax, chunks=1):
    """One step of :func:`_lif_gaba` (``chunks`` > 1: :func:`_lif_gaba_par`) on copies, for tests: (u, gA, gG,
    ref, flag, neurons at rest)."""
    if (int(p[P_METHOD]), nf) not in FUSED:
        raise ValueError(f"no fused loop for method {int(p[P_METHOD])} with {nf} sub-steps")
    u, gA, gG, ref = (np.array(a, dtype=np.float32) for a in (u, gA, gG, ref))
    flag = np.zeros(len(u), np.uint8)
    if chunks > 1:
        _, nrest = _lif_gaba_par(u, gA, gG, ref, flag, p, nf, np.float32(gmax), chunks)
    else:
        _, nrest = _lif_gaba(u, gA, gG, ref, flag, p, nf, np.float32(gmax))
    return u, gA, gG, ref, flag, nrest


def rest_count(u, gA, gN, gG, ref, gmax):
    """:func:`_rest_full` on float32 copies, for tests."""
    return _rest_full(*(np.asarray(a, dtype=np.float32) for a in (u, gA, gN, gG, ref)), np.float32(gmax))


def lif_step(u, gA, gN, gG, ref, p, nf, listed=False):
    """One step of a lif_cond population with NMDA/GABA input by :func:`_lif_full_fine` (``listed``:
    :func:`_lif_full_listed`) on copies, for tests: (u, gA, gN, gG, ref, flag)."""
    u, gA, gN, gG, ref = (np.array(a, dtype=np.float32) for a in (u, gA, gN, gG, ref))
    flag = np.zeros(len(u), np.uint8)
    if listed:
        _lif_full_listed(u, gA, gN, gG, ref, flag, np.zeros(len(u), np.float32), p, nf)
    else:
        _lif_full_fine(u, gA, gN, gG, ref, flag, p, nf)
    return u, gA, gN, gG, ref, flag


# --------------------------------------------------------------------------- AdEx (aeif_cond_exp)
W_FLOOR = np.float32(1e-12)  # |w| below this (pA) becomes exactly 0 (avoids denormals when a = 0)


@njit(cache=True, fastmath=True, error_model="numpy", boundscheck=False)
def _exp32(y):
    """e^y in float32 without a library call, so the AdEx loop vectorises (numba has no vector exp without
    SVML): e^y = (e^(y/256))^256, a degree-6 Taylor polynomial for e^(y/256), y clamped to [-80, 60] (the
    schema bounds the exponent at 60; e^-80 ~ 2e-35). Max relative error 5e-5 (float32 rounding of the eight
    squarings; see tests). Not inlined by numba: LLVM inlines it, with the same results and speed, and compiling
    :func:`_adex` (21 copies of it) took 16 s instead of 11."""
    f32 = np.float32
    y = min(max(y, f32(-80.0)), f32(60.0)) * f32(1.0 / 256.0)
    e = f32(1.0) + y * (f32(1.0) + y * (f32(0.5) + y * (f32(1.0 / 6.0) + y * (f32(1.0 / 24.0) + y * (
        f32(1.0 / 120.0) + y * f32(1.0 / 720.0))))))
    e = e * e
    e = e * e
    e = e * e
    e = e * e
    e = e * e
    e = e * e
    e = e * e
    return e * e


def exp32(y: np.ndarray) -> np.ndarray:
    """The AdEx kernel's exponential (float32), for tests."""
    return _exp32_vec(np.ascontiguousarray(y, dtype=np.float32))


@njit(cache=True, fastmath=True, error_model="numpy", boundscheck=False)
def _exp32_vec(y):
    out = np.empty_like(y)
    for i in range(y.shape[0]):
        out[i] = _exp32(y[i])
    return out


@njit(cache=True, fastmath=True, error_model="numpy", boundscheck=False, inline="always")
def _adex_rhs(x, w, ge, gi, live, c):
    """(du/dt, dw/dt) of NEST aeif_cond_exp at u = x (V - E_L), adaptation w, conductances (ge, gi); V is
    bounded by V_peak in every term (as NEST does) and held (du = 0) while refractory (live = 0).
    c: (gL, invC, EEL, EIL, VT, upk, sc, invDT, a, itw, Ie) in float32, u-relative potentials."""
    gL, invC, EEL, EIL, VT, upk, sc, invDT, a, itw, Ie = c
    v = min(x, upk)
    iexp = sc * _exp32((v - VT) * invDT)  # sc = 0 without the exponential term (then invDT = 0 too)
    du = live * (-gL * v + iexp - ge * (v - EEL) - gi * (v - EIL) - w + Ie) * invC
    dw = (a * v - w) * itw
    return du, dw


@njit(cache=True, fastmath=True, error_model="numpy", boundscheck=False, inline="always")
def _adex_rk(x, w, ge, gi, live, h, dec, method, c):
    """One step of the method from (x, w) with the conductances exact at every stage time (dec: their decays
    over h and h/2, (dE, dEh, dI, dIh))."""
    dE, dEh, dI, dIh = dec
    half = np.float32(0.5)
    if method == 2:
        k1, l1 = _adex_rhs(x, w, ge, gi, live, c)
        k2, l2 = _adex_rhs(x + half * h * k1, w + half * h * l1, ge * dEh, gi * dIh, live, c)
        k3, l3 = _adex_rhs(x + half * h * k2, w + half * h * l2, ge * dEh, gi * dIh, live, c)
        k4, l4 = _adex_rhs(x + h * k3, w + h * l3, ge * dE, gi * dI, live, c)
        s = h * np.float32(1.0 / 6.0)
        two = np.float32(2.0)
        return x + s * (k1 + two * k2 + two * k3 + k4), w + s * (l1 + two * l2 + two * l3 + l4)
    if method == 1:
        k1, l1 = _adex_rhs(x, w, ge, gi, live, c)
        k2, l2 = _adex_rhs(x + h * k1, w + h * l1, ge * dE, gi * dI, live, c)
        return x + half * h * (k1 + k2), w + half * h * (l1 + l2)
    k1, l1 = _adex_rhs(x, w, ge, gi, live, c)
    return x + h * k1, w + h * l1


@njit(cache=True, fastmath=True, error_model="numpy", boundscheck=False, inline="always")
def _adex_loop(u, w, gE, gI, ref, flag, c, k, method, fine):
    """The neurons of :func:`_adex`; inlined with a constant ``method`` and ``fine`` = False, the loop has no
    branch and vectorises (ten times faster than with the refinement's branch)."""
    h, hf, dE, dEh, dI, dIh, fE, fEh, fI, fIh, uth, urst, b, nref, ufine, nf = k
    zero, one = np.float32(0.0), np.float32(1.0)
    cnt = zero
    for i in range(u.shape[0]):
        x, wi, ge, gi, r = u[i], w[i], gE[i], gI[i], ref[i]
        live = one if r <= zero else zero
        un, wn = _adex_rk(x, wi, ge, gi, live, h, (dE, dEh, dI, dIh), method, c)
        if fine and ((x > ufine) | (un > ufine)):
            un, wn = x, wi
            for _ in range(nf):
                un, wn = _adex_rk(un, wn, ge, gi, live, hf, (fE, fEh, fI, fIh), method, c)
                ge, gi = ge * fE, gi * fI
        spk = (un >= uth) & (r <= zero)
        u[i] = urst if spk else un
        wn = wn + b if spk else wn
        w[i] = wn if abs(wn) >= W_FLOOR else zero
        ref[i] = nref if spk else max(r - one, zero)
        flag[i] = np.uint8(spk)
        cnt += one if spk else zero
    return int(cnt)


@njit(cache=True, fastmath=True, error_model="numpy", boundscheck=False)
def _adex(u, w, gE, gI, ref, flag, p, nf):
    """One step of an adex_cond population (u = V - E_L, adaptation w, g_ex in gE, g_in in gI): the method's
    stages with exact conductances, bifixed sub-steps as for lif_cond; a spike when V >= the spike threshold
    at the step's end resets V to V_reset and adds b to w; V is then held at V_reset for t_ref while w keeps
    evolving (with V = V_reset). Returns the spike count."""
    f32 = np.float32
    h = f32(p[P_H])
    el = p[P_EL]
    c = (f32(p[P_GL]), f32(1.0 / p[P_CM]), f32(p[P_EA] - el), f32(p[P_EG] - el), f32(p[P_VT]), f32(p[P_UPK]),
         f32(p[P_GL] * p[P_DT]), f32(p[P_INVDT]), f32(p[P_A]), f32(p[P_ITW]), f32(p[P_IE]))
    k = (h, h / f32(nf), f32(p[P_DA]), f32(p[P_DAH]), f32(p[P_DG]), f32(p[P_DGH]), f32(p[P_DFA]), f32(p[P_DFAH]),
         f32(p[P_DFG]), f32(p[P_DFGH]), f32(p[P_VTH] - el), f32(p[P_URST]), f32(p[P_B]), f32(p[P_NREF]),
         f32(p[P_UFINE]), nf)
    method = int(p[P_METHOD])
    if nf > 1:
        cnt = _adex_loop(u, w, gE, gI, ref, flag, c, k, method, True)
    elif method == 2:
        cnt = _adex_loop(u, w, gE, gI, ref, flag, c, k, 2, False)
    elif method == 1:
        cnt = _adex_loop(u, w, gE, gI, ref, flag, c, k, 1, False)
    else:
        cnt = _adex_loop(u, w, gE, gI, ref, flag, c, k, 0, False)
    _decay(gE, f32(p[P_DA]))
    _decay(gI, f32(p[P_DG]))
    return cnt


@njit(cache=True, fastmath=True, error_model="numpy", boundscheck=False)
def _mg_vec(v):
    out = np.empty_like(v)
    for i in range(v.shape[0]):
        out[i] = _mg(v[i])
    return out


# --------------------------------------------------------------------------- bookkeeping
@njit(cache=True, boundscheck=False)
def _collect(flag, ids, ring_idx, slot, ring_n, out_idx, out_t, n_out, stamp, sort):
    """Append the flagged neurons (flag/ids: a population's compact slice) to the ring slot and
    the step's output, 8 flags per word; with ``sort`` the appended block is put in index order."""
    m0 = m = ring_n[slot]
    o0 = n_out
    n = flag.shape[0]
    n8 = n // 8
    words = flag[: n8 * 8].view(np.uint64)
    for wi in range(n8):
        if words[wi] == 0:
            continue
        for i in range(wi * 8, wi * 8 + 8):
            if flag[i]:
                ring_idx[slot, m] = ids[i]
                m += 1
                out_idx[n_out] = ids[i]
                out_t[n_out] = stamp
                n_out += 1
    for i in range(n8 * 8, n):
        if flag[i]:
            ring_idx[slot, m] = ids[i]
            m += 1
            out_idx[n_out] = ids[i]
            out_t[n_out] = stamp
            n_out += 1
    if sort:  # few spikes per step: insertion sort
        for a in range(m0 + 1, m):
            v = ring_idx[slot, a]
            b = a - 1
            while b >= m0 and ring_idx[slot, b] > v:
                ring_idx[slot, b + 1] = ring_idx[slot, b]
                b -= 1
            ring_idx[slot, b + 1] = v
        for a in range(o0, n_out):
            out_idx[a] = ring_idx[slot, m0 + a - o0]
    ring_n[slot] = m
    return n_out


@njit(cache=True, boundscheck=False)
def _compact(lo, na, nrn, buf, full, gmax):
    """Drop the neurons at rest from the ``na`` listed neurons of the compact population
    starting at ``lo`` and put the others in global index order (the order of the list does not
    affect any result: every per-neuron operation is independent and collected spikes are sorted;
    index order makes the targets of one presynaptic neuron long runs, see :func:`_build_runs`).
    Only the list is read, never the whole population: each neuron that stays sets its bit (index - lo) in
    the bitmap ``buf.bits`` (zero on entry and left zero), which is then read in index order; a neuron's
    listed position is its ``slot`` until it is rewritten. ``full``: the population has NMDA/GABA conductances
    (moved too); a neuron at rest whose GABA conductance is in (0, gmax] leaves the list (a lazy-GABA
    population's ``g_gaba`` holds that conductance already). Returns the new count."""
    u, g, ref, cid, slot = nrn.u, nrn.g, nrn.ref, nrn.cid, nrn.slot
    sf, bits = buf.scr_f, buf.bits
    one = np.uint64(1)
    w_lo, w_hi = bits.shape[0], 0
    for k in range(lo, lo + na):
        i = cid[k]
        if full:
            if _at_rest(u[k], g[0, k], g[1, k], ref[k], g[2, k], gmax):
                slot[i] = -1
                continue
        elif u[k] == 0.0 and g[0, k] == 0.0 and ref[k] == 0.0:
            slot[i] = -1
            continue
        d = i - lo
        w = d >> 6
        bits[w] |= one << np.uint64(d & 63)
        w_lo = min(w_lo, w)
        w_hi = max(w_hi, w + 1)
    m = 0
    for w in range(w_lo, w_hi):
        x = bits[w]
        if x == 0:
            continue
        bits[w] = 0
        base = lo + (w << 6)
        while x != 0:
            i = base + np.int64(trailing_zeros(x))
            k = slot[i]
            sf[0, m] = u[k]
            sf[1, m] = g[0, k]
            sf[2, m] = ref[k]
            if full:
                sf[3, m] = g[1, k]
                sf[4, m] = g[2, k]
            cid[lo + m] = i
            slot[i] = lo + m
            m += 1
            x &= x - one
    u[lo : lo + m] = sf[0, :m]
    g[0, lo : lo + m] = sf[1, :m]
    ref[lo : lo + m] = sf[2, :m]
    if full:
        g[1, lo : lo + m] = sf[3, :m]
        g[2, lo : lo + m] = sf[4, :m]
    return m


@njit(cache=True, boundscheck=False)
def _build_runs(qa, qb, plo, pp, nrn, dl):
    """Positions in the compact list of population pp (starting at plo) of the targets
    sp_post[qa:qb] of one presynaptic neuron (activating the ones at rest), as runs of consecutive
    positions: c_k start position, c_q first synapse, c_l length, stored from qa on. Returns the
    number of runs. Valid until the population is compacted again (activation only appends; an activated
    neuron takes its GABA conductance from ``g_gaba``, 0 outside lazy-GABA populations)."""
    u, g, ref, cid, slot, n_act = nrn.u, nrn.g, nrn.ref, nrn.cid, nrn.slot, nrn.n_act
    sp_post, c_k, c_q, c_l = dl.sp_post, dl.c_k, dl.c_q, dl.c_l
    nr = 0
    prev = -2
    k0 = 0
    q0 = qa
    ln = 0
    na = n_act[pp]
    for q in range(qa, qb):
        i = sp_post[q]
        kq = slot[i]
        if kq < 0:
            kq = plo + na
            na += 1
            slot[i] = kq
            cid[kq] = i
            u[kq] = 0.0
            g[0, kq] = 0.0
            g[1, kq] = 0.0
            g[2, kq] = nrn.g_gaba[i]
            ref[kq] = 0.0
        if kq == prev + 1:
            ln += 1
        else:
            if ln > 0:
                c_k[qa + nr] = k0
                c_q[qa + nr] = q0
                c_l[qa + nr] = ln
                nr += 1
            k0 = kq
            q0 = q
            ln = 1
        prev = kq
    if ln > 0:
        c_k[qa + nr] = k0
        c_q[qa + nr] = q0
        c_l[qa + nr] = ln
        nr += 1
    n_act[pp] = na
    return nr


@njit(cache=True, fastmath=True, boundscheck=False)
def _ltd(plast, pl, w, n_post, n_col, t, buf):
    """LTD of rule pl for CF arrivals at time t on the PCs in buf.col_buf[:n_col]: every buffered
    PF arrival (t_pf, j) adds ltd * k(t - t_pf) to w[j, i] (w: the rule's [n_pre, n_post] block,
    flat), clipped at w_lo. The kernel values are first summed per PF (float64), so each touched
    weight is updated once (LTD terms are all <= 0, so clipping the sum equals clipping after every
    term)."""
    k_off, k_len = plast.pl_i[pl, 2], plast.pl_i[pl, 3]
    kern = plast.kern[k_off : k_off + k_len]
    pf_t, pf_j, pf_head = plast.pf_t[pl], plast.pf_j[pl], plast.pf_head[pl]
    lo_w, ltd = np.float32(plast.pl_f[pl, 2]), plast.pl_f[pl, 1]
    col, acc, acc_j = buf.col_buf, buf.acc, buf.acc_j
    dirty = plast.dirty[pl]
    cap = pf_t.shape[0]
    klen = kern.shape[0]
    h = pf_head
    stop = max(0, pf_head - cap)
    nj = 0
    while h > stop:
        h -= 1
        e = h % cap
        m = t - pf_t[e]
        if m >= klen:
            break
        kv = kern[m]
        if kv == 0.0:
            continue
        j = pf_j[e]
        if acc[j] == 0.0:
            acc_j[nj] = j
            nj += 1
        acc[j] += kv
    for a in range(nj):
        j = acc_j[a]
        dw = np.float32(ltd * acc[j])
        acc[j] = 0.0
        dirty[j] = 1
        base = j * n_post
        for q in range(n_col):
            k = base + col[q]
            x = w[k] + dw
            w[k] = x if x > lo_w else lo_w


@njit(cache=True, nogil=True, fastmath=True, error_model="numpy", boundscheck=False)
def run_step(t0, n_sub, inputs, learn, par, net, prof):
    """Advance the network (``net``: its :class:`KernelState`) by one control step of ``n_sub``
    substeps starting at substep t0.

    ``inputs`` are global indices of input fibres spiking at t0; ``learn``: plasticity on; ``par``:
    numba threads for the large populations; ``prof``: :data:`NO_PROF`, or a cost profile the step adds
    its parts' times to (:data:`PROF_PARTS`). Returns the number of spikes written to
    out_idx/out_t (out_t = substep 1..n_sub at whose end the spike happened).

    Sparse projections onto a compact population deliver through a per-presynaptic-neuron cache of
    the targets' compact positions (``_build_runs``; sp_c[off + j] = (epoch, runs), valid while
    the epoch equals pop_ep of the target population, which every compaction increments).
    GABA onto a lazy-GABA population (``Populations.lazy``) adds into ``g_gaba``, listing a neuron at rest only
    when the sum leaves [0, lazy] (it would then move from rest).
    """
    nrn, pops, dl, plast, buf = net.neurons, net.populations, net.delivery, net.plasticity, net.buffers
    lumps = net.lumps
    u, g, ref, flag, cid, slot = nrn.u, nrn.g, nrn.ref, nrn.flag, nrn.cid, nrn.slot
    n_act, n_rest, pop_ep = nrn.n_act, nrn.n_rest, nrn.pop_ep
    g_gaba = nrn.g_gaba
    pop_i, pop_par, pop_lazy = pops.pop_i, pops.pop_par, pops.lazy
    ring_idx, ring_n = dl.ring_idx, dl.ring_n
    sp_i, sp_ptr, sp_post, sp_w, sp_c = dl.sp_i, dl.sp_ptr, dl.sp_post, dl.sp_w, dl.sp_c
    c_k, c_q, c_l, de_i, dense_w = dl.c_k, dl.c_q, dl.c_l, dl.de_i, dl.dense_w
    pl_i, pl_f, pf_t, pf_j = plast.pl_i, plast.pl_f, plast.pf_t, plast.pf_j
    pf_head, pf_lost = plast.pf_head, plast.pf_lost
    col_buf, out_idx, out_t = buf.col_buf, buf.out_idx, buf.out_t
    R = ring_idx.shape[0]
    pb = pop_i.shape[0]  # the profile's first part (after the populations)
    tk = prof_now(prof)
    slot0 = t0 % R
    m = ring_n[slot0]
    for k in range(inputs.shape[0]):
        ring_idx[slot0, m] = inputs[k]
        m += 1
    ring_n[slot0] = m
    n_out = 0
    for s in range(n_sub):
        t = t0 + s
        tk = prof_lap(prof, pb + BOOKKEEPING, tk)
        run_rules(t, learn, net.learning, dl)  # before delivery: a synapse delivers its updated weight
        tk = prof_lap(prof, pb + PLASTICITY, tk)
        # sparse projections (CSR by presynaptic neuron); teaching ones carry no current
        for p in range(sp_i.shape[0]):
            if sp_i[p, S_TEACHING] != 0:
                continue
            pre_lo, n_pre, off = sp_i[p, S_PRE_LO], sp_i[p, S_N_PRE], sp_i[p, S_ROW]
            rec, delay, pp = sp_i[p, S_RECEPTOR], sp_i[p, S_DELAY], sp_i[p, S_POST_POP]
            ratio = pop_i[pp, I_RATIO]
            if t % ratio != 0:
                continue
            plo = pop_i[pp, I_LO]
            if lumps.proj[pp] == p:  # a lumped population: only the neurons whose input changed move
                if not lumping.in_window(t, delay, n_sub, ratio):
                    continue
                if lumping.arrival_window(lumps, pp, p, t, n_sub, ratio, dl, nrn, plo, pop_i[pp, I_HI]) == 0:
                    continue
            compact = pop_i[pp, I_COMPACT] != 0
            lazy = compact and rec == 2 and pop_lazy[pp] > 0.0
            gmax = np.float32(pop_lazy[pp])
            dec = pop_par[pp, P_D1A + rec]
            scale = 1.0
            for a in range(ratio):  # arrivals since the population's previous step boundary
                ta = t - a
                sc = np.float32(scale)
                scale *= dec
                if ta - delay < 0:
                    continue
                sl = (ta - delay) % R
                for k in range(ring_n[sl]):
                    j = ring_idx[sl, k] - pre_lo
                    if j < 0 or j >= n_pre:
                        continue
                    if lazy:
                        for q in range(sp_ptr[off + j], sp_ptr[off + j + 1]):
                            i = sp_post[q]
                            x = g_gaba[i] + sp_w[q] * sc
                            g_gaba[i] = x
                            if (x >= 0.0 and x <= gmax) or slot[i] >= 0:  # listed, or stays exactly at rest
                                continue
                            kq = plo + n_act[pp]
                            n_act[pp] += 1
                            slot[i] = kq
                            cid[kq] = i
                            u[kq] = 0.0
                            g[0, kq] = 0.0
                            g[1, kq] = 0.0
                            g[2, kq] = x
                            ref[kq] = 0.0
                        continue
                    if compact:
                        cj = off + j
                        qa = sp_ptr[cj]
                        if sp_c[cj, 0] != pop_ep[pp]:
                            sp_c[cj, 1] = _build_runs(qa, sp_ptr[cj + 1], plo, pp, nrn, dl)
                            sp_c[cj, 0] = pop_ep[pp]
                        gr = g[rec]
                        for r in range(qa, qa + sp_c[cj, 1]):
                            k0, q0, ln = c_k[r], c_q[r], c_l[r]
                            if ln >= RUN_MIN:  # (slices: the add loop vectorises)
                                gs, ws = gr[k0 : k0 + ln], sp_w[q0 : q0 + ln]
                                for m in range(ln):
                                    gs[m] += ws[m] * sc
                            else:
                                for m in range(ln):
                                    gr[k0 + m] += sp_w[q0 + m] * sc
                        continue
                    for q in range(sp_ptr[off + j], sp_ptr[off + j + 1]):
                        i = sp_post[q]
                        kq = slot[i]
                        if kq < 0:  # activate a resting neuron (written out: a helper call
                            kq = plo + n_act[pp]  # here costs refcount traffic per synapse)
                            n_act[pp] += 1
                            slot[i] = kq
                            cid[kq] = i
                            u[kq] = 0.0
                            g[0, kq] = 0.0
                            g[1, kq] = 0.0
                            g[2, kq] = g_gaba[i]
                            ref[kq] = 0.0
                        g[rec, kq] += sp_w[q] * sc
        # dense (all-to-all) projections: a spike adds its weight row; plastic rows get LTP
        for d in range(de_i.shape[0]):
            pre_lo, n_pre, post_lo, n_post = de_i[d, 0], de_i[d, 1], de_i[d, 2], de_i[d, 3]
            w_off, rec, delay, pl, pp = de_i[d, 4], de_i[d, 5], de_i[d, 6], de_i[d, 7], de_i[d, 8]
            ratio = pop_i[pp, I_RATIO]
            if t % ratio != 0:
                continue
            compact = pop_i[pp, I_COMPACT] != 0
            lazy = compact and rec == 2 and pop_lazy[pp] > 0.0  # GABA into g_gaba (global index order)
            dec = pop_par[pp, P_D1A + rec]
            scale = 1.0
            for a in range(ratio):
                ta = t - a
                sc = np.float32(scale)
                scale *= dec
                if ta - delay < 0:
                    continue
                sl = (ta - delay) % R
                for k in range(ring_n[sl]):
                    j = ring_idx[sl, k] - pre_lo
                    if j < 0 or j >= n_pre:
                        continue
                    row = w_off + j * n_post
                    if compact:
                        for q in range(n_post):
                            i = post_lo + q
                            kq = slot[i]
                            if kq < 0:
                                kq = post_lo + n_act[pp]
                                n_act[pp] += 1
                                slot[i] = kq
                                cid[kq] = i
                                u[kq] = 0.0
                                g[0, kq] = 0.0
                                g[1, kq] = 0.0
                                g[2, kq] = g_gaba[i]
                                ref[kq] = 0.0
                            if lazy:
                                g_gaba[i] += dense_w[row + q] * sc
                            else:
                                g[rec, kq] += dense_w[row + q] * sc
                    elif a == 0:  # (1D slices: these loops vectorise)
                        gs, ws = g[rec, post_lo : post_lo + n_post], dense_w[row : row + n_post]
                        for q in range(n_post):
                            gs[q] += ws[q]
                    else:
                        gs, ws = g[rec, post_lo : post_lo + n_post], dense_w[row : row + n_post]
                        for q in range(n_post):
                            gs[q] += ws[q] * sc
                    if pl >= 0:
                        tk = prof_lap(prof, pb + DELIVERY, tk)
                    if pl >= 0 and learn:
                        ltp, hi_w = np.float32(pl_f[pl, 0]), np.float32(pl_f[pl, 3])
                        ws = dense_w[row : row + n_post]
                        for q in range(n_post):
                            x = ws[q] + ltp
                            ws[q] = x if x < hi_w else hi_w
                        plast.dirty[pl, j] = 1
                    if pl >= 0:
                        cap = pf_t.shape[1]
                        e = pf_head[pl] % cap
                        if pf_head[pl] >= cap and t - pf_t[pl, e] < pl_i[pl, 3]:
                            pf_lost[pl] += 1
                        pf_t[pl, e] = ta
                        pf_j[pl, e] = j
                        pf_head[pl] += 1
                        tk = prof_lap(prof, pb + PLASTICITY, tk)
        tk = prof_lap(prof, pb + DELIVERY, tk)
        # LTD: teacher (CF) spikes arriving now at PCs of each plastic projection
        if learn:
            for pl in range(pl_i.shape[0]):
                d, tp = pl_i[pl, 0], pl_i[pl, 1]
                delay = sp_i[tp, S_DELAY]
                if t - delay < 0:
                    continue
                sl = (t - delay) % R
                pre_lo, n_pre, off = sp_i[tp, S_PRE_LO], sp_i[tp, S_N_PRE], sp_i[tp, S_ROW]
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
                    _ltd(plast, pl, dense_w[w_off : w_off + de_i[d, 1] * n_post], n_post, n_col, t, buf)
        tk = prof_lap(prof, pb + PLASTICITY, tk)
        # integrate the LIF populations whose step ends at t + 1; spikes are stamped t + 1
        nxt = (t + 1) % R
        ring_n[nxt] = 0
        for pi in range(pop_i.shape[0]):
            kind = pop_i[pi, I_KIND]
            if kind == KIND_INPUT or (t + 1) % pop_i[pi, I_RATIO] != 0:
                continue
            lo = pop_i[pi, I_LO]
            if lumps.proj[pi] >= 0:  # its classes, each one neuron's arithmetic for all its members
                nc = lumps.n_cls[pi]
                if nc == 0:
                    continue
                tk = prof_lap(prof, pb + BOOKKEEPING, tk)
                cnt, nr = _lif_poly(lumps.cu[lo : lo + nc], lumps.cg[lo : lo + nc], lumps.cref[lo : lo + nc],
                                    lumps.cflag[lo : lo + nc], pops, pi)
                tk = prof_lap(prof, pi, tk)
                if cnt > 0:
                    n_out = lumping.collect(lumps, pi, lo, ring_idx, nxt, ring_n, out_idx, out_t, n_out, s + 1)
                if nr > lumps.n_free[pi]:
                    lumping.dissolve(lumps, pi, lo, n_act)
                lumping.merge(lumps, pi, lo)
                if not lumping.worth_it(lumps.n_cls, lumps.n_free, pi, n_act):
                    lumping.release(lumps, pi, lo, pop_i[pi, I_HI], nrn)
                continue
            na = n_act[pi]
            if pop_lazy[pi] > 0.0:  # the listed neurons' GABA, then every neuron's decayed as the loop decays it
                gg = g[2]
                for k in range(lo, lo + na):
                    gg[k] = g_gaba[cid[k]]
                _decay(g_gaba[lo : pop_i[pi, I_HI]], np.float32(pop_par[pi, P_DG]))
            if na == 0:
                continue
            hi = lo + na
            pp = pop_par[pi]
            tk = prof_lap(prof, pb + BOOKKEEPING, tk)  # the spikes collected so far
            nf = pop_i[pi, I_NFINE]
            fused = (kind != KIND_LIF_AMPA and kind != KIND_ADEX and pop_i[pi, I_COMPACT] != 0 and pops.nmda[pi] == 0
                     and _fusable(int(pp[P_METHOD]), nf))
            if kind == KIND_LIF_AMPA:
                if par > 1 and na >= PAR_MIN:
                    cnt, nr = _lif_poly_par(u[lo:hi], g[0, lo:hi], ref[lo:hi], flag[lo:hi], pops, pi, par)
                else:
                    cnt, nr = _lif_poly(u[lo:hi], g[0, lo:hi], ref[lo:hi], flag[lo:hi], pops, pi)
                n_rest[pi] = nr
            elif kind == KIND_ADEX:
                cnt = _adex(u[lo:hi], nrn.w[lo:hi], g[0, lo:hi], g[2, lo:hi], ref[lo:hi], flag[lo:hi], pp,
                            pop_i[pi, I_NFINE])
            elif fused:
                gmax = np.float32(pop_lazy[pi])
                if par > 1 and na >= PAR_MIN:
                    cnt, nr = _lif_gaba_par(u[lo:hi], g[0, lo:hi], g[2, lo:hi], ref[lo:hi], flag[lo:hi], pp, nf,
                                            gmax, par)
                else:
                    cnt, nr = _lif_gaba(u[lo:hi], g[0, lo:hi], g[2, lo:hi], ref[lo:hi], flag[lo:hi], pp, nf, gmax)
                n_rest[pi] = nr
            elif pop_i[pi, I_NFINE] > 1 and pop_i[pi, I_COMPACT] != 0 and pops.nmda[pi] == 0:
                if par > 1 and na >= PAR_MIN:
                    cnt = _lif_full_listed_par(u[lo:hi], g[0, lo:hi], g[1, lo:hi], g[2, lo:hi], ref[lo:hi],
                                               flag[lo:hi], buf.scr_f[0, :na], pp, pop_i[pi, I_NFINE], par)
                else:
                    cnt = _lif_full_listed(u[lo:hi], g[0, lo:hi], g[1, lo:hi], g[2, lo:hi], ref[lo:hi], flag[lo:hi],
                                           buf.scr_f[0], pp, pop_i[pi, I_NFINE])
            elif pop_i[pi, I_NFINE] > 1:
                cnt = _lif_full_fine(u[lo:hi], g[0, lo:hi], g[1, lo:hi], g[2, lo:hi], ref[lo:hi], flag[lo:hi], pp,
                                     pop_i[pi, I_NFINE])
            else:
                cnt = _lif_full(u[lo:hi], g[0, lo:hi], g[1, lo:hi], g[2, lo:hi], ref[lo:hi], flag[lo:hi], pp)
            if kind != KIND_LIF_AMPA and pop_i[pi, I_COMPACT] != 0 and not fused:
                n_rest[pi] = _rest_full(u[lo:hi], g[0, lo:hi], g[1, lo:hi], g[2, lo:hi], ref[lo:hi],
                                        np.float32(pop_lazy[pi]))
            tk = prof_lap(prof, pi, tk)
            if cnt > 0:
                n_out = _collect(flag[lo:hi], cid[lo:hi], ring_idx, nxt, ring_n, out_idx, out_t, n_out,
                                 s + 1, pop_i[pi, I_COMPACT] != 0)
    # drop neurons that came back to rest (only worth a pass when enough of them did; until then
    # they are integrated as exact no-ops)
    for pi in range(pop_i.shape[0]):
        if pop_i[pi, I_COMPACT] != 0 and n_rest[pi] > 0 and COMPACT_FRACTION * n_rest[pi] >= n_act[pi]:
            n_act[pi] = _compact(pop_i[pi, I_LO], n_act[pi], nrn, buf, pop_i[pi, I_KIND] != KIND_LIF_AMPA,
                                 np.float32(pop_lazy[pi]))
            pop_ep[pi] += 1
            n_rest[pi] = 0
    prof_lap(prof, pb + BOOKKEEPING, tk)
    return n_out


@njit(cache=True, nogil=True, boundscheck=False)
def run_chunk(t0, n_sub, inputs, in_off, learn, par, net, chunk_idx, chunk_off, prof):
    """``len(in_off) - 1`` consecutive :func:`run_step` calls in one GIL-free call (a pipelined
    chunk runs without touching Python). Inputs of step s are inputs[in_off[s]:in_off[s + 1]];
    its spikes (global indices) end up in chunk_idx[chunk_off[s]:chunk_off[s + 1]] (the copy is
    the profile's bookkeeping)."""
    out_idx = net.buffers.out_idx
    total = 0
    chunk_off[0] = 0
    for s in range(in_off.shape[0] - 1):
        n = run_step(t0 + s * n_sub, n_sub, inputs[in_off[s]:in_off[s + 1]], learn, par, net, prof)
        tk = prof_now(prof)
        for i in range(n):
            chunk_idx[total + i] = out_idx[i]
        prof_lap(prof, net.populations.pop_i.shape[0] + BOOKKEEPING, tk)
        total += n
        chunk_off[s + 1] = total
    return total
