"""The link's wire format and key: packets round-trip exactly, and every kind of bad packet is refused
with its reason (never another exception), counted and dropped by the receiving end."""

from __future__ import annotations

import struct

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cerebx.errors import CerebxError, ConfigError
from cerebx.link.auth import KEY_ENV, KEY_FILE_ENV, Signer, key_from_env, require_key
from cerebx.link.channel import LinkEnd
from cerebx.link.transport import Arrival, Inbox
from cerebx.link.wire import HEADER, HEADER_BYTES, MIN_BYTES, REASONS, VERSION, Kind, WireError, decode, encode
from cerebx.signals import Message

KEY = Signer(b"k" * 32)
OTHER = Signer(b"o" * 32)
RUN = bytes(range(16))
SIGNALS = {"joint.torque": 6}
FAST = settings(max_examples=1000, derandomize=True, deadline=None, database=None,
                suppress_health_check=[HealthCheck.too_slow])


def command(values=None, signer=KEY, run=RUN, kind=Kind.COMMAND, seq=7, tick=11, stamp=0.022) -> bytes:
    values = {"joint.torque": np.linspace(-1, 1, 6)} if values is None else values
    return encode(signer, kind, run, seq, tick, stamp, 123456789, values)


def reason(data: bytes, run=RUN, expected=SIGNALS, signer=KEY) -> str:
    with pytest.raises(WireError) as err:
        decode(data, signer, run, expected)
    return err.value.reason


def test_data_packet_round_trips_exactly():
    values = {"joint.torque": np.array([0.1, -2.5, 1e-300, 3e300, 0.0, -0.0]), "muscle.ag": np.arange(3.0)}
    data = encode(KEY, Kind.COMMAND, RUN, 42, 1000, 2.05, 987654321, values)
    pkt = decode(data, KEY, RUN, {"joint.torque": 6, "muscle.ag": 3})
    assert (pkt.kind, pkt.run_id, pkt.seq, pkt.tick, pkt.stamp_s, pkt.send_ns) == (Kind.COMMAND, RUN, 42, 1000,
                                                                                     2.05, 987654321)
    assert list(pkt.values) == ["joint.torque", "muscle.ag"]
    for name, v in values.items():
        assert np.array_equal(pkt.values[name], v)
    assert HEADER_BYTES == 60 and len(data) == 60 + 2 + (1 + 12 + 2 + 48) + (1 + 9 + 2 + 24) + 16


def test_control_packet_round_trips():
    data = encode(KEY, Kind.HELLO, RUN, 0, 0, 0.0, 5, info={"fingerprint": "abc", "n": [1, 2]})
    assert decode(data, KEY, None, SIGNALS).info == {"fingerprint": "abc", "n": [1, 2]}


@pytest.mark.parametrize("cut", [0, 1, 5, HEADER_BYTES - 1, HEADER_BYTES + 10, MIN_BYTES + 20])
def test_truncated(cut):
    data = command()
    assert reason(data[:cut]) == "truncated"


def test_other_version_magic_and_trailing_bytes():
    data = bytearray(command())
    data[4] = VERSION + 1
    assert reason(bytes(data)) == "version"
    assert reason(b"XXXX" + command()[4:]) == "malformed"
    assert reason(command() + b"\0") == "malformed"


def test_unauthenticated_and_other_run():
    assert reason(command(signer=OTHER)) == "unauthenticated"
    assert reason(command(run=bytes(16))) == "other_run"
    tampered = bytearray(command())
    tampered[HEADER_BYTES + 20] ^= 1  # a value changed in flight
    assert reason(bytes(tampered)) == "unauthenticated"


def test_signal_names_sizes_and_values():
    assert reason(command({"joint.torque": np.zeros(6), "joint.extra": np.zeros(1)})) == "unknown_signal"
    assert reason(command({"joint.torqueX": np.zeros(6)})) == "unknown_signal"
    assert reason(command({"joint.torque": np.zeros(5)})) == "wrong_size"
    assert reason(command({})) == "missing_signal"
    assert reason(command({"joint.torque": np.array([0, 1, np.nan, 0, 0, 0])})) == "non_finite"
    assert reason(command(stamp=float("inf"))) == "non_finite"


def test_every_reason_is_documented():
    assert set(REASONS) >= {"truncated", "malformed", "version", "unauthenticated", "other_run", "unknown_signal",
                            "wrong_size", "missing_signal", "non_finite", "stale"}


@FAST
@given(st.binary(max_size=400))
def test_random_bytes_are_refused(data):
    with pytest.raises(WireError):
        decode(data, KEY, RUN, SIGNALS)


