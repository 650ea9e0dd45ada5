"""The closed loop end to end on the planar arm: determinism, crash and Ctrl-C safety, sweeps."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from cerebx.cli import main
from cerebx.controllers.pd import PD
from cerebx.loop.runner import run_experiment
from cerebx.recording.reader import channel_counts, read_messages, read_summary

pytestmark = pytest.mark.integration

DEMO = ["+experiment=demo"]


def _payload(run_dir: Path) -> list:
    """Every recorded message (topic, time, content) — what 'identical data' means."""
    out = []
    for topic, t, msg in read_messages(run_dir):
        out.append((topic, t, msg))
    return out


def test_same_seed_records_identical_data(load, tmp_path):
    cfg = load([*DEMO, "trials=2", "seed=7", "controller=pd_planar2", "plant.sensor_noise_rad=0.001"])
    a = run_experiment(cfg, tmp_path / "a")
    b = run_experiment(cfg, tmp_path / "b")
    assert a["status"] == b["status"] == "completed"
    assert a["mae_per_trial"] == b["mae_per_trial"]
    pa, pb = _payload(tmp_path / "a"), _payload(tmp_path / "b")
    assert len(pa) > 2000 and pa == pb
    c = run_experiment(load([*DEMO, "trials=2", "seed=8", "plant.sensor_noise_rad=0.001"]), tmp_path / "c")
    assert c["mae_per_trial"] != a["mae_per_trial"]


def test_summary_and_channels(load, tmp_path):
    s = run_experiment(load([*DEMO, "trials=3"]), tmp_path)
    for key in ("status", "task", "controller", "plant", "delay", "seed", "trials", "mae_per_trial", "final_mae",
                "sim_seconds", "wall_seconds", "rt_factor", "version"):
        assert key in s
    assert s["trials_completed"] == 3 and len(s["mae_per_trial"]) == 3
    assert s["final_mae"] == pytest.approx(s["mae_per_trial"][-1])
    assert s["sim_seconds"] == pytest.approx(6.0)
    assert json.loads((tmp_path / "summary.json").read_text()) == s
    counts = channel_counts(tmp_path)
    assert counts["/joint_states/actual"] == counts["/control"] == 3000
    assert counts["/trial_metrics"] == 3


def test_pd_tracks_within_bound(load, tmp_path):
    """PD on the planar arm follows the sinusoid within a few hundredths of a radian."""
    s = run_experiment(load([*DEMO, "trials=2"]), tmp_path)
    assert s["final_mae"] < 0.1


def test_crash_midway_leaves_readable_log(load, tmp_path, monkeypatch):
    calls = {"n": 0}
    original = PD.control

    def exploding(self, inp):
        calls["n"] += 1
        if calls["n"] == 1500:
            raise RuntimeError("boom")
        return original(self, inp)

    monkeypatch.setattr(PD, "control", exploding)
    s = run_experiment(load([*DEMO, "trials=5"]), tmp_path)
    assert s["status"] == "failed" and "boom" in s["error"]
    assert s["trials_completed"] == 1
    assert read_summary(tmp_path)["status"] == "failed"
    counts = channel_counts(tmp_path)
    assert counts["/control"] == 1499


def test_diverging_run_stops_cleanly(load, tmp_path, monkeypatch):
    """A controller that starts emitting NaN ends the run with status 'diverged', log intact."""
    calls = {"n": 0}
    original = PD.control

    def nan_after_a_while(self, inp):
        calls["n"] += 1
        msg = original(self, inp)
        return type(msg)(msg.stamp_s, msg.tau * np.nan) if calls["n"] > 1200 else msg

    monkeypatch.setattr(PD, "control", nan_after_a_while)
    s = run_experiment(load([*DEMO, "trials=3"]), tmp_path)
    assert s["status"] == "diverged", s
    assert "non-finite joint.torque command" in s["error"]
    assert s["trials_completed"] == 1
    assert channel_counts(tmp_path)["/control"] == 1200


def test_sigint_leaves_readable_log(tmp_path):
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    proc = subprocess.Popen(
        [sys.executable, "-m", "cerebx.cli", "run", *DEMO, "trials=2000", "hydra.run.dir=run"],
        cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        # a shell that starts the tests in the background ignores SIGINT, and children inherit that
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    mcap = tmp_path / "run" / "run.mcap"
    deadline = time.time() + 120  # generous: CI machines can be slow to start Python + Hydra
    while not (mcap.exists() and mcap.stat().st_size > 0) and time.time() < deadline:
        time.sleep(0.1)
    assert mcap.exists(), "the run did not start within 120 s"
    time.sleep(1.5)
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err.decode()
    s = read_summary(tmp_path / "run")
    assert s["status"] == "interrupted"
    assert 0 < s["trials_completed"] < 2000
    assert channel_counts(tmp_path / "run")["/trial_metrics"] == s["trials_completed"]


def test_multirun_joblib_two_complete_runs(in_tmp):
    code = subprocess.run(
        [sys.executable, "-m", "cerebx.cli", "run", "-m", *DEMO, "trials=1", "seed=1,2",
         "hydra/launcher=joblib", "hydra.launcher.n_jobs=2"],
        cwd=in_tmp, capture_output=True, text=True, timeout=300,
    )
    assert code.returncode == 0, code.stderr
    summaries = sorted(in_tmp.glob("runs/multirun/*/*/*/summary.json"))
    assert len(summaries) == 2
    assert len({p.parent for p in summaries}) == 2
    seeds = sorted(json.loads(p.read_text())["seed"] for p in summaries)
    assert seeds == [1, 2]
    for p in summaries:
        assert json.loads(p.read_text())["status"] == "completed"
        assert (p.parent / "run.mcap").exists() and (p.parent / ".hydra" / "config.yaml").exists()


def test_two_sweeps_in_the_same_second_do_not_collide(in_tmp):
    procs = [subprocess.Popen([sys.executable, "-m", "cerebx.cli", "run", "-m", *DEMO, "trials=1", "seed=3"],
                              cwd=in_tmp, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE) for _ in range(2)]
    for p in procs:
        assert p.wait(timeout=300) == 0
    assert len(list(in_tmp.glob("runs/multirun/*/*/*/summary.json"))) == 2


def test_inspect_prints_summary_and_channels(load, tmp_path, capsys):
    run_experiment(load([*DEMO, "trials=1"]), tmp_path)
    assert main(["inspect", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "status    completed" in out and "/joint_states/actual" in out and "1,000" in out


def test_inspect_summary_without_final_mae_computes_it(tmp_path, capsys):
    # found by the fuzzing test: a damaged key left the per-trial MAE list but no final_mae
    s = {"status": "completed", "task": "joint_sine", "controller": "pd", "plant": "planar2", "delay": "none",
         "seed": 0, "trials": 10, "trials_completed": 10, "mae_per_trial": [0.5] * 9 + [0.125]}
    (tmp_path / "summary.json").write_text(json.dumps(s))
    assert main(["inspect", str(tmp_path)]) in (0, 2)
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    assert "first 0.5000 rad   final 0.1250 rad" in out


def test_inspect_file_that_is_not_mcap_one_line(tmp_path, capsys, load):
    run_experiment(load([*DEMO, "trials=1"]), tmp_path / "r")
    data = (tmp_path / "r" / "run.mcap").read_bytes()
    bad = tmp_path / "bad.mcap"
    bad.write_bytes(b"garbage!" + data[8: len(data) // 2])
    assert main(["inspect", str(bad)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "bad.mcap" in err[0]


def test_joint_states_are_foxglove_typed(load, tmp_path):
    run_experiment(load([*DEMO, "trials=1"]), tmp_path)
    topic, t, msg = next(read_messages(tmp_path, ["/joint_states/actual"]))
    assert [j["name"] for j in msg["joints"]] == ["shoulder", "elbow"]
    assert np.isfinite(msg["joints"][0]["position"])
    assert msg["timestamp"] == {"sec": t // 1_000_000_000, "nsec": t % 1_000_000_000}
