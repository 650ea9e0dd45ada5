"""The cerebellar spiking-network torque controller (docs/models.md#network).

Pathway delay model (docs/models.md#pathway-delay; the original's spike time stamps:
docs/provenance.md#original-spike-timestamps): the original stamps MF/CF spikes with the
sample time + D and the DCN output with the network time + D. Here both are FIFOs of
round(D / 2 ms) control steps: spikes encoded from the sample of step n enter the network at step
n + k (afferent), and the torque the network decodes at step m is returned at step m + k
(efferent), stamped with the step's own time. The CF error pairs the measured state with the
desired state of the same sample time (the sensor message's stamp). ``cf_pathway_delay_ms`` gives
the CF spikes their own afferent delay (the [B] setup shifted CF spikes by 40 ms and MF spikes by
50 ms): the shared input FIFO is as long as the shorter of the two, and the longer one's spikes
wait the difference in a FIFO of their own first.

Pipelining: because the network's output is not needed until k steps after its input exists,
the network can run ahead on a second thread, one chunk of k steps at a time, while the loop
steps the plant and records (``pipeline: true``). The network sees the same inputs in the same
order, so the results are identical to the synchronous order; only the wall time changes.

Output (``output``): a joint torque (Eq. 3.5), or for a muscle stage the agonist and antagonist
sides apart as ``muscle.ag``/``muscle.at`` = spikes of the side in the step / ``spikes_full_scale``
The teaching signal is the joint error either way.
"""

from __future__ import annotations

import copy
import hashlib
import json
import queue
import threading
import time
import weakref
from collections import deque
from collections.abc import Mapping
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
from numba import njit

from cerebx import phase_clock, registry
from cerebx.builders import BuildContext
from cerebx.controllers.base import CommandMsg, ControlInput, Controller, TorqueMsg
from cerebx.controllers.ranges import mf_ranges
from cerebx.controllers.snn.schema import SNNController
from cerebx.errors import StateMismatchError
from cerebx.persistence.state import load_state_npz, save_state_npz
from cerebx.recording.spike_chunks import chunk_spike_messages
from cerebx.signals import Deferred
from cerebx.snn.decoder import DCNDecoder, chunk_select, chunk_sides, chunk_torques
from cerebx.snn.encoders import AfferentRing, EncoderPair, compose_steps, encode_ticks
from cerebx.snn.kernels import OUTPUTS, _clock_ns, prof_lap, prof_now, run_chunk
from cerebx.snn.network import Network, pack
from cerebx.snn.schema import layout_problem
from cerebx.snn.sync import _load_acquire, _sleep_us, _store_release, _thread_cpu_ns, load_acquire, store_release
from cerebx.vectors import vector_bits

STEP_S = 0.002
STATE_VERSION = 1
_NONE = np.zeros(0, np.int64)  # no population recorded


def encoder_ranges(cfg: SNNController, n_joints: int, task: Any = None) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi) of shape (n_joints, 4) for the MF signals q_d, q, qd_d, qd."""
    return mf_ranges(cfg.mf.ranges, n_joints, task)


class Chunk(NamedTuple):
    """A simulated chunk: its first step; per step the output (a torque or [M_ag, M_at]) and the DCN spike
    count; the recorded populations' spikes as encoded messages (32-bit words) and the byte where each starts
    (:func:`~cerebx.recording.spike_chunks.chunk_spike_messages`), None when none are recorded; the PF spikes
    the LTD buffers dropped so far, after the chunk."""

    first: int
    out: np.ndarray
    counts: np.ndarray
    spikes: np.ndarray | None
    starts: np.ndarray | None
    lost: int


@njit(cache=True, nogil=True, boundscheck=False)
def _chunk_outputs(idx, off, decode, record, first, step_s):  # pragma: no cover
    """A chunk's torques and DCN counts (:func:`~cerebx.snn.decoder.chunk_torques`) and its recorded spikes'
    messages (:func:`~cerebx.snn.decoder.chunk_select`,
    :func:`~cerebx.recording.spike_chunks.chunk_spike_messages`) in one call: each return from compiled code
    waits for the interpreter lock, which the loop's thread holds but for its MuJoCo steps. ``decode``: the
    DCN's first and end index, per_joint, sign and alpha of the decoder, whether the output is the muscles'
    sides (:func:`~cerebx.snn.decoder.chunk_sides`) with their full scale per joint and saturation;
    ``record``: the recorded neurons' (lo, hi) ranges."""
    lo, hi, per_joint, sign, alpha, sides, full_scale, saturate = decode
    rec_lo, rec_hi = record
    if sides:
        taus, counts = chunk_sides(idx, off, lo, hi, per_joint, full_scale, saturate)
    else:
        taus, counts = chunk_torques(idx, off, lo, hi, per_joint, sign, alpha)
    local, ends = chunk_select(idx, off, rec_lo, rec_hi)
    words, starts = chunk_spike_messages(local, ends, first, step_s)
    return taus, counts, words, starts


@njit(cache=True, nogil=True, boundscheck=False)
def _run_chunk_outputs(net, clock, chunk, outputs, prof):  # pragma: no cover
    """A whole chunk on the network thread in one compiled call: the network's steps
    (:func:`~cerebx.snn.kernels.run_chunk`), then :func:`_chunk_outputs`, and the PF spikes dropped so far. The
    thread needs the interpreter lock once a chunk, to hand the result over: each time it does, the loop's
    thread, which holds the lock but for its MuJoCo steps, waits for it to let go and for its own wake-up.
    ``net``: the network's kernel state; ``clock``: (first substep, substeps per step, plasticity on, threads);
    ``chunk``: the packed inputs and offsets, and the spike buffer and step offsets to fill
    (:meth:`~cerebx.snn.network.Network.chunk_buffers`); ``outputs``: the arguments of :func:`_chunk_outputs`
    after the spikes; ``prof``: the network's cost profile or :data:`~cerebx.snn.kernels.NO_PROF`
    (:attr:`~cerebx.snn.network.Network.kernel_prof`)."""
    t0, n_sub, learn, par = clock
    flat, in_off, idx_buf, off = chunk
    decode, record, first, step_s = outputs
    total = run_chunk(t0, n_sub, flat, in_off, learn, par, net, idx_buf, off, prof)
    tk = prof_now(prof)
    taus, counts, words, starts = _chunk_outputs(idx_buf[:total], off, decode, record, first, step_s)
    prof_lap(prof, net.populations.pop_i.shape[0] + OUTPUTS, tk)
    return taus, counts, words, starts, net.plasticity.pf_lost.sum()


