"""The live view (live.enabled) serves what run.mcap records, over Foxglove's WebSocket protocol, without
ever waiting for a client; and the recorded 3-D scene holds the plant's bodies."""

from __future__ import annotations

import json
import resource
import socket
import time

import numpy as np
import pytest
from live_client import SUBPROTOCOLS, LiveClient
from mcap.reader import make_reader

from cerebx.build import build_components
from cerebx.loop.runner import run_experiment
from cerebx.recording import live, scene
from cerebx.recording.reader import read_messages
from cerebx.schema.live import LiveConfig

pytestmark = pytest.mark.integration

SIGNALS = {"/joint_states/desired", "/joint_states/actual", "/control", "/spikes/dcn"}
SCENE = {scene.TRANSFORMS, scene.MARKERS}


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def raw_messages(path) -> dict[tuple[str, int], bytes]:
    with open(path, "rb") as fh:
        return {(ch.topic, m.log_time): m.data for _s, ch, m in make_reader(fh).iter_messages()}


def without_stamps(entities: list[dict]) -> list[dict]:
    return [{k: v for k, v in e.items() if k != "timestamp"} for e in entities]


def test_live_run_serves_what_the_mcap_records(load, tmp_path):
    port = free_port()
    cfg = load(["+task=circle", "+experiment=small_snn", "trials=2", "recording.progress=off", "live.enabled=true",
                f"live.port={port}", "live.display_hz=200", "recording.scene_every=1"])
    client = LiveClient(port, SIGNALS | SCENE | {scene.ROBOT, scene.LOG}).start()
    summary = run_experiment(cfg, tmp_path)
    client.join()
    assert client.error is None, client.error
    assert summary["status"] == "completed"
    assert client.subprotocol in SUBPROTOCOLS
    recorded = raw_messages(tmp_path / "run.mcap")
    got: dict[str, list[tuple[int, bytes]]] = {}
    for topic, t, data in client.messages:
        got.setdefault(topic, []).append((t, data))
    for topic in sorted(SIGNALS | SCENE):
        # the scene goes out at most display_hz times a wall-clock second: fewer frames the faster the run
        least = 10 if topic in SCENE else 50
        assert len(got.get(topic, ())) > least, f"{topic}: {len(got.get(topic, ()))} messages received"
        for t, data in got[topic]:
            assert recorded.get((topic, t)) == data, f"{topic} at {t} ns differs from run.mcap"
    # the scene is sent at the display rate, far fewer frames than the 2,000 steps
    assert len(got[scene.TRANSFORMS]) < len(got["/control"])
    # the robot's geometry, resent for late viewers, is what the file has
    file_robot = next(msg for topic, _t, msg in read_messages(tmp_path, [scene.ROBOT]))
    assert got[scene.ROBOT]
    for _t, data in got[scene.ROBOT]:
        assert without_stamps(json.loads(data)["entities"]) == without_stamps(file_robot["entities"])
    assert any(b"MAE" in data for _t, data in got.get(scene.LOG, ()))
    assert client.times == sorted(client.times) and client.times


def test_recorded_scene_has_the_robots_entities(load, tmp_path):
    cfg = load(["+task=circle", "controller=pd", "trials=1", "recording.progress=off", "recording.scene_every=25"])
    summary = run_experiment(cfg, tmp_path)
    assert summary["status"] == "completed"
    model = build_components(cfg, tmp_path / "build").plant.model
    frames = scene.body_frames(model)
    msgs = {}
    for topic, _t, msg in read_messages(tmp_path, [scene.ROBOT, scene.TRANSFORMS, scene.MARKERS]):
        msgs.setdefault(topic, []).append(msg)
    robot = msgs[scene.ROBOT][0]["entities"]
    ids = {e["id"] for e in robot}
    assert {f"body/{f}" for f in frames} <= ids and "path/desired" in ids
    # the Baxter model has no geoms: every body is a joint ball, every link a stick in its parent's frame
    assert all(e["spheres"] for e in robot if e["id"].startswith("body/") and e["id"] != "body/world")
    links = int((np.linalg.norm(model.body_pos[1:], axis=1) > 1e-6).sum())
    assert sum(len(e["cylinders"]) for e in robot) == links > 0
    assert len(msgs[scene.TRANSFORMS]) == 1000 // 25
    tf = msgs[scene.TRANSFORMS][-1]["transforms"]
    assert [x["child_frame_id"] for x in tf] == frames
    markers = {e["id"] for e in msgs[scene.MARKERS][-1]["entities"]}
    assert markers == {"ee/actual", "ee/desired"}


