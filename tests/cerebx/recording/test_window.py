"""recording.trials: a windowed run records the control steps of the trials its window holds and no others,
the per-trial data of every trial, and the same metrics as a run without a window; a run recorded before
windows existed is still the same experiment; a resumed run keeps the windows it started with."""

from __future__ import annotations

import collections
import json
import signal

import numpy as np
import pytest
from run_processes import cerebx_run as _cerebx
from run_processes import wait_for_checkpoint as _wait_for_checkpoint

from cerebx.errors import ConfigError
from cerebx.loop import resume
from cerebx.loop.runner import run_experiment
from cerebx.recording.reader import channel_counts, read_messages, read_metadata
from cerebx.recording.summary import read_summary
from cerebx.schema.legacy import upgrade
from cerebx.schema.window import TrialWindow

# PD on the planar arm over a random link delay (tests/cerebx/loop/test_resume.py): every trial differs
RUN = ["+experiment=demo", "delay=gamma25", "recording.progress=off"]
PD = ["+task=circle", "controller=pd", "recording.progress=off", "trials=6"]
WINDOW = "recording.trials={first:1,last:1,ranges:[[3,4]]}"


def test_a_window_holds_the_union_of_its_parts():
    w = TrialWindow(first=2, last=3, every=4, ranges=[[6, 8]])
    assert w.trials(12) == [0, 1, 4, 6, 7, 8, 9, 10, 11]
    assert TrialWindow().trials(5) == []
    assert TrialWindow(last=10).trials(4) == [0, 1, 2, 3]
    assert TrialWindow(first=10, ranges=[[149, 160]], last=11).describe(500) == "0-9, 149-159, 489-499 (32 of 500)"


def test_recording_trials_values(load):
    assert load(["+task=circle", "controller=pd"]).recording.trials is None
    assert load(["+task=circle", "controller=pd", "recording.trials=all"]).recording.trials is None
    assert load(["+task=circle", "controller=pd", "recording.trials=none"]).recording.trials == TrialWindow()
    w = load(["+task=circle", "controller=pd", "recording.trials={every:100,ranges:[[3,5]]}"]).recording.trials
    assert w == TrialWindow(every=100, ranges=((3, 5),))
    for bad, says in (("{ranges:[[5,3]]}", "recording.trials.ranges: [5, 3] is not a range"),
                      ("{frist:3}", "recording.trials.frist: unknown key; did you mean first?"),
                      ("some", "recording.trials: 'some': give all, none or a mapping")):
        with pytest.raises(ConfigError) as err:
            load(["+task=circle", "controller=pd", f"recording.trials={bad}"])
        assert str(err.value).startswith(says) and "\n" not in str(err.value)


def _control_trials(run_dir) -> collections.Counter:
    return collections.Counter(m["trial"] for _, _, m in read_messages(run_dir, ["/control"]))


def test_a_windowed_run_records_only_its_trials_and_computes_the_same(tmp_path):
    from cerebx.config import load

    whole, windowed = tmp_path / "whole", tmp_path / "windowed"
    exp, plain = load(PD)
    run_experiment(exp, whole, plain)
    exp, plain = load([*PD, WINDOW])
    run_experiment(exp, windowed, plain)
    steps = 1000  # a 2 s circle trial
    assert _control_trials(windowed) == {0: steps, 3: steps, 5: steps}
    counts = channel_counts(windowed)
    assert counts["/joint_states/actual"] == counts["/joint_states/desired"] == 3 * steps
    assert counts["/trial_metrics"] == 6
    # the held trials' messages are those of the run without a window, bit for bit
    ends = [t for _, t, _ in read_messages(whole, ["/trial_metrics"])]
    for k in (0, 3, 5):
        lo = ends[k - 1] if k else 0
        for topic in ("/control", "/joint_states/actual", "/joint_states/desired"):
            assert (list(read_messages(windowed, [topic], lo, ends[k]))
                    == list(read_messages(whole, [topic], lo, ends[k]))), (k, topic)
    a, b = read_summary(whole), read_summary(windowed)
    assert a["mae_per_trial"] == b["mae_per_trial"] and a["mae_per_joint_per_trial"] == b["mae_per_joint_per_trial"]
    recorded = json.loads(read_metadata(windowed)["config"]["json"])["recording"]["trials"]
    assert TrialWindow(**recorded) == TrialWindow(first=1, last=1, ranges=[[3, 4]])


