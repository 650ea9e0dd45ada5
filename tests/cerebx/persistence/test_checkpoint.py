"""Checkpoint files (``persistence/checkpoint.py``): the tracked arrays whole in the first checkpoint, only their
changed ranges in later ones, and a crash at any point leaving one whole checkpoint, the old or the new."""

from __future__ import annotations

import io
import os
import pickle
import threading
from types import SimpleNamespace

import cloudpickle
import numpy as np
import pytest

from cerebx.persistence import checkpoint


class Tracked:
    """A learned array that says which of its rows changed, as the spiking network does."""

    def __init__(self, rows: int, cols: int):
        self.w = np.zeros(rows * cols, np.float32)
        self.cols = cols
        self.dirty: set[int] = set()
        self.step = 0

    def learn(self, rows: list[int]) -> None:
        self.step += 1
        for r in rows:
            self.w[r * self.cols:(r + 1) * self.cols] += r + 0.5
            self.dirty.add(r)

    def changed_ranges(self):
        starts = np.array(sorted(self.dirty), np.int64) * self.cols
        self.dirty.clear()
        return [(self.w, starts, self.cols)]


def _write(run_dir, trials, state, store):
    ckpt = checkpoint.prepare(run_dir, {"trials_done": trials}, state, store, {})
    ckpt.write()
    return ckpt


def _load(run_dir):
    head, state = checkpoint.load(run_dir, {})
    return head["trials_done"], state


def test_later_checkpoints_write_only_changed_rows_and_load_whole(tmp_path):
    net, store = Tracked(50, 8), checkpoint.ArrayStore()
    net.learn([1, 2])
    first = _write(tmp_path, 10, {"net": net, "other": np.arange(3)}, store)
    assert first.whole is not None and not first.changes
    net.learn([7])
    second = _write(tmp_path, 20, {"net": net, "other": np.arange(3)}, store)
    assert second.whole is None and [c[1].tolist() for c in second.changes] == [[7 * 8]]
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "checkpoint.10.arrays", "checkpoint.journal", "checkpoint.pkl", "checkpoint.pkl.json"]
    done, state = _load(tmp_path)
    assert done == 20 and state["net"].step == 2
    np.testing.assert_array_equal(state["net"].w, net.w)
    np.testing.assert_array_equal(state["other"], np.arange(3))
    checkpoint.remove(tmp_path)
    assert not list(tmp_path.iterdir())


def test_a_crash_before_the_commit_leaves_the_previous_checkpoint(tmp_path):
    net, store = Tracked(20, 4), checkpoint.ArrayStore()
    net.learn([3])
    _write(tmp_path, 5, {"net": net}, store)
    net.learn([4])
    _write(tmp_path, 10, {"net": net}, store)
    at_10 = net.w.copy()
    net.learn([3, 9])
    ckpt = checkpoint.prepare(tmp_path, {"trials_done": 15}, {"net": net}, store, {})
    checkpoint._write_file(tmp_path / checkpoint.JOURNAL, ckpt._journal(15))  # died right after the journal
    done, state = _load(tmp_path)
    assert done == 10
    np.testing.assert_array_equal(state["net"].w, at_10)


def test_a_crash_after_the_commit_replays_the_journal(tmp_path):
    net, store = Tracked(20, 4), checkpoint.ArrayStore()
    net.learn([3])
    _write(tmp_path, 5, {"net": net}, store)
    net.learn([3, 9])
    ckpt = checkpoint.prepare(tmp_path, {"trials_done": 10}, {"net": net}, store, {})
    ckpt._apply = lambda: None  # died before the ranges reached the arrays file
    ckpt.write()
    done, state = _load(tmp_path)
    assert done == 10
    np.testing.assert_array_equal(state["net"].w, net.w)
    raw = bytearray((tmp_path / checkpoint.JOURNAL).read_bytes())
    raw[-1] ^= 0xFF
    (tmp_path / checkpoint.JOURNAL).write_bytes(bytes(raw))
    with pytest.raises(ValueError, match="damaged"):
        _load(tmp_path)


