"""Checkpoint files (``loop/checkpoint.py``): the tracked arrays whole in the first checkpoint, only their
changed ranges in later ones, and a crash at any point leaving one whole checkpoint, the old or the new."""

from __future__ import annotations

import numpy as np
import pytest

from cerebx.loop import checkpoint


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
