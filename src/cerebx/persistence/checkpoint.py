"""Checkpoint files, written off the loop's thread and atomically, with the large learned arrays rewritten
only where they changed (``loop/resume.py`` decides what goes in and when).

A checkpoint is

- ``checkpoint.pkl``: one line of JSON, the head (:func:`read_head`), then the pickled state (cloudpickle).
  Written to a temporary file, flushed to the disk, then renamed over the old one: that rename commits it.
- ``checkpoint.<n>.arrays``: the arrays an object of the state tracks (a ``changed_ranges()`` method, e.g. the
  spiking network's weights, 145 MB for the full network, and its fixed tables, reported once and never
  changed), stored beside the pickle, which refers to them by
  key. The first checkpoint a process writes puts them whole into a new file (``<n>``: its trial count),
  unless the file was written ahead (below); each later one writes only the ranges changed since (a few % of
  the PF-PC rows per 10 trials), first into ``checkpoint.journal`` (flushed to the disk), then commits the
  pickle, then writes the ranges into the arrays file in place (then flushes it to the disk).

A crash at any moment leaves the previous checkpoint or the new one, whole: before the commit the old
pickle names the old arrays file, which a full write never touches (a new file) and a journal of a newer
checkpoint leaves alone; after it, the journal of the committed checkpoint is complete on the disk and
:func:`load` applies it again (it holds values, not increments), whatever part of it reached the arrays file.

Written ahead (:func:`prime`, before the first trial of a process): the first checkpoint would copy the
arrays whole on the loop's thread (0.4 s for the full network) to write them into a new file. Instead, at a
moment the state does not change (between trials), :func:`prime` takes the tracked objects' changed ranges
(which starts a new interval) and has the writer thread write the *live* arrays whole into the new file
``checkpoint.<n>.arrays`` (``<n>``: the trial count of the first checkpoint due) while the run goes on; the
first checkpoint is then written like a later one, a journal of the ranges changed since on top of that file.
Why the file and its journal hold the state of the checkpoint:

- a range not reported changed at the checkpoint was not written since the reset (a tracked object reports
  every write since its last ``changed_ranges()``, which only the checkpoints call): the writer read it after
  the reset and before the checkpoint (a checkpoint uses the file only once the writer has finished it), so
  the file holds its value at the checkpoint;
- a range written meanwhile (before, while or after the writer read it; its bytes in the file may be old, new
  or torn) is reported changed at the checkpoint, so it is in the journal, with its value at the checkpoint,
  which is applied after the commit and again by :func:`load` after a crash, overwriting those bytes;
- the file is flushed to the disk and its name too before the first checkpoint is written, and no committed
  pickle names it before that checkpoint commits (a name no committed pickle uses: a resumed run's checkpoint
  is older than the checkpoint due); a crash while it is written leaves the previous checkpoint as it was;
- the journal of the first checkpoint replaces that of the committed checkpoint (a resumed run's) before its
  commit, so the writer first applies the committed journal to its own arrays file and flushes it (what the
  process that wrote it would have done after its commit; the journal stays valid), and only then writes ahead.

If writing ahead fails, the first checkpoint writes the arrays whole, as without it; a run that stops before
its first checkpoint deletes the file (:func:`drop_ahead`).

The loop's thread only pickles (into memory) and copies the changed ranges; a :class:`Writer` thread does
the writing and flushing, one checkpoint at a time.
"""

from __future__ import annotations

import io
import json
import logging
import mmap
import os
import pickle
import sys
import threading
import time
import zlib
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import cloudpickle
import numpy as np
from numba import njit

from cerebx import phase_clock, runfiles

log = logging.getLogger("cerebx")

CHECKPOINT = runfiles.CHECKPOINT
JOURNAL = "checkpoint.journal"
_JOURNAL_MAGIC = b"CXJ1"
_ALIGN = 64
_ndarray = np.ndarray