def test_a_new_process_writes_whole_again(tmp_path):
    net = Tracked(10, 4)
    net.learn([1])
    _write(tmp_path, 5, {"net": net}, checkpoint.ArrayStore())
    resumed = _load(tmp_path)[1]["net"]
    resumed.learn([2])
    ckpt = _write(tmp_path, 10, {"net": resumed}, checkpoint.ArrayStore())
    assert ckpt.whole is not None
    assert sorted(p.name for p in tmp_path.glob("*.arrays")) == ["checkpoint.10.arrays"]
    np.testing.assert_array_equal(_load(tmp_path)[1]["net"].w, resumed.w)


def test_writer_raises_what_writing_raised(tmp_path):
    net, store = Tracked(4, 2), checkpoint.ArrayStore()
    writer = checkpoint.Writer()
    writer.submit(checkpoint.prepare(tmp_path / "missing", {"trials_done": 1}, {"net": net}, store, {}))
    with pytest.raises(FileNotFoundError):
        writer.wait()
    writer.wait()  # raised once


# ---------------------------------------------------------------- changed ranges: copied, scattered, written


def _ranges_by_index(flat, starts, length):
    return np.concatenate([flat[s:s + length] for s in starts]) if len(starts) else flat[:0]


@pytest.mark.parametrize("dtype", [np.float32, np.float64, np.int64])
def test_gather_and_scatter_ranges(dtype):
    rng = np.random.default_rng(3)
    rows, cols = 97, 13
    flat = rng.normal(size=rows * cols).astype(dtype)
    picks = {
        "random": np.sort(rng.choice(rows, 30, replace=False)),
        "first and last": np.array([0, rows - 1]),
        "adjacent": np.array([4, 5, 6, 40, 41, 96]),
        "none": np.zeros(0, np.int64),
        "unsorted": np.array([50, 2, 51]),
    }
    for what, picked in picks.items():
        starts = picked.astype(np.int64) * cols
        got = checkpoint._gather(flat, starts, cols)
        assert got.dtype == flat.dtype and got.shape == (len(starts) * cols,), what
        np.testing.assert_array_equal(got, _ranges_by_index(flat, starts, cols), err_msg=what)
        target = np.zeros_like(flat)
        checkpoint._scatter(target, starts, cols, got)
        expect = np.zeros_like(flat)
        for s in starts:
            expect[s:s + cols] = flat[s:s + cols]
        np.testing.assert_array_equal(target, expect, err_msg=what)
    whole = checkpoint._gather(flat, np.zeros(1, np.int64), flat.size)  # one range: all of it
    np.testing.assert_array_equal(whole, flat)
    # ranges that need not be rows: any offsets, overlapping ones scattered in order
    np.testing.assert_array_equal(checkpoint._gather(flat, np.array([1, 3]), 4), flat[[1, 2, 3, 4, 3, 4, 5, 6]])
    target = np.zeros(8, dtype)
    checkpoint._scatter(target, np.array([0, 2]), 3, np.arange(1, 7).astype(dtype))
    np.testing.assert_array_equal(target, np.array([1, 2, 4, 5, 6, 0, 0, 0], dtype))
    # read-only values (a journal read from the disk)
    values = np.frombuffer(np.arange(6, dtype=dtype).tobytes(), dtype)
    checkpoint._scatter(target, np.array([5, 0]), 3, values)
    np.testing.assert_array_equal(target, np.array([3, 4, 5, 5, 6, 0, 1, 2], dtype))


def test_ranges_outside_the_array_are_refused():
    flat = np.zeros(20, np.float32)
    for starts, length in [(np.array([18]), 3), (np.array([-1]), 2), (np.array([0, 17]), 4)]:
        with pytest.raises(ValueError, match="outside"):
            checkpoint._gather(flat, starts, length)
        with pytest.raises(ValueError, match="outside"):
            checkpoint._scatter(flat, starts, length, np.zeros(len(starts) * length, np.float32))
    with pytest.raises(ValueError):
        checkpoint._scatter(flat, np.array([0]), 4, np.zeros(5, np.float32))
    checkpoint._gather(flat, np.array([0, 17]), 3)  # up to the last element


