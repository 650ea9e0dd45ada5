"""Resumable runs: a run killed with SIGKILL and resumed from its last checkpoint logs the same trials as
one never interrupted, and its log reads as one run across its MCAP segments."""

from __future__ import annotations

import functools
import json
import os
import signal
import time
from pathlib import Path

import numpy as np
import pytest
from run_processes import cerebx_run as _cerebx
from run_processes import wait_for_checkpoint as _wait_for_checkpoint

from cerebx.controllers.snn.schema import SNNController
from cerebx.errors import ConfigError
from cerebx.loop import resume
from cerebx.persistence import checkpoint
from cerebx.recording.reader import channel_counts, read_messages, read_metadata
from cerebx.recording.segments import segments

pytestmark = pytest.mark.integration

# PD on the planar arm over a random (gamma) link delay: every trial differs, so the continuation only
# matches when the generators, the messages in flight and the plant's state are all restored.
RUN = ["+experiment=demo", "delay=gamma25", "recording.progress=off"]


def _summary(run_dir: Path) -> dict:
    return json.loads((run_dir / "summary.json").read_text())


def test_sigkilled_run_resumes_to_the_same_trials(tmp_path):
    trials, every, kill_after = 20, 4, 8
    whole, killed = tmp_path / "whole", tmp_path / "killed"
    ref = _cerebx(*RUN, f"trials={trials}", f"recording.checkpoint_every={every}", f"hydra.run.dir={whole}",
                  cwd=tmp_path)
    run = _cerebx(*RUN, f"trials={trials}", f"recording.checkpoint_every={every}", f"hydra.run.dir={killed}",
                  cwd=tmp_path)
    _wait_for_checkpoint(killed, kill_after, run)
    time.sleep(0.2)  # into the next trials, which the continuation runs again
    run.send_signal(signal.SIGKILL)
    run.wait()
    assert ref.wait() == 0, ref.stdout.read()
    assert not (killed / "summary.json").exists() or _summary(killed)["status"] != "completed"
    done_at_kill = checkpoint.read_head(killed)["trials_done"]  # the committed one (its .json copy may lag)
    assert kill_after <= done_at_kill < trials

    cont = _cerebx(f"resume={killed}", cwd=tmp_path)
    out, _ = cont.communicate(timeout=300)
    assert cont.returncode == 0, out

    a, b = _summary(whole), _summary(killed)
    assert b["status"] == "completed" and b["trials_completed"] == trials
    assert len(b["mae_per_trial"]) == trials
    assert b["mae_per_trial"] == a["mae_per_trial"]  # exactly: same seed, same trials
    assert b["mae_per_joint_per_trial"] == a["mae_per_joint_per_trial"]
    assert np.std(a["mae_per_trial"]) > 0  # the trials differ from each other (random delays)
    assert b["sim_seconds"] == a["sim_seconds"]

    segs = segments(killed)
    assert [s.path.name for s in segs] == ["run.mcap", "run.1.mcap"]
    assert segs[1].start_ns == done_at_kill * 2_000_000_000  # demo trials last 2 s
    assert not (killed / resume.CHECKPOINT).exists()  # a completed run drops its checkpoint
    # the killed segment is still readable on its own, and the run reads as one log equal to the whole run's
    first = [m["trial"] for _t, _ns, m in read_messages(segs[0].path, ["/trial_metrics"])]
    assert first[:done_at_kill] == list(range(done_at_kill))
    topics = ("/trial_metrics", "/control", "/joint_states/actual")
    by_topic = [{t: [m for m in messages if m[0] == t] for t in topics}
                for messages in (list(read_messages(d, list(topics))) for d in (killed, whole))]
    for topic in topics:  # one pass over each log (its chunks decoded once), compared topic by topic
        assert by_topic[0][topic] == by_topic[1][topic], topic
    assert channel_counts(killed) == channel_counts(whole)
    assert json.loads(read_metadata(killed)["summary"]["json"])["trials_completed"] == trials