# (key, starts, length, values): the ranges flat[s:s + length] of one array, their values one after the other
Changes = list[tuple[str, np.ndarray, int, np.ndarray]]


def arrays_name(seq: int) -> str:
    return f"checkpoint.{seq}.arrays"


class ArrayStore:
    """The tracked arrays of one process's checkpoints: which array is which key, and where the current
    arrays file keeps it."""

    def __init__(self) -> None:
        self.file: str | None = None
        self.layout: dict[str, dict[str, Any]] = {}  # key -> offset, dtype, shape in self.file
        self.key_of: dict[int, str] = {}  # id(array) -> key; the arrays are kept alive in self.arrays
        self.arrays: dict[str, np.ndarray] = {}
        self.ahead: ArraysFile | None = None  # the arrays file being written ahead (prime)
        # per checkpoint
        self.ranges: dict[int, list[tuple[np.ndarray, int]]] = {}  # id(array) -> (starts, length) ranges
        self.asked: set[int] = set()
        self.used: set[str] = set()

    def begin(self) -> None:
        self.ranges, self.asked, self.used = {}, set(), set()

    def ask(self, owner: Any, changed_ranges: Any) -> None:
        """Take ``owner``'s changed ranges once per checkpoint."""
        if id(owner) in self.asked:
            return
        self.asked.add(id(owner))
        for array, starts, length in changed_ranges(owner):
            self.ranges.setdefault(id(array), []).append((np.asarray(starts, np.int64), int(length)))
            if id(array) not in self.key_of:
                key = f"a{len(self.key_of)}"
                self.key_of[id(array)] = key
                self.arrays[key] = array

    def ref(self, array: np.ndarray) -> str | None:
        """The key of ``array`` if it is tracked (then the pickle holds the key instead of the data)."""
        if id(array) not in self.ranges:
            return None
        key = self.key_of[id(array)]
        self.used.add(key)
        return key

    def full(self) -> bool:
        """Whether this checkpoint must write its arrays whole (a new file): none written yet, or an array
        the file does not hold. An array whose changes were taken but that went into the pickle after all is
        dropped from the file's layout, so its next checkpoint is whole too."""
        for i in self.ranges:
            if self.key_of[i] not in self.used:
                self.layout.pop(self.key_of[i], None)
        return self.file is None or any(k not in self.layout for k in self.used)

    def take_ahead(self) -> None:
        """Use the arrays file written ahead if the writer finished it (else the next checkpoint is whole)."""
        ahead, self.ahead = self.ahead, None
        if ahead is not None and ahead.done and self.file is None:
            self.file, self.layout = ahead.name, dict(ahead.layout)


class _Pickler(cloudpickle.Pickler):
    def __init__(self, fh: Any, store: ArrayStore, persistent: dict[type, str]):
        # the dispatch table as a plain dict instead of the base class's ChainMap (the same entries, looked up
        # the same way): the pickler looks the class of every object it reduces up in it, and a ChainMap lookup
        # runs Python code (two KeyErrors for most classes). The pickler reads it when it is created: set first.
        self.dispatch_table = dict(cloudpickle.Pickler.dispatch_table)
        super().__init__(fh, protocol=pickle.HIGHEST_PROTOCOL)
        self.store = store
        self.persistent = persistent
        # per class, decided once (the state has ~57 k objects, each passed to persistent_id)
        self.plain: set[type] = set()  # neither persistent nor tracked: most of them (str, tuple, int, ...)
        self.how: dict[type, tuple[str, Any]] = {}  # the others: ("id", pid) or ("tracked", changed_ranges)

    def persistent_id(self, obj: Any) -> Any:
        cls = type(obj)
        if cls in self.plain:
            return None
        if cls is _ndarray:
            key = self.store.ref(obj)
            return None if key is None else ("array", key)
        how = self.how.get(cls)
        if how is None:
            how = self._classify(cls)
            if how[0] == "plain":
                self.plain.add(cls)
                return None
            self.how[cls] = how
        if how[0] == "id":
            return how[1]
        self.store.ask(obj, how[1])
        return None

    def reducer_override(self, obj: Any) -> Any:
        if type(obj) is _ndarray:  # neither a class nor a function: what the base class returns for it
            return NotImplemented
        return super().reducer_override(obj)

    def _classify(self, cls: type) -> tuple[str, Any]:
        for kind, pid in self.persistent.items():
            if issubclass(cls, kind):
                return "id", pid
        changed = getattr(cls, "changed_ranges", None)
        if changed is not None and cls is not type:
            return "tracked", changed
        return "plain", None