@FAST
@given(st.data())
def test_mutated_packets_are_refused(data):
    """A byte changed, cut or added anywhere in a valid packet: refused with a reason, never a crash."""
    raw = bytearray(command())
    op = data.draw(st.sampled_from(["flip", "cut", "insert"]))
    i = data.draw(st.integers(0, len(raw) - 1))
    if op == "flip":
        raw[i] ^= data.draw(st.integers(1, 255))
    elif op == "cut":
        del raw[i]
    else:
        raw.insert(i, data.draw(st.integers(0, 255)))
    with pytest.raises(WireError):
        decode(bytes(raw), KEY, RUN, SIGNALS)


@FAST
@given(kind=st.integers(0, 255), version=st.integers(0, 255), body=st.binary(max_size=120),
       body_len=st.one_of(st.none(), st.integers(0, 2**32 - 1)), seq=st.integers(0, 2**64 - 1))
def test_well_formed_headers_with_any_fields_are_refused_or_decoded(kind, version, body, body_len, seq):
    """Signed packets (the key is right) whose fields are anything: decoded, or refused with a reason."""
    head = HEADER.pack(b"CBXL", version, kind, 0, RUN, seq, 3, 0.5, 1, len(body) if body_len is None else body_len)
    raw = head + body
    raw += KEY.tag(raw)
    try:
        decode(raw, KEY, RUN, SIGNALS)
    except WireError as err:
        assert err.reason in REASONS


def test_key_from_file_and_env(tmp_path):
    f = tmp_path / "link.key"
    f.write_text("ab" * 32 + "\n")
    s = key_from_env({KEY_FILE_ENV: str(f)})
    assert s is not None and s.tag(b"x") == Signer(bytes.fromhex("ab" * 32)).tag(b"x")
    assert key_from_env({KEY_ENV: "cd" * 16}).tag(b"x") == Signer(bytes.fromhex("cd" * 16)).tag(b"x")
    assert key_from_env({}) is None
    with pytest.raises(CerebxError, match="at least 16 are needed"):
        key_from_env({KEY_ENV: "short"})
    with pytest.raises(CerebxError, match="cannot be read"):
        key_from_env({KEY_FILE_ENV: str(tmp_path / "missing")})
    with pytest.raises(CerebxError, match="no key"):
        require_key({})
    assert "ab" not in repr(s) and "hidden" in repr(s)


def test_the_key_is_not_configuration(load):
    with pytest.raises(ConfigError, match="link.key"):
        load(["+task=circle", "controller=pd", "link=zenoh", "clock=wall", "+link.key=abcdefabcdefabcdef"])


class FakeTransport:
    def __init__(self):
        self.inbox = Inbox()
        self.sent = []

    def send(self, path, hop, data):
        self.sent.append((path, hop, data))


def test_link_end_counts_and_drops_what_it_refuses():
    t = FakeTransport()
    end = LinkEnd(t, OTHER, "robot", SIGNALS, run_id=RUN, session=KEY)
    good = [command(seq=s, tick=s) for s in (0, 1, 3)]  # 2 never arrives
    bad = [command(signer=OTHER, seq=9), command(run=bytes(16), seq=9), b"junk", command(seq=1, tick=1),
           command({"joint.torque": np.zeros(2)}, seq=10), command(kind=Kind.SENSOR, seq=11)]
    for data in good[:2] + bad[:3] + good[2:] + bad[3:]:
        t.inbox.put(Arrival("c2r", 0, data, 5))
    data, control = end.poll()
    assert [a.seq for a in data] == [0, 1, 3] and control == []
    assert end.data.lost == 1 and end.data.received == 3
    assert dict(end.rejected) == {"unauthenticated": 1, "other_run": 1, "truncated": 1, "stale": 1, "wrong_size": 1,
                                  "unexpected_kind": 1}
    assert data[0].message.stamp_s == pytest.approx(0.022)


def test_link_end_sends_signed_packets_and_measures_delay():
    t = FakeTransport()
    end = LinkEnd(t, OTHER, "brain", {"joint.q": 2, "joint.qd": 2}, run_id=RUN, session=KEY)
    end.send_message(Message(0.004, {"joint.torque": np.ones(6)}), 2)
    path, hop, raw = t.sent[0]
    assert (path, hop) == ("c2r", 0)
    pkt = decode(raw, KEY, RUN, SIGNALS)
    assert (pkt.kind, pkt.seq, pkt.tick, pkt.stamp_s) == (Kind.COMMAND, 0, 2, 0.004)
    sensor = encode(KEY, Kind.SENSOR, RUN, 0, 2, 0.004, 1_000_000, {"joint.q": np.zeros(2), "joint.qd": np.zeros(2)})
    end.offset_ns = 250_000  # robot clock 0.25 ms ahead of ours
    t.inbox.put(Arrival("r2c", 0, sensor, 3_000_000))
    (arrived,), _ = end.poll()
    assert arrived.delay_ms == pytest.approx(2.25)
    assert struct.unpack_from("<Q", raw, 24)[0] == 0