def test_upper_limb_muscles_are_lines_coloured_by_activation(load, tmp_path):
    cfg = load(["+experiment=upper_limb_pd", "+task=flexion_extension"])
    plant = build_components(cfg, tmp_path).plant
    plant.reset(np.array([0.3, 1.0]), np.random.default_rng(0))
    writer = scene.SceneWriter(plant, None, 0)
    robot = scene.robot_entities(plant.model, 0)
    assert {e["id"] for e in robot} >= {"body/r_humerus", "body/r_ulna_radius_hand"}
    plant.data.act[:] = [0.0, 1.0, 0, 0, 0, 0, 0]
    lines = next(e for e in writer.markers(0, None, None)["entities"] if e["id"] == "muscles")["lines"]
    assert len(lines) == 7 and all(len(line["indices"]) >= 2 for line in lines)
    assert lines[0]["color"] == scene.activation_color(0.0) and lines[1]["color"] == scene.activation_color(1.0)
    assert lines[1]["color"]["r"] > lines[0]["color"]["r"]


def test_a_client_that_stops_reading_loses_messages_and_never_blocks():
    view = live.LiveView(LiveConfig(enabled=True, port=0, backlog_messages=64))
    client = LiveClient(view.port, {"/big"}, read_delay_s=30.0).start()
    try:
        assert client.connected.wait(10)
        payload = {"blob": "x" * 10_000}
        view.log("/big", "cerebx.WeightSummary", 0.0, payload)  # advertise; the client subscribes
        time.sleep(0.5)
        rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        t0 = time.perf_counter()
        n = 20_000  # 200 MB if it were all queued
        for i in range(n):
            view.log("/big", "cerebx.WeightSummary", i * 0.002, payload)
        per_log_us = (time.perf_counter() - t0) / n * 1e6
        grown_mb = (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - rss0) / 1024
    finally:
        view.stop()
    assert per_log_us < 200, f"{per_log_us:.0f} us per message to a stalled client"
    assert grown_mb < 60, f"memory grew by {grown_mb:.0f} MB for a stalled client"


def test_signal_hz_thins_what_the_viewer_gets_only():
    view = live.LiveView(LiveConfig(enabled=True, port=0, signal_hz=20))
    try:
        sent = []
        ch = view.twin("/control", "cerebx.Control")
        ch.channel = type("Sink", (), {"log": lambda self, data, log_time: sent.append(log_time)})()
        t0 = time.perf_counter()
        n = 0
        while time.perf_counter() - t0 < 0.5:
            ch.log(b"{}", log_time=n)
            n += 1
        assert view.twin(scene.TRANSFORMS, "foxglove.FrameTransforms") is None
    finally:
        view.stop()
    assert n > 1000 and 8 <= len(sent) <= 12 and sent[0] == 0


def test_live_view_binds_to_localhost_by_default():
    assert LiveConfig().host == "127.0.0.1" and not LiveConfig().enabled


@pytest.mark.parametrize("every, enabled, want", [(None, False, 0), (None, True, scene.DEFAULT_EVERY), (0, True, 0),
                                                  (7, False, 7)])
def test_scene_rate(load, every, enabled, want):
    cfg = load(["+experiment=demo", f"recording.scene_every={'null' if every is None else every}",
                f"live.enabled={str(enabled).lower()}"])
    assert scene.scene_every(cfg) == want


def test_shipped_layout_shows_recorded_topics():
    layout = json.loads(live.LAYOUT.read_text())
    panels = set(layout["configById"])
    assert {"3D!scene", "Plot!mae", "Plot!raster", "RosOut!log"} <= panels
    assert {"/scene/robot", "/scene/markers"} <= set(layout["configById"]["3D!scene"]["topics"])

    def ids(node):
        if isinstance(node, str):
            yield node
        elif isinstance(node, dict):
            yield from (i for k in ("first", "second") for i in ids(node[k]))

    placed = set(ids(layout["layout"]))
    for tab in layout["configById"]["Tab!signals"]["tabs"]:
        placed |= set(ids(tab["layout"]))
    assert placed | {"Tab!signals"} >= panels