MOVED = {"cerebx.controllers.pid": "cerebx.stages.pid", "cerebx.loop.link": "cerebx.delay_channel",
         "cerebx.loop.checkpoint": "cerebx.persistence.checkpoint",
         "cerebx.controllers.state": "cerebx.persistence.state"}
"""Modules renamed since a checkpoint may have been written (old -> new), so that an earlier run resumes."""

MOVED_CLASSES = {("cerebx.stages.controllers", "TorqueControllerStage"):
                 ("cerebx.persistence.checkpoint", "TorqueControllerStage")}
"""Classes gone or moved since a checkpoint may have been written ((module, name) old -> new)."""


class TorqueControllerStage:
    """What a checkpoint written before joint-torque controllers were stages holds in a controller's place:
    the adapter that ran it. :func:`unwrap_adapters` puts the controller back in its place."""


def unwrap_adapters(stages: list[Any]) -> list[Any]:
    """``stages`` (and, in place, the parts of composite ones) with each old adapter replaced by the
    controller it ran, which takes over the adapter's name, signals and last converted sensor message."""
    out = []
    for st in stages:
        if isinstance(st, TorqueControllerStage):
            d = st.__dict__
            inner = d["controller"]
            inner.name, inner.reads, inner.writes = d["name"], d["reads"], d["writes"]
            inner.adds = d.get("adds", frozenset())
            inner._sensed, inner._sensor = d.get("_sensed"), d.get("_sensor")
            st = inner
        parts = getattr(st, "parts", None)
        if isinstance(parts, list):
            parts[:] = unwrap_adapters(parts)
        out.append(st)
    return out


class _Unpickler(pickle.Unpickler):
    def __init__(self, fh: Any, arrays: dict[str, np.ndarray], objects: dict[str, Any]):
        super().__init__(fh)
        self.arrays, self.objects = arrays, objects

    def find_class(self, module: str, name: str) -> Any:
        module, name = MOVED_CLASSES.get((module, name), (module, name))
        return super().find_class(MOVED.get(module, module), name)

    def persistent_load(self, pid: Any) -> Any:
        if isinstance(pid, tuple) and len(pid) == 2 and pid[0] == "array" and pid[1] in self.arrays:
            return self.arrays[pid[1]]
        if isinstance(pid, str) and pid in self.objects:
            return self.objects[pid]
        raise pickle.UnpicklingError(f"unknown persistent id {pid!r}")


def _fsync_dir(path: Path) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


PACE_PIECE = 256 * 1024
"""Bytes a paced write writes between two naps (:class:`Pace`)."""
PACE_NAP_S = 0.002
"""Seconds a paced write sleeps after each piece: at most ~120 MB/s, a checkpoint of the full network (5 MB of
pickle, ~5 MB of changed rows) in ~0.1 s of the ~0.75 s until the next."""


class Pace:
    """How the writer spreads a checkpoint's files over time: :data:`PACE_PIECE` bytes, then :data:`PACE_NAP_S`
    asleep, until :meth:`hurry` (the loop waits for the writer) drops the naps.

    Written in one burst, the ~10 MB of a checkpoint of the full network slowed the trial after it by 15-25 ms
    (a median 98-105 against 90 ms with the writes paced, a 200-trial ``make_run``, same hour): filling that
    many fresh pages of the page cache at once held up the loop's and the network's threads, idle priority or
    not. Paced, the same bytes cost them next to nothing."""

    def __init__(self) -> None:
        self._hurried = threading.Event()

    def nap(self) -> None:
        self._hurried.wait(PACE_NAP_S)

    def hurry(self) -> None:
        self._hurried.set()


