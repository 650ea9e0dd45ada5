"""A built spiking network with its state, advanced one 2 ms control step per call."""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass

import numba
import numpy as np

from cerebx.snn import kernels, learning, lumping
from cerebx.snn.learning import R_NPOST, R_POST_LO
from cerebx.snn.plasticity import HISTORY_MAX, TraceSpec
from cerebx.snn.schema import NetworkConfig
from cerebx.snn.topology import (
    I_COMPACT,
    I_RATIO,
    KIND_INPUT,
    KIND_LIF_AMPA,
    KIND_LIF_FULL,
    N_SPAR,
    P_EL,
    S_DELAY,
    S_N_PRE,
    S_POST_POP,
    S_PRE_LO,
    S_RECEPTOR,
    S_ROW,
    S_TEACHING,
    Topology,
    build_topology,
    fill_dense,
    integrators,
)
from cerebx.snn.weight_stats import Beside, RunCache, weight_stats

COMPACT_MIN = 4096  # lif_cond populations this large integrate only their non-resting neurons
PF_RING = 1 << 16  # buffered PF arrivals per plastic projection (must cover the kernel window)


@dataclass(frozen=True)
class StepSpikes:
    """Spikes of one control step: global neuron index and time in substeps from the step start
    (1..n_sub: the spike happened at the end of that substep)."""

    idx: np.ndarray
    sub: np.ndarray


