"""The recorder's early chunks: :meth:`Recorder.idle` finishes the MCAP chunk being filled once it holds
:data:`EARLY_CHUNK` of a chunk's size, and changes nothing else in the file."""

from __future__ import annotations

import numpy as np
from mcap.reader import make_reader

from cerebx.recording.recorder import EARLY_CHUNK, Recorder

CHUNK_KB = 16


def _log(path, compression: str = "zstd", idle_every: int | None = None) -> None:
    """200 ``/control`` messages of ~0.5 kB and joint states, with ``idle`` after every ``idle_every``."""
    rec = Recorder(path, joint_names=("a", "b"), chunk_size_kb=CHUNK_KB, compression=compression)
    rng = np.random.default_rng(0)
    for k in range(200):
        t = k * 0.002
        rec.write("/control", "cerebx.Control", t, {"t": t, "trial": 0, "tau_controller": rng.normal(size=20)})
        rec.joint_states("/joint_states/actual", t, rng.normal(size=2), rng.normal(size=2))
        if idle_every and k % idle_every == idle_every - 1:
            rec.idle()
    rec.close()


def _read(path) -> tuple[list[tuple[str, int, bytes]], list[int]]:
    """Every message (topic, log time, bytes) in file order, and each chunk's uncompressed size."""
    with open(path, "rb") as f:
        reader = make_reader(f)
        messages = [(ch.topic, m.log_time, m.data) for _, ch, m in reader.iter_messages(log_time_order=False)]
        f.seek(0)
        sizes = [c.uncompressed_size for c in make_reader(f).get_summary().chunk_indexes]
    return messages, sizes


def test_idle_finishes_the_chunk_early_and_keeps_every_message(tmp_path):
    _log(tmp_path / "plain.mcap")
    _log(tmp_path / "early.mcap", idle_every=4)
    plain, plain_sizes = _read(tmp_path / "plain.mcap")
    early, early_sizes = _read(tmp_path / "early.mcap")
    assert early == plain
    assert len(early_sizes) > len(plain_sizes)
    # finished by idle: from EARLY_CHUNK of the size on, and before the writer would have (the last one is
    # finished by close)
    assert all(EARLY_CHUNK * CHUNK_KB * 1024 <= s < CHUNK_KB * 1024 for s in early_sizes[:-1])


def test_idle_below_the_threshold_or_without_compression_leaves_the_file_as_it_was(tmp_path):
    _log(tmp_path / "plain.mcap", compression="none")
    _log(tmp_path / "early.mcap", compression="none", idle_every=4)
    assert (tmp_path / "early.mcap").read_bytes() == (tmp_path / "plain.mcap").read_bytes()
    rec = Recorder(tmp_path / "one.mcap", chunk_size_kb=CHUNK_KB)
    rec.write("/control", "cerebx.Control", 0.0, {"t": 0.0})
    rec.idle()  # far below the threshold: the chunk goes on filling
    rec.write("/control", "cerebx.Control", 0.002, {"t": 0.002})
    rec.close()
    assert len(_read(tmp_path / "one.mcap")[1]) == 1


def test_the_same_messages_and_idles_give_the_same_file(tmp_path):
    _log(tmp_path / "a.mcap", idle_every=3)
    _log(tmp_path / "b.mcap", idle_every=3)
    assert (tmp_path / "a.mcap").read_bytes() == (tmp_path / "b.mcap").read_bytes()


def test_idle_after_close_does_nothing(tmp_path):
    rec = Recorder(tmp_path / "x.mcap", chunk_size_kb=CHUNK_KB)
    for k in range(100):
        rec.write("/control", "cerebx.Control", k * 0.002, {"t": k * 0.002, "tau_controller": list(range(30))})
    rec.close()
    rec.idle()  # e.g. a network chunk collected after the log was finished
    assert len(_read(tmp_path / "x.mcap")[0]) == 100