def _write_file(path: Path, parts: Iterable[Any], pace: Pace | None = None) -> None:
    """Write ``parts`` (bytes-like) into ``path`` through a temporary file, flushed, then renamed; with
    ``pace``, a piece at a time."""
    tmp = path.with_name(path.name + ".tmp")
    with open(tmp, "wb") as fh:
        for part in parts:
            if pace is None:
                fh.write(part)
                continue
            view = memoryview(part).cast("B")
            for k in range(0, len(view), PACE_PIECE):
                fh.write(view[k : k + PACE_PIECE])
                pace.nap()
        fh.flush()
        os.fsync(fh.fileno())
    os.replace(tmp, path)


def _raw(a: np.ndarray) -> memoryview:
    return memoryview(np.ascontiguousarray(a)).cast("B")


def _whole_parts(arrays: Iterable[np.ndarray]) -> list[Any]:
    """The arrays one after the other, each at an offset aligned as :func:`_layout` says."""
    parts: list[Any] = []
    size = 0
    for a in arrays:
        pad = -size % _ALIGN
        parts.append(b"\0" * pad)
        size += pad + a.nbytes
        parts.append(_raw(a))
    return parts


class Checkpoint:
    """One checkpoint, ready to be written: the pickle and the arrays (whole or the changed ranges)."""

    def __init__(self, run_dir: Path, head: dict[str, Any], stream: memoryview, whole: dict[str, np.ndarray] | None,
                 changes: Changes, layout: dict[str, dict[str, Any]], file: str | None):
        self.run_dir, self.head, self.stream = run_dir, head, stream
        self.whole, self.changes, self.layout, self.file = whole, changes, layout, file

    def write(self, pace: Pace | None = None) -> None:
        """Write the files (the journal and the pickle with ``pace``) and commit."""
        run_dir, seq = self.run_dir, self.head["trials_done"]
        if self.whole is not None:
            _write_file(run_dir / self.file, _whole_parts(self.whole.values()))
        elif self.changes:
            _write_file(run_dir / JOURNAL, self._journal(seq), pace)
        if self.whole is not None or self.changes:
            _fsync_dir(run_dir)  # the arrays file's or the journal's name is on the disk before the pickle names it
        _write_file(run_dir / CHECKPOINT, [json.dumps(self.head).encode() + b"\n", self.stream], pace)
        _fsync_dir(run_dir)  # the renames are on the disk too
        tmp_head = run_dir / (runfiles.CHECKPOINT_HEAD + ".tmp")  # a copy of the committed head for people and tools
        tmp_head.write_text(json.dumps(self.head))
        os.replace(tmp_head, run_dir / runfiles.CHECKPOINT_HEAD)
        if self.whole is None and self.changes:
            self._apply()
        for p in run_dir.glob("checkpoint.*.arrays"):
            if p.name != self.file:
                p.unlink(missing_ok=True)
        if self.whole is not None:
            (run_dir / JOURNAL).unlink(missing_ok=True)

    def _journal(self, seq: int) -> list[Any]:
        entries, data = [], []
        for key, starts, length, values in self.changes:
            entries.append({"key": key, "count": len(starts), "length": length, "dtype": values.dtype.str})
            data += [_raw(starts), _raw(values)]
        crc = 0
        for part in data:
            crc = zlib.crc32(part, crc)
        header = {"seq": seq, "file": self.file, "entries": entries, "crc32": crc}
        return [_JOURNAL_MAGIC, json.dumps(header).encode() + b"\n", *data]

    def _apply(self) -> None:
        _apply_file(self.run_dir / self.file, self.layout, self.changes)