@njit(cache=True, nogil=True, boundscheck=False)
def _run_ticks_chunk_outputs(aff, net, clock, chunk, outputs, prof):  # pragma: no cover
    """:func:`_run_chunk_outputs` on the ticks the loop kept in the ring ``aff``
    (:class:`~cerebx.snn.encoders.AfferentRing`), in the same compiled call: ``chunk`` is the ticks (the arguments
    of :func:`~cerebx.snn.encoders.encode_ticks` after the ring), the chunk's steps, and the spike buffer and
    step offsets to fill. The ticks are encoded first and the steps' inputs packed from the ring. (The ring is an
    argument of its own: numba types a structref inside a tuple through Python at every call, ~2.7 M
    instructions, where it takes one in front from its cache.)"""
    ticks, steps, idx_buf, off = chunk
    signals, sensed, u = ticks
    encode_ticks(aff, signals, sensed, u)
    flat, in_off = compose_steps(aff, outputs[2], steps)
    return _run_chunk_outputs(net, clock, (flat, in_off, idx_buf, off), outputs, prof)


class NetworkThread:
    """The long-lived thread that simulates the network's chunks, one at a time, in the order given. The chunks
    and their results pass through C queues: a thread started per chunk cost the loop ~1 ms each (``start``
    waits until the new thread holds the interpreter lock), and an executor's futures run interpreted
    locking code on both threads per chunk. The thread ends when its owner is garbage-collected.

    The loop queues the next chunk while the one before is still simulated; the thread takes it the moment it
    is done, without sleeping. To an idle thread :meth:`submit` hands the chunk over, returning once the thread
    has taken it: without that the thread, woken by the queue, waited for the interpreter lock until the loop's
    thread next let go of it (its next MuJoCo step), a median 0.1 ms and a mean 0.2 ms a chunk of the network's
    time, where the hand-over costs the loop's thread the thread's wake-up (a median 55 us on a 2-core VM)."""

    def __init__(self) -> None:
        self._jobs: queue.SimpleQueue = queue.SimpleQueue()
        self._taken: queue.SimpleQueue = queue.SimpleQueue()
        self._done: queue.SimpleQueue = queue.SimpleQueue()
        threading.Thread(target=_serve, args=(self._jobs, self._taken, self._done), name="cerebx-snn",
                         daemon=True).start()
        weakref.finalize(self, self._jobs.put, None)

    def submit(self, job: Any, hand_over: bool = True) -> None:
        """Queue ``job``. With ``hand_over`` (the thread is idle) return once the thread has taken it; without
        (the thread is busy with the chunk before) at once: the thread takes it as soon as it is done, with the
        interpreter lock it holds then."""
        self._jobs.put((job, hand_over))
        if hand_over:
            self._taken.get()  # lets go of the interpreter lock until the thread holds it and has the job

    def ready(self) -> bool:
        """Whether the oldest chunk not yet collected is done (:meth:`result` would not wait)."""
        return not self._done.empty()

    def result(self) -> Any:
        """The result of the oldest chunk not yet collected (waits for it); raises what the chunk raised."""
        ok, value = self._done.get()
        if not ok:
            raise value
        return value


def _serve(jobs: queue.SimpleQueue, taken: queue.SimpleQueue, done: queue.SimpleQueue) -> None:
    while (item := jobs.get()) is not None:
        job, hand_over = item
        if hand_over:
            taken.put(None)
        try:
            done.put((True, job()))
        except BaseException as exc:  # handed to the loop's thread, raised by result()
            done.put((False, exc))


# The chunk server's shared words (``ChunkServer.box``) and the fields of each job slot (``ChunkServer.job``).
_SUBMITTED, _DONE, _STOP, _FAILED, _STARTED = range(5)
_ROWS, _TICKS, _STEPS, _T0, _LEARN, _FIRST, _RECORD, _LOST, _WORDS, _WALL_NS, _CPU_NS = range(11)
_SLOTS = 2  # a chunk simulated and the next one waiting
_SPINS = 2000  # polls of an idle server before it sleeps between them
_NAPS = 250  # sleeps of each length (20 us, 200 us, then 2 ms twice as many) before the next longer one (20 ms)


@njit(cache=True, nogil=True, boundscheck=False)
def _serve_chunks(box, job, inputs, outputs, aff, net, decode, record, par, prof):  # pragma: no cover - numba
    """The chunk server's thread: every chunk the loop's thread submits, in order, without the interpreter lock
    from start to stop. Waits for ``box[_SUBMITTED]`` to pass the chunks done (polling, then sleeping 20 us,
    idle for longer 200 us, idle for ~0.1 s 2 ms (~2 % of a core) and idle for ~1 s 20 ms between polls);
    encodes the chunk's ticks into the ring ``aff``, composes its steps, runs them
    (:func:`~cerebx.snn.kernels.run_chunk`), decodes them (:func:`_chunk_outputs`) into the slot's outputs, and
    releases ``box[_DONE]``. ``job``: per slot the fields above; ``inputs``: per slot the ticks'
    signals, their rows and uniforms (:meth:`~cerebx.snn.encoders.AfferentRing.draws`); ``outputs``: per slot
    the steps' torques and DCN counts and the recorded spikes' messages (words, and where each starts), then the
    spike buffer and step offsets; ``record``: the recorded populations' (lo, hi) and an empty array (a chunk
    whose ``_RECORD`` is 0 records none); ``par``: (substeps per step, threads). Returns when ``box[_STOP]`` is
    set."""
    signals, rows, uniforms = inputs
    taus_out, counts_out, words_out, starts_out, idx_buf, off = outputs
    rec_lo, rec_hi, none = record
    n_sub, threads = par
    done = box[_DONE]
    _store_release(box, _STARTED, 1)
    while True:
        polls = 0
        while _load_acquire(box, _SUBMITTED) == done:
            if _load_acquire(box, _STOP) != 0:
                return done
            polls += 1
            if polls > _SPINS:
                _sleep_us(20 if polls < _SPINS + _NAPS else 200 if polls < _SPINS + 2 * _NAPS
                          else 2000 if polls < _SPINS + 4 * _NAPS else 20000)
        t_wall, t_cpu = _clock_ns(), _thread_cpu_ns()
        s = done % _SLOTS
        nr, nt, n = job[s, _ROWS], job[s, _TICKS], job[s, _STEPS]
        first = job[s, _FIRST]
        encode_ticks(aff, signals[s, :nr], rows[s, :nt], uniforms[s, :nr])
        flat, in_off = compose_steps(aff, first, n)
        total = run_chunk(job[s, _T0], n_sub, flat, in_off, job[s, _LEARN] != 0, threads, net, idx_buf, off[:n + 1],
                          prof)
        tk = prof_now(prof)
        if job[s, _RECORD] != 0:
            taus, counts, words, starts = _chunk_outputs(idx_buf[:total], off[:n + 1], decode, (rec_lo, rec_hi),
                                                         first, STEP_S)
            words_out[s, :words.shape[0]] = words
            starts_out[s, :starts.shape[0]] = starts
            job[s, _WORDS] = words.shape[0]
        else:
            taus, counts, _w, _st = _chunk_outputs(idx_buf[:total], off[:n + 1], decode, (none, none), first,
                                                   STEP_S)
        prof_lap(prof, net.populations.pop_i.shape[0] + OUTPUTS, tk)
        taus_out[s, :n] = taus
        counts_out[s, :n] = counts
        job[s, _LOST] = net.plasticity.pf_lost.sum()
        job[s, _WALL_NS] = _clock_ns() - t_wall
        job[s, _CPU_NS] = _thread_cpu_ns() - t_cpu
        done += 1
        _store_release(box, _DONE, done)


