"""The link under attack, over real sockets and processes (loopback only; every process has a time limit and
is stopped by the test): a recorded session replayed into a fresh robot side, replayed PINGs after the brain
side died, a flood of junk datagrams at the robot's port, set-up that fails, and zenoh over mutual TLS."""

from __future__ import annotations

import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
import uuid
from pathlib import Path

import pytest
from link_processes import PD, finish, ports, start, ticking, wait_for

from cerebx.link.auth import Signer
from cerebx.link.pairing import fingerprint
from cerebx.link.transport import free_port
from cerebx.link.wire import Kind, decode, encode
from cerebx.recording.reader import read_messages, read_metadata, read_summary

pytestmark = pytest.mark.integration

KEY = {"CEREBX_LINK_KEY": "ef" * 32}


def stderr_lines(err: str) -> list[str]:
    """What a command said, without Hydra's and the estimate's lines."""
    return [ln for ln in err.splitlines() if ln.strip() and not ln.startswith(("[", "run: estimate"))]


def test_a_brain_side_that_cannot_pair_exits_2_and_leaves_nothing(tmp_path):
    run = tmp_path / "run"
    code, _, err = finish(start(["run", *PD, "link=udp", "trials=1", "link.spawn_robot=false",
                                 "link.pair_timeout_s=2", f"hydra.run.dir={run}", *ports()], KEY), 90)
    assert code == 2 and stderr_lines(err) == ["link: no robot side answered within 2 s"], err
    assert not run.exists()


def test_an_empty_or_unsafe_run_dir_is_refused_before_anything_is_written(tmp_path):
    for value in ("", ".", str(tmp_path)):
        code, _, err = finish(start(["run", *PD, "link=udp", "trials=1", f"hydra.run.dir={value}"], KEY,
                                    cwd=tmp_path), 90)
        assert code == 2 and len(stderr_lines(err)) == 1 and "hydra.run.dir" in err, err
        assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
def test_a_port_in_use_exits_2_with_one_line_and_leaves_nothing(tmp_path):
    run = tmp_path / "run"
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as taken:
        taken.bind(("127.0.0.1", 0))
        port = taken.getsockname()[1]
        code, _, err = finish(start(["run", *PD, "link=udp", "trials=1", f"link.brain=127.0.0.1:{port}",
                                     f"hydra.run.dir={run}"]), 90)
    assert code == 2 and stderr_lines(err) == [f"link: udp cannot listen on 127.0.0.1:{port} (Address already "
                                               "in use)"], err
    assert not run.exists()


@pytest.mark.slow
def test_an_unresolvable_host_exits_2_with_one_line_and_leaves_nothing(tmp_path):
    run = tmp_path / "run"
    code, _, err = finish(start(["run", *PD, "link=udp", "trials=1", "link.spawn_robot=false",
                                 "link.beyond_loopback=true", "link.robot=nowhere.invalid:7000",
                                 f"hydra.run.dir={run}"], KEY), 90)
    (line,) = stderr_lines(err)
    assert code == 2 and line.startswith("link: nowhere.invalid:7000: the host cannot be resolved"), err
    assert not run.exists()


# ---------------------------------------------------------------------- zenoh eavesdropper
def _zenoh_session(endpoints: list[str]):
    zenoh = pytest.importorskip("zenoh")
    conf = zenoh.Config()
    conf.insert_json5("mode", '"peer"')
    conf.insert_json5("listen/endpoints", json.dumps([f"tcp/127.0.0.1:{free_port('127.0.0.1')}"]))
    conf.insert_json5("connect/endpoints", json.dumps(endpoints))
    conf.insert_json5("scouting/multicast/enabled", "false")
    conf.insert_json5("scouting/gossip/enabled", "false")
    return zenoh.open(conf)


def _endpoint(override: str) -> str:
    return "tcp/" + override.split("=", 1)[1]


def record_session(tmp_path: Path, extra: list[str]) -> list[bytes]:
    """A whole run over zenoh as an eavesdropper on both sides' endpoints sees it: every packet the brain side
    sent to the robot side."""
    addr = ports(socket.SOCK_STREAM)
    seen: list[bytes] = []
    run = tmp_path / "recorded"
    brain = start(["run", *PD, "link=zenoh", "trials=1", f"hydra.run.dir={run}", *addr, *extra], KEY)
    wait_for(lambda: (run / "robot").exists(), 60, "the robot side to start")
    time.sleep(1.0)
    with _zenoh_session([_endpoint(addr[0]), _endpoint(addr[1])]) as session:
        session.declare_subscriber("cerebx/c2r/0", lambda s: seen.append(s.payload.to_bytes()))
        code, _, err = finish(brain)
    assert code == 0, err
    return seen


