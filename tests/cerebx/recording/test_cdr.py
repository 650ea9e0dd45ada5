"""Joint states and spikes in CDR: what the encoders write is a valid ``sensor_msgs/msg/JointState`` and
``cerebx_msgs/msg/Spikes`` for the ROS 2 decoder the mcap project maintains (the one Foxglove's own stack
mirrors), the spikes a network chunk encodes in compiled code are the same bytes message by message, and
cerebx's reader gives the values back in the shape the JSON messages had."""

from __future__ import annotations

import numpy as np
import pytest
from mcap.records import Schema

from cerebx.recording.cdr import (
    JOINT_STATE,
    JOINT_STATE_DEFINITION,
    SPIKES,
    SPIKES_DEFINITION,
    JointStateEncoder,
    decode_joint_state,
    decode_spikes,
    encode_spikes,
)
from cerebx.recording.reader import read_messages
from cerebx.recording.recorder import Recorder, stamps_ns, to_ns
from cerebx.recording.spike_chunks import chunk_spike_messages
from cerebx.snn.decoder import chunk_select

mcap_ros2 = pytest.importorskip("mcap_ros2.decoder")

NAMES = [("left_s0", "left_s1", "left_e0", "left_e1", "left_w0", "left_w1", "left_w2"), ("a",), ("",),
         ("shoulder", "ellbow\u00e9", "w"), ()]


def reference(data: bytes, name: str = JOINT_STATE, definition: str = JOINT_STATE_DEFINITION):
    schema = Schema(id=1, name=name, encoding="ros2msg", data=definition.encode())
    return mcap_ros2.DecoderFactory().decoder_for("cdr", schema)(data)


@pytest.mark.parametrize("names", NAMES)
def test_the_ros2_decoder_reads_what_the_encoder_writes(names):
    rng = np.random.default_rng(len(names))
    n = len(names)
    q, qd, tau = rng.normal(size=n + 2), rng.normal(size=n), rng.normal(size=n)
    t_ns = 12_345_678_901_234
    enc = JointStateEncoder(names)
    for effort in (tau, None):
        data = enc.encode(t_ns, q, qd, effort)
        msg = reference(data)
        assert (msg.header.stamp.sec, msg.header.stamp.nanosec) == (12_345, 678_901_234)
        assert msg.header.frame_id == "" and list(msg.name) == list(names)
        assert list(msg.position) == q[:n].tolist() and list(msg.velocity) == qd.tolist()
        assert list(msg.effort) == (tau.tolist() if effort is not None else [0.0] * n)
        mine = decode_joint_state()(data)
        assert mine == {"timestamp": {"sec": 12_345, "nsec": 678_901_234},
                        "joints": [{"name": a, "position": b, "velocity": c, "effort": d}
                                   for a, b, c, d in zip(msg.name, msg.position, msg.velocity, msg.effort)]}


def test_one_decoder_follows_a_channel_whose_joints_change():
    decode = decode_joint_state()
    a, b = JointStateEncoder(("x", "y")), JointStateEncoder(("x", "z", "w"))
    for enc, n in ((a, 2), (a, 2), (b, 3), (a, 2)):
        v = np.arange(n, dtype=float)
        msg = decode(enc.encode(5, v, -v, v * 2))
        assert [j["name"] for j in msg["joints"]] == list(enc.names)
        assert [j["effort"] for j in msg["joints"]] == (v * 2).tolist()


def test_a_run_log_reads_back_with_fewer_values_than_names(tmp_path):
    """The recorder pairs names with values as zip does; the log reads back the JSON-era shape, in order."""
    rec = Recorder(tmp_path / "r.mcap", ("j0", "j1", "j2"))
    rec.joint_states("/joint_states/actual", 0.002, np.array([1.0, 2.0, 3.0]), np.array([4.0, 5.0, 6.0]),
                     np.array([7.0, 8.0, 9.0]))
    rec.joint_states("/joint_states/actual", 0.004, np.array([1.5, 2.5]), np.array([4.5, 5.5]))
    rec.close()
    got = list(read_messages(tmp_path / "r.mcap"))
    assert [t for _, t, _ in got] == [2_000_000, 4_000_000]
    assert got[0][2]["joints"][2] == {"name": "j2", "position": 3.0, "velocity": 6.0, "effort": 9.0}
    assert got[1][2] == {"timestamp": {"sec": 0, "nsec": 4_000_000},
                         "joints": [{"name": "j0", "position": 1.5, "velocity": 4.5, "effort": 0.0},
                                    {"name": "j1", "position": 2.5, "velocity": 5.5, "effort": 0.0}]}


def test_a_damaged_message_is_refused():
    with pytest.raises(ValueError, match="CDR"):
        decode_joint_state()(b"\x01\x00\x00\x00" + bytes(40))


@pytest.mark.parametrize("indices", [[], [0], [3, 17, 17, 4_000_000_000], list(range(300))])
def test_the_ros2_decoder_reads_a_spikes_message(indices):
    data = encode_spikes(123.456, np.array(indices, np.int64))
    msg = reference(data, SPIKES, SPIKES_DEFINITION)
    assert msg.t == 123.456 and list(msg.indices) == indices
    assert decode_spikes(data) == {"t": 123.456, "indices": indices}
    with pytest.raises(ValueError, match="bytes for"):
        decode_spikes(data[:-1] if indices else data + b"\0")


