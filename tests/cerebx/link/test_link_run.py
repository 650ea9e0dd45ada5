"""Wall-clock runs end to end: the brain side and the robot side as processes over a real link, and
what happens when the link or a side fails. Traffic goes only to loopback, or to network namespaces the
test makes itself; every process is started with a time limit and stopped by the test.

All are ``slow``: ``make test-slow`` runs them one at a time. A wall-clock loop needs a core of its own; beside
``make test``'s two workers a 2 ms tick came late and PD's error moved by 20 %, or the robot side stalled past the
link's timeout.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import socket
import struct
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from link_processes import CLI, PD, finish, ports, start, ticking, wait_for

from cerebx.config import load
from cerebx.link.auth import KEY_ENV, Signer
from cerebx.link.transport import free_port
from cerebx.link.wire import HEADER, Kind, encode
from cerebx.loop.runner import run_experiment
from cerebx.recording.reader import channel_counts, read_messages, read_summary

pytestmark = pytest.mark.integration

def alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except OSError:
        return False
    try:
        return Path(f"/proc/{pid}/stat").read_text().split()[2] != "Z"
    except OSError:
        return False


def sim_mae(tmp_path: Path, overrides: list[str]) -> list[float]:
    cfg, plain = load(overrides)
    return run_experiment(cfg, tmp_path / "sim", plain)["mae_per_trial"]


def complete_log(run_dir: Path) -> None:
    """Both logs read as one; the robot side logged /timing for every tick its summary counts."""
    counts = {}
    for topic, _t, _m in read_messages(run_dir):
        counts[topic] = counts.get(topic, 0) + 1
    robot = read_summary(run_dir / "robot")
    assert counts["/timing"] == robot["link"]["timing"]["ticks"]
    assert channel_counts(run_dir / "robot")["/timing"] == counts["/timing"]
    return counts


@pytest.mark.slow
def test_pd_over_udp_matches_simulated_time(tmp_path):
    run = tmp_path / "run"
    code, out, err = finish(start(["run", *PD, "link=udp", "trials=1", f"hydra.run.dir={run}"]))
    assert code == 0, err
    s = read_summary(run)
    assert s["status"] == "completed" and s["trials_completed"] == 1
    assert s["mae_per_trial"][0] == pytest.approx(sim_mae(tmp_path, ["+task=circle", "controller=pd", "trials=1"])[0],
                                                 rel=0.05)
    assert s["sim_seconds"] == 2.0 and s["wall_seconds"] == pytest.approx(2.0, rel=0.05)
    timing = s["link"]["timing"]
    assert timing["robot"]["ticks"] == 1000 and timing["brain"]["ticks"] == 1000
    assert {"p50", "p99", "max"} <= set(timing["robot"]["lateness_ms"]) and "overruns" in timing["robot"]
    assert s["link"]["run_id"] == read_summary(run / "robot")["link"]["run_id"]
    counts = complete_log(run)
    assert counts["/control"] == 1000 and counts["/timing/brain"] == 1000
    first = next(m for topic, _t, m in read_messages(run, topics=["/control"]))
    assert {"tau_controller", "error", "r2c_ms", "c2r_ms"} <= set(first)
    assert subprocess.run(CLI + ["inspect", str(run)], capture_output=True, timeout=60).returncode == 0


@pytest.mark.slow
def test_zenoh_relay_delays_are_measured_and_replayed(tmp_path):
    run = tmp_path / "run"
    args = ["run", *PD, "link=zenoh", "trials=2", "delay=gamma45", f"hydra.run.dir={run}"]
    code, _, err = finish(start(args + ports(socket.SOCK_STREAM)))
    assert code == 0, err
    s = read_summary(run)
    assert s["status"] == "completed"
    relay = json.loads((run / "relay" / "summary.json").read_text())
    assert relay["counts"]["r2c"]["forwarded"] >= 1990
    trace = tmp_path / "trace.csv"
    res = subprocess.run(CLI + ["delays", str(run), "--json", "--out", str(trace)], capture_output=True, text=True,
                         timeout=60)
    assert res.returncode == 0, res.stderr
    cmp = json.loads(res.stdout.split("\nwrote")[0])
    for path in ("r2c", "c2r"):
        measured, model = cmp[path]["measured_ms"], cmp[path]["model_ms"]
        assert model["mean"] == pytest.approx(21.4, abs=1.5)  # gamma45: 21.4 ms per path
        # the measured delay is the model's plus the transport's, a packet at a time (the difference of the two
        # medians is not the transport's median: on a busy host it came out at 3.2 ms with the transport's at < 3)
        assert measured["mean"] >= model["mean"] and measured["p50"] - model["p50"] < 5.0
        assert cmp[path]["transport_ms"]["p50"] < 3.0
    replay = sim_mae(tmp_path, ["+task=circle", "controller=pd", "trials=2", "delay=trace", f"delay.path={trace}",
                                "delay.loop=false"])
    assert np.allclose(replay, s["mae_per_trial"], rtol=0.10)


@pytest.mark.slow
def test_sides_composed_differently_refuse_to_pair(tmp_path):
    """The brain side is refused and stops at once; the robot side keeps waiting for a brain side of its own
    configuration until its pairing timeout, then says what it refused."""
    addr = ports()
    env = {KEY_ENV: "ab" * 32}
    robot = start(["robot", "--run-dir", str(tmp_path / "robot"), *PD, "link=udp", "trials=2",
                   "link.pair_timeout_s=20", *addr], env)
    brain = start(["run", *PD, "link=udp", "trials=1", "link.spawn_robot=false", f"hydra.run.dir={tmp_path / 'b'}",
                   *addr], env)
    for proc, said in ((brain, "the robot side runs another configuration"),
                       (robot, "no brain side paired within 20 s; refused")):
        code, _, err = finish(proc, 60)
        lines = [ln for ln in err.splitlines() if ln.strip() and not ln.startswith(("[", "run: estimate"))]
        assert code == 2 and len(lines) == 1 and said in lines[0] and "another configuration" in lines[0], err
    assert not (tmp_path / "robot").exists()


@pytest.mark.slow
def test_robot_side_killed(tmp_path):
    run = tmp_path / "run"
    brain = start(["run", *PD, "link=udp", "trials=3", f"hydra.run.dir={run}"])
    pid = wait_for(lambda: ticking(run), 60, "the robot side")
    time.sleep(2.0)
    os.kill(pid, signal.SIGKILL)
    code, _, err = finish(brain, 60)
    assert code == 130 and "link lost" in err
    s = read_summary(run)
    assert s["status"] == "interrupted" and s["error"].startswith("link lost")
    wait_for(lambda: read_summary(run / "robot")["status"] == "killed", 20, "the robot side's sentinel")
    counts = {}
    for topic, _t, _m in read_messages(run):  # both logs readable, the killed one up to its last chunk
        counts[topic] = counts.get(topic, 0) + 1
    assert counts["/timing/brain"] > 500 and counts["/timing"] > 0


@pytest.mark.slow
def test_brain_side_killed(tmp_path):
    run = tmp_path / "run"
    brain = start(["run", *PD, "link=udp", "trials=3", "delay=constant", "delay.total_ms=4", f"hydra.run.dir={run}"])
    robot_pid = wait_for(lambda: ticking(run), 60, "the robot side")
    time.sleep(2.0)
    os.killpg(brain.pid, signal.SIGKILL)
    brain.communicate(timeout=30)
    wait_for(lambda: not alive(robot_pid), 30, "the robot side to stop")
    s = read_summary(run / "robot")
    assert s["status"] == "interrupted" and s["error"].startswith("link lost"), s["error"]
    assert (run / "robot" / "robot.log").read_text().strip().count("\n") == 0  # one line
    events = [e["event"] for e in s["link"]["events"]]
    assert events[:1] == ["paired"] and "safe_stop" in events and "hold_pose" in events
    assert events.index("safe_stop") < events.index("hold_pose")
    wait_for(lambda: read_summary(run)["status"] == "killed", 20, "the brain side's sentinel")
    complete_log(run)


def relay_pid(run: Path) -> int | None:
    want = f"{run / 'relay'}"
    for p in Path("/proc").iterdir():
        if p.name.isdigit():
            try:
                cmd = (p / "cmdline").read_bytes().split(b"\0")
            except OSError:
                continue
            if b"relay" in cmd and want.encode() in cmd:
                return int(p.name)
    return None


@pytest.mark.slow
def test_relay_stopped_for_200_ms(tmp_path):
    run = tmp_path / "run"
    brain = start(["run", *PD, "link=zenoh", "trials=2", "delay=constant", "delay.total_ms=4",
                   f"hydra.run.dir={run}", *ports(socket.SOCK_STREAM)])
    wait_for(lambda: ticking(run), 60, "the robot side")
    pid = wait_for(lambda: relay_pid(run), 30, "the relay")
    time.sleep(2.0)
    os.kill(pid, signal.SIGSTOP)
    time.sleep(0.2)
    os.kill(pid, signal.SIGCONT)
    code, _, err = finish(brain)
    assert code == 0, err
    s, r = read_summary(run), read_summary(run / "robot")
    assert s["status"] == r["status"] == "completed"
    robot_events = [e["event"] for e in r["link"]["events"]]
    assert "safe_stop" in robot_events and robot_events[-1] == "commands_resumed"
    brain_events = [e["event"] for e in s["link"]["events"]]
    assert "holding" in brain_events and brain_events[-1] == "sensors_resumed"
    assert "holding the last one" in err
    complete_log(run)


@pytest.mark.slow
def test_five_percent_of_packets_dropped(tmp_path):
    run = tmp_path / "run"
    code, _, err = finish(start(["run", *PD, "link=udp", "trials=2", "link.drop_fraction=0.05",
                                 f"hydra.run.dir={run}"]))
    assert code == 0, err
    s, r = read_summary(run), read_summary(run / "robot")
    assert s["status"] == "completed"
    for packets in (s["link"]["packets"], r["link"]["packets"]):
        assert 0.02 < packets["lost"] / (packets["lost"] + packets["received"]) < 0.08
        assert packets["rejected_total"] == 0
    assert s["final_mae"] < 0.2
    complete_log(run)


def fuzz_packets(signer: Signer) -> st.SearchStrategy[bytes]:
    """Anything: random bytes, truncated or oversized headers, signed with a wrong key, other versions and
    kinds, unknown signals, wrong sizes."""
    header = st.builds(lambda v, k, rid, seq, n: HEADER.pack(b"CBXL", v, k, 0, rid, seq, 0, 0.0, 0, n),
                       st.integers(0, 255), st.integers(0, 255), st.binary(min_size=16, max_size=16),
                       st.integers(0, 2**64 - 1), st.integers(0, 2**32 - 1))
    signals = st.dictionaries(st.sampled_from(["joint.torque", "joint.q", "x", "joint.torque.extra"]),
                              st.integers(0, 12).map(lambda n: np.zeros(n)), max_size=3)
    wrong_key = st.builds(lambda vals, seq: encode(signer, Kind.COMMAND, bytes(16), seq, seq, 0.0, 0, vals),
                          signals, st.integers(0, 2**32))
    return st.one_of(st.binary(max_size=800), header, st.tuples(header, st.binary(max_size=200)).map(b"".join),
                     wrong_key, wrong_key.map(lambda b: b[:-3]))


@pytest.mark.slow
def test_fuzzed_packets_to_the_robot_side(tmp_path):
    """Anything published on the robot side's incoming path reaches its check (zenoh: any peer that reaches an
    endpoint may publish; over UDP the kernel drops other senders' datagrams after pairing) and is refused."""
    zenoh = pytest.importorskip("zenoh")
    run = tmp_path / "run"
    addr = ports(socket.SOCK_STREAM)
    # long enough (20 s of wall clock) that the robot side still listens when the last packet is sent,
    # even when generating the packets is slow on a busy machine
    brain = start(["run", *PD, "link=zenoh", "trials=10", f"hydra.run.dir={run}", *addr])
    wait_for(lambda: ticking(run), 60, "the robot side")
    time.sleep(1.0)
    sent = []
    conf = zenoh.Config()
    conf.insert_json5("mode", '"peer"')
    conf.insert_json5("listen/endpoints", json.dumps([f"tcp/127.0.0.1:{free_port('127.0.0.1')}"]))
    conf.insert_json5("connect/endpoints", json.dumps(["tcp/" + addr[0].split("=", 1)[1]]))
    conf.insert_json5("scouting/multicast/enabled", "false")
    conf.insert_json5("scouting/gossip/enabled", "false")
    with zenoh.open(conf) as session:
        time.sleep(0.5)
        pub = session.declare_publisher("cerebx/c2r/0", congestion_control=zenoh.CongestionControl.BLOCK)

        @settings(max_examples=1000, derandomize=True, database=None, deadline=None,
                  suppress_health_check=list(HealthCheck))
        @given(fuzz_packets(Signer(b"w" * 32)))
        def fire(data):
            pub.put(data)
            sent.append(len(data))
            time.sleep(0.0005)

        fire()
        time.sleep(0.5)
    assert len(sent) == 1000
    code, _, err = finish(brain)
    assert code == 0, err
    r = read_summary(run / "robot")
    assert r["status"] == "completed" and "traceback" not in r
    assert r["link"]["packets"]["rejected_total"] == 1000, r["link"]["packets"]
    complete_log(run)