def _apply_file(path: Path, layout: dict[str, dict[str, Any]], changes: Changes) -> None:
    """Write the changed ranges into the arrays file in place, then flush it to the disk.

    The file is mapped and each array's ranges are copied in by compiled code without the interpreter lock
    (:func:`_scatter`), page faults included; then the file is flushed with ``fsync``, which lets go of the lock
    too. On Linux the map's pages are the file's pages in the page cache, so ``fsync`` writes them; the map's own
    flush (``msync``) would hold the lock the whole time (40-50 ms for a checkpoint of the full network), and so
    would a numpy assignment into the map (~15 ms): the loop's thread, waiting for the lock, left the network
    idle. One ``pwrite`` per run of ranges (600-800 of them) took the lock back after each, stalling the loop a
    millisecond or more each time."""
    with open(path, "r+b") as fh:
        mm = mmap.mmap(fh.fileno(), 0)
        try:
            for key, starts, length, values in changes:
                item = layout[key]
                count = int(np.prod(item["shape"], dtype=np.int64))
                _scatter(np.frombuffer(mm, np.dtype(item["dtype"]), count, item["offset"]), starts, length, values)
            if sys.platform != "linux":  # elsewhere the map may not be the file's cache
                mm.flush()
        finally:
            try:
                mm.close()
            except BufferError:  # an error's traceback still holds an array on the map: it closes with it
                pass
        os.fsync(fh.fileno())


def prepare(run_dir: Path, head: dict[str, Any], state: Any, store: ArrayStore,
            persistent: dict[type, str]) -> Checkpoint:
    """Pickle ``state`` and copy what changed (the loop's thread; the state must not change meanwhile)."""
    store.take_ahead()
    store.begin()
    stream = _dumps(state, store, persistent)
    seq = head["trials_done"]
    whole = None
    changes: Changes = []
    if store.full():
        whole = {k: store.arrays[k].copy() for k in _ordered(store.used)}
        store.file, store.layout = arrays_name(seq), _layout(whole)
    else:
        for key in sorted(store.used):
            a = store.arrays[key]
            for starts, length in store.ranges[id(a)]:
                if len(starts):
                    changes.append((key, starts, length, _gather(a.reshape(-1), starts, length)))
    head = {**head, "arrays": {"file": store.file, "layout": {k: store.layout[k] for k in sorted(store.used)}}
            if store.used else None}
    return Checkpoint(run_dir, head, stream, whole, changes, dict(store.layout), store.file)


def _ordered(keys: Iterable[str]) -> list[str]:
    return sorted(keys, key=lambda k: int(k[1:]))


class ArraysFile:
    """The tracked arrays written whole from the live arrays, ahead of the first checkpoint (:func:`prime`):
    ``done`` once the file and its name are on the disk."""

    def __init__(self, run_dir: Path, name: str, arrays: dict[str, np.ndarray], settle: bool):
        self.run_dir, self.name, self.arrays, self.settle = run_dir, name, arrays, settle
        self.layout = _layout(arrays)
        self.done = False

    def write(self, pace: Pace | None = None) -> None:
        """Write the file, at full speed (``pace`` is not used: the first checkpoint needs it done)."""
        try:
            if self.settle:
                _settle(self.run_dir)
            _write_file(self.run_dir / self.name, _whole_parts(self.arrays.values()))
            _fsync_dir(self.run_dir)
        except Exception as err:  # the first checkpoint writes the arrays whole instead
            log.warning("could not write %s ahead of the first checkpoint: %s", self.name, err)
            return
        finally:
            self.arrays = {}
        self.done = True


