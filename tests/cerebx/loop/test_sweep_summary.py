"""`cerebx summarize`: one row per job of a sweep, the swept overrides as columns (fixture folders)."""

from __future__ import annotations

import csv
import json
import os
import socket
from pathlib import Path

import pytest

from cerebx.cli import main
from cerebx.report.sweep import summarize, write

pytestmark = pytest.mark.integration


def _job(root: Path, num: int, overrides: list[str], summary: dict | None) -> None:
    d = root / str(num)
    (d / ".hydra").mkdir(parents=True)
    (d / ".hydra" / "overrides.yaml").write_text("".join(f"- {o}\n" for o in overrides))
    if summary is not None:
        (d / "summary.json").write_text(json.dumps(summary))


def _sweep(root: Path) -> Path:
    runs = [("0", "none", 0.30, "completed"), ("20", "gamma25", 0.45, "completed"), ("40", "none", None, "failed")]
    for i, (ms, delay, mae, status) in enumerate(runs):
        _job(root, i, ["+experiment=fig3_4_pd", f"delay.total_ms={ms}", f"delay={delay}", "trials=12"],
             {"status": status, "task": "circle", "controller": "pd", "plant": "baxter", "delay": delay,
              "seed": 0, "error": None if mae else "Diverged: joint 2 left its bounds", "trials": 12,
              "trials_completed": 12 if mae else 3, "final_mae": mae,
              "rt_factor": 2.5 + i})
    _job(root, 10, ["+experiment=fig3_4_pd", "delay.total_ms=80", "delay=none", "trials=12"], None)  # no summary
    (root / "multirun.yaml").write_text(
        "hydra:\n  overrides:\n    task: ['+experiment=fig3_4_pd', 'delay.total_ms=0,20,40,80', 'trials=12']\n")
    (root / ".submitit").mkdir()
    return root


def test_table_has_swept_overrides_and_results(tmp_path):
    s = summarize(_sweep(tmp_path))
    assert s.keys == ["delay.total_ms", "delay"]  # declared sweep, and a value that differs between jobs
    head, *rows = s.table()
    assert head == ["job", "delay.total_ms", "delay", "status", "trials", "final_mae_rad", "rt_factor", "reason"]
    assert [r[0] for r in rows] == ["0", "1", "2", "10"]  # job order, not text order
    assert rows[0] == ["0", "0", "none", "completed", "12/12", "0.3000", "2.5000", ""]
    assert rows[2][3:6] == ["failed", "3/12", ""] and rows[2][7] == "Diverged: joint 2 left its bounds"
    assert rows[3][3] == "missing" and rows[3][7] == "the job left no summary.json"
    assert s.failed == 2 and s.exit_code() == 2
    assert s.numeric_keys() == ["delay.total_ms"]


def test_files_beside_the_job_folders(tmp_path):
    paths = write(summarize(_sweep(tmp_path)))
    assert [p.name for p in paths] == ["sweep_summary.csv", "sweep_summary.md", "sweep_summary.png"]
    with open(paths[0]) as fh:
        table = list(csv.reader(fh))
    assert table[1][:3] == ["0", "0", "none"] and len(table) == 5
    md = paths[1].read_text().splitlines()
    assert md[0] == "| job | delay.total_ms | delay | status | trials | final_mae_rad | rt_factor | reason |"
    assert md[3] == "| 1 | 20 | gamma25 | completed | 12/12 | 0.4500 | 3.5000 |  |"
    assert paths[2].stat().st_size > 5000


def test_cli_prints_the_table_and_refuses_a_non_sweep(tmp_path, capsys):
    assert main(["summarize", str(_sweep(tmp_path / "sweep"))]) == 2  # the exit code counts failed jobs
    out = capsys.readouterr().out
    assert "| 2 | 40 | none | failed | 3/12 |" in out and "sweep_summary.png" in out
    assert out.rstrip().endswith("2 of 4 jobs completed, 2 failed (exit code 2)")
    (tmp_path / "empty").mkdir()
    assert main(["summarize", str(tmp_path / "empty")]) == 2
    assert capsys.readouterr().err.strip().endswith("empty: no job folders (expected 0/, 1/ … with summary.json)")


def test_multirun_prints_the_summary_when_it_ends(in_tmp, capsys):
    code = main(["run", "-m", "+experiment=demo", "trials=1", "seed=1,2", "recording.progress=off",
                 "hydra.sweep.dir=sweep"])
    assert code == 0
    out = capsys.readouterr().out
    assert "| job | seed | status | trials | final_mae_rad | rt_factor |" in out
    assert (in_tmp / "sweep" / "sweep_summary.md").exists()


def test_a_job_still_running_in_another_process_is_not_a_failure(tmp_path):
    """Two multiruns into one folder (the report's paired jobs) see each other's jobs: a live one is
    ``running``, not failed; one whose process is gone reads as ``killed`` and is."""
    base = {"task": "eight", "controller": "snn", "plant": "baxter", "delay": "none", "seed": 0, "error": None,
            "trials": 10, "host": socket.gethostname()}
    _job(tmp_path, 0, ["muscle.cocontraction=0"], {**base, "status": "completed", "trials_completed": 10,
                                                   "final_mae": 0.02, "rt_factor": 4.0})
    _job(tmp_path, 1, ["muscle.cocontraction=1"], {**base, "status": "running", "trials_completed": 3,
                                                   "pid": os.getpid()})
    s = summarize(tmp_path)
    assert [r.status for r in s.rows] == ["completed", "running"] and s.exit_code() == 0
    assert s.outcome().endswith("1 of 2 jobs completed, 1 still running in another process")
    dead = json.loads((tmp_path / "1" / "summary.json").read_text()) | {"pid": 2**22 + 1}
    (tmp_path / "1" / "summary.json").write_text(json.dumps(dead))
    s = summarize(tmp_path)
    assert [r.status for r in s.rows] == ["completed", "killed"] and s.exit_code() == 1