@pytest.mark.slow
def test_commands_with_a_wrong_key(tmp_path):
    zenoh = pytest.importorskip("zenoh")
    run = tmp_path / "run"
    addr = ports(socket.SOCK_STREAM)
    endpoint = "tcp/" + addr[0].split("=", 1)[1]
    brain = start(["run", *PD, "link=zenoh", "trials=2", f"hydra.run.dir={run}", *addr])
    wait_for(lambda: ticking(run), 60, "the robot side")
    conf = zenoh.Config()
    conf.insert_json5("mode", '"peer"')
    conf.insert_json5("listen/endpoints", json.dumps([f"tcp/127.0.0.1:{free_port('127.0.0.1')}"]))
    conf.insert_json5("connect/endpoints", json.dumps([endpoint]))
    conf.insert_json5("scouting/multicast/enabled", "false")
    conf.insert_json5("scouting/gossip/enabled", "false")
    seen: list[bytes] = []
    with zenoh.open(conf) as session:
        session.declare_subscriber("cerebx/r2c/0", lambda s: seen.append(s.payload.to_bytes()))
        first = wait_for(lambda: seen[:1], 30, "a sensor packet to read the run id from")[0]
        run_id = first[8:24]  # the header is readable by anyone on the path; the tag is what counts
        tick = struct.unpack_from("<q", first, 32)[0]
        pub = session.declare_publisher("cerebx/c2r/0")
        intruder = Signer(b"i" * 32)
        for i in range(300):
            pub.put(encode(intruder, Kind.COMMAND, run_id, 10_000 + i, tick + i, (tick + i) * 0.002, 0,
                           {"joint.torque": np.full(6, 50.0)}))
            time.sleep(0.001)
    code, _, err = finish(brain)
    assert code == 0, err
    r = read_summary(run / "robot")
    assert r["status"] == "completed"
    assert r["link"]["packets"]["rejected"] == {"unauthenticated": 300}
    assert r["mae_per_trial"] == pytest.approx(
        sim_mae(tmp_path, ["+task=circle", "controller=pd", "trials=2"]), rel=0.05)