@pytest.mark.slow
def test_a_recorded_session_replayed_into_a_fresh_robot_side_is_refused_and_the_real_brain_pairs(tmp_path):
    recorded = record_session(tmp_path, [])
    kinds = {p[5] for p in recorded}
    assert {1, 4, 6} <= kinds, kinds  # HELLO, START and commands were seen
    addr = ports(socket.SOCK_STREAM)
    robot = start(["robot", "--run-dir", str(tmp_path / "robot"), *PD, "link=zenoh", "trials=1", *addr], KEY)
    stop = threading.Event()
    replayed = {"n": 0}

    def replay():
        with _zenoh_session([_endpoint(addr[0])]) as session:
            pub = session.declare_publisher("cerebx/c2r/0")
            while not stop.is_set():
                for data in recorded[:200]:
                    pub.put(data)
                    replayed["n"] += 1
                time.sleep(0.05)

    attacker = threading.Thread(target=replay, daemon=True)
    attacker.start()
    time.sleep(8.0)  # the replay runs alone at the robot side first (it starts in a few seconds)
    brain = start(["run", *PD, "link=zenoh", "trials=1", "link.spawn_robot=false", f"hydra.run.dir={tmp_path / 'b'}",
                   *addr], KEY)
    try:
        code, _, err = finish(brain)
        rcode, _, rerr = finish(robot)
    finally:
        stop.set()
        attacker.join(10)
    assert code == 0 and rcode == 0, err + rerr
    s, r = read_summary(tmp_path / "b"), read_summary(tmp_path / "robot")
    print(f"\nreplayed {replayed['n']} packets; robot side: {r['status']}, {r['link']['packets']}; brain side: "
          f"{s['status']}, {s['link']['packets']}")
    assert s["status"] == r["status"] == "completed" and s["link"]["run_id"] == r["link"]["run_id"]
    assert r["link"]["packets"]["rejected"].get("unauthenticated", 0) > 0, r["link"]["packets"]
    assert r["trials_completed"] == 1 and replayed["n"] > 1000


