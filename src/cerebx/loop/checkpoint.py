"""Checkpoint files, written off the loop's thread and atomically, with the large learned arrays rewritten
only where they changed (``loop/resume.py`` decides what goes in and when).

A checkpoint is

- ``checkpoint.pkl``: one line of JSON, the head (:func:`read_head`), then the pickled state (cloudpickle).
  Written to a temporary file, flushed to the disk, then renamed over the old one: that rename commits it.
- ``checkpoint.<n>.arrays``: the arrays an object of the state tracks (a ``changed_ranges()`` method, e.g. the
  spiking network's weights, 145 MB for the full network), stored beside the pickle, which refers to them by
  key. The first checkpoint a process writes puts them whole into a new file (``<n>``: its trial count);
  each later one writes only the ranges changed since (a few % of the PF-PC rows per 10 trials), first into
  ``checkpoint.journal`` (flushed to the disk), then commits the pickle, then writes the ranges into the
  arrays file in place.

A crash at any moment leaves the previous checkpoint or the new one, whole: before the commit the old
pickle names the old arrays file, which a full write never touches (a new file) and a journal of a newer
checkpoint leaves alone; after it, the journal of the committed checkpoint is complete on the disk and
:func:`load` applies it again (it holds values, not increments), whatever part of it reached the arrays file.

The loop's thread only pickles (into memory) and copies the changed ranges; a :class:`Writer` thread does
the writing and flushing, one checkpoint at a time.
"""

from __future__ import annotations

import io
import json
import os
import pickle
import threading
import time
import zlib
from pathlib import Path
from typing import Any

import cloudpickle
import numpy as np

from cerebx import phase_clock, runfiles

CHECKPOINT = runfiles.CHECKPOINT
JOURNAL = "checkpoint.journal"
_JOURNAL_MAGIC = b"CXJ1"
_ALIGN = 64


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


class _Pickler(cloudpickle.Pickler):
    def __init__(self, fh: Any, store: ArrayStore, persistent: dict[type, str]):
        super().__init__(fh, protocol=pickle.HIGHEST_PROTOCOL)
        self.store = store
        self.persistent = persistent
        self.how: dict[type, tuple[str, Any]] = {}  # per class, decided once: the state has ~50 k objects

    def persistent_id(self, obj: Any) -> Any:
        cls = type(obj)
        if cls is np.ndarray:
            key = self.store.ref(obj)
            return None if key is None else ("array", key)
        how = self.how.get(cls)
        if how is None:
            how = self.how[cls] = self._classify(cls)
        if how[0] == "id":
            return how[1]
        if how[0] == "tracked":
            self.store.ask(obj, how[1])
        return None

    def _classify(self, cls: type) -> tuple[str, Any]:
        for kind, pid in self.persistent.items():
            if issubclass(cls, kind):
                return "id", pid
        changed = getattr(cls, "changed_ranges", None)
        if changed is not None and cls is not type:
            return "tracked", changed
        return "plain", None


class _Unpickler(pickle.Unpickler):
    def __init__(self, fh: Any, arrays: dict[str, np.ndarray], objects: dict[str, Any]):
        super().__init__(fh)
        self.arrays, self.objects = arrays, objects

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


def _write_file(path: Path, parts: list[Any]) -> None:
    """Write ``parts`` (bytes-like) into ``path`` through a temporary file, flushed, then renamed."""
    tmp = path.with_name(path.name + ".tmp")
    with open(tmp, "wb") as fh:
        for part in parts:
            fh.write(part)
        fh.flush()
        os.fsync(fh.fileno())
    os.replace(tmp, path)


def _raw(a: np.ndarray) -> memoryview:
    return memoryview(np.ascontiguousarray(a)).cast("B")


class Checkpoint:
    """One checkpoint, ready to be written: the pickle and the arrays (whole or the changed ranges)."""

    def __init__(self, run_dir: Path, head: dict[str, Any], stream: memoryview, whole: dict[str, np.ndarray] | None,
                 changes: list[tuple[str, np.ndarray, int, np.ndarray]], layout: dict[str, dict[str, Any]],
                 file: str | None):
        self.run_dir, self.head, self.stream = run_dir, head, stream
        self.whole, self.changes, self.layout, self.file = whole, changes, layout, file

    def write(self) -> None:
        run_dir, seq = self.run_dir, self.head["trials_done"]
        if self.whole is not None:
            parts: list[Any] = []
            size = 0
            for a in self.whole.values():
                pad = -size % _ALIGN
                parts.append(b"\0" * pad)
                size += pad + a.nbytes
                parts.append(_raw(a))
            _write_file(run_dir / self.file, parts)
        elif self.changes:
            _write_file(run_dir / JOURNAL, self._journal(seq))
        _write_file(run_dir / CHECKPOINT, [json.dumps(self.head).encode() + b"\n", self.stream])
        _fsync_dir(run_dir)  # the renames are on the disk too
        if self.whole is None and self.changes:
            self._apply()
        for p in run_dir.glob("checkpoint.*.arrays"):
            if p.name != self.file:
                p.unlink(missing_ok=True)
        if self.whole is not None:
            (run_dir / JOURNAL).unlink(missing_ok=True)
        tmp_head = run_dir / (runfiles.CHECKPOINT_HEAD + ".tmp")  # a copy of the head for people and tools
        tmp_head.write_text(json.dumps(self.head))
        os.replace(tmp_head, run_dir / runfiles.CHECKPOINT_HEAD)

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
        fd = os.open(self.run_dir / self.file, os.O_WRONLY)
        try:
            for key, starts, length, values in self.changes:
                _pwrite_ranges(fd, self.layout[key]["offset"], starts, length, values)
            os.fsync(fd)
        finally:
            os.close(fd)