def prime(run_dir: Path, seq: int, state: Any, store: ArrayStore, persistent: dict[type, str]) -> ArraysFile | None:
    """Before the first checkpoint of this process (the loop's thread, between trials): take the tracked
    objects' changed ranges and return the job that writes their live arrays into ``checkpoint.<seq>.arrays``
    (``seq``: the trial count of the first checkpoint due), for the :class:`Writer`; None when there is
    nothing to write ahead, or ``run_dir``'s committed checkpoint uses that name."""
    if store.file is not None or store.ahead is not None:
        return None
    run_dir = Path(run_dir)
    name = arrays_name(seq)
    try:
        committed = read_head(run_dir)
    except FileNotFoundError:
        committed = None
    except (OSError, ValueError):
        return None
    if committed is not None and (committed.get("arrays") or {}).get("file") == name:
        return None
    store.begin()
    _dumps(state, store, persistent)  # finds the tracked arrays (and takes their changed ranges)
    if not store.used:
        return None
    for key in store.used:  # the writer's compiled copy, loaded here: loading holds the interpreter lock
        _warm_scatter(store.arrays[key].dtype)
    store.ahead = ArraysFile(run_dir, name, {k: store.arrays[k] for k in _ordered(store.used)},
                             settle=committed is not None)
    return store.ahead


def drop_ahead(store: ArrayStore) -> None:
    """Delete the arrays file written ahead of a checkpoint that never came (the run stopped before it); the
    writer must be done with it. No committed pickle names it."""
    ahead, store.ahead = store.ahead, None
    if ahead is not None:
        for name in (ahead.name, ahead.name + ".tmp"):
            (ahead.run_dir / name).unlink(missing_ok=True)


def _settle(run_dir: Path) -> None:
    """Apply the journal of ``run_dir``'s committed checkpoint to its arrays file and flush that to the disk,
    so that the journal can be replaced before the next commit."""
    try:
        head = read_head(run_dir)
    except FileNotFoundError:
        return
    changes = _read_journal(run_dir, head)
    if changes:
        _apply_file(run_dir / head["arrays"]["file"], head["arrays"]["layout"], changes)


def _dumps(state: Any, store: ArrayStore, persistent: dict[type, str]) -> memoryview:
    buf = io.BytesIO()
    _Pickler(buf, store, persistent).dump(state)
    return buf.getbuffer()


def _check_ranges(flat: np.ndarray, starts: np.ndarray, length: int) -> np.ndarray:
    starts = np.ascontiguousarray(starts, dtype=np.int64)
    if flat.ndim != 1 or length < 0:
        raise ValueError("ranges of a flat array, of a length >= 0")
    if len(starts) and (int(starts.min()) < 0 or int(starts.max()) > flat.size - length):
        raise ValueError(f"ranges of length {length} outside an array of {flat.size}")
    return starts


def _rows(flat: np.ndarray, starts: np.ndarray, length: int) -> tuple[np.ndarray, np.ndarray] | None:
    """``flat`` as a [rows, length] view and the row of each start, when the starts are increasing whole
    numbers of ranges apart (the rows of a weight matrix); else None."""
    if not len(starts) or length <= 0:
        return None
    base = int(starts[0]) % length
    rows, off = np.divmod(starts - base, length)
    if off.any() or (len(rows) > 1 and not (np.diff(rows) > 0).all()):
        return None
    n = (flat.size - base) // length
    return flat[base:base + n * length].reshape(n, length), rows


def _gather(flat: np.ndarray, starts: np.ndarray, length: int) -> np.ndarray:
    """The ranges ``flat[s:s + length]`` for s in ``starts``, one after the other (a copy)."""
    starts = _check_ranges(flat, starts, length)
    view = _rows(flat, starts, length)
    if view is not None:  # one copy per row, no index per element
        return np.take(view[0], view[1], axis=0).reshape(-1)
    if not len(starts):
        return flat[:0].copy()
    return np.concatenate([flat[s:s + length] for s in starts.tolist()])