def test_a_windowed_snn_run_records_its_spikes_in_the_held_trials_only(tmp_path):
    from cerebx.config import load

    args = ["+task=circle", "+experiment=small_snn", "recording.progress=off", "trials=4"]
    whole, windowed = tmp_path / "whole", tmp_path / "windowed"
    exp, plain = load(args)
    run_experiment(exp, whole, plain)
    exp, plain = load([*args, "recording.trials={ranges:[[1,2]]}"])
    run_experiment(exp, windowed, plain)
    ends = [t for _, t, _ in read_messages(whole, ["/trial_metrics"])]
    spikes = list(read_messages(windowed, ["/spikes/dcn"]))
    assert spikes and all(ends[0] <= t < ends[1] for _, t, _ in spikes)
    assert spikes == list(read_messages(whole, ["/spikes/dcn"], ends[0], ends[1]))
    assert sum(len(m["indices"]) for _, _, m in spikes) > 0
    assert read_summary(whole)["mae_per_trial"] == read_summary(windowed)["mae_per_trial"]


def test_a_run_recorded_before_windows_is_the_same_experiment(tmp_path):
    """Its recorded config has no recording.trials: reused by today's composition, with or without a window."""
    from cerebx.config import load

    exp, plain = load(PD)
    older = json.loads(json.dumps(plain))
    del older["recording"]["trials"]
    run_dir = tmp_path / "older"
    run_experiment(exp, run_dir, older)
    assert "trials" not in json.loads(read_metadata(run_dir)["config"]["json"])["recording"]
    assert upgrade(older)["recording"]["trials"] is None
    done = read_summary(run_dir)
    assert resume.stale(run_dir, plain, done) is None
    assert resume.stale(run_dir, load([*PD, WINDOW])[1], done) is None
    assert resume.stale(run_dir, load([*PD, "seed=3"])[1], done) is not None


@pytest.mark.integration
def test_a_resumed_run_keeps_its_windows(tmp_path):
    """Killed after a checkpoint and resumed with another window, the run records the trials of the window it
    started with, as one never interrupted."""
    window = "recording.trials={first:2,every:7,last:3}"
    args = [*RUN, "trials=24", "recording.checkpoint_every=4", window]
    whole, killed = tmp_path / "whole", tmp_path / "killed"
    ref = _cerebx(*args, f"hydra.run.dir={whole}", cwd=tmp_path)
    run = _cerebx(*args, f"hydra.run.dir={killed}", cwd=tmp_path)
    _wait_for_checkpoint(killed, 8, run)
    run.send_signal(signal.SIGKILL)
    run.wait()
    assert ref.wait() == 0, ref.stdout.read()
    cont = _cerebx(f"resume={killed}", "recording.trials=all", cwd=tmp_path)
    out, _ = cont.communicate(timeout=300)
    assert cont.returncode == 0, out
    held = TrialWindow(first=2, every=7, last=3).trials(24)
    assert sorted(_control_trials(killed)) == held == [0, 1, 7, 14, 21, 22, 23]
    for topic in ("/trial_metrics", "/control", "/joint_states/actual"):
        assert list(read_messages(killed, [topic])) == list(read_messages(whole, [topic])), topic
    assert np.std(read_summary(whole)["mae_per_trial"]) > 0


def test_the_size_estimate_counts_the_held_trials(tmp_path):
    """The disk estimate of a windowed run is within 30 % of what it writes, about a third of the whole run's."""
    from cerebx.config import load
    from cerebx.estimate import estimate

    whole, windowed = load(PD)[0], load([*PD, "recording.trials={first:2}"])[0]
    run_experiment(windowed, tmp_path)
    written = (tmp_path / "run.mcap").stat().st_size
    assert abs(estimate(windowed).mcap_bytes / written - 1) < 0.3, (estimate(windowed), written)
    assert estimate(windowed).mcap_bytes == pytest.approx(estimate(whole).mcap_bytes / 3)


def test_the_delay_table_of_a_run_without_delay_needs_no_control_step(tmp_path):
    """delays.csv lists every run launched with a delay preset; one without a link delay has a realised round trip
    of 0 ms whatever its window, so a run recording no control step still reads 0.0 (as one recording every step)."""
    from cerebx.config import load
    from cerebx.report.delays import delay_rows
    from cerebx.report.runs import Run, RunSet

    rows = {}
    for name, extra in (("whole", []), ("none", ["recording.trials=none"])):
        exp, plain = load([*PD, "trials=2", *extra])
        run_experiment(exp, tmp_path / name, plain, choices={"delay": "none"})
        rows[name] = delay_rows(RunSet([Run.load(tmp_path / name)]))[1]
    assert channel_counts(tmp_path / "none").get("/control", 0) == 0
    assert rows["none"][4] == rows["whole"][4] == "0.0"
    assert rows["none"][:-1] == rows["whole"][:-1]