def _run_server(box: np.ndarray, failed: list, args: tuple) -> None:
    """The server thread's body: :func:`_serve_chunks` until stopped, or the exception it raised, kept in
    ``failed`` for the loop's thread (which polls ``box[_FAILED]``)."""
    try:
        _serve_chunks(box, *args)
    except BaseException as exc:  # raised on the loop's thread by ChunkServer.result
        failed.append(exc)
        box[_FAILED] = 1


class ChunkServer:
    """The network's chunks simulated on a thread that never takes the interpreter lock: a compiled loop
    (:func:`_serve_chunks`) that waits on a word of shared memory for the next chunk, whose inputs the loop's
    thread has copied into one of two slots, and releases its outputs into the same slot. The :class:`NetworkThread`
    needs the lock at each chunk's start and end; each time it took it the loop's thread, back from a MuJoCo step,
    waited for it to let go and to wake up again (~15 us a step of the `full` network's closed loop) and the
    chunks came later (docs/guide/speed.md#chunk-server). The server is made for one network state, ring, decoder
    and profile (:meth:`fits`); it stops when garbage-collected."""

    def __init__(self, aff: Any, net: Network, decode: tuple, record: tuple[np.ndarray, np.ndarray], chunk: int,
                 ticks: int, n_ctrl: int, width: int, n_cf: int):
        self.refs = (aff, net._state, net.kernel_prof, decode, record, chunk)
        self.box = np.zeros(8, np.int64)
        self.job = np.zeros((_SLOTS, 11), np.int64)
        self._signals = np.zeros((_SLOTS, ticks, 6, n_ctrl))
        self._rows = np.zeros((_SLOTS, ticks), np.int64)
        self._uniforms = np.zeros((_SLOTS, ticks, n_cf))
        self._taus = np.zeros((_SLOTS, chunk, width))
        self._counts = np.zeros((_SLOTS, chunk), np.int64)
        idx_buf, _ = net.chunk_buffers(chunk)
        messages = len(record[0]) * chunk  # populations x steps (chunk_spike_messages: 4 words each and a spike's)
        self._words = np.zeros((_SLOTS, idx_buf.shape[0] + 4 * messages), np.uint32)
        self._starts = np.zeros((_SLOTS, messages + 1), np.int64)
        self._outputs = (self._taus, self._counts, self._words, self._starts, idx_buf, np.zeros(chunk + 1, np.int64))
        self._failed: list[BaseException] = []
        self.submitted = self.collected = 0
        weakref.finalize(self, self.box.__setitem__, _STOP, 1)
        args = (self.job, (self._signals, self._rows, self._uniforms), self._outputs, aff, net._state, decode,
                (*record, np.zeros(0, np.int64)), (net.n_sub, net.n_threads), net.kernel_prof)
        self._thread = threading.Thread(target=_run_server, args=(self.box, self._failed, args),
                                        name="cerebx-snn-server", daemon=True)
        self._thread.start()

    def fits(self, aff: Any, net: Network, decode: tuple, record: tuple[np.ndarray, np.ndarray], chunk: int) -> bool:
        """Whether this server simulates chunks of ``chunk`` steps for this ring, network state, profile, decoder
        and recorded populations (each made again by a reset, a loaded state or a profile started)."""
        refs = (aff, net._state, net.kernel_prof, decode, record, chunk)
        return all(a is b for a, b in zip(self.refs, refs)) and not self.box[_FAILED]

    def wait_started(self) -> None:
        """Return once the server's loop runs (its kernel loaded or compiled): before a wall-clock run's first
        tick."""
        while not self.box[_STARTED] and not self.box[_FAILED]:
            time.sleep(1e-3)

    def submit(self, ticks: tuple[np.ndarray, np.ndarray, np.ndarray], steps: int, first: int, learn: bool,
               t0: int, record: bool) -> None:
        """Queue the chunk of ``steps`` steps from ``first`` on (substep ``t0``), whose ``ticks`` (signals, rows,
        uniforms) are encoded into the ring first, its recorded populations' spikes kept when ``record``; at most
        :data:`_SLOTS` are queued and not collected."""
        signals, rows, u = ticks
        nr, nt = signals.shape[0], rows.shape[0]
        if self.submitted - self.collected >= _SLOTS or nt > self._rows.shape[1] or steps > self._counts.shape[1]:
            raise RuntimeError(f"chunk server: {self.submitted - self.collected} chunks queued, {nt} ticks, "
                               f"{steps} steps (at most {_SLOTS}, {self._rows.shape[1]}, {self._counts.shape[1]})")
        s = self.submitted % _SLOTS
        self._signals[s, :nr] = signals
        self._rows[s, :nt] = rows
        self._uniforms[s, :nr] = u
        self.job[s, :_LOST] = (nr, nt, steps, t0, int(learn), first, int(record))
        self.submitted += 1
        store_release(self.box, _SUBMITTED, self.submitted)

    def ready(self) -> bool:
        """Whether the oldest chunk not yet collected is done."""
        return bool(self.box[_DONE] > self.collected)

    def result(self) -> tuple[np.ndarray, np.ndarray, np.ndarray | None, np.ndarray | None, int, float, float]:
        """The oldest chunk not yet collected (waits for it, polling, then sleeping 20 us between polls): its
        steps' outputs and DCN counts, its recorded spikes' messages and where each starts (None when not
        recorded), the PF spikes dropped so far, its wall and CPU seconds on the server; raises what the server
        raised."""
        k, box = self.collected, self.box
        polls = 0
        while box[_DONE] <= k:
            if box[_FAILED]:
                raise self._failed[0]
            polls += 1
            if polls > _SPINS:
                time.sleep(2e-5)
        load_acquire(box, _DONE)  # the slot's outputs as the server released them
        s = k % _SLOTS
        n = int(self.job[s, _STEPS])
        self.collected = k + 1
        words = starts = None
        if self.job[s, _RECORD]:
            words = self._words[s, :self.job[s, _WORDS]].copy()
            starts = self._starts[s, :len(self.refs[4][0]) * n + 1].copy()
        return (self._taus[s, :n].copy(), self._counts[s, :n].copy(), words, starts, int(self.job[s, _LOST]),
                self.job[s, _WALL_NS] * 1e-9, self.job[s, _CPU_NS] * 1e-9)

    def stop(self) -> None:
        """Stop the server's thread once the chunks queued are done (they are not collected)."""
        self.box[_STOP] = 1
        self._thread.join()