def _scatter(flat: np.ndarray, starts: np.ndarray, length: int, values: np.ndarray) -> None:
    """``flat[s:s + length]`` = the next ``length`` values, for s in ``starts`` (the inverse of :func:`_gather`),
    in compiled code without the interpreter lock."""
    starts = _check_ranges(flat, starts, length)
    if values.shape != (len(starts) * length,) or values.dtype != flat.dtype:
        raise ValueError(f"{values.shape} {values.dtype} values for {len(starts)} ranges of {length} {flat.dtype}")
    if len(starts) and length:
        _put_ranges(flat, starts, length, values)


def _warm_scatter(dtype: np.dtype) -> None:
    """Load (or compile) :func:`_scatter`'s compiled code for arrays of ``dtype``, here and now: that holds the
    interpreter lock for tens of milliseconds, which the writer's thread must not do while the trials run."""
    flat = np.zeros(2, dtype)
    _scatter(flat, np.zeros(1, np.int64), 1, flat[:1].copy())


@njit(cache=True, nogil=True, boundscheck=False)
def _put_ranges(flat, starts, length, values):  # pragma: no cover - numba
    k = 0
    for s in starts:
        flat[s:s + length] = values[k:k + length]
        k += length


def _layout(arrays: dict[str, np.ndarray]) -> dict[str, dict[str, Any]]:
    out, offset = {}, 0
    for key, a in arrays.items():
        offset += -offset % _ALIGN
        out[key] = {"offset": offset, "dtype": a.dtype.str, "shape": list(a.shape)}
        offset += a.nbytes
    return out


def _can_restore_priority() -> bool:
    """Whether a thread of this process that gave up its priority can take it back: Linux lets a thread leave
    ``SCHED_IDLE`` for ``SCHED_OTHER`` at nice 0 when privileged or when ``RLIMIT_NICE`` allows nice 0."""
    if not hasattr(os, "SCHED_IDLE"):
        return False
    try:
        import resource

        soft = resource.getrlimit(resource.RLIMIT_NICE)[0]
    except (ImportError, AttributeError, OSError, ValueError):
        return False
    return os.geteuid() == 0 or soft == resource.RLIM_INFINITY or soft >= 20


def _set_policy(tid: int, idle: bool) -> bool:
    try:
        os.sched_setscheduler(tid, os.SCHED_IDLE if idle else os.SCHED_OTHER, os.sched_param(0))
    except OSError:
        return False
    return True


class Writer:
    """Writes checkpoints on a thread of its own, one at a time; an error is raised by the next call.

    A learning run keeps both cores of a 2-core machine busy (the network's thread and the loop's). A writer at
    their priority takes its CPU time from them: the write ahead of the first checkpoint ~0.35 s, each later
    checkpoint ~35 ms, and the loop, delayed, leaves the network waiting for inputs. Where the thread can get
    its priority back (Linux, privileged or ``RLIMIT_NICE`` allowing it) it writes at idle priority
    (``SCHED_IDLE``), in the gaps the two leave (the loop waits for the network ~15 % of the time), and gets
    its priority back when the loop waits for it (the next checkpoint, the end), so that it is never left
    behind other work. Elsewhere it writes at the loop's priority. It paces a checkpoint's files (:class:`Pace`)
    until the loop waits for it."""

    def __init__(self) -> None:
        self._pace = Pace()
        self._thread: threading.Thread | None = None
        self._tid = 0  # the writing thread's native id while it runs at idle priority
        self._error: BaseException | None = None
        self._idle = _can_restore_priority()

    def submit(self, ckpt: Checkpoint | ArraysFile) -> None:
        self.wait()
        clock = phase_clock.active()
        ready = threading.Event()
        pace = self._pace = Pace()

        def work() -> None:
            if self._idle and _set_policy(0, True):
                self._tid = threading.get_native_id()
            ready.set()
            t0, c0 = time.perf_counter(), time.thread_time()
            try:
                ckpt.write(pace)
            except BaseException as exc:  # raised in the loop's thread by the next wait()
                self._error = exc
            if clock is not None:
                clock.add_background("checkpoint_writer", time.perf_counter() - t0, time.thread_time() - c0)

        self._thread = threading.Thread(target=work, name="cerebx-checkpoint")
        self._thread.start()
        ready.wait()  # its priority is set before wait() may restore it

    def wait(self) -> None:
        """Until the checkpoint being written is on the disk (raises what writing it raised)."""
        if self._thread is not None:
            with phase_clock.charge("checkpoint_wait"):
                self._pace.hurry()
                if self._tid and self._thread.is_alive():
                    _set_policy(self._tid, False)
                self._thread.join()
            self._thread, self._tid = None, 0
        if self._error is not None:
            err, self._error = self._error, None
            raise err