def chunk(seed: int, n_steps: int, n_cells: int = 5000):
    """A chunk's spikes as the network thread has them: global indices per step, ``off`` where each step starts."""
    rng = np.random.default_rng(seed)
    counts = rng.integers(0, 300, n_steps)
    counts[::4] = 0  # silent steps too
    off = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    return rng.integers(0, n_cells, off[-1]).astype(np.int32), off


@pytest.mark.parametrize("seed,n_steps,pops", [(0, 25, [(100, 400), (4000, 4900)]), (1, 1, [(0, 5000)]),
                                                (2, 12, [(0, 0)]), (3, 7, [])])
def test_a_chunk_encoded_at_once_is_each_step_encoded_alone(seed, n_steps, pops):
    idx, off = chunk(seed, n_steps)
    lo, hi = np.array([a for a, _ in pops], np.int64), np.array([b for _, b in pops], np.int64)
    local, ends = chunk_select(idx, off, lo, hi)
    first, step_s = 1234 + seed, 0.002
    words, starts = chunk_spike_messages(local, ends.reshape(len(pops), n_steps), first, step_s)
    data = words.tobytes()
    assert len(starts) == len(pops) * n_steps + 1 and starts[-1] == len(data)
    k = 0
    for a, b in pops:
        for s in range(n_steps):
            step = idx[off[s]:off[s + 1]]
            fired = step[(step >= a) & (step < b)] - a
            assert data[starts[k]:starts[k + 1]] == encode_spikes((first + s) * step_s, fired)
            k += 1


def test_a_chunk_of_spikes_reads_back_per_population_and_step(tmp_path):
    idx, off = chunk(4, 6)
    lo, hi = np.array([0, 2500], np.int64), np.array([2500, 5000], np.int64)
    local, ends = chunk_select(idx, off, lo, hi)
    words, starts = chunk_spike_messages(local, ends, 10, 0.002)
    rec = Recorder(tmp_path / "r.mcap")
    times = [(10 + s) * 0.002 for s in range(6)]
    rec.spike_messages(("/spikes/a", "/spikes/b"), times, words.tobytes(), starts.tolist())
    rec.close()
    got: dict[str, list] = {"/spikes/a": [], "/spikes/b": []}
    for topic, t_ns, msg in read_messages(tmp_path / "r.mcap"):
        assert t_ns == round(msg["t"] * 1e9)
        got[topic].append(msg)
    for topic, base in (("/spikes/a", 0), ("/spikes/b", 2500)):
        assert [m["t"] for m in got[topic]] == times
        for s, m in enumerate(got[topic]):
            step = idx[off[s]:off[s + 1]]
            assert m["indices"] == (step[(step >= base) & (step < base + 2500)] - base).tolist()


@pytest.mark.parametrize("names", NAMES)
def test_a_trials_joint_states_encoded_at_once_are_the_messages_encoded_one_by_one(names):
    rng = np.random.default_rng(3)
    n, steps = len(names), 257
    q, qd = rng.normal(size=(steps, n + 2)), rng.normal(size=(steps, n + 2))  # wider: the first n are taken
    first_tick = 1_999_873  # about an hour of 2 ms ticks: stamps with a carry into the seconds
    stamps = stamps_ns(first_tick, steps, 0.002)
    enc = JointStateEncoder(names)
    one_by_one = [enc.encode(int(ns), q[i], qd[i], None) for i, ns in enumerate(stamps)]
    assert JointStateEncoder(names).encode_many(stamps, q, qd) == one_by_one


def test_the_stamps_of_a_trial_are_the_log_times_of_its_ticks():
    for first, dt in [(0, 0.002), (123_456, 0.002), (10**7 - 500, 0.002), (77, 0.001), (5, 0.0025)]:
        got = stamps_ns(first, 1000, dt)
        assert got.dtype == np.int64
        assert got.tolist() == [to_ns(k * dt) for k in range(first, first + 1000)]


def test_a_message_encoded_ahead_is_logged_as_joint_states_logs_it(tmp_path):
    names = NAMES[0]
    q, qd = np.linspace(-1, 1, 21).reshape(3, 7), np.linspace(2, 3, 21).reshape(3, 7)
    for way in ("now", "ahead"):
        rec = Recorder(tmp_path / f"{way}.mcap", joint_names=names)
        if way == "now":
            for i in range(3):
                rec.joint_states("/joint_states/desired", i * 0.002, q[i], qd[i])
        else:
            stamps = stamps_ns(0, 3, 0.002)
            for data, ns in zip(rec.joint_state_messages("/joint_states/desired", stamps, q, qd), stamps):
                rec.log_encoded("/joint_states/desired", JOINT_STATE, data, int(ns))
        rec.close()
    assert list(read_messages(tmp_path / "now.mcap")) == list(read_messages(tmp_path / "ahead.mcap"))