class SNNControllerImpl(Controller):
    def __init__(self, cfg: SNNController, ctx: BuildContext):
        t0 = time.perf_counter()
        self.cfg = cfg
        self.net_cfg = cfg.network
        self.k_delay = int(round(cfg.pathway_delay_ms / (STEP_S * 1000)))
        cf_ms = cfg.pathway_delay_ms if cfg.cf_pathway_delay_ms is None else cfg.cf_pathway_delay_ms
        self.k_cf = int(round(cf_ms / (STEP_S * 1000)))
        self.k_in = min(self.k_delay, self.k_cf)  # the shared afferent FIFO
        # pipelined: the network gets its own core, so its kernels run single-threaded
        self.hold = cfg.efferent != "stamp"  # 'auto' is resolved by the experiment; alone it means hold
        # steps the network may run ahead of the tick that needs its output: afferent D, plus the
        # efferent D when outputs are held back; a chunk is half of that so one can be in flight
        slack = self.k_in + (self.k_delay if self.hold else 0)
        self.chunk = max(1, slack // 2)
        self.pipeline = cfg.pipeline and slack >= 2
        self._in_flight = 0  # chunks handed to the network thread and not yet collected (at most 2)
        self._thread: NetworkThread | None = None
        self._srv: ChunkServer | None = None
        self._served: deque[bool] = deque()  # per chunk in flight: whether the chunk server has it
        seed = getattr(getattr(ctx, "cfg", None), "seed", 0)  # random connectors draw from the run's seed
        self.net = Network(self.net_cfg, parallel=cfg.parallel and not self.pipeline, seed=seed, lumped=cfg.lumped)
        self.net.learn = cfg.plasticity
        io = self.net_cfg.io
        self.sl_mf, self.sl_cf, self.sl_dcn = (self.net.index(p) for p in (io.mossy, io.climbing, io.output))
        nj = cfg.n_joints
        self.n_ctrl = nj
        plant = getattr(ctx, "plant", None)
        self.n_joints = plant.n_joints if plant is not None else nj
        n_dcn = self.sl_dcn.stop - self.sl_dcn.start
        n_cf = self.sl_cf.stop - self.sl_cf.start
        if n_dcn % nj or n_cf % nj:
            raise ValueError(f"network: {io.output} ({n_dcn}) and {io.climbing} ({n_cf}) must split "
                             f"evenly into {nj} joints")
        lo, hi = encoder_ranges(cfg, nj, getattr(ctx, "task", None))
        self.mf = registry.encoders.build(cfg.mf, lo, hi)
        if isinstance(getattr(self.mf, "rng", None), np.random.Generator):  # a stochastic MF encoder (poisson)
            self.mf.rng = ctx.rng("controller.snn.mf")
        if self.mf.n_fibers != self.sl_mf.stop - self.sl_mf.start:
            raise ValueError(f"network: {io.mossy} has {self.sl_mf.stop - self.sl_mf.start} fibres, the "
                             f"encoder needs {self.mf.n_fibers} ({nj} joints x 4 signals x "
                             f"{getattr(cfg.mf, 'fibers_per_signal', '?')})")
        self._rng_seed = ctx.rng("controller.snn.cf")
        self.cf = registry.encoders.build(cfg.cf, nj, n_cf // nj, cfg.error.kpos, cfg.error.kvel, self._rng_seed)
        self.decoder = DCNDecoder(cfg.decoder.alpha_Nm_per_spike, nj, n_dcn // nj)
        self.muscles = cfg.output == "agonist_antagonist"
        self.width = 2 * nj if self.muscles else nj  # values per step in the output FIFO ([ag, at] or tau)
        self.full_scale = np.asarray(cfg.decoder.full_scale(nj), float)  # M = 1 (agonist_antagonist output)
        self.recorder = None
        self.pathway_delay_ms = cfg.pathway_delay_ms
        self._shed = 0  # real-time load shedding level (link/shedding.py); 0: everything runs
        self._summaries = True  # periodic weight summaries (left out in wall-clock runs)
        self.record = {name: self.net.index(name) for name in cfg.record_spikes}
        self._derive_kernel_args()
        self.fingerprint = self.net.fingerprint
        self.config_hash = hashlib.sha256(
            json.dumps([self.net_cfg.model_dump(mode="json"), cfg.model_dump(mode="json")],
                       sort_keys=True).encode()).hexdigest()[:16]
        self._reset_loop_state()
        self.build_s = time.perf_counter() - t0

    # ------------------------------------------------------------------ loop
    def _reset_loop_state(self) -> None:
        self._join()
        k = self.k_delay
        empty = np.zeros(0, np.int32)
        self._pending: deque[np.ndarray] = deque([empty] * self.k_in)  # inputs not yet simulated
        # MF / CF spikes waiting for the shared FIFO (the longer pathway's extra delay)
        self._mf_lag: deque[np.ndarray] = deque([empty] * (k - self.k_in))
        self._cf_lag: deque[np.ndarray] = deque([empty] * (self.k_cf - self.k_in))
        # outputs not yet emitted (held back by the efferent delay unless they are stamped instead)
        self._ready: deque[np.ndarray] = deque([np.zeros(self.width)] * (k if self.hold else 0))
        self._net_step = 0  # network steps simulated so far (step m is stamped m * 2 ms)
        # where the next chunk's CF uniforms are drawn (the same numbers either way, AfferentRing): on this thread
        # while the network thread is the one behind (it was not done when this thread came for its chunk)
        self._draw_here = False
        self._fifos_to_ring()
        self._des: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        self._dcn_spikes = 0
        self._steps = 0
        self._no_closing()
        self._last_error = np.zeros(self.n_ctrl)

    def _fifos_to_ring(self) -> None:
        """With the encoders on the network thread (``_aff``), the FIFOs of encoded ticks become its ring."""
        if self._aff is not None:
            self._aff.from_fifos(self._net_step, self.k_in, list(self._pending), list(self._mf_lag),
                                 list(self._cf_lag))
            self._pending = self._mf_lag = self._cf_lag = None  # type: ignore[assignment]

    def _fifos(self) -> tuple[list[np.ndarray], list[np.ndarray], list[np.ndarray]]:
        """The FIFOs of encoded ticks (the shared input FIFO, the MF and CF lags), nothing in flight: with the
        encoders on the network thread, the ticks kept are encoded here first."""
        self._join()
        if self._aff is None:
            return list(self._pending), list(self._mf_lag), list(self._cf_lag)
        self._aff.encode_now()
        return self._aff.to_fifos(self._net_step, self.k_in)

    def _n_pending(self) -> int:
        """Network inputs that exist and have not been handed to the network."""
        if self._aff is None:
            return len(self._pending)
        return self.k_in + self._aff.ticks - self._net_step - self._in_flight * self.chunk

    @property
    def last_error(self) -> np.ndarray:
        """The CF error of the newest tick with a sensor sample."""
        if self._aff is not None:
            self._join()
            self._aff.encode_now()
            return self._aff.error
        return self._last_error

    def _no_closing(self) -> None:
        """No trial waits for the chunks in flight to close (:meth:`end_trial`)."""
        self._closing: Deferred | None = None
        self._closing_steps = self._closing_left = 0

    # ------------------------------------------------------------------ network execution
    def _simulate(self, inputs: list[np.ndarray], first_step: int) -> Chunk:
        """Run the network over ``inputs`` (one GIL-free call) and decode its output."""
        return self._simulate_packed(*pack(inputs), first_step)

    def _simulate_packed(self, flat: np.ndarray, in_off: np.ndarray, first_step: int,
                         mode: tuple[int, bool] | None = None) -> Chunk:
        """Run the network over packed inputs (:func:`~cerebx.snn.network.pack`) and decode the whole chunk at
        once. With spike propagation shed the network is not run and the DCN stay silent. This is what the
        network thread runs: its work is compiled code without the interpreter lock (interpreted work there
        holds up the loop's thread, which needs the lock back after every MuJoCo step); cutting the result
        into steps is left to :meth:`_absorb`. ``mode``: the chunk's :meth:`_mode`, taken when it was handed
        over (default: now)."""
        return self._run_chunk(_run_chunk_outputs, (flat, in_off), len(in_off) - 1, first_step, (),
                               self._mode() if mode is None else mode)

    def _simulate_ticks(self, ticks: tuple[np.ndarray, ...], n: int, first_step: int,
                        mode: tuple[int, bool] | None = None) -> Chunk:
        """:meth:`_simulate_packed` of the ``n`` steps from ``first_step`` on, their inputs packed from the ring of
        encoded ticks after the ``ticks`` kept (:meth:`~cerebx.snn.encoders.AfferentRing.take`) are encoded: their
        CF uniforms are drawn here unless they were when the chunk was handed over
        (:meth:`~cerebx.snn.encoders.AfferentRing.draws`, :meth:`_launch`)."""
        mode = self._mode() if mode is None else mode
        ticks = self._aff.draws(ticks)
        if mode[0] >= 2:  # the encoders go on (bursts, draws); the network does not run
            encode_ticks(self._aff.state, *ticks)
        return self._run_chunk(_run_ticks_chunk_outputs, (ticks, n), n, first_step, (self._aff.state,), mode)

    def _mode(self) -> tuple[int, bool]:
        """What a chunk handed over now runs with: the shedding level and whether the network learns. Taken on
        the loop's thread when the chunk is handed over, not read on the network thread when it runs: a
        :meth:`shed` meanwhile applies from the next chunk on, whatever the two threads' timing."""
        return self._shed, self.net.learn

    def _run_chunk(self, kernel: Any, inputs: tuple, n: int, first_step: int, lead: tuple,
                   mode: tuple[int, bool]) -> Chunk:
        """``kernel`` (:func:`_run_chunk_outputs` or :func:`_run_ticks_chunk_outputs`, whose arguments ``lead``
        come first) over ``n`` steps from ``first_step`` on, ``inputs`` its chunk's first members (the spike
        buffer and step offsets follow), with ``mode`` (:meth:`_mode`). With spike propagation shed the network is
        not run and the DCN stay silent."""
        net = self.net
        shed, learn = mode
        if shed >= 2:
            net.t_sub += net.n_sub * n
            return Chunk(first_step, np.zeros((n, self.width)), np.zeros(n, np.int64), None, None,
                         int(net.pf_lost.sum()))
        recording = self._recording(mode)
        record = (self._record_lo, self._record_hi) if recording else (_NONE, _NONE)
        idx_buf, off = net.chunk_buffers(n)
        taus, counts, words, starts, lost = kernel(
            *lead, net._state, (net.t_sub, net.n_sub, learn, net.n_threads), (*inputs, idx_buf, off),
            (self._decode, record, first_step, STEP_S), net.kernel_prof)
        net.t_sub += net.n_sub * n
        return Chunk(first_step, taus, counts, words if recording else None, starts if recording else None, lost)

    def _absorb(self, chunk: Chunk) -> None:
        """Queue a simulated chunk's outputs and log its recorded spikes (``_net_step`` is advanced by the
        caller, which may launch the next chunk first)."""
        self._ready.extend(chunk.out)
        self._dcn_spikes += int(chunk.counts.sum())
        if chunk.spikes is not None:  # made bytes here: the network's thread would need the interpreter lock
            times = [(chunk.first + i) * STEP_S for i in range(len(chunk.counts))]
            self.recorder.spike_messages(self._spike_topics, times, chunk.spikes.tobytes(), chunk.starts.tolist())
        if self._closing is not None:
            self._closing_left -= 1
            if not self._closing_left:  # the last chunk of the trial that ended: its counts are complete
                closing, self._closing = self._closing, None
                closing.set(self._trial_counts(self._closing_steps, chunk.lost))

    def _run_now(self) -> None:
        """Simulate the next pending input on this thread."""
        if self._aff is not None:
            chunk = self._simulate_ticks(self._aff.take(), 1, self._net_step)
        else:
            chunk = self._simulate([self._pending.popleft()], self._net_step)
        self._net_step += 1
        self._absorb(chunk)

    serve_chunks = True
    """Whether chunks the :class:`ChunkServer` can simulate go to it (the same results as the network thread's)."""

    def _serves(self, mode: tuple[int, bool]) -> bool:
        """Whether a chunk handed over with ``mode`` goes to the chunk server: the built-in encoders (on the
        network side) and the network run (not shed)."""
        return self.serve_chunks and self._aff is not None and mode[0] < 2

    def _recording(self, mode: tuple[int, bool]) -> bool:
        """Whether a chunk handed over with ``mode`` keeps its recorded populations' spikes."""
        return self.recorder is not None and mode[0] < 3 and bool(self.record)

    def _server(self) -> ChunkServer:
        """The chunk server of this network state, ring, profile and decoder (made again when one changed)."""
        srv = self._srv
        if srv is None or not srv.fits(self._aff.state, self.net, self._decode, self._records, self.chunk):
            if srv is not None:
                srv.stop()
            span = self._aff.R  # the ring holds every tick kept
            srv = self._srv = ChunkServer(self._aff.state, self.net, self._decode, self._records, self.chunk, span,
                                          self.n_ctrl, self.width, self._aff.cf.burst_left.shape[0])
        return srv

    def _launch(self) -> None:
        """Hand the next chunk of pending inputs to the chunk server or the network thread (packed here, so that
        the thread's work is compiled code from the start)."""
        mode = self._mode()
        served = self._serves(mode)
        if self._in_flight and (self._served[-1] != served or (served and not self._srv.fits(
                self._aff.state, self.net, self._decode, self._records, self.chunk))):
            self._join()  # the chunks in flight elsewhere first: one thread at a time steps the network
        first = self._net_step + self._in_flight * self.chunk  # after the chunk still in flight, if one is
        if served:
            ticks = self._aff.draws(self._aff.take())  # every batch drawn as it is taken, in order
            t0 = self.net.t_sub + self.net.n_sub * self.chunk * self._in_flight  # after the chunk in flight
            self._server().submit(ticks, self.chunk, first, mode[1], t0, self._recording(mode))
            self._served.append(True)
            self._in_flight += 1
            return
        if self._aff is not None:
            ticks = self._aff.take()
            if self._draw_here and self._aff.may_draw_now():  # else drawn on the network thread as the chunk starts
                ticks = self._aff.draws(ticks)
            simulate, args = self._simulate_ticks, (ticks, self.chunk, first, mode)
        else:
            simulate, args = self._simulate_packed, (*pack([self._pending.popleft() for _ in range(self.chunk)]), first,
                                                     mode)
        clock = phase_clock.active()

        def work() -> Chunk:
            t0, c0 = (time.perf_counter(), time.thread_time()) if clock is not None else (0.0, 0.0)
            try:
                return simulate(*args)
            finally:
                if clock is not None:
                    clock.add_background("network", time.perf_counter() - t0, time.thread_time() - c0)

        if self._thread is None:
            self._thread = NetworkThread()
        self._thread.submit(work, hand_over=not self._in_flight)
        self._served.append(False)
        self._in_flight += 1

    def _join(self, launch_next: bool = False) -> None:
        """Collect the oldest chunk in flight, or every one without ``launch_next``. With ``launch_next`` the next
        chunk, whose inputs are there, is queued first, behind the one in flight: the network thread goes on
        to it the moment it is done, instead of sleeping until this thread has woken up, collected and handed
        it over (two thread wake-ups a chunk, ~0.1 ms of the network's ~1.8 ms)."""
        if launch_next and self._in_flight == 1 and self._n_pending() >= self.chunk:
            self._launch()
        while self._in_flight:
            self._in_flight -= 1
            if self.recorder is not None:
                self.recorder.idle()  # the log's chunk compressed while this thread would wait
            if self._served.popleft():
                chunk = self._collect_served()
            else:
                # the network thread behind this one: the next chunks' uniforms are drawn here, else there
                self._draw_here = not self._thread.ready()
                try:
                    with phase_clock.charge("wait"):
                        chunk = self._thread.result()  # an exception of the network thread is raised here
                except BaseException:
                    self._drain()
                    raise
            self._net_step += len(chunk.counts)
            self._absorb(chunk)
            if launch_next:
                return

    def _collect_served(self) -> Chunk:
        """The oldest chunk the server has, as a :class:`Chunk` (waits for it); the network's clock advanced. When
        the server failed, its exception is raised here and the chunk queued behind is dropped (it would run on
        a network the failed one left half-stepped); when the wait is interrupted, the server finishes its chunks
        and stops before the interrupt goes on."""
        first = self._net_step
        try:
            with phase_clock.charge("wait"):
                taus, counts, words, starts, lost, wall_s, cpu_s = self._srv.result()
        except BaseException:  # the server's failure, or an interrupt while waiting (Ctrl-C)
            srv, self._srv = self._srv, None
            self._in_flight = 0
            self._served.clear()
            srv.stop()  # the network is left to this thread only when the server's chunks are over
            raise
        clock = phase_clock.active()
        if clock is not None:
            clock.add_background("network", wall_s, cpu_s)
        self.net.t_sub += self.net.n_sub * len(counts)
        return Chunk(first, taus, counts, words, starts, lost)

    def _drain(self) -> None:
        """After a chunk failed: wait for the one queued behind it and drop it (it ran on a network the failed
        chunk left half-stepped), so that nothing is in flight."""
        while self._in_flight:
            self._in_flight -= 1
            self._served.popleft()
            try:
                self._thread.result()
            except BaseException:  # noqa: BLE001 - the first failure is the one raised
                pass

    def __getstate__(self) -> dict:
        """For checkpoints (pickled between trials, when no chunk is in flight): the network thread is not
        part of the state; a restored controller starts its own when it first needs one. The desired states
        of the last 2,000 ticks go in as three arrays (ticks, q_des, qd_des): as 4,000 small arrays they were
        two thirds of the time a checkpoint held up the loop (20 of 30 ms)."""
        pending, mf_lag, cf_lag = self._fifos()  # joins
        state = self.__dict__.copy()
        state["_thread"] = state["_srv"] = None
        state["_served"] = deque()
        state.pop("_pair", None)  # made again from the encoders restored
        state.pop("_aff", None)  # as is the ring, from the FIFOs
        state["_pending"], state["_mf_lag"], state["_cf_lag"] = deque(pending), deque(mf_lag), deque(cf_lag)
        des = self._des
        if des:
            state["_des"] = ("stacked", np.fromiter(des, np.int64, len(des)),
                             np.stack([q for q, _ in des.values()]), np.stack([qd for _, qd in des.values()]))
        return state

    def __setstate__(self, state: dict) -> None:
        """A checkpoint of this code, or of the code before the network thread's queues (which kept an
        executor and the chunk's future instead, both None between trials): the derived arrays are rebuilt."""
        state = {k: v for k, v in state.items() if k not in ("_worker", "_pool")}
        des = state.get("_des")
        if isinstance(des, tuple):  # stacked by __getstate__ (a dict in checkpoints of earlier code)
            _, ticks, q, qd = des
            state["_des"] = {int(t): (q[i], qd[i]) for i, t in enumerate(ticks)}
        self.__dict__.update(state)
        self.__dict__.setdefault("_draw_here", False)  # checkpoints of earlier code
        self._in_flight, self._thread, self._srv, self._served = 0, None, None, deque()
        self._no_closing()  # pickled after every chunk was collected, so none was waiting (older code: none)
        if "_last_error" not in state:  # older code kept it as an attribute
            self._last_error = state.get("last_error", np.zeros(self.n_ctrl))
            self.__dict__.pop("last_error", None)
        self._derive_kernel_args()
        self._fifos_to_ring()

    def _derive_kernel_args(self) -> None:
        """The decoder's gains and the recorded populations' bounds as the chunk kernels take them, their
        topics, and the encoders stepped together."""
        self._alpha = np.ascontiguousarray(np.broadcast_to(self.decoder.alpha, (self.n_ctrl,)), dtype=np.float64)
        self._record_lo = np.array([sl.start for sl in self.record.values()], np.int64)
        self._record_hi = np.array([sl.stop for sl in self.record.values()], np.int64)
        self._records = (self._record_lo, self._record_hi)
        scale = np.ascontiguousarray(np.broadcast_to(self.full_scale, (self.n_ctrl,)), dtype=np.float64)
        self._decode = (self.sl_dcn.start, self.sl_dcn.stop, self.decoder.per_joint, self.decoder.sign, self._alpha,
                        self.muscles, scale, bool(self.cfg.decoder.saturate))
        self._spike_topics = tuple(f"/spikes/{name}" for name in self.record)
        self._pair = EncoderPair.of(self.mf, self.cf, self.sl_mf.start, self.sl_cf.start)
        # pipelined, the built-in encoders run on the network thread, in the chunk that needs their ticks: the
        # ring holds from the oldest tick a step still needs (the longer pathway) to the newest kept (at most
        # the FIFOs' slack, with chunks in flight, ahead of the network)
        span = max(self.k_delay, self.k_cf) + self.k_in + (self.k_delay if self.hold else 0) + 4 * self.chunk + 8
        self._aff = AfferentRing.of(self.mf, self.cf, self.sl_mf.start, self.sl_cf.start, self.k_delay, self.k_cf,
                                    span) if self.pipeline else None

    def _on_network_thread(self, fn: Any, *args: Any) -> Any:
        """Run ``fn(*args)`` on the network thread, idle while no chunk is in flight (between trials); returns
        the function that waits for its result."""
        if self._thread is None:
            self._thread = NetworkThread()
        self._thread.submit(lambda: fn(*args))
        return self._thread.result

    def _advance(self) -> None:
        """Make sure this tick's torque is ready; in pipeline mode keep one chunk in flight."""
        if not self.pipeline:
            self._run_now()
            return
        while not self._ready:
            if self._in_flight:
                self._join(launch_next=True)
            else:
                self._run_now()
        if not self._in_flight and self._n_pending() >= self.chunk:
            self._launch()

    def prepare_real_time(self) -> None:
        """Before the first tick of a wall-clock run: load (or compile) every kernel a step uses, changing no
        state, and leave out the periodic weight summaries (a pass over every plastic weight takes longer than
        the pathway delay leaves between two ticks; the learned state is still saved at the end)."""
        self._simulate_packed(*pack([]), self._net_step)  # a chunk of no steps: the network's kernels, decoding
        if self._aff is not None:  # and with the encoders on the network thread, encoding no tick
            self._simulate_ticks((np.zeros((0, 6, self.n_ctrl)), np.zeros(0, np.int64),
                                  np.zeros((0, self.cf.burst_left.shape[0]))), 0, self._net_step)
        if self._serves(self._mode()):  # and the chunk server's loop, running before the first tick
            self._server().wait_started()
        z = np.zeros(self.n_ctrl)
        copy.deepcopy(self.mf).active(z, z, z, z)
        self.cf.error(z, z, z, z)
        copy.deepcopy(self.cf).active(z)
        pair = EncoderPair.of(copy.deepcopy(self.mf), copy.deepcopy(self.cf), self.sl_mf.start, self.sl_cf.start)
        if pair is not None:
            pair.active(z, z, z, z, z, z)
        self._summaries = False

    def shed(self, level: int) -> None:
        """Real-time load shedding (the original's watchdog levels): 0 everything runs, 1 plasticity off,
        2 spike propagation off too, 3 spike recording and weight summaries off too."""
        self._shed = level
        self.net.learn = self.cfg.plasticity and level == 0

    def reset(self, rng: np.random.Generator) -> None:
        self._join()  # pipelined, the network thread writes the CF bursts
        self.cf.rng = rng
        self.cf.reset()
        self.net.reset_state()
        self._reset_loop_state()

    def position_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """The MF position-encoder ranges, which the original used as watchdog bounds."""
        lo, hi = self.mf.lo[:, 1], self.mf.hi[:, 1]
        if self.n_joints > self.n_ctrl:
            pad = self.n_joints - self.n_ctrl
            lo, hi = np.concatenate([lo, np.zeros(pad)]), np.concatenate([hi, np.zeros(pad)])
        return lo.copy(), hi.copy()

    def _desired_at(self, stamp_s: float, inp: ControlInput) -> tuple[np.ndarray, np.ndarray]:
        return self._des.get(int(round(stamp_s / STEP_S)), (inp.q_des, inp.qd_des))

    def control(self, inp: ControlInput) -> TorqueMsg:
        self._des[inp.tick] = (inp.q_des, inp.qd_des)
        self._des.pop(inp.tick - 2000, None)
        s = inp.sensor
        if s is not None:
            q_des, qd_des = self._desired_at(s.stamp_s, inp)
            q_des_cf, qd_des_cf = q_des, qd_des
            if self.cfg.error_reference_lag_ms:
                q_des_cf, qd_des_cf = self._desired_at(s.stamp_s - self.cfg.error_reference_lag_ms / 1000.0, inp)
        if self._aff is not None:  # the tick's signals kept; the network thread encodes them
            self._aff.kept.append(None if s is None else (q_des, qd_des, q_des_cf, qd_des_cf, s.q, s.qd))
        elif s is None:
            mf = cf = np.zeros(0, np.int32)
        else:
            both = self._pair.active(q_des, qd_des, q_des_cf, qd_des_cf, s.q, s.qd) if self._pair else None
            if both is not None:
                mf, cf, self._last_error = both
            else:
                mf = (self.mf.active(q_des, s.q, qd_des, s.qd) + self.sl_mf.start).astype(np.int32, copy=False)
                e = self.cf.error(q_des_cf, s.q, qd_des_cf, s.qd)
                self._last_error = e
                cf = (self.cf.active(e) + self.sl_cf.start).astype(np.int32, copy=False)
        if self._aff is None:
            self._mf_lag.append(mf)
            self._cf_lag.append(cf)
            self._pending.append(np.concatenate([self._mf_lag.popleft(), self._cf_lag.popleft()]))
        self._advance()
        self._steps += 1
        stamp = inp.t_s if self.hold else inp.t_s + self.k_delay * STEP_S
        out = self._ready.popleft()
        if self.muscles:
            ag, at = np.zeros(self.n_joints), np.zeros(self.n_joints)
            ag[: self.n_ctrl], at[: self.n_ctrl] = out[: self.n_ctrl], out[self.n_ctrl:]
            return CommandMsg(stamp, {"muscle.ag": ag, "muscle.at": at})
        if self.n_joints == self.n_ctrl:
            return TorqueMsg(stamp, out.copy())
        tau = np.zeros(self.n_joints)
        tau[: self.n_ctrl] = out
        return TorqueMsg(stamp, tau)

    # ------------------------------------------------------------------ reporting
    def end_trial(self, trial: int) -> Mapping[str, float]:
        """The trial's DCN rate, the PF spikes the LTD buffers dropped so far and, every
        ``weight_summary_every_trials``, the plastic weights' statistics: of the network once the chunks in
        flight are done, which run ahead into the next trial by up to the pathway delay.

        Without weight statistics due, the loop need not wait for those chunks: a :class:`Deferred` is
        returned, which the last of them completes when the loop collects it (a few ticks into the next
        trial). The loop's thread and the network's then go on across the trial's end, where waiting cost both
        ~3 ms a trial (the network idle until 22 ticks of the next trial had given it a chunk's inputs)."""
        if self._closing is not None:  # the trial before is still waiting (a trial shorter than the chunks)
            self._join()
        every = self.cfg.weight_summary_every_trials
        weights = bool(every and trial % every == 0 and self._summaries and self._shed < 3)
        if self.pipeline and self._in_flight and not weights:
            self._closing = Deferred(self._join)
            self._closing_steps, self._closing_left = self._steps, self._in_flight
            self._steps = 0
            return self._closing
        self._join()  # weights and counters must not change while they are read
        out = self._trial_counts(self._steps, None)
        self._steps = 0
        if weights:
            beside = self._on_network_thread if self.pipeline else None
            for name in self.net.plastic_projections:
                stats = self.net.weight_stats(name, beside)
                out.update(zip((f"w_{name}_mean", f"w_{name}_std", f"w_{name}_min", f"w_{name}_max"), stats))
        lost = int(self.net.pf_lost.sum())
        if lost:
            out["ltd_pf_spikes_dropped"] = float(lost)
        return out

    def _trial_counts(self, steps: int, lost: int | None) -> dict[str, float]:
        """The DCN rate over the ``steps`` ticks of the trial that ended (the DCN spike count restarts), and
        the dropped PF spikes when ``lost`` is given."""
        out: dict[str, float] = {}
        if steps:
            out["dcn_rate_hz"] = self._dcn_spikes / ((self.sl_dcn.stop - self.sl_dcn.start) * steps * STEP_S)
        self._dcn_spikes = 0
        if lost:
            out["ltd_pf_spikes_dropped"] = float(lost)
        return out

    def attach_recorder(self, recorder: Any) -> None:
        self.recorder = recorder if hasattr(recorder, "spike_messages") else None

    def describe(self) -> dict[str, Any]:
        return {
            "network": self.net_cfg.name,
            "neurons": self.net.n_neurons,
            "synapses": self.net.n_synapses,
            "plastic_synapses": self.net.n_plastic,
            "build_s": round(self.build_s, 3),
            "pathway_delay_steps": self.k_delay,
            "cf_pathway_delay_steps": self.k_cf,
            "fingerprint": self.fingerprint,
            "integrators": self.net.integrators(),
            "vector_bits": vector_bits(),
            **self._built(),
        }

    def _built(self) -> dict[str, Any]:
        """The synapses built per projection, where a random connector made another count than declared."""
        declared = {k: p.synapses for k, p in self.net_cfg.projections.items()}
        built = self.net.built_synapses
        return {"built_synapses": built} if built != declared else {}

    # ------------------------------------------------------------------ state
    def save_state(self, path: Path) -> bool:
        pending, mf_lag, cf_lag = self._fifos()  # joins
        path = Path(path)
        arrays = {f"net_{k}": v for k, v in self.net.state_arrays().items()}
        arrays["cf_burst_left"] = self.cf.burst_left
        arrays["out_fifo"] = np.array(list(self._ready)).reshape(len(self._ready), self.width)
        meta = {"version": STATE_VERSION, "fingerprint": self.fingerprint, "config": self.config_hash,
                "network": self.net_cfg.name, "layout": self.net_cfg.layout(), "rng": self.cf.rng.bit_generator.state}
        if isinstance(getattr(self.mf, "rng", None), np.random.Generator):
            meta["mf_rng"] = self.mf.rng.bit_generator.state
        arrays["in_fifo"] = np.array(json.dumps([a.tolist() for a in pending]))
        arrays["lag_fifos"] = np.array(json.dumps([[a.tolist() for a in mf_lag], [a.tolist() for a in cf_lag]]))
        save_state_npz(path, meta, **arrays)
        return True

    def load_state(self, path: Path) -> None:
        path = Path(path)
        data, meta = load_state_npz(path, "SNN")
        if meta.get("fingerprint") != self.fingerprint:
            raise StateMismatchError(
                f"{path}: saved from network {meta.get('network')!r} with a different structure "
                f"(fingerprint {meta.get('fingerprint')}), this controller runs {self.net_cfg.name!r} "
                f"({self.fingerprint})")
        problem = layout_problem(meta.get("layout"), self.net_cfg)
        if problem:
            raise StateMismatchError(f"{path}: {problem}")
        self._join()  # the network thread writes the network and, pipelined, the CF bursts
        if self._aff is not None:  # the ticks kept draw from the generator as it was
            self._aff.encode_now()
        try:
            self.net.load_arrays({k[4:]: data[k] for k in data.files if k.startswith("net_")})
        except (KeyError, ValueError) as exc:
            raise StateMismatchError(f"{path}: {exc}") from None
        self.cf.burst_left[:] = data["cf_burst_left"]
        self.cf.rng.bit_generator.state = meta["rng"]
        if "mf_rng" in meta and isinstance(getattr(self.mf, "rng", None), np.random.Generator):
            self.mf.rng.bit_generator.state = meta["mf_rng"]
        fifo = json.loads(str(data["in_fifo"]))
        lags = json.loads(str(data["lag_fifos"])) if "lag_fifos" in data.files else [[], []]
        out_fifo = data["out_fifo"]
        same = (len(fifo) + len(out_fifo) == self.k_in + (self.k_delay if self.hold else 0)
                and len(lags[0]) == self.k_delay - self.k_in and len(lags[1]) == self.k_cf - self.k_in
                and out_fifo.shape[1:] == (self.width,))
        if same:  # resume exactly (same delays and output kind)
            self._pending = deque(np.asarray(a, dtype=np.int32) for a in fifo)
            self._ready = deque(np.asarray(r, dtype=float) for r in out_fifo)
            self._mf_lag = deque(np.asarray(a, dtype=np.int32) for a in lags[0])
            self._cf_lag = deque(np.asarray(a, dtype=np.int32) for a in lags[1])
            self._fifos_to_ring()