def _ip(*args: str) -> None:
    subprocess.run(["ip", *args], check=True, capture_output=True, timeout=10)


@pytest.mark.slow
@pytest.mark.skipif(os.geteuid() != 0 or shutil.which("ip") is None,
                    reason="needs root and iproute2 to make network namespaces and a veth pair")
def test_two_namespaces_joined_by_a_veth_pair(tmp_path):
    tag = f"{os.getpid() % 100000}"
    ns_r, ns_b, dev_r, dev_b = f"cbxr{tag}", f"cbxb{tag}", f"cbxr{tag}", f"cbxb{tag}"
    net = f"10.{200 + os.getpid() % 50}.{os.getpid() % 250}"
    try:
        _ip("netns", "add", ns_r)
        _ip("netns", "add", ns_b)
        _ip("link", "add", dev_r, "type", "veth", "peer", "name", dev_b)
        _ip("link", "set", dev_r, "netns", ns_r)
        _ip("link", "set", dev_b, "netns", ns_b)
        for ns, dev, host in ((ns_r, dev_r, 1), (ns_b, dev_b, 2)):
            _ip("-n", ns, "addr", "add", f"{net}.{host}/24", "dev", dev)
            _ip("-n", ns, "link", "set", dev, "up")
            _ip("-n", ns, "link", "set", "lo", "up")
        addr = [f"link.robot={net}.1:7611", f"link.brain={net}.2:7612", f"link.relay={net}.2:7613"]
        common = [*PD, "link=zenoh", "trials=1", "link.clock_sync=ping", "link.beyond_loopback=true", *addr]
        env = {KEY_ENV: "cd" * 32}
        netns = ["ip", "netns", "exec"]
        robot = subprocess.Popen(netns + [ns_r] + CLI + ["robot", "--run-dir", str(tmp_path / "robot"), *common],
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                 env={**os.environ, **env}, start_new_session=True)
        brain = subprocess.Popen(netns + [ns_b] + CLI + ["run", *common, "link.spawn_robot=false",
                                                         f"hydra.run.dir={tmp_path / 'brain'}"],
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                 env={**os.environ, **env}, start_new_session=True)
        for proc in (brain, robot):
            code, _, err = finish(proc)
            assert code == 0, err
        s = read_summary(tmp_path / "brain")
        assert s["status"] == "completed"
        sync = s["link"]["clock_sync"][0]
        assert sync["method"] == "ping" and abs(sync["offset_ms"]) <= sync["uncertainty_ms"] + 0.05
        stats = subprocess.run(["ip", "-n", ns_r, "-s", "-j", "link", "show", dev_r], capture_output=True,
                               text=True, timeout=10, check=True)
        counters = json.loads(stats.stdout)[0]["stats64"]
        assert counters["rx"]["packets"] > 900 and counters["tx"]["packets"] > 900  # crossed the veth pair
    finally:
        for ns in (ns_r, ns_b):
            subprocess.run(["ip", "netns", "del", ns], capture_output=True, timeout=10)