def test_apply_writes_the_ranges_in_place_without_a_write_call_per_range_and_flushes(tmp_path, monkeypatch):
    rows, cols = 40, 6
    old = np.arange(rows * cols, dtype=np.float32)
    before = np.zeros(8, np.int64)  # an array before it in the file
    after = np.arange(5, dtype=np.float64)  # and one after it
    layout = checkpoint._layout({"a0": before, "a1": old, "a2": after})
    path = tmp_path / "x.arrays"
    checkpoint._write_file(path, checkpoint._whole_parts([before, old, after]))
    size = path.stat().st_size
    rows_starts = np.array([0, 1, 2, 9, 20, 21, 39], np.int64) * cols  # first row, adjacent rows, last row
    rows_values = -np.arange(len(rows_starts) * cols, dtype=np.float32)
    odd_starts = np.array([1, 3], np.int64)  # ranges that are not rows
    odd_values = np.array([-1.0, -2.0, -3.0, -4.0])
    calls = {"pwrite": 0, "fsync": 0}
    pwrite, fsync = checkpoint.os.pwrite, checkpoint.os.fsync

    def counted_pwrite(fd, data, offset):
        calls["pwrite"] += 1
        return pwrite(fd, data, offset)

    def counted_fsync(fd):
        calls["fsync"] += 1
        return fsync(fd)

    monkeypatch.setattr(checkpoint.os, "pwrite", counted_pwrite)
    monkeypatch.setattr(checkpoint.os, "fsync", counted_fsync)
    checkpoint._apply_file(path, layout, [("a1", rows_starts, cols, rows_values), ("a2", odd_starts, 2, odd_values)])
    assert calls == {"pwrite": 0, "fsync": 1}
    assert path.stat().st_size == size
    expect = old.copy()  # computed without _scatter, which _apply_file uses
    expect.reshape(rows, cols)[rows_starts // cols] = rows_values.reshape(-1, cols)
    expect_after = after.copy()
    checkpoint._scatter(expect_after, odd_starts, 2, odd_values)
    raw = path.read_bytes()
    np.testing.assert_array_equal(np.frombuffer(raw, np.int64, 8, 0), before)
    np.testing.assert_array_equal(np.frombuffer(raw, np.float32, rows * cols, layout["a1"]["offset"]), expect)
    np.testing.assert_array_equal(np.frombuffer(raw, np.float64, 5, layout["a2"]["offset"]), expect_after)
    assert expect_after.tolist() == [0.0, -1.0, -2.0, -3.0, -4.0]


def test_apply_raises_a_bad_range_and_leaves_the_file_readable(tmp_path):
    old = np.arange(12, dtype=np.float32)
    layout = checkpoint._layout({"a0": old})
    path = tmp_path / "x.arrays"
    checkpoint._write_file(path, checkpoint._whole_parts([old]))
    with pytest.raises(ValueError, match="outside"):
        checkpoint._apply_file(path, layout, [("a0", np.array([11], np.int64), 3, np.zeros(3, np.float32))])
    np.testing.assert_array_equal(np.frombuffer(path.read_bytes(), np.float32), old)


def test_the_pickler_fast_paths_change_no_byte():
    class Persistent:
        pass

    class Sub(Persistent):
        pass

    plain = {"a": [1, 2.5, "s", b"b", (3, None, True)], "f": np.float64(1.5), "x": np.arange(5.0),
             "d": np.dtype("f4"), "set": {1, 2}, "fn": _load}
    store = checkpoint.ArrayStore()
    stream = checkpoint._dumps(plain, store, {Persistent: "p"})
    assert bytes(stream) == cloudpickle.dumps(plain, protocol=pickle.HIGHEST_PROTOCOL)
    net = Tracked(3, 2)
    net.learn([1])
    state = {"p": Persistent(), "s": Sub(), "net": net, "again": [Sub(), net.w]}
    stream = checkpoint._dumps(state, checkpoint.ArrayStore(), {Persistent: "p"})
    out = checkpoint._Unpickler(io.BytesIO(stream), {"a0": "W"}, {"p": "P"}).load()
    assert out["p"] == out["s"] == out["again"][0] == "P" and out["again"][1] == "W" and out["net"].w == "W"


# ---------------------------------------------------------------- the arrays file written ahead (prime)


def _torn_writes(monkeypatch, at_byte, during):
    """The writer writes each array in two pieces, split at ``at_byte``, and ``during()`` runs between them
    (the network learning while the arrays are written)."""
    write_file = checkpoint._write_file

    def pieces(parts):
        for part in parts:
            if len(part) > at_byte:
                yield part[:at_byte]
                during()
                yield part[at_byte:]
            else:
                yield part

    monkeypatch.setattr(checkpoint, "_write_file", lambda path, parts: write_file(path, pieces(parts)))


def test_arrays_written_ahead_from_the_live_arrays_give_the_state_of_the_checkpoint(tmp_path, monkeypatch):
    rows, cols = 30, 4
    net, store = Tracked(rows, cols), checkpoint.ArrayStore()
    net.learn(range(rows))
    job = checkpoint.prime(tmp_path, 10, {"net": net}, store, {})
    assert job is not None and job.name == "checkpoint.10.arrays"
    # mid-write, rows 2 (written already), 11 (torn: its middle is where the write pauses) and 25 (not yet
    # written) change; the write sees 2 old, 11 half old half new, 25 new
    _torn_writes(monkeypatch, (11 * cols + 2) * 4, lambda: net.learn([2, 11, 25]))
    job.write()
    monkeypatch.undo()
    assert job.done
    on_disk = np.fromfile(tmp_path / job.name, np.float32)
    assert on_disk[2 * cols] != net.w[2 * cols] and on_disk[11 * cols] != net.w[11 * cols]
    assert on_disk[11 * cols + 3] == net.w[11 * cols + 3] and on_disk[25 * cols] == net.w[25 * cols]
    net.learn([0, 29])  # after the write
    at_10 = net.w.copy()
    ckpt = checkpoint.prepare(tmp_path, {"trials_done": 10}, {"net": net}, store, {})
    assert ckpt.whole is None and ckpt.file == job.name  # only a journal on top of the file written ahead
    assert sorted((ckpt.changes[0][1] // cols).tolist()) == [0, 2, 11, 25, 29]
    ckpt._apply = lambda: None  # died right after the commit
    ckpt.write()
    np.testing.assert_array_equal(_load(tmp_path)[1]["net"].w, at_10)
    del ckpt._apply
    ckpt.write()  # or not
    np.testing.assert_array_equal(np.fromfile(tmp_path / job.name, np.float32), at_10)
    np.testing.assert_array_equal(_load(tmp_path)[1]["net"].w, at_10)
    net.learn([5])
    later = _write(tmp_path, 20, {"net": net}, store)
    assert later.whole is None
    np.testing.assert_array_equal(_load(tmp_path)[1]["net"].w, net.w)


def test_a_crash_while_writing_ahead_leaves_no_checkpoint_or_the_previous_one(tmp_path, monkeypatch):
    net = Tracked(10, 4)
    net.learn([1])
    job = checkpoint.prime(tmp_path, 10, {"net": net}, checkpoint.ArrayStore(), {})

    def crash():
        raise KeyboardInterrupt

    _torn_writes(monkeypatch, 8, crash)
    with pytest.raises(KeyboardInterrupt):
        job.write()
    assert not job.done and not (tmp_path / checkpoint.CHECKPOINT).exists()
    monkeypatch.undo()
    with pytest.raises(FileNotFoundError):
        _load(tmp_path)


def test_a_resumed_run_settles_the_committed_journal_before_replacing_it(tmp_path):
    net, store = Tracked(20, 4), checkpoint.ArrayStore()
    net.learn([3])
    _write(tmp_path, 5, {"net": net}, store)
    net.learn([3, 9])
    ckpt = checkpoint.prepare(tmp_path, {"trials_done": 10}, {"net": net}, store, {})
    ckpt._apply = lambda: None  # killed after the commit: checkpoint.5.arrays lacks the rows of trial 10
    ckpt.write()
    at_10 = net.w.copy()
    resumed = _load(tmp_path)[1]["net"]  # a new process
    store = checkpoint.ArrayStore()
    job = checkpoint.prime(tmp_path, 15, {"net": resumed}, store, {})
    job.write()
    assert job.done and sorted(p.name for p in tmp_path.glob("*.arrays")) == [
        "checkpoint.15.arrays", "checkpoint.5.arrays"]
    np.testing.assert_array_equal(np.fromfile(tmp_path / "checkpoint.5.arrays", np.float32), at_10)
    resumed.learn([7])
    first = checkpoint.prepare(tmp_path, {"trials_done": 15}, {"net": resumed}, store, {})
    assert first.whole is None
    checkpoint._write_file(tmp_path / checkpoint.JOURNAL, first._journal(15))  # died right after the journal
    done, state = _load(tmp_path)
    assert done == 10
    np.testing.assert_array_equal(state["net"].w, at_10)
    first.write()
    done, state = _load(tmp_path)
    assert done == 15 and sorted(p.name for p in tmp_path.glob("*.arrays")) == ["checkpoint.15.arrays"]
    np.testing.assert_array_equal(state["net"].w, resumed.w)


def test_nothing_is_written_ahead_over_the_committed_arrays_file(tmp_path):
    net = Tracked(6, 2)
    net.learn([1])
    _write(tmp_path, 10, {"net": net}, checkpoint.ArrayStore())
    assert checkpoint.prime(tmp_path, 10, {"net": net}, checkpoint.ArrayStore(), {}) is None
    assert checkpoint.prime(tmp_path, 20, {"net": np.zeros(3)}, checkpoint.ArrayStore(), {}) is None  # untracked


def test_when_writing_ahead_fails_the_first_checkpoint_is_whole(tmp_path, monkeypatch):
    net, store = Tracked(6, 2), checkpoint.ArrayStore()
    job = checkpoint.prime(tmp_path, 10, {"net": net}, store, {})

    def fail(path, parts):
        raise OSError("no space left")

    monkeypatch.setattr(checkpoint, "_write_file", fail)
    job.write()
    monkeypatch.undo()
    assert not job.done
    net.learn([4])
    ckpt = _write(tmp_path, 10, {"net": net}, store)
    assert ckpt.whole is not None
    np.testing.assert_array_equal(_load(tmp_path)[1]["net"].w, net.w)


def test_the_checkpointer_writes_ahead_only_when_a_checkpoint_is_due(tmp_path):
    from cerebx.loop import resume  # imports the closed loop

    net = Tracked(6, 2)

    def loop(done, trials, every):
        cfg = SimpleNamespace(trials=trials, recording=SimpleNamespace(checkpoint_every=every),
                              model_dump=lambda **_: {})
        return SimpleNamespace(cfg=cfg, trials_done=done, ctx={"net": net}, tick=0, dt_s=0.01, metrics=[],
                               _sensed=None, _task_rng=None, _events=[], window=None, _last_held=None)

    for done, trials, every, expect in [(0, 10, 10, None), (0, 11, 10, 10), (3, 30, 10, 10), (10, 30, 10, 20),
                                        (0, 30, 0, None)]:
        ck = resume.Checkpointer(tmp_path / f"{done}-{trials}-{every}")
        ck.run_dir.mkdir()
        ck.prime(loop(done, trials, every))
        ck.writer.wait()
        names = [p.name for p in ck.run_dir.iterdir()]
        assert names == ([] if expect is None else [f"checkpoint.{expect}.arrays"]), (done, trials, every)
        ck.close()  # the run stopped before its first checkpoint: nothing is left
        assert not list(ck.run_dir.iterdir())
    ck = resume.Checkpointer(tmp_path / "saved")  # once used by a checkpoint, the file stays
    ck.run_dir.mkdir()
    ck.prime(loop(0, 30, 10))
    net.learn([2])
    ck.save(loop(10, 30, 10), 1.0)
    ck.close()
    assert sorted(p.name for p in ck.run_dir.iterdir()) == [
        "checkpoint.10.arrays", "checkpoint.journal", "checkpoint.pkl", "checkpoint.pkl.json"]
    np.testing.assert_array_equal(_load(ck.run_dir)[1]["ctx"]["net"].w, net.w)


@pytest.mark.skipif(not checkpoint._can_restore_priority(), reason="needs a thread that can take its priority back")
def test_the_writer_writes_at_idle_priority_and_gets_its_priority_back_when_waited_for():
    started, go_on = threading.Event(), threading.Event()
    seen = []

    class Job:
        def write(self, pace):
            seen.append(os.sched_getscheduler(0))
            started.set()
            go_on.wait(10)
            seen.append(os.sched_getscheduler(0))

    writer = checkpoint.Writer()
    writer.submit(Job())
    started.wait(10)
    threading.Timer(0.2, go_on.set).start()  # still writing when the loop waits for it
    writer.wait()
    assert seen == [os.SCHED_IDLE, os.SCHED_OTHER]
    assert os.sched_getscheduler(0) == os.SCHED_OTHER  # the loop's own thread is left as it was


def test_a_writer_that_could_not_get_its_priority_back_writes_at_the_loops(monkeypatch):
    monkeypatch.setattr(checkpoint, "_can_restore_priority", lambda: False)
    seen = []

    class Job:
        def write(self, pace):
            seen.append(os.sched_getscheduler(0) if hasattr(os, "sched_getscheduler") else None)

    writer = checkpoint.Writer()
    writer.submit(Job())
    writer.wait()
    assert seen[0] != getattr(os, "SCHED_IDLE", -1)


def test_the_networks_fixed_arrays_go_into_the_arrays_file_once_and_come_back(tmp_path):
    """The spiking network reports the arrays it never writes after its build (its sparse tables, resting
    potentials) as tracked: the first checkpoint puts them in the arrays file, later pickles only name them, and
    a loaded network goes on as the original. Driving the network leaves them as they were."""
    from cerebx.snn.network import Network
    from cerebx.snn.presets import network as full_network

    net = Network(full_network(fibers=5, per_joint=20), parallel=False)
    fixed = [a.copy() for a in net._fixed()]
    mf = net.index("mf")
    rng = np.random.default_rng(0)

    def drive(n, network):
        for _ in range(n):
            network.step(rng.choice(np.arange(mf.start, mf.stop, dtype=np.int32), 12, replace=False))

    drive(50, net)
    store = checkpoint.ArrayStore()
    first = _write(tmp_path, 10, {"net": net}, store)
    assert first.whole is not None and len(first.whole) == 1 + len(net._fixed())
    drive(50, net)
    plain = len(pickle.dumps(net))
    second = _write(tmp_path, 20, {"net": net}, store)
    fixed_bytes = sum(a.nbytes for a in net._fixed())
    assert second.whole is None and len(second.stream) < plain - fixed_bytes + 1024
    assert all(len(starts) == 0 for key, starts, _, _ in second.changes if key != store.key_of[id(net.dense_w)])
    for a, b in zip(net._fixed(), fixed):
        np.testing.assert_array_equal(a, b)
    _, state = _load(tmp_path)
    loaded = state["net"]
    for a, b in zip(loaded._fixed(), fixed):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(loaded.dense_w, net.dense_w)
    rng_a, rng_b = np.random.default_rng(5), np.random.default_rng(5)
    for _ in range(40):
        sa = net.step(rng_a.choice(np.arange(mf.start, mf.stop, dtype=np.int32), 12, replace=False))
        sb = loaded.step(rng_b.choice(np.arange(mf.start, mf.stop, dtype=np.int32), 12, replace=False))
        np.testing.assert_array_equal(sa.idx, sb.idx)
    np.testing.assert_array_equal(loaded.dense_w, net.dense_w)


def test_a_paced_write_writes_the_same_file_a_piece_at_a_time(tmp_path, monkeypatch):
    monkeypatch.setattr(checkpoint, "PACE_PIECE", 1000)
    naps = []

    class Counting(checkpoint.Pace):
        def nap(self):
            naps.append(1)

    parts = [b"head\n", np.arange(1500, dtype=np.float32), memoryview(b"x" * 10)]
    checkpoint._write_file(tmp_path / "plain", parts)
    checkpoint._write_file(tmp_path / "paced", parts, Counting())
    assert (tmp_path / "paced").read_bytes() == (tmp_path / "plain").read_bytes()
    assert len(naps) == 1 + 6 + 1  # 5 bytes, 6000 bytes in pieces of 1000, 10 bytes
    assert not list(tmp_path.glob("*.tmp"))


def test_waiting_for_the_writer_drops_the_naps_of_a_paced_checkpoint(monkeypatch):
    """A nap would last a minute here: the loop's wait for the writer must not sit through them."""
    monkeypatch.setattr(checkpoint, "PACE_NAP_S", 60.0)
    napped = []

    class Job:
        def write(self, pace):
            for _ in range(3):
                pace.nap()
                napped.append(1)

    writer = checkpoint.Writer()
    writer.submit(Job())
    waiting = threading.Thread(target=writer.wait, daemon=True)
    waiting.start()
    waiting.join(timeout=20)
    assert not waiting.is_alive() and napped == [1, 1, 1]
