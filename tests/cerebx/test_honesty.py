"""Every failure honest (issue #17): sweeps that survive a bad job, hard-killed runs that stay first-class,
no code from configuration, one-line errors at the edges, limits and estimates."""

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
from cerebx.loop import runner
from cerebx.loop.runner import run_experiment
from cerebx.recording.reader import channel_counts, read_messages, read_summary

pytestmark = pytest.mark.integration

DEMO = ["+experiment=demo"]


def _one_line(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    return err[0]


# ---- a sweep survives a bad job ---------------------------------------------------------------------

def test_sweep_runs_every_job_and_counts_the_failures(in_tmp, monkeypatch, capsys):
    from cerebx.loop import runner

    build = runner.build_components

    def fail_for_seed_1(cfg, run_dir):
        if cfg.seed == 1:
            raise RuntimeError("state of another network")
        return build(cfg, run_dir)

    monkeypatch.setattr(runner, "build_components", fail_for_seed_1)
    code = main(["run", "-m", *DEMO, "trials=1", "seed=1,2", "hydra.sweep.dir=sw"])
    assert code == 1  # one job failed
    bad, good = read_summary(in_tmp / "sw" / "0"), read_summary(in_tmp / "sw" / "1")
    assert bad["status"] == "failed" and "state of another network" in bad["error"]
    assert good["status"] == "completed" and good["trials_completed"] == 1
    err = capsys.readouterr().err
    assert "1 of 2 jobs completed, 1 failed (exit code 1)" in err
    table = [ln.split("|")[1:-1] for ln in err.splitlines() if ln.startswith(("| 0 |", "| 1 |"))]
    assert [c.strip() for c in table[0][:3]] == ["0", "1", "failed"] and "state of another network" in table[0][-1]
    assert [c.strip() for c in table[1][:3]] == ["1", "2", "completed"]


def test_sweep_exit_code_is_the_number_of_failed_jobs(in_tmp, monkeypatch, capsys):
    def boom(cfg, run_dir):
        raise RuntimeError("boom")

    monkeypatch.setattr("cerebx.loop.runner.build_components", boom)
    assert main(["run", "-m", *DEMO, "trials=1", "seed=1,2,3", "hydra.sweep.dir=sw"]) == 3
    assert [read_summary(in_tmp / "sw" / str(i))["status"] for i in range(3)] == ["failed"] * 3
    assert "0 of 3 jobs completed, 3 failed" in capsys.readouterr().err


def test_a_job_that_runs_clears_the_refusal_an_earlier_attempt_left(in_tmp, capsys):
    """error.txt says a sweep job was refused before it ran; once a later attempt of the job runs, the sweep's
    summary must not go on counting it as failed (the report's Fig. 4.6 seeds: three jobs completed in folders
    with an older refusal were listed as failed and the study exited with 5)."""
    for job in ("0", "1"):  # as a job refused by other code (the sweep is checked before any job starts now)
        (in_tmp / "sw" / job).mkdir(parents=True)
        (in_tmp / "sw" / job / "error.txt").write_text("recording.trials: unknown key\n")
    assert main(["run", "-m", *DEMO, "trials=1", "seed=1,2", "hydra.sweep.dir=sw"]) == 0
    assert not (in_tmp / "sw" / "0" / "error.txt").exists() and not (in_tmp / "sw" / "1" / "error.txt").exists()
    assert "2 of 2 jobs completed" in capsys.readouterr().out


# ---- a hard-killed run stays first-class ------------------------------------------------------------

def _start(tmp_path: Path, *args: str) -> subprocess.Popen:
    env = {**os.environ, "PYTHONUNBUFFERED": "1", "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
    return subprocess.Popen([sys.executable, "-m", "cerebx.cli", "run", *args], cwd=tmp_path, env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def _wait_for(pred, seconds: float, what: str) -> None:
    deadline = time.time() + seconds
    while not pred():
        assert time.time() < deadline, what
        time.sleep(0.1)


def _trials_done(run: Path) -> int:
    try:
        return json.loads((run / "summary.json").read_text()).get("trials_completed", 0)
    except (OSError, ValueError):
        return 0


def test_sigkill_leaves_a_killed_run_the_standard_reader_reads(tmp_path, capsys):
    from mcap.reader import make_reader

    run = tmp_path / "run"
    proc = _start(tmp_path, *DEMO, "trials=5000", "hydra.run.dir=run")
    _wait_for(lambda: _trials_done(run) >= 3, 120, "the run did not finish 3 trials within 120 s")
    assert json.loads((run / "summary.json").read_text())["status"] == "running"
    proc.send_signal(signal.SIGKILL)
    proc.wait(timeout=30)
    _wait_for(lambda: json.loads((run / "summary.json").read_text())["status"] != "running", 30,
              "the sentinel did not mark the run")
    s = read_summary(run)
    assert s["status"] == "killed" and 3 <= s["trials_completed"] < 5000
    assert len(s["mae_per_trial"]) == s["trials_completed"]
    with open(run / "run.mcap", "rb") as fh:  # the standard seeking reader, as any MCAP tool uses it
        topics = [ch.topic for _, ch, _ in make_reader(fh).iter_messages()]
    # every trial the summary lists reached the log (chunks hold at most a few trials of this run)
    assert topics.count("/trial_metrics") >= s["trials_completed"] - 2
    assert topics.count("/control") >= 1000 * (s["trials_completed"] - 2)
    assert channel_counts(run)["/control"] == topics.count("/control")
    assert main(["inspect", str(run)]) == 0
    out = capsys.readouterr().out
    assert "status    killed" in out and f"trials    {s['trials_completed']}/5000" in out
    assert main(["report", str(run), "--out", str(tmp_path / "rep"), "--figures", "fig3_4"]) == 0
    rows = (tmp_path / "rep" / "runs.csv").read_text().splitlines()
    assert rows[1].split(",")[1:2] == ["killed"] and f",{s['trials_completed']}," in rows[1]


def test_a_running_summary_whose_process_is_gone_reads_as_killed(load, tmp_path):
    run_experiment(load([*DEMO, "trials=1"]), tmp_path)
    s = json.loads((tmp_path / "summary.json").read_text())
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    s.update(status="running", pid=dead.pid)
    (tmp_path / "summary.json").write_text(json.dumps(s))
    assert read_summary(tmp_path)["status"] == "killed"
    s["pid"] = os.getpid()  # alive: still running
    (tmp_path / "summary.json").write_text(json.dumps(s))
    assert read_summary(tmp_path)["status"] == "running"


@pytest.mark.parametrize("every_s, progress", [(0.0, [0, 1, 2]), (3600.0, [0, 1, 1])])
def test_summary_says_running_while_the_run_goes(load, tmp_path, monkeypatch, every_s, progress):
    """summary.json says running, with the trials done so far, at most every SUMMARY_EVERY_S (the first trial
    is always there); the last summary has them all."""
    seen = []
    original = PD.end_trial

    def peek(self, trial):
        seen.append(json.loads((tmp_path / "summary.json").read_text()))
        return original(self, trial)

    monkeypatch.setattr(PD, "end_trial", peek)
    monkeypatch.setattr(runner, "SUMMARY_EVERY_S", every_s)
    run_experiment(load([*DEMO, "trials=3"]), tmp_path)
    assert [x["status"] for x in seen] == ["running"] * 3
    assert [x["trials_completed"] for x in seen] == progress
    final = read_summary(tmp_path)
    assert final["status"] == "completed" and final["trials_completed"] == 3 and len(final["mae_per_trial"]) == 3


def test_an_unsealed_log_is_read_by_scanning_everywhere(load, tmp_path, capsys):
    from cerebx.recording.reader import read_metadata

    run_experiment(load([*DEMO, "trials=2"]), tmp_path / "r")
    whole = (tmp_path / "r" / "run.mcap").read_bytes()
    full = channel_counts(tmp_path / "r")
    cut = tmp_path / "cut"
    cut.mkdir()
    (cut / "run.mcap").write_bytes(whole[: int(len(whole) * 0.7)])
    counts = channel_counts(cut)
    assert 0 < counts["/control"] < full["/control"]
    assert sum(1 for _ in read_messages(cut, ["/control"])) == counts["/control"]
    scanned = list(read_messages(cut, ["/joint_states/actual"]))  # CDR channels are decoded by scanning too
    assert len(scanned) == counts["/joint_states/actual"] > 0
    assert scanned[:50] == list(read_messages(tmp_path / "r", ["/joint_states/actual"]))[:50]
    assert "config" in read_metadata(cut)
    assert main(["inspect", str(cut / "run.mcap")]) == 0
    assert "counted by scanning" in capsys.readouterr().out


# ---- configuration never carries code ---------------------------------------------------------------

CODE_ROUTES = [
    ["+hydra.callbacks.e._target_=os.makedirs", "+hydra.callbacks.e._args_=[{dir}]"],  # the example
    ["+hydra={{callbacks:{{e:{{_target_:os.makedirs,_args_:[{dir}]}}}}}}"],
    ["+hydra/callbacks=anything"],
    ["hydra/launcher=my_launcher"],
    ["hydra/launcher=basic,my_launcher"],
    ["+hydra.launcher._target_=os.makedirs"],
    ["+controller.gains={{_target_:os.makedirs,_args_:[{dir}]}}"],
    ["+extra=[1,{{_target_:os.makedirs}}]"],
    ["+hydra.job.env_set.LD_PRELOAD=/tmp/x.so"],
    ["hydra.searchpath=[file://{dir}]"],
    ['+hydra.job_logging.handlers.h={{"()":os.makedirs}}'],
    ["--experimental-rerun", "{dir}/config.pickle"],
]


@pytest.mark.parametrize("route", CODE_ROUTES, ids=lambda r: r[0][:40])
def test_code_bearing_overrides_are_refused_before_hydra_acts(route, in_tmp, capsys):
    made = in_tmp / "made_by_config"
    args = [a.format(dir=made) for a in route]
    assert main(["run", *DEMO, "trials=1", *args]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err and all(": " in ln for ln in err) and len(err) <= len(args)
    assert not made.exists() and not (in_tmp / "runs").exists()
    assert main(["validate", *DEMO, *args]) == 2


def test_a_config_dir_preset_with_code_is_refused(in_tmp, capsys):
    made = in_tmp / "made_by_config"
    (in_tmp / "cd" / "experiment").mkdir(parents=True)
    (in_tmp / "cd" / "experiment" / "evil.yaml").write_text(
        f"# @package _global_\nhydra:\n  callbacks:\n    e:\n      _target_: os.makedirs\n      _args_: [{made}]\n")
    assert main(["run", "--config-dir", str(in_tmp / "cd"), *DEMO, "+experiment=evil", "trials=1"]) == 2
    line = _one_line(capsys)
    assert "evil.yaml: hydra.callbacks" in line
    assert not made.exists() and not (in_tmp / "runs").exists()
    (in_tmp / "cd" / "hydra" / "launcher").mkdir(parents=True)
    (in_tmp / "cd" / "experiment" / "evil.yaml").write_text("# @package _global_\ntrials: 1\n")
    (in_tmp / "cd" / "hydra" / "launcher" / "mine.yaml").write_text("_target_: os.makedirs\n")
    assert main(["run", "-cd", str(in_tmp / "cd"), *DEMO, "hydra/launcher=mine"]) == 2
    err = capsys.readouterr().err
    assert "mine.yaml: _target_" in err and "unknown launcher 'mine'" in err


def test_a_package_preset_with_code_fails_validation(tmp_path, monkeypatch, capsys):
    import shutil

    from cerebx import guard

    tree = tmp_path / "conf"
    shutil.copytree(guard.CONF_ROOT, tree)
    (tree / "experiment" / "evil.yaml").write_text(
        "# @package _global_\ndefaults:\n  - override /hydra/launcher: mine\nhydra:\n  callbacks:\n"
        "    e: {_target_: os.makedirs, _args_: [x]}\n")
    monkeypatch.setattr(guard, "CONF_ROOT", tree)
    guard._package_tree_problems.cache_clear()
    try:
        assert main(["validate", *DEMO]) == 2
    finally:
        guard._package_tree_problems.cache_clear()
    err = capsys.readouterr().err.strip().splitlines()
    installed = ", ".join(guard.installed_plugins("launcher"))
    assert err == [f"conf/experiment/evil.yaml: defaults: unknown launcher 'mine' (installed: {installed})",
                   "conf/experiment/evil.yaml: hydra.callbacks: hydra.callbacks is not accepted (it runs code, adds "
                   "config sources or sets the environment of every process)"]


def test_the_shipped_presets_carry_no_code():
    from cerebx import guard

    assert guard.check_tree(guard.CONF_ROOT) == []
    assert guard.check_overrides(["hydra/launcher=joblib", "hydra.launcher.n_jobs=2", "seed=1,2",
                                  "hydra.run.dir=x", "+task=circle"]) == []


# ---- init_from states are opened and fingerprinted at validation ------------------------------------

SMALL = ["+task=circle", "+experiment=small_snn"]


@pytest.fixture(scope="module")
def small_state(tmp_path_factory):
    """A run folder holding the learned state of one trial of the small SNN."""
    from cerebx.config import load

    d = tmp_path_factory.mktemp("small")
    s = run_experiment(load([*SMALL, "trials=1"])[0], d)
    assert s["status"] == "completed" and (d / "controller_state.npz").stat().st_size > 1000
    return d


def _damaged(tmp_path: Path, small_state: Path, how: str) -> Path:
    data = (small_state / "controller_state.npz").read_bytes()
    if how == "truncated":
        data = data[: len(data) // 2]
    elif how == "corrupt":
        mid = len(data) // 2
        data = data[:mid] + bytes(b ^ 0xFF for b in data[mid: mid + 64]) + data[mid + 64:]
    elif how == "garbage":
        data = b"not a state at all"
    d = tmp_path / how
    d.mkdir()
    (d / "controller_state.npz").write_bytes(data)
    return d


@pytest.mark.parametrize("how", ["truncated", "corrupt", "garbage"])
def test_a_damaged_state_is_refused_at_validation(how, small_state, in_tmp, capsys):
    bad = _damaged(in_tmp, small_state, how)
    assert main(["run", *SMALL, "trials=1", f"init_from={bad}"]) == 2
    line = _one_line(capsys)
    assert line.startswith("init_from: ") and "not a readable cerebx state" in line, line
    assert not (in_tmp / "runs").exists()


def test_a_state_of_another_network_is_refused_at_validation(small_state, in_tmp, capsys):
    assert main(["run", "+task=circle", "trials=1", f"init_from={small_state}"]) == 2
    line = _one_line(capsys)
    assert "fingerprint" in line and "'full'" in line and not (in_tmp / "runs").exists()
    assert main(["validate", *SMALL, f"init_from={small_state}"]) == 0  # the same network is fine
    capsys.readouterr()
    assert main(["validate", "+task=circle", "controller=ann", f"init_from={small_state}"]) == 2
    assert "is not an ANN state" in _one_line(capsys)


# ---- run-folder problems and bad summaries: one line -------------------------------------------------

@pytest.mark.parametrize("folder", ["/proc/cerebx_x", "a_file", "a_file/sub"])
def test_a_run_folder_that_cannot_be_made_is_one_line(folder, in_tmp, capsys):
    (in_tmp / "a_file").write_text("x")
    assert main(["run", *DEMO, "trials=1", f"hydra.run.dir={folder}"]) == 2
    line = _one_line(capsys)
    assert line.startswith(f"hydra.run.dir: {folder}") and not Path("/proc/cerebx_x").exists()
    assert main(["run", "-m", *DEMO, "trials=1", "seed=1,2", f"hydra.sweep.dir={folder}"]) == 2
    assert _one_line(capsys).startswith(f"hydra.sweep.dir: {folder}")
    assert sorted(p.name for p in in_tmp.iterdir()) == ["a_file"]


@pytest.mark.parametrize("change", [{"final_mae": "banana"}, {"task": None}, {"trials": -3}, {"status": "odd"}])
def test_a_wrong_shaped_summary_is_one_line_and_the_report_is_built(change, load, tmp_path, capsys):
    good, bad = tmp_path / "runs" / "good", tmp_path / "runs" / "bad"
    for d in (good, bad):
        run_experiment(load([*DEMO, "trials=1"]), d)
    s = json.loads((bad / "summary.json").read_text())
    s.update(change)
    s = {k: v for k, v in s.items() if v is not None}
    (bad / "summary.json").write_text(json.dumps(s))
    key = next(iter(change))
    assert main(["inspect", str(bad)]) == 2
    captured = capsys.readouterr()
    assert f"summary.json: {key}: " in _one_line_of(captured.err) and "/control" in captured.out
    code = main(["report", str(tmp_path / "runs"), "--out", str(tmp_path / "rep"), "--figures", "fig3_4"])
    err = capsys.readouterr().err
    assert code == 0 and f"bad/summary.json: {key}: " in err
    rows = (tmp_path / "rep" / "runs.csv").read_text().splitlines()
    assert len(rows) == 2 and "good" in rows[1]


def _one_line_of(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1, lines
    return lines[0]


# ---- limits and estimates ---------------------------------------------------------------------------

def test_absurd_trials_are_refused(in_tmp, capsys):
    assert main(["run", *DEMO, "trials=1e12"]) == 2
    assert _one_line(capsys) == "trials: Input should be less than or equal to 100000"
    assert not (in_tmp / "runs").exists()


def test_a_sweep_larger_than_the_limit_is_refused(in_tmp, capsys):
    seeds = ",".join(str(i) for i in range(1001))
    assert main(["run", "-m", *DEMO, "trials=1", f"seed={seeds}"]) == 2
    assert _one_line(capsys) == "sweep: 1,001 jobs; at most 1,000 are run by one command (split the sweep)"


def test_a_run_that_does_not_fit_on_the_disk_is_refused(in_tmp, capsys, monkeypatch):
    from cerebx import estimate

    monkeypatch.setattr(estimate, "free_bytes", lambda folder: 10_000_000)
    assert main(["run", *DEMO, "trials=100"]) == 2  # 200 s of planar2 at 103 kB/s: ~20.6 MB
    err = capsys.readouterr().err.strip().splitlines()
    assert err[0].startswith("run: estimate: 200 s simulated, run.mcap ~20.6 MB")
    assert err[1] == ("run: needs ~20.6 MB but runs has 10.0 MB free; lower trials or record less "
                      "(recording.decimation=N, recording.joint_states=false)")
    assert not (in_tmp / "runs").exists()


def test_the_estimate_matches_a_measured_run(load, tmp_path):
    """The disk estimate of the demo is within 30 % of what a run writes."""
    from cerebx.estimate import estimate

    cfg = load([*DEMO, "trials=4"])
    run_experiment(cfg, tmp_path)
    written = (tmp_path / "run.mcap").stat().st_size
    assert abs(estimate(cfg).mcap_bytes / written - 1) < 0.3, (estimate(cfg), written)


def test_the_full_network_estimate_and_its_compressed_state(load, small_state):
    from cerebx.estimate import estimate

    e = estimate(load(["+task=circle", "trials=100"]))
    assert 140e6 < e.state_bytes < 150e6  # 36 M plastic synapses x 4 bytes + neurons (147.9 MB measured raw)
    assert 57e6 < e.mcap_bytes < 64e6  # 200 s at 303 kB/s (zstd level 1, joint states and spikes in CDR)
    with np.load(small_state / "controller_state.npz") as data:
        raw = sum(data[k].nbytes for k in data.files)
    assert (small_state / "controller_state.npz").stat().st_size < raw / 2  # written compressed


def test_runs_sharing_the_cores_take_the_cpu_they_need(load):
    """A spiking run keeps two threads busy: alone it has both cores, beside another run one. The thesis
    network's learning runs of the full profile from an empty folder (--jobs 2, 2026-11-28) took 588-651 s for
    5,000 s simulated, with 579-614 s of CPU; two such runs at a time take about one run's CPU each."""
    from cerebx.estimate import estimate, total

    e = estimate(load(["+task=circle", "trials=2500"]))  # 5,000 s simulated
    assert 540 < e.cpu_s < 660
    assert e.wall_s < 0.6 * e.cpu_s  # alone: both cores
    assert total([e, e], jobs=1).wall_s == pytest.approx(2 * e.wall_s)  # one after the other
    assert total([e, e], jobs=2).wall_s == pytest.approx(e.cpu_s)  # side by side on 2 cores
    pd = estimate(load(["+task=circle", "controller=pd", "trials=2500"]))  # one thread
    assert pd.wall_s == pytest.approx(pd.cpu_s, rel=0.1)
    assert total([pd, pd], jobs=2).wall_s == pytest.approx(pd.wall_s, rel=0.1)
    assert "2 runs at a time" in total([e, pd], jobs=2).line()


def test_report_dry_run_prints_an_estimate(in_tmp, capsys):
    assert main(["report", "--profile", "quick", "--dry-run", "--figures", "fig3_4"]) == 0
    *_, last, where = capsys.readouterr().out.strip().splitlines()
    assert " runs to do: estimate: " in last and "run.mcap ~" in last and "quiet 2-core machine" in last
    assert where.startswith("where the time goes: learn_circle_ch3 ~")  # the learning the figure starts from


# ---- small things -----------------------------------------------------------------------------------

def test_completion_install_prints_the_script():
    exe = Path(sys.executable).parent / "cerebx"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
    done = subprocess.run([str(exe), "-sc", "install=bash"], capture_output=True, text=True, env=env, timeout=120)
    assert done.returncode == 0, done.stderr
    out = done.stdout
    assert "hydra_bash_completion()" in out and "complete -o nospace -o default -F hydra_bash_completion cerebx" in out


def test_run_help_lists_the_groups_of_cerebx_and_its_plugins(capsys):
    with pytest.raises(SystemExit) as ex:
        main(["run", "--help"])
    assert ex.value.code in (0, None)
    out = capsys.readouterr().out
    assert "\ntask: " in out and "\nnetwork: " in out and "\nkernel: " in out  # kernel: the thesis plugin's


def test_numba_cache_defaults_to_the_checkout(monkeypatch):
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.delenv("CEREBX_CACHE", raising=False)
    assert main(["--version"]) == 0
    root = Path(__file__).resolve().parents[2]
    assert os.environ["NUMBA_CACHE_DIR"] == str(root / ".cache" / "numba")


def test_a_small_network_without_its_preset_points_to_it(capsys):
    assert main(["validate", "+task=circle", "network=small"]) == 2
    assert _one_line(capsys).endswith("(network 'small' comes with matching encoders in +experiment=small_snn)")


def test_the_setup_line_names_the_chosen_presets(load, tmp_path, capsys):
    run_experiment(load([*DEMO, "trials=1"]), tmp_path)
    s = json.loads((tmp_path / "summary.json").read_text())
    s["presets"] = {**s.get("presets", {}), "delay": "gamma45", "controller": "pd_planar2"}
    (tmp_path / "summary.json").write_text(json.dumps(s))
    assert main(["inspect", str(tmp_path)]) == 0
    assert "controller=pd_planar2 plant=planar2 delay=gamma45 " in capsys.readouterr().out


def test_a_summary_key_with_control_characters_is_still_one_line():
    """Found by the long fuzz run: a presets key holding \\x1e split the error over two lines."""
    from cerebx.errors import CerebxError
    from cerebx.recording.summary import validate_summary

    bad = {"status": "completed", "task": "circle", "controller": "pd", "plant": "baxter", "delay": "none",
           "seed": 0, "trials": 1, "presets": {"a\x1eb\nc": 1}}
    with pytest.raises(CerebxError) as err:
        validate_summary(bad, "run/summary.json")
    assert str(err.value).splitlines() == ["run/summary.json: presets.a\\x1eb\\nc: Input should be a valid string"]


def test_a_robot_list_that_is_not_a_list_with_a_delay_is_one_line(capsys):
    """Found by the long fuzz run: the delay-robust default indexed `robot=1` and crashed."""
    assert main(["validate", "+task=circle", "+biodelay=d100", "robot=1"]) == 2
    assert _one_line(capsys) == "robot: Input should be a valid list"