def test_sigkilled_learning_run_resumes_to_the_same_weights(tmp_path):
    """The spiking network's weights: written ahead of the first checkpoint from the live array, then only
    their changed rows; a resumed process writes its own file ahead (after settling the committed journal)."""
    trials = 16
    args = ["+task=circle", "+experiment=small_snn", "recording.progress=off", f"trials={trials}",
            "recording.checkpoint_every=4"]
    whole, killed = tmp_path / "whole", tmp_path / "killed"
    ref = _cerebx(*args, f"hydra.run.dir={whole}", cwd=tmp_path)  # beside the run that is killed
    run = _cerebx(*args, f"hydra.run.dir={killed}", cwd=tmp_path)
    _wait_for_checkpoint(killed, 8, run)
    run.send_signal(signal.SIGKILL)
    run.wait()
    assert ref.wait() == 0, ref.stdout.read()
    head = checkpoint.read_head(killed)
    assert head["arrays"]["file"] == "checkpoint.4.arrays"  # written ahead, then journals on top
    assert head["trials_done"] < trials
    cont = _cerebx(f"resume={killed}", cwd=tmp_path)
    out, _ = cont.communicate(timeout=300)
    assert cont.returncode == 0, out
    a, b = _summary(whole), _summary(killed)
    assert b["status"] == "completed" and b["mae_per_trial"] == a["mae_per_trial"]
    with np.load(whole / "controller_state.npz") as sa, np.load(killed / "controller_state.npz") as sb:
        assert sa.files == sb.files and all(np.array_equal(sa[k], sb[k]) for k in sa.files)


def test_resume_refuses_another_config(tmp_path):
    run_dir = tmp_path / "run"
    p = _cerebx(*RUN, "trials=4", "recording.checkpoint_every=2", f"hydra.run.dir={run_dir}", cwd=tmp_path)
    assert p.wait() == 0
    # a completed run has no checkpoint left
    p = _cerebx(f"resume={run_dir}", "trials=8", cwd=tmp_path)
    out, _ = p.communicate()
    assert p.returncode == 2 and "resume:" in out and "checkpoint" in out, out


def test_checkpoint_head_is_checked_before_anything_is_written(tmp_path, load):
    from cerebx.build import build_components
    from cerebx.loop.loop import ClosedLoop

    cfg = load([*RUN, "trials=6", "recording.checkpoint_every=2"])
    loop = ClosedLoop(build_components(cfg), None)
    loop.start()
    for trial in range(2):
        loop.run_trial(trial)
    resume.save(loop, tmp_path, wall_seconds=1.0)
    resume.check(cfg, tmp_path)
    with pytest.raises(ConfigError, match=r"^delay\.c2r\.offset_ms: 6\.0 differs from the resumed run's 5\.0$"):
        resume.check(load([*RUN, "delay.r2c.offset_ms=6.0", "delay.c2r.offset_ms=6.0", "trials=6"]), tmp_path)
    with pytest.raises(ConfigError, match="trials: 2, but the checkpoint already has 2 trials done"):
        resume.check(load([*RUN, "trials=2"]), tmp_path)
    assert not (tmp_path / "segments.json").exists()


def test_resume_args_repeat_the_run_overrides(tmp_path):
    (tmp_path / ".hydra").mkdir()
    (tmp_path / ".hydra" / "overrides.yaml").write_text("- +experiment=demo\n- trials=10\n- seed=3\n")
    args = resume.expand_args([f"resume={tmp_path}", "trials=20"])
    assert args == ["+experiment=demo", "seed=3", "trials=20", f"resume={tmp_path}", f"hydra.run.dir={tmp_path}",
                    "hydra.output_subdir=.hydra.resumed"]
    assert resume.expand_args(["+experiment=demo"]) == ["+experiment=demo"]