@pytest.mark.slow
def test_replayed_pings_neither_move_the_clock_nor_keep_a_robot_side_alive(tmp_path):
    addr = ports(socket.SOCK_STREAM)
    run = tmp_path / "run"
    brain = start(["run", *PD, "link=zenoh", "trials=5", "link.clock_sync=ping", "link.resync_every_s=0.3",
                   f"hydra.run.dir={run}", *addr], KEY)
    robot_pid = wait_for(lambda: ticking(run), 60, "the robot side")
    pings: list[bytes] = []
    with _zenoh_session([_endpoint(addr[0]), _endpoint(addr[1])]) as session:
        session.declare_subscriber("cerebx/c2r/0", lambda s: pings.append(s.payload.to_bytes())
                                   if s.payload.to_bytes()[5] == 7 else None)
        wait_for(lambda: len(pings) >= 16, 30, "a burst of PINGs")
        pub = session.declare_publisher("cerebx/c2r/0")
        for data in pings[:80] * max(1, 80 // len(pings[:80])):
            pub.put(data)
            time.sleep(0.005)
        time.sleep(1.0)
        os.killpg(brain.pid, signal.SIGKILL)
        brain.communicate(timeout=30)
        killed = time.monotonic()
        while time.monotonic() - killed < 4.0:  # the same PINGs again, to a robot side whose brain is gone
            for data in pings[:16]:
                pub.put(data)
            time.sleep(0.02)
    wait_for(lambda: read_summary(run / "robot").get("status") not in (None, "running"), 30, "the robot side")
    r = read_summary(run / "robot")
    sync = [m for topic, _t, m in read_messages(run, topics=["/clock_sync"]) if "refused" not in m["method"]]
    offsets = [(round(m["offset_ms"], 3), round(m["uncertainty_ms"], 3)) for m in sync]
    print(f"\nrobot side: {r['status']} ({r['error']}), {r['link']['packets']}; brain offsets +- uncertainty "
          f"(ms): {offsets}")
    assert r["status"] == "interrupted" and r["error"].startswith("link lost"), r["error"]
    assert r["link"]["packets"]["rejected"].get("replayed", 0) >= 80, r["link"]["packets"]
    # one host, one clock: each estimate within its own uncertainty of 0 (a replay moved it by 2 s before)
    assert offsets and all(abs(o) <= u + 0.05 for o, u in offsets), offsets
    assert robot_pid is not None


def test_a_hello_of_another_configuration_or_run_leaves_the_robot_side_waiting_for_its_brain(tmp_path, load):
    """A brain side of another experiment (same key, same ports) says HELLO to a waiting robot side first, then a
    brain side of this configuration that never signs anything after it: the robot side refuses the first,
    answers the second, and pairs with the real brain side that starts later; the run completes."""
    addr = ports()
    args = [*PD, "link=udp", "trials=1", "link.pair_timeout_s=40"]
    robot = start(["robot", "--run-dir", str(tmp_path / "robot"), *args, *addr], KEY)
    key = Signer(bytes.fromhex(KEY["CEREBX_LINK_KEY"]))
    brain_at = ("127.0.0.1", int(addr[1].rsplit(":", 1)[1]))
    robot_at = ("127.0.0.1", int(addr[0].rsplit(":", 1)[1]))
    answers: list = []
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as stranger:
        stranger.bind(brain_at)  # where the robot side expects its brain side
        stranger.settimeout(0.25)
        deadline = time.monotonic() + 60
        for fp in ("f" * 16, fingerprint(load(args))):
            hello = encode(key, Kind.HELLO, uuid.uuid4().bytes, 0, 0, 0.0, 1,
                           info={"fingerprint": fp, "version": "0", "nonce": uuid.uuid4().hex})
            got = None
            while got is None and time.monotonic() < deadline and robot.poll() is None:
                stranger.sendto(hello, robot_at)  # until the robot side (building its parts first) answers
                try:
                    got = decode(stranger.recv(65536), key)
                except TimeoutError:
                    pass
            answers.append(got.kind if got is not None else None)
    assert answers == [Kind.REFUSE, Kind.WELCOME] and robot.poll() is None, answers
    brain = start(["run", *args, "link.spawn_robot=false", f"hydra.run.dir={tmp_path / 'b'}", *addr], KEY)
    code, _, err = finish(brain)
    rcode, _, rerr = finish(robot)
    assert code == 0 and rcode == 0, err + rerr
    s, r = read_summary(tmp_path / "b"), read_summary(tmp_path / "robot")
    print(f"\nrobot side: {r['status']}, {r['link']['packets']}, {r['link']['events'][:2]}")
    assert s["status"] == r["status"] == "completed" and s["link"]["run_id"] == r["link"]["run_id"]
    assert r["link"]["packets"]["rejected"].get("other_config", 0) >= 1, r["link"]["packets"]
    refused = [e for e in r["link"]["events"] if e["event"] == "refused_hello"]
    assert len(refused) == 1 and "another configuration (fingerprint ffffffffffffffff" in refused[0]["detail"]


# ---------------------------------------------------------------------- junk traffic
FLOOD = """
import os, socket, sys, time
port, rate, seconds = int(sys.argv[1]), int(sys.argv[2]), float(sys.argv[3])
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
junk = os.urandom(100)
sent, t0 = 0, time.monotonic()
while time.monotonic() - t0 < seconds:
    due = int((time.monotonic() - t0) * rate)
    while sent < due:
        try:
            s.sendto(junk, ("127.0.0.1", port))
        except OSError:
            pass
        sent += 1
    time.sleep(0.001)
print(sent)
"""


def udp_no_ports() -> int:
    lines = [ln.split() for ln in Path("/proc/net/snmp").read_text().splitlines() if ln.startswith("Udp:")]
    return int(lines[1][lines[0].index("NoPorts")])


def robot_run(tmp_path: Path, name: str, flood_rate: int, extra: tuple[str, ...] = ()) -> dict:
    """A 5,000-tick PD run over UDP, with ``flood_rate`` junk datagrams/s at the robot side's port for 5 s once
    it ticks: the robot side's lateness p99 and overruns, and what reached its process."""
    addr = ports()
    run = tmp_path / name
    brain = start(["run", *PD, "link=udp", "trials=5", f"hydra.run.dir={run}", *addr, *extra])
    pid = wait_for(lambda: ticking(run), 60, "the robot side")
    out: dict = {}
    cmdline = Path(f"/proc/{pid}/cmdline").read_bytes().decode(errors="replace")
    environ = Path(f"/proc/{pid}/environ").read_bytes().decode(errors="replace")
    out["private"] = "link.robot=" not in cmdline and "link.brain=" not in cmdline and "CEREBX_LINK" not in environ
    sched = Path(f"/proc/{pid}/sched").read_text().splitlines()  # the paced thread's fair-scheduler slice
    out["slice_ns"] = next((int(ln.split(":")[1]) for ln in sched if ln.startswith("se.slice")), None)
    if flood_rate:
        port = int(addr[0].rsplit(":", 1)[1])
        before = udp_no_ports()
        res = subprocess.run([sys.executable, "-c", FLOOD, str(port), str(flood_rate), "5"], capture_output=True,
                             text=True, timeout=60)
        out["sent"] = int(res.stdout.strip())
        out["no_ports"] = udp_no_ports() - before
    code, _, err = finish(brain)
    assert code == 0, err
    r = read_summary(run / "robot")
    t = r["link"]["timing"]
    out.update(p99=t["lateness_ms"]["p99"], overruns=t["overruns"], ticks=t["ticks"],
               dropped=r["link"]["packets"].get("dropped_before_decoding"), status=r["status"])
    return out


@pytest.mark.slow
def test_a_flood_of_junk_datagrams_does_not_move_the_pacing(tmp_path):
    for attempt in range(2):  # a pair measured again once: another job's burst can stall any loop on a shared host
        base = robot_run(tmp_path / str(attempt), "baseline", 0)
        flood = robot_run(tmp_path / str(attempt), "flood", 20_000)
        print(f"\nbaseline {base}\nflood    {flood}")
        if flood["p99"] < max(5.0, 2 * base["p99"]) and flood["overruns"] <= 2 * base["overruns"] + 20:
            break
    assert base["private"] and flood["private"]  # neither addresses nor the key on the robot side's command line
    assert flood["status"] == "completed" and flood["ticks"] == 5000
    assert flood["sent"] >= 95_000 and flood["no_ports"] >= 0.9 * flood["sent"]  # the kernel dropped them
    assert flood["dropped"] == {}  # not one junk datagram reached the robot side's process
    # under 5 ms; on a machine whose other jobs already make the baseline later than that, within 2x of it
    assert flood["p99"] < max(5.0, 2 * base["p99"])
    assert flood["overruns"] <= 2 * base["overruns"] + 20


# ---------------------------------------------------------------------- confidentiality
def _certificates(folder: Path) -> dict[str, Path]:
    """A CA and one certificate for 127.0.0.1 signed by it (server and client use), made with openssl."""
    def ssl(*args: str) -> None:
        subprocess.run(["openssl", *args], check=True, capture_output=True, timeout=60, cwd=folder)

    ssl("req", "-x509", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:P-256", "-nodes", "-keyout", "ca.key",
        "-out", "ca.pem", "-days", "2", "-subj", "/CN=cerebx test CA")
    ssl("req", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:P-256", "-nodes", "-keyout", "side.key", "-out",
        "side.csr", "-subj", "/CN=localhost")
    (folder / "ext.cnf").write_text("subjectAltName=DNS:localhost,IP:127.0.0.1\n"
                                    "extendedKeyUsage=serverAuth,clientAuth\nbasicConstraints=CA:FALSE\n")
    ssl("x509", "-req", "-in", "side.csr", "-CA", "ca.pem", "-CAkey", "ca.key", "-CAcreateserial", "-out",
        "side.pem", "-days", "2", "-extfile", "ext.cnf")
    return {"ca": folder / "ca.pem", "cert": folder / "side.pem", "key": folder / "side.key"}


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("openssl") is None, reason="needs openssl to make the test certificates")
def test_zenoh_over_mutual_tls_completes_and_a_peer_without_a_certificate_reads_nothing(tmp_path):
    certs = _certificates(tmp_path)
    addr = ports(socket.SOCK_STREAM)
    run = tmp_path / "run"
    brain = start(["run", *PD, "link=zenoh", "trials=2", f"hydra.run.dir={run}", *addr,
                   f"+link.tls.root_ca_certificate={certs['ca']}", f"+link.tls.listen_certificate={certs['cert']}",
                   f"+link.tls.listen_private_key={certs['key']}"], KEY)
    wait_for(lambda: ticking(run), 60, "the robot side")
    seen: list[bytes] = []
    with _zenoh_session([_endpoint(addr[0]), "tls/" + addr[0].split("=", 1)[1]]) as session:
        session.declare_subscriber("cerebx/r2c/0", lambda s: seen.append(s.payload.to_bytes()))
        time.sleep(1.5)
    code, _, err = finish(brain)
    assert code == 0, err
    assert read_summary(run)["status"] == "completed" and seen == []
    meta = read_metadata(run)["link"]
    assert meta["listen"].startswith("['tls/") and meta["connect"].startswith("['tls/")