def _pwrite_ranges(fd: int, offset: int, starts: np.ndarray, length: int, values: np.ndarray) -> None:
    item = values.dtype.itemsize
    rows = values.reshape(len(starts), length)
    for start, row in zip(starts.tolist(), rows):
        os.pwrite(fd, _raw(row), offset + start * item)


def prepare(run_dir: Path, head: dict[str, Any], state: Any, store: ArrayStore,
            persistent: dict[type, str]) -> Checkpoint:
    """Pickle ``state`` and copy what changed (the loop's thread; the state must not change meanwhile)."""
    store.begin()
    stream = _dumps(state, store, persistent)
    seq = head["trials_done"]
    whole = None
    changes: list[tuple[str, np.ndarray, int, np.ndarray]] = []
    if store.full():
        whole = {k: store.arrays[k].copy() for k in sorted(store.used, key=lambda k: int(k[1:]))}
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


def _dumps(state: Any, store: ArrayStore, persistent: dict[type, str]) -> memoryview:
    buf = io.BytesIO()
    _Pickler(buf, store, persistent).dump(state)
    return buf.getbuffer()


def _gather(flat: np.ndarray, starts: np.ndarray, length: int) -> np.ndarray:
    """The ranges ``flat[s:s + length]`` for s in ``starts``, one after the other (a copy)."""
    if len(starts) <= 16:  # few long ranges (a whole array): slices, no index array
        return np.concatenate([flat[s:s + length] for s in starts.tolist()])
    return flat[(starts[:, None] + np.arange(length, dtype=np.int64)).reshape(-1)]


def _scatter(flat: np.ndarray, starts: np.ndarray, length: int, values: np.ndarray) -> None:
    rows = values.reshape(len(starts), length)
    if len(starts) <= 16:
        for s, row in zip(starts.tolist(), rows):
            flat[s:s + length] = row
    else:
        flat[(starts[:, None] + np.arange(length, dtype=np.int64)).reshape(-1)] = values


def _layout(arrays: dict[str, np.ndarray]) -> dict[str, dict[str, Any]]:
    out, offset = {}, 0
    for key, a in arrays.items():
        offset += -offset % _ALIGN
        out[key] = {"offset": offset, "dtype": a.dtype.str, "shape": list(a.shape)}
        offset += a.nbytes
    return out


class Writer:
    """Writes checkpoints on a thread of its own, one at a time; an error is raised by the next call."""

    def __init__(self) -> None:
        self._thread: threading.Thread | None = None
        self._error: BaseException | None = None

    def submit(self, ckpt: Checkpoint) -> None:
        self.wait()
        clock = phase_clock.active()

        def work() -> None:
            t0, c0 = time.perf_counter(), time.thread_time()
            try:
                ckpt.write()
            except BaseException as exc:  # raised in the loop's thread by the next wait()
                self._error = exc
            if clock is not None:
                clock.add_background("checkpoint_writer", time.perf_counter() - t0, time.thread_time() - c0)

        self._thread = threading.Thread(target=work, name="cerebx-checkpoint")
        self._thread.start()

    def wait(self) -> None:
        """Until the checkpoint being written is on the disk (raises what writing it raised)."""
        if self._thread is not None:
            with phase_clock.charge("checkpoint_wait"):
                self._thread.join()
            self._thread = None
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
    _apply_journal(run_dir, head, arrays)
    return arrays


def _apply_journal(run_dir: Path, head: dict[str, Any], arrays: dict[str, np.ndarray]) -> None:
    """Apply ``checkpoint.journal`` when it belongs to the committed checkpoint (same trial count and file)."""
    try:
        raw = (run_dir / JOURNAL).read_bytes()
    except FileNotFoundError:
        return
    if not raw.startswith(_JOURNAL_MAGIC):
        return
    line_end = raw.index(b"\n")
    header = json.loads(raw[len(_JOURNAL_MAGIC):line_end])
    if header["seq"] != head["trials_done"] or header["file"] != head["arrays"]["file"]:
        return  # a journal of a checkpoint that was never committed
    data = memoryview(raw)[line_end + 1:]
    if zlib.crc32(data) != header["crc32"]:
        raise ValueError(f"{JOURNAL} of the committed checkpoint is damaged")
    pos = 0
    for e in header["entries"]:
        n, length, dtype = e["count"], e["length"], np.dtype(e["dtype"])
        starts = np.frombuffer(data, np.int64, n, pos)
        pos += starts.nbytes
        values = np.frombuffer(data, dtype, n * length, pos)
        pos += values.nbytes
        _scatter(arrays[e["key"]].reshape(-1), starts, length, values)


def remove(run_dir: Path) -> None:
    """Delete every checkpoint file in ``run_dir``."""
    for p in [*Path(run_dir).glob("checkpoint.*")]:
        p.unlink(missing_ok=True)