def test_resume_auto_reuses_continues_or_restarts(tmp_path, load):
    from cerebx.build import build_components
    from cerebx.loop.loop import ClosedLoop

    cfg = load([*RUN, "trials=6", "resume=auto"])
    plain: dict = {}
    # nothing there: a fresh run, and stale files of an attempt without checkpoint are dropped
    (tmp_path / "segments.json").write_text("{}")
    exp, run_dir, reused = resume.continued(cfg, plain, tmp_path)
    assert (exp.resume, run_dir, reused) == (None, tmp_path, None) and not (tmp_path / "segments.json").exists()
    # a checkpoint of the same config: continue from it
    loop = ClosedLoop(build_components(load([*RUN, "trials=6"])), None)
    loop.start()
    loop.run_trial(0)
    resume.save(loop, tmp_path, wall_seconds=0.5)
    exp, run_dir, reused = resume.continued(cfg, plain, tmp_path)
    assert exp.resume == str(tmp_path) and plain["resume"] == str(tmp_path) and reused is None
    # completed with fewer trials than asked: continue from its checkpoint
    (tmp_path / "summary.json").write_text(json.dumps({"status": "completed", "trials_completed": 6}))
    assert resume.continued(load([*RUN, "trials=8", "resume=auto"]), {}, tmp_path)[0].resume == str(tmp_path)


def test_resume_auto_reuses_only_a_run_of_todays_config_after_its_source(tmp_path, load):
    """A completed run is reused only when the presets still compose to its recorded configuration (the
    trial count aside) and the run it started from has not been written since (else it runs again)."""
    from cerebx.config import load as compose
    from cerebx.loop.runner import run_experiment
    from cerebx.recording.summary import read_summary

    source, run = tmp_path / "source", tmp_path / "run"
    exp, plain = compose([*RUN, "trials=2"])
    run_experiment(exp, source, plain)
    named = {**plain, "init_from": str(source)}  # recorded as if it had started from `source`
    run_experiment(exp, run, named)
    done = read_summary(run)
    assert resume.stale(run, named, done) is None
    assert resume.stale(run, {**named, "trials": 9, "recording": {}}, done) is None  # longer: continued()'s call
    assert resume.continued(load([*RUN, "trials=2", "resume=auto"]), dict(named), run)[2] is not None
    # a preset value changed since: run again
    _, other = compose([*RUN, "trials=2", "seed=1"])
    assert resume.stale(run, {**other, "init_from": str(source)}, done).startswith("the configuration changed: seed")
    assert resume.continued(load([*RUN, "trials=2", "resume=auto", "seed=1"]),
                            {**other, "init_from": str(source)}, run)[2] is None
    # the run it started from was written again after it started: run again
    later = float(done["started_at"]) + 60.0
    os.utime(source / "summary.json", (later, later))
    assert "was written after it started" in resume.stale(run, named, done)


def test_older_recorded_layouts_are_the_same_experiment(tmp_path):
    """A run recorded before an option was added (with the value that does what it did) or when the network
    was a top-level key of every experiment still counts as the same experiment; another value does not."""
    from cerebx.config import load as compose
    from cerebx.loop.runner import run_experiment
    from cerebx.recording.summary import read_summary

    exp, plain = compose(["+task=circle", "+experiment=small_snn", "trials=1", "recording.progress=off"])
    dotted, old_value = next(iter(SNNController.added_without_effect.items()))
    *parents, last = ["controller", *dotted.split(".")]

    def recorded(value=None, flat=False):  # `plain` as an older version recorded it
        out = json.loads(json.dumps(plain))
        node = functools.reduce(lambda d, k: d.setdefault(k, {}), parents, out)
        node.pop(last, None)
        if value is not None:
            node[last] = value
        if flat:
            out["network"] = out["controller"].pop("network")
        return out

    older = tmp_path / "older"
    run_experiment(exp, older, recorded(flat=True))
    done = read_summary(older)
    assert resume.stale(older, plain, done) is None
    assert resume.stale(older, recorded(old_value), done) is None
    assert resume.stale(older, recorded("something else"), done) is not None
    assert resume.stale(older, {**plain, "seed": 7}, done).startswith("the configuration changed: seed")


def test_a_checkpoint_naming_a_moved_module_still_loads():
    """The velocity PID moved from cerebx.controllers.pid to cerebx.stages.pid; a checkpoint written before
    names the old module."""
    import io
    import pickle

    from cerebx.persistence.checkpoint import _Unpickler
    from cerebx.stages.pid import PIDVelocityStage

    data = pickle.dumps(PIDVelocityStage, protocol=0).replace(b"cerebx.stages.pid", b"cerebx.controllers.pid")
    assert b"cerebx.controllers.pid" in data
    assert _Unpickler(io.BytesIO(data), {}, {}).load() is PIDVelocityStage