def pack(inputs: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """The inputs of consecutive steps (global fibre indices per step) as one int32 array and the offsets of
    each step's part, what :meth:`Network.step_packed` takes."""
    n = len(inputs)
    flat = np.concatenate(inputs).astype(np.int32) if n else np.zeros(0, np.int32)
    in_off = np.zeros(n + 1, dtype=np.int64)
    in_off[1:] = np.cumsum([len(x) for x in inputs])
    return flat, in_off


_SCRATCH = ("col_buf", "acc", "acc_j", "out_idx", "out_t", "scr_f", "bits")
"""The kernels' scratch buffers: each is written before it is read (``acc`` is all zeros between calls)."""
_CACHES = ("c_k", "c_q", "c_l")
"""The sparse projections' delivery caches (``kernels._build_runs``), valid while ``sp_c``'s epoch is current."""
_LEFT_OUT = "cerebx.left-out"


SPARSE_STATE = ("sp_w", "sl_tr_v", "sl_tr_t", "sl_hs_t", "sl_hs_n", "sl_lost")
"""State of the sparse learning rules: the weights they write, their traces and spike histories."""


def _sparse_learning(topo: Topology) -> learning.SparseLearning:
    """The kernels' arrays of ``topo.sparse_rules`` (:mod:`cerebx.snn.learning`)."""
    rules = topo.sparse_rules
    if not rules:
        return learning.empty()
    L = learning
    base = np.concatenate([[0], np.cumsum([len(s.post) for s in topo.sparse])])
    sr_i = np.zeros((len(rules), L.N_RI), np.int64)
    sr_f = np.zeros((len(rules), L.N_RF))
    ptrs, qs, js, kerns = [], [], [], []
    rows = csc = k_off = n_q = 0
    teach_syn = 0
    for r, rule in enumerate(rules):
        s = topo.sparse[rule.piece]
        post_lo = int(topo.lo[topo.index[topo.cfg.projections[rule.proj].post]])
        n_post = len(rule.csc_ptr) - 1
        spec = rule.spec
        if isinstance(spec, TraceSpec):
            fam, klen = L.FAM_TRACE, 0
            sr_f[r, [L.R_LAM, L.R_ALPHA, L.R_MUP, L.R_MUM]] = spec.lam, spec.alpha, spec.mu_plus, spec.mu_minus
            sr_f[r, L.R_RATEP] = topo.dt_ms / spec.tau_plus_ms
            sr_f[r, L.R_RATEM] = topo.dt_ms / spec.tau_minus_ms
        else:
            fam, klen = L.FAM_PAIRING, max(len(spec.k_pre), len(spec.k_post))
            for table in (spec.k_pre, spec.k_post):
                kerns.append(np.pad(np.asarray(table, float), (0, klen - len(table))))
            sr_f[r, L.R_FIXED] = spec.fixed_nS
        t_lo, t_hi = rule.teachers
        teach_syn = max(teach_syn, sum(len(topo.sparse[k].post) for k in range(t_lo, t_hi)))
        pdelay = 2 * s.delay if isinstance(spec, TraceSpec) and spec.dendritic else 0
        sr_i[r] = (fam, rule.piece, t_lo, t_hi, post_lo, n_post, csc, k_off, klen, rows, rows + s.n_pre, pdelay)
        sr_f[r, L.R_WLO], sr_f[r, L.R_WHI] = rule.w_lo, rule.w_hi
        ptrs.append(rule.csc_ptr + n_q)
        qs.append(rule.csc_q + base[rule.piece])
        n_q += len(rule.csc_q)
        js.append(rule.csc_j)
        rows += s.n_pre + n_post
        csc += n_post + 1
        k_off += 2 * klen
    klen_max = int(sr_i[:, L.R_KLEN].max())
    H = max(1, min(klen_max, HISTORY_MAX))  # at most one spike per neuron and substep fits the window
    return L.SparseLearning(
        sr_i, sr_f, np.concatenate(ptrs), np.concatenate(qs), np.concatenate(js).astype(np.int64),
        np.concatenate(kerns) if kerns else np.zeros(1), np.zeros(rows), np.zeros(rows, np.int64),
        np.zeros((rows, H), np.int64), np.zeros(rows, np.int64), np.zeros(len(rules), np.int64),
        np.zeros(max(teach_syn, topo.n_neurons, 1), np.int64))


class Network:
    """Flat-array spiking network (see :mod:`cerebx.snn.kernels` for the numerics).

    ``parallel``: integrate the large populations with numba threads (omp); otherwise everything
    runs on the calling thread. ``compact_min``: AMPA-only populations at least this large keep
    only their non-resting neurons in the integration loop (exact; see kernels).
    ``seed``: the run's seed, which random connectors, weights and delays draw from (``snn/connectors.py``;
    networks without them do not depend on it).
    ``V``, ``g`` and ``ref`` are assembled from the kernel state on access (read-only views of
    the state; use :meth:`load_arrays` to set it). ``arrays`` groups the same array objects for the
    kernels (:class:`~cerebx.snn.kernels.NetworkArrays`, handed to them as one ``KernelState``):
    write into an array, never replace one.
    """

    STATE_KEYS = ("V", "g", "ref", "ring_idx", "ring_n", "pf_t", "pf_j", "pf_head", "pf_lost", "dense_w", "w")

    def __init__(self, cfg: NetworkConfig, parallel: bool = True, pf_ring: int = PF_RING,
                 compact_min: int = COMPACT_MIN, seed: int = 0, lumped: bool = True):
        t_start = time.perf_counter()
        self.cfg = cfg
        self.parallel = parallel
        # started even when serial: a cached run_chunk that was compiled in a process which took
        # run_step from the cache does not start numba's parallel runtime itself, and crashes
        # without it (numba issue 8578)
        threads = numba.get_num_threads()
        self.n_threads = threads if parallel else 1
        self.topo = topo = build_topology(cfg, fill=False, seed=seed)
        # the weights' first touch beside the rest of the set-up (mostly the kernels' loading, which holds the
        # interpreter lock that the fill lets go of): joined before anything reads them
        failed: list[BaseException] = []

        def fill() -> None:
            try:
                fill_dense(topo)
            except BaseException as err:  # raised here once joined: the weights would be left unwritten
                failed.append(err)

        filling = threading.Thread(target=fill, name="cerebx-weights", daemon=True)
        filling.start()
        try:
            self._set_up(cfg, topo, pf_ring, compact_min, lumped)
        finally:
            filling.join()
        if failed:
            raise failed[0]
        self.reset_state()
        self.build_s = time.perf_counter() - t_start

    def _set_up(self, cfg: NetworkConfig, topo: Topology, pf_ring: int, compact_min: int, lumped: bool) -> None:
        """Every array but the weights' values, and the kernels' handle on them."""
        self.n_sub = topo.n_sub
        self.fingerprint = cfg.fingerprint()
        n = topo.n_neurons
        self.u = np.zeros(n, dtype=np.float32)
        self._g = np.zeros((3, n), dtype=np.float32)
        self._ref = np.zeros(n, dtype=np.float32)
        self.w = np.zeros(n, dtype=np.float32)  # adex_cond adaptation currents (pA), global index order
        self.g_gaba = np.zeros(n, dtype=np.float32)  # GABA of lazy-GABA populations' neurons (kernels), by index
        self.flag = np.zeros(n, dtype=np.uint8)
        self.cid = np.arange(n, dtype=np.int32)
        self.slot = np.arange(n, dtype=np.int32)
        self.n_act = np.zeros(len(topo.names), dtype=np.int64)
        self.n_rest = np.zeros(len(topo.names), dtype=np.int64)
        R = topo.max_delay + int(topo.ipar[:, I_RATIO].max()) + 1
        self.ring_idx = np.zeros((R, n), dtype=np.int32)
        self.ring_n = np.zeros(R, dtype=np.int64)

        self.pop_lo, self.pop_hi, self.pop_kind = topo.lo, topo.hi, topo.kind
        self.pop_par = topo.par
        self.pop_i = topo.ipar.copy()
        sizes = self.pop_hi - self.pop_lo
        listed = (topo.kind == KIND_LIF_AMPA) | (topo.kind == KIND_LIF_FULL)
        self.pop_i[:, I_COMPACT] = listed & (sizes >= compact_min)
        self.pop_lazy = np.where(self.pop_i[:, I_COMPACT] != 0, topo.lazy_gaba, 0.0)
        self.pop_nmda = topo.nmda_in.copy()
        self.poly = topo.poly
        self.el = np.repeat(topo.par[:, P_EL], sizes).astype(np.float32)
        sp = topo.sparse
        ptr_parts, off = [], 0
        sp_i = np.zeros((len(sp), N_SPAR), dtype=np.int64)
        syn_base = 0
        pop_of = {int(lo): k for k, lo in enumerate(self.pop_lo)}
        for k, s in enumerate(sp):
            post_pop = int(np.searchsorted(self.pop_hi, s.post[0], side="right")) if len(s.post) else 0
            row = sp_i[k]
            row[S_PRE_LO], row[S_N_PRE], row[S_ROW], row[S_RECEPTOR] = s.pre_lo, s.n_pre, off, s.receptor
            row[S_DELAY], row[S_TEACHING], row[S_POST_POP] = s.delay, int(s.teaching), post_pop
            ptr_parts.append(s.ptr + syn_base)
            off += len(s.ptr)
            syn_base += len(s.post)
        self.sp_i = sp_i
        self.sp_ptr = np.concatenate(ptr_parts) if sp else np.zeros(1, np.int64)
        self.sp_post = np.concatenate([s.post for s in sp]) if sp else np.zeros(0, np.int32)
        self.sp_w = np.concatenate([s.w for s in sp]) if sp else np.zeros(0, np.float32)
        self.de_i = np.array(
            [(d.pre_lo, d.n_pre, d.post_lo, d.n_post, d.w_off, d.receptor, d.delay, d.plastic,
              pop_of[d.post_lo]) for d in topo.dense], dtype=np.int64).reshape(-1, 9)
        self.dense_w = topo.dense_w
        pl = topo.plastic
        k_off = np.cumsum([0] + [len(r.kernel) for r in pl])
        self.pl_i = np.array([(r.dense, r.teacher, k_off[i], len(r.kernel)) for i, r in enumerate(pl)],
                             dtype=np.int64).reshape(-1, 4)
        self.pl_f = np.array([(r.ltp, r.ltd, r.w_lo, r.w_hi) for r in pl], dtype=np.float64).reshape(-1, 4)
        self.kern = np.concatenate([r.kernel for r in pl]) if pl else np.zeros(1, np.float32)
        longest = max([len(r.kernel) for r in pl] + [1])
        self.pf_t = np.zeros((len(pl), pf_ring), dtype=np.int64)
        self.pf_j = np.zeros((len(pl), pf_ring), dtype=np.int32)
        self.pf_head = np.zeros(len(pl), dtype=np.int64)
        self.pf_lost = np.zeros(len(pl), dtype=np.int64)
        n_pre = [int(self.de_i[r.dense, 1]) for r in pl]
        self.pl_dirty = np.zeros((len(pl), max(n_pre + [1])), dtype=np.uint8)
        # rows the kernels marked that a checkpoint took from pl_dirty since the last weight statistics
        self._stats_dirty = np.zeros_like(self.pl_dirty)
        self._stats_cache: dict[str, RunCache] = {}
        self.kernel_window_sub = longest
        self.col_buf = np.zeros(n, dtype=np.int64)
        self.acc = np.zeros(n, dtype=np.float64)
        self.acc_j = np.zeros(n, dtype=np.int64)
        self.out_idx = np.zeros(n * self.n_sub, dtype=np.int32)
        self.out_t = np.zeros(n * self.n_sub, dtype=np.int32)
        # delivery caches of sparse projections onto compact populations (see kernels.run_step)
        self.sp_c = np.zeros((len(self.sp_ptr), 2), dtype=np.int64)
        nsyn = len(self.sp_post)
        self.c_k = np.zeros(nsyn, dtype=np.int64)
        self.c_q = np.zeros(nsyn, dtype=np.int64)
        self.c_l = np.zeros(nsyn, dtype=np.int64)
        self.pop_ep = np.ones(len(topo.names), dtype=np.int64)
        self.scr_f = np.zeros((5, n), dtype=np.float32)
        self.bits = np.zeros(n // 64 + 2, dtype=np.uint64)
        self.sl = _sparse_learning(topo)
        if lumped:  # populations stepped as classes of equal neurons (snn/lumping.py; the same results)
            rules = [(int(r[R_POST_LO]), int(r[R_NPOST])) for r in self.sl.sr_i]
            proj, w = lumping.eligible(self.pop_i, self.pop_lazy, self.pop_nmda, sp, sp_i, self.de_i, rules,
                                       self.n_sub)
        else:
            proj, w = np.full(len(topo.names), -1, np.int64), np.zeros(len(topo.names), np.float32)
        self.lp = lumping.build(n, proj, w, self.pop_i)
        self.learn = True
        self.t_sub = 0
        self._all_changed = True  # every weight counts as changed until the first changed_ranges()
        self.arrays = self._kernel_arrays()
        self._state = kernels.kernel_state(self.arrays)
        self.prof: np.ndarray | None = None

    def _kernel_arrays(self) -> kernels.NetworkArrays:
        """The kernels' view of this network: the same array objects, grouped (state is only ever
        written in place, so it stays valid for the network's life)."""
        return kernels.NetworkArrays(
            neurons=kernels.Neurons(self.u, self._g, self._ref, self.flag, self.cid, self.slot, self.n_act,
                                    self.n_rest, self.pop_ep, self.w, self.g_gaba),
            populations=kernels.Populations(self.pop_i, self.pop_par, self.poly, self.pop_lazy, self.pop_nmda),
            delivery=kernels.Delivery(self.ring_idx, self.ring_n, self.sp_i, self.sp_ptr, self.sp_post, self.sp_w,
                                      self.sp_c, self.c_k, self.c_q, self.c_l, self.de_i, self.dense_w),
            plasticity=kernels.Plasticity(self.pl_i, self.pl_f, self.kern, self.pf_t, self.pf_j, self.pf_head,
                                          self.pf_lost, self.pl_dirty),
            buffers=kernels.Buffers(self.col_buf, self.acc, self.acc_j, self.out_idx, self.out_t, self.scr_f,
                                    self.bits),
            learning=self.sl if len(self.sl.sr_i) else learning.NO_LEARNING,
            lumps=self.lp,
        )

    # ------------------------------------------------------------------ state
    def _set_neurons(self, V: np.ndarray, g: np.ndarray, ref: np.ndarray) -> None:
        """Kernel state from full per-neuron arrays: compact populations keep their non-resting
        neurons, in index order; a neuron at rest but for a GABA conductance it may hold unlisted
        (``pop_lazy``) is left out of the list; such a population's GABA conductances are all in ``g_gaba``."""
        n = len(self.u)
        self.g_gaba[:] = 0
        self.u[:] = (V - self.el).astype(np.float32)
        self._g[:] = g
        self._ref[:] = ref
        self.cid[:] = np.arange(n, dtype=np.int32)
        self.slot[:] = self.cid
        self.n_rest[:] = 0
        self.sp_c[:, 0] = 0  # the compact lists are rebuilt: delivery caches are stale
        for pi in range(len(self.pop_lo)):
            lo, hi = int(self.pop_lo[pi]), int(self.pop_hi[pi])
            self.n_act[pi] = 0 if self.pop_kind[pi] == KIND_INPUT else hi - lo
            if not self.pop_i[pi, I_COMPACT]:
                continue
            u, gg, r = self.u[lo:hi].copy(), self._g[:, lo:hi].copy(), self._ref[lo:hi].copy()
            gmax = np.float32(self.pop_lazy[pi])
            kept = (gg[2] > 0) & (gg[2] <= gmax) & (u == 0) & (gg[:2] == 0).all(axis=0) & (r == 0)
            live = np.flatnonzero(((u != 0) | (gg != 0).any(axis=0) | (r != 0)) & ~kept)
            if gmax > 0:
                self.g_gaba[lo:hi] = gg[2]
            na = len(live)
            self.n_act[pi] = na
            self.slot[lo:hi] = -1
            self.slot[lo + live] = lo + np.arange(na, dtype=np.int32)
            self.cid[lo : lo + na] = lo + live
            self.u[lo : lo + na], self._g[:, lo : lo + na] = u[live], gg[:, live]
            self._ref[lo : lo + na] = r[live]
            self.u[lo + na : hi], self._g[:, lo + na : hi], self._ref[lo + na : hi] = 0, 0, 0
        self._lump()

    @property
    def lumped(self) -> list[str]:
        """The populations stepped as classes of neurons with equal state and input (:mod:`cerebx.snn.lumping`)."""
        return [self.topo.names[pi] for pi in np.flatnonzero(self.lp.proj >= 0)]

    def _lump(self) -> None:
        """The lumped populations' classes from their compact lists."""
        for pi in np.flatnonzero(self.lp.proj >= 0):
            k = int(self.lp.proj[pi])
            lumping.lump(self.lp, int(pi), int(self.pop_lo[pi]), int(self.pop_hi[pi]),
                         (int(self.sp_i[k, S_PRE_LO]), int(self.sp_i[k, S_N_PRE])), self.arrays.neurons)

    def _unlump(self) -> None:
        """The lumped populations' compact lists written from their classes (the state Python reads)."""
        for pi in np.flatnonzero(self.lp.proj >= 0):
            lumping.unlump(self.lp, int(pi), int(self.pop_lo[pi]), int(self.pop_hi[pi]), self.arrays.neurons)

    def _neurons(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Full per-neuron (V, g, ref) assembled from the kernel state."""
        self._unlump()
        V, g, ref = self.el.copy(), np.zeros_like(self._g), np.zeros_like(self._ref)
        for pi in range(len(self.pop_lo)):
            lo = int(self.pop_lo[pi])
            na = int(self.n_act[pi])
            idx = self.cid[lo : lo + na]
            V[idx] = self.el[idx] + self.u[lo : lo + na]
            g[:, idx] = self._g[:, lo : lo + na]
            ref[idx] = self._ref[lo : lo + na]
            if self.pop_lazy[pi] > 0:  # every neuron's GABA (the listed ones' g[2] is a copy taken each step)
                g[2, lo : int(self.pop_hi[pi])] = self.g_gaba[lo : int(self.pop_hi[pi])]
        return V, g, ref

    @property
    def V(self) -> np.ndarray:
        return self._neurons()[0]

    @property
    def g(self) -> np.ndarray:
        return self._neurons()[1]

    @property
    def ref(self) -> np.ndarray:
        return self._neurons()[2]

    def reset_state(self) -> None:
        """Neurons at rest, no conductances, nothing in flight; weights are kept."""
        self.t_sub = 0
        self._set_neurons(self.el, np.zeros_like(self._g), np.zeros_like(self._ref))
        self.w[:] = 0
        self.ring_n[:] = 0
        self.pf_head[:] = 0
        self.pf_lost[:] = 0
        self.sl.tr_v[:], self.sl.tr_t[:], self.sl.hs_n[:], self.sl.lost[:] = 0, 0, 0, 0
        self.t_sub = 0

    @property
    def state_keys(self) -> tuple[str, ...]:
        """:attr:`STATE_KEYS`, and with sparse learning rules their weights, traces and histories."""
        return self.STATE_KEYS + (SPARSE_STATE if len(self.sl.sr_i) else ())

    def state_arrays(self) -> dict[str, np.ndarray]:
        V, g, ref = self._neurons()
        d = {"V": V, "g": g, "ref": ref}
        d.update({k: self._state_array(k) for k in self.state_keys if k not in d})
        d["t_sub"] = np.array(self.t_sub, dtype=np.int64)
        return d

    def load_arrays(self, arrays: dict[str, np.ndarray]) -> None:
        """Set the state from :meth:`state_arrays`' output (one saved before the adaptation currents ``w`` were
        kept comes from a network without adex_cond populations: its ``w`` is all zeros)."""
        if "w" not in arrays:
            arrays = {**arrays, "w": np.zeros_like(self.w)}
        cur = self.state_arrays()
        for k in self.state_keys:
            if k not in arrays:
                raise ValueError(f"state array {k}: missing from the saved state")
            dst, src = cur[k], arrays[k]
            if src.shape != dst.shape or src.dtype != dst.dtype:
                raise ValueError(f"state array {k}: saved {src.shape} {src.dtype}, "
                                 f"network needs {dst.shape} {dst.dtype}")
        for k in self.state_keys:
            if k not in ("V", "g", "ref"):
                self._state_array(k)[...] = arrays[k]
        self.t_sub = int(arrays["t_sub"])
        self._set_neurons(arrays["V"], arrays["g"], arrays["ref"])
        self._all_changed = True
        self._stats_cache = {}

    def changed_ranges(self) -> list[tuple[np.ndarray, np.ndarray, int]]:
        """The weights written since the last call, as (array, start offsets, length) ranges: the rows of
        the plastic projections the kernels marked (LTP, LTD), or all of ``dense_w`` after a load. Lets a
        checkpoint rewrite only those (``persistence/checkpoint.py``); the call starts a new interval.

        With sparse learning rules, their weights (``sp_w``) are reported whole every time. The arrays the network
        never writes after its build (:meth:`_fixed`) are reported too, whole after a load and with no range
        since: a checkpoint then keeps them in its arrays file, written once per process, instead of in every
        pickle (4.1 of the full network's 9.2 MB)."""
        fixed = [a for a in self._fixed() if a.size]
        np.bitwise_or(self._stats_dirty, self.pl_dirty, out=self._stats_dirty)
        if self._all_changed:
            self._all_changed = False
            self.pl_dirty[:] = 0
            whole = np.zeros(1, np.int64)
            learned = [(self.sp_w, whole, self.sp_w.size)] if len(self.sl.sr_i) else []
            return [(self.dense_w, whole, self.dense_w.size), *learned, *((a, whole, a.size) for a in fixed)]
        out = [(self.sp_w, np.zeros(1, np.int64), self.sp_w.size)] if len(self.sl.sr_i) else []
        for r, d in enumerate(self.pl_i[:, 0]):
            n_pre, n_post, w_off = (int(x) for x in self.de_i[d, [1, 3, 4]])
            rows = np.flatnonzero(self.pl_dirty[r, :n_pre])
            out.append((self.dense_w, w_off + rows.astype(np.int64) * n_post, n_post))
        self.pl_dirty[:] = 0
        none = np.zeros(0, np.int64)
        return out + [(a, none, a.size) for a in fixed]

    def _fixed(self) -> list[np.ndarray]:
        """The arrays no kernel or method writes once the network is built: the sparse projections' tables
        (the network's and the topology's own) and the resting potentials."""
        arrays = [self.sp_ptr, self.sp_post, self.el] + ([] if len(self.sl.sr_i) else [self.sp_w])
        for s in self.topo.sparse:
            arrays += [s.ptr, s.post, s.w]
        return arrays

    def __getstate__(self) -> dict:
        """The state without what a checkpoint need not keep (~10 MB of the full network's ~20 MB pickle,
        which the loop's thread pickles while the network waits): the kernels' scratch buffers (written before
        they are read; ``acc`` is all zeros between calls) and the sparse delivery caches (rebuilt on first
        use), each left as its dtype and shape; the kernels' handles on the arrays are made again too."""
        self._unlump()  # the lumped populations' state in their compact lists; the classes are rebuilt from them
        state = self.__dict__.copy()
        state["lp"] = (_LEFT_OUT, self.lp.proj, self.lp.w)
        state.pop("_chunk_idx", None)  # step_many's output scratch (rebuilt on use)
        state["_stats_cache"] = {}  # the weight statistics' first pass is read whole after a load
        state.pop("arrays", None)
        state.pop("_state", None)
        state["prof"] = None  # a cost profile belongs to the process that timed it
        for name in _SCRATCH + _CACHES:
            a = state[name]
            state[name] = (_LEFT_OUT, a.dtype.str, a.shape)
        return state

    def __setstate__(self, state: dict) -> None:
        """A state of :meth:`__getstate__`, or of earlier code (every array in it, and the kernels' handles)."""
        numba.get_num_threads()  # numba's parallel runtime started, as __init__ does (a process that only loads a
        # pickled network crashed on the network thread's first chunk otherwise: numba issue 8578)
        state = dict(state)
        stale = False
        for name in _SCRATCH + _CACHES:
            v = state.get(name)
            if isinstance(v, tuple) and v and v[0] == _LEFT_OUT:
                state[name] = np.zeros(v[2], np.dtype(v[1]))
                stale = stale or name in _CACHES
        self.__dict__.update(state)
        if "w" not in state:  # pickled before adex_cond (no adaptation currents)
            self.w = np.zeros_like(self._ref)
        if "sl" not in state:  # pickled before sparse learning rules existed
            self.sl = learning.empty()
        if "_stats_dirty" not in state:  # pickled by earlier code
            self._stats_dirty, self._stats_cache = np.zeros_like(self.pl_dirty), {}
        if "pop_lazy" not in state:  # pickled before lazy GABA: its populations keep the lists they had
            self.pop_lazy = np.zeros(len(self.pop_lo))
            self.pop_nmda = np.ones(len(self.pop_lo), np.uint8)
        if "g_gaba" not in state:  # pickled when the listed neurons' GABA lived in g[2] only, the others' in g_rest
            g_rest = self.__dict__.pop("g_rest", None)
            self.g_gaba = np.zeros_like(self._ref) if g_rest is None else g_rest
            for pi in np.flatnonzero(self.pop_lazy > 0):
                lo, na = int(self.pop_lo[pi]), int(self.n_act[pi])
                self.g_gaba[self.cid[lo : lo + na]] = self._g[2, lo : lo + na]
        self.__dict__.pop("scr_i", None)  # the compaction's sort keys, pickled before it read a bitmap instead
        if "bits" not in state:  # pickled before the compaction's bitmap
            self.bits = np.zeros(len(self._ref) // 64 + 2, dtype=np.uint64)
        if self.scr_f.shape[0] < 5:  # its compaction scratch had 3 rows
            self.scr_f = np.zeros((5, self.scr_f.shape[1]), np.float32)
        self.prof = None
        lp = state.get("lp")
        # by __getstate__: the classes are rebuilt from the compact lists (below); pickled whole (its __dict__), the
        # classes are the state as they are
        relump = isinstance(lp, tuple) and not isinstance(lp, lumping.Lumps) and bool(lp) and lp[0] == _LEFT_OUT
        if relump:
            self.lp = lumping.build(len(self._ref), lp[1], lp[2], self.pop_i)
        elif not isinstance(lp, lumping.Lumps):  # pickled before lumped populations: none is lumped
            self.lp = lumping.empty(len(self._ref), len(self.pop_lo))
        if stale:
            self.sp_c[:, 0] = 0  # no cache is valid (epochs start at 1): each is rebuilt when first used
        self.arrays = self._kernel_arrays()
        self._state = kernels.kernel_state(self.arrays)
        if relump:
            self._lump()

    def _state_array(self, key: str) -> np.ndarray:
        return getattr(self.sl, key[3:]) if key.startswith("sl_") else getattr(self, key)

    # ------------------------------------------------------------------ access
    @property
    def built_synapses(self) -> dict[str, int]:
        """Synapses built per projection (differs from the declared count only for random connectors)."""
        return dict(self.topo.built)

    @property
    def pairing_lost(self) -> int:
        """Spikes the pairing rules' histories dropped while still inside their kernel window."""
        return int(self.sl.lost.sum())

    def sparse_weights(self, projection: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(pre, post, weight) of every synapse of a sparse projection (local indices; a view of nothing: copies)."""
        pre, post, w = [], [], []
        base = np.concatenate([[0], np.cumsum([len(s.post) for s in self.topo.sparse])])
        for k, s in enumerate(self.topo.sparse):
            if s.name != projection:
                continue
            pre.append(np.repeat(np.arange(s.n_pre), np.diff(s.ptr)))
            post.append(s.post - self.index(self.cfg.projections[projection].post).start)
            w.append(self.sp_w[base[k] : base[k + 1]].copy())
        if not pre:
            raise KeyError(f"{projection!r} is not a sparse projection")
        return np.concatenate(pre), np.concatenate(post), np.concatenate(w)

    def index(self, pop: str) -> slice:
        return self.topo.slice(pop)

    def weights(self, projection: str) -> np.ndarray:
        """Weights of an all-to-all projection as a [n_pre, n_post] view (float32, nS). Set weights with
        :meth:`load_arrays` once a run has checkpointed: checkpoints rewrite only the rows the kernels
        marked as changed (:meth:`changed_ranges`)."""
        for d in self.topo.dense:
            if d.name == projection:
                return self.topo.dense_block(d)
        raise KeyError(f"{projection!r} is not an all-to-all projection")

    def weight_stats(self, projection: str, beside: Beside | None = None) -> tuple[float, float, float, float]:
        """(mean, std, min, max) of a plastic projection's weights (:func:`~cerebx.snn.weight_stats.weight_stats`):
        its first pass reads again only the runs of the rows the kernels wrote since the last call (the rows they
        mark for checkpoints), the rest from that call; after a load, all. Weights written through
        :meth:`weights` are not seen: set them with :meth:`load_arrays`."""
        r = self.plastic_projections.index(projection)
        n_pre, n_post = (int(x) for x in self.de_i[self.pl_i[r, 0], [1, 3]])
        w = self.weights(projection)
        cache = self._stats_cache.get(projection)
        if cache is None or cache.bufsize != np.getbufsize():
            cache = self._stats_cache[projection] = RunCache(w.size, np.getbufsize())
        rows = np.flatnonzero(self._stats_dirty[r, :n_pre] | self.pl_dirty[r, :n_pre])
        self._stats_dirty[r] = 0
        return weight_stats(w, beside, cache, cache.runs_of(rows * n_post, n_post))

    def integrators(self) -> dict[str, dict]:
        """The integrator each neuron population uses (:func:`~cerebx.snn.topology.integrators`); a lumped
        population (:attr:`lumped`) says so with ``lumped: true`` (the same arithmetic, once per class of equal
        neurons)."""
        out = integrators(self.topo)
        for name in self.lumped:
            out[name]["lumped"] = True
        return out

    @property
    def plastic_projections(self) -> list[str]:
        return [r.proj for r in self.topo.plastic]

    @property
    def n_neurons(self) -> int:
        return self.cfg.n_neurons

    @property
    def n_synapses(self) -> int:
        return self.cfg.n_synapses

    @property
    def n_plastic(self) -> int:
        return self.cfg.n_plastic

    # ------------------------------------------------------------------ run
    def step_many(self, inputs: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        """Several consecutive steps in one GIL-free call. Returns (spike indices, offsets): the
        spikes of step s are ``idx[off[s]:off[s + 1]]`` (same spikes as calling :meth:`step`)."""
        return self.step_packed(*pack(inputs))

    def step_packed(self, flat: np.ndarray, in_off: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`step_many` of inputs already packed (:func:`pack`)."""
        n = len(in_off) - 1
        idx, off = self.chunk_buffers(n)
        total = kernels.run_chunk(self.t_sub, self.n_sub, flat, in_off, self.learn, self.n_threads, self._state,
                                  idx, off, self.kernel_prof)
        self.t_sub += self.n_sub * n
        return idx[:total].copy(), off

    def start_profile(self) -> None:
        """Time the kernels' parts from now on (:data:`~cerebx.snn.kernels.PROF_PARTS`; ``cerebx bench``), until
        ``prof`` is set to None. Profiled and unprofiled steps run the same compiled code, with the same results;
        unprofiled, its timing calls read no clock."""
        self.prof = np.zeros(len(self.topo.names) + len(kernels.PROF_PARTS), dtype=np.int64)

    @property
    def kernel_prof(self) -> np.ndarray:
        """``prof`` as the step kernels take it: the profile, or :data:`~cerebx.snn.kernels.NO_PROF`."""
        return kernels.NO_PROF if self.prof is None else self.prof

    def profile(self) -> dict[str, float]:
        """Seconds per part since :meth:`start_profile`: ``integrate.<population>`` for each population integrated,
        then each of :data:`~cerebx.snn.kernels.PROF_PARTS` (empty when not profiling)."""
        if self.prof is None:
            return {}
        n = len(self.topo.names)
        out = {f"integrate.{name}": float(self.prof[i]) * 1e-9 for i, name in enumerate(self.topo.names)
               if self.topo.kind[i] != KIND_INPUT}
        out.update({part: float(self.prof[n + k]) * 1e-9 for k, part in enumerate(kernels.PROF_PARTS)})
        return out

    def chunk_buffers(self, n: int) -> tuple[np.ndarray, np.ndarray]:
        """The spike buffer and the step offsets :func:`~cerebx.snn.kernels.run_chunk` fills for ``n`` steps (the
        buffer is reused: its spikes hold until the next chunk). A caller that runs the kernel itself, inside
        compiled code of its own, takes its arguments from here and advances ``t_sub`` by ``n_sub * n``."""
        cap = n * self.out_idx.shape[0]
        if getattr(self, "_chunk_idx", None) is None or self._chunk_idx.shape[0] < cap:
            self._chunk_idx = np.zeros(cap, dtype=np.int32)
        return self._chunk_idx, np.zeros(n + 1, dtype=np.int64)

    def step(self, inputs: np.ndarray) -> StepSpikes:
        """One 2 ms step; ``inputs`` are global indices of input fibres spiking at its start
        (each fibre at most once)."""
        inputs = np.ascontiguousarray(inputs, dtype=np.int32)
        n = kernels.run_step(self.t_sub, self.n_sub, inputs, self.learn, self.n_threads, self._state,
                             self.kernel_prof)
        self.t_sub += self.n_sub
        return StepSpikes(self.out_idx[:n], self.out_t[:n])
