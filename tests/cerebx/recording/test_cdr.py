"""Joint states in CDR: what the encoder writes is a valid ``sensor_msgs/msg/JointState`` for the ROS 2
decoder the mcap project maintains (the one Foxglove's own stack mirrors), and cerebx's reader gives the
values back in the shape the JSON joint states had."""

from __future__ import annotations

import numpy as np
import pytest
from mcap.records import Schema

from cerebx.recording.cdr import JOINT_STATE, JOINT_STATE_DEFINITION, JointStateEncoder, decode_joint_state
from cerebx.recording.reader import read_messages
from cerebx.recording.recorder import Recorder

mcap_ros2 = pytest.importorskip("mcap_ros2.decoder")

NAMES = [("left_s0", "left_s1", "left_e0", "left_e1", "left_w0", "left_w1", "left_w2"), ("a",), ("",),
         ("shoulder", "ellbow\u00e9", "w"), ()]


def reference(data: bytes):
    schema = Schema(id=1, name=JOINT_STATE, encoding="ros2msg", data=JOINT_STATE_DEFINITION.encode())
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
