"""The run lifecycle: whatever ends a run, its summary.json says how and its log is whole and readable."""

from __future__ import annotations

import json

import pytest

from cerebx.loop.lifecycle import RunLifecycle
from cerebx.metrics import TrialMetrics
from cerebx.recording.reader import has_summary, read_messages, read_metadata
from cerebx.recording.summary import read_summary

DEMO = ["+experiment=demo", "trials=3"]


def _metrics(n: int) -> list[TrialMetrics]:
    return [TrialMetrics(i, 0.5 / (i + 1), (0.5 / (i + 1),), 1.0, 0.1, None) for i in range(n)]


def _run(cfg, run_dir, body, seen=None):
    """A run whose trials are ``body(life)``; returns the lifecycle after it closed."""
    with RunLifecycle(cfg, run_dir, overrides=["trials=3"], fields={"presets": {"task": "circle"}}) as life:
        life.on_close(lambda: (seen if seen is not None else []).append(life.status))
        life.rec.write("/events", "cerebx.PlantEvent", 0.0, {"t": 0.0, "kind": "push", "params": {}})
        body(life)
    return life


def _files(run_dir):
    """The summary as read back, and the log's metadata (the log must be closed, with its summary section)."""
    assert has_summary(run_dir / "run.mcap")
    return read_summary(run_dir), read_metadata(run_dir / "run.mcap")


def test_a_run_that_finishes_is_completed(load, tmp_path):
    cfg = load(DEMO)
    seen: list[str] = []

    def body(life):
        for n in (1, 2, 3):
            life.progress(_metrics(n), 2.0 * n)
            assert json.loads((tmp_path / "summary.json").read_text())["trials_completed"] == n
        life.completed()

    life = _run(cfg, tmp_path, body, seen)
    assert seen == ["completed"]  # the closing steps know how the run ended
    s, meta = _files(tmp_path)
    assert s["status"] == "completed" and s["error"] is None
    assert s["trials_completed"] == 3 and s["mae_per_trial"] == pytest.approx([0.5, 0.25, 0.5 / 3])
    assert s["sim_seconds"] == 6.0 and s["presets"] == {"task": "circle"} and s["overrides"] == ["trials=3"]
    assert json.loads(meta["summary"]["json"]) == life.summary
    assert json.loads(meta["config"]["json"]) == cfg.model_dump(mode="json")
    assert [topic for topic, _, _ in read_messages(tmp_path)] == ["/events"]


@pytest.mark.parametrize(("error", "status", "message"), [
    (RuntimeError("boom"), "failed", "RuntimeError: boom"),
    (KeyboardInterrupt(), "interrupted", "interrupted by signal"),
])
def test_an_exception_or_ctrl_c_is_recorded_and_ends_there(load, tmp_path, error, status, message):
    seen: list[str] = []

    def body(life):
        life.progress(_metrics(1), 2.0)
        raise error

    life = _run(load(DEMO), tmp_path, body, seen)  # the exception does not leave the with block
    assert seen == [status] and life.error is error
    s, meta = _files(tmp_path)
    assert s["status"] == status and s["error"] == message and s["trials_completed"] == 1
    assert ("traceback" in s) == isinstance(error, RuntimeError)
    assert json.loads(meta["summary"]["json"])["status"] == status


def test_system_exit_is_recorded_and_raised_again(load, tmp_path):
    def body(life):
        raise SystemExit(3)

    with pytest.raises(SystemExit):
        _run(load(DEMO), tmp_path, body)
    s, _ = _files(tmp_path)
    assert s["status"] == "failed"


def test_a_run_that_ends_without_a_word_is_failed(load, tmp_path):
    _run(load(DEMO), tmp_path, lambda life: None)
    assert _files(tmp_path)[0]["status"] == "failed"


def test_a_failing_closing_step_still_finishes_the_files(load, tmp_path):
    cfg = load(DEMO)
    with pytest.raises(OSError, match="disk full"):
        with RunLifecycle(cfg, tmp_path) as life:
            @life.on_close
            def _broken() -> None:
                raise OSError("disk full")
            life.completed()
    s, _ = _files(tmp_path)
    assert s["status"] == "completed"


def test_a_state_that_cannot_be_saved_is_noted_not_fatal(load, tmp_path):
    class Broken:
        def save_state(self, path):
            raise OSError("read-only")

    def body(life):
        life.save_state(Broken())
        life.completed()

    _run(load(DEMO), tmp_path, body)
    s, _ = _files(tmp_path)
    assert s["status"] == "completed" and s["state_error"] == "read-only"