def read_head(run_dir: Path) -> dict[str, Any]:
    """The head of the checkpoint in ``run_dir`` (its first line); FileNotFoundError if there is none."""
    with open(Path(run_dir) / CHECKPOINT, "rb") as fh:
        return json.loads(fh.readline())


def load(run_dir: Path, objects: dict[str, Any]) -> tuple[dict[str, Any], Any]:
    """(head, state) of the checkpoint in ``run_dir``; ``objects``: what the pickle's string persistent ids
    stand for (the recorder)."""
    run_dir = Path(run_dir)
    with open(run_dir / CHECKPOINT, "rb") as fh:
        head = json.loads(fh.readline())
        arrays = _read_arrays(run_dir, head)
        state = _Unpickler(fh, arrays, objects).load()
    return head, state


def _read_arrays(run_dir: Path, head: dict[str, Any]) -> dict[str, np.ndarray]:
    spec = head.get("arrays")
    if not spec:
        return {}
    arrays = {}
    with open(run_dir / spec["file"], "rb") as fh:
        for key, item in spec["layout"].items():
            dtype = np.dtype(item["dtype"])
            count = int(np.prod(item["shape"], dtype=np.int64))
            fh.seek(item["offset"])
            a = np.fromfile(fh, dtype=dtype, count=count)
            if a.size != count:
                raise ValueError(f"{spec['file']}: {key} is cut short")
            arrays[key] = a.reshape(item["shape"])
    for key, starts, length, values in _read_journal(run_dir, head) or []:
        _scatter(arrays[key].reshape(-1), starts, length, values)
    return arrays


def _read_journal(run_dir: Path, head: dict[str, Any]) -> Changes | None:
    """The changed ranges in ``checkpoint.journal`` when it belongs to the committed checkpoint ``head`` (same
    trial count and arrays file), else None."""
    try:
        raw = (run_dir / JOURNAL).read_bytes()
    except FileNotFoundError:
        return None
    if not raw.startswith(_JOURNAL_MAGIC) or not head.get("arrays"):
        return None
    line_end = raw.index(b"\n")
    header = json.loads(raw[len(_JOURNAL_MAGIC):line_end])
    if header["seq"] != head["trials_done"] or header["file"] != head["arrays"]["file"]:
        return None  # a journal of a checkpoint that was never committed
    data = memoryview(raw)[line_end + 1:]
    if zlib.crc32(data) != header["crc32"]:
        raise ValueError(f"{JOURNAL} of the committed checkpoint is damaged")
    pos = 0
    changes: Changes = []
    for e in header["entries"]:
        n, length, dtype = e["count"], e["length"], np.dtype(e["dtype"])
        starts = np.frombuffer(data, np.int64, n, pos)
        pos += starts.nbytes
        values = np.frombuffer(data, dtype, n * length, pos)
        pos += values.nbytes
        changes.append((e["key"], starts, length, values))
    return changes


def remove(run_dir: Path) -> None:
    """Delete every checkpoint file in ``run_dir``."""
    for p in [*Path(run_dir).glob("checkpoint.*")]:
        p.unlink(missing_ok=True)
