"""Headline numbers over seeds (95 % intervals and whether the paper's number is inside), studies learned from
several seeds, and failing checks linked to the page that explains them."""

from __future__ import annotations

import csv
import json
import re
from pathlib import Path

import numpy as np
import pytest

from cerebx.errors import ConfigError
from cerebx.report import registry
from cerebx.report.build import PAPER_HEADER, build_from, paper_row
from cerebx.report.explain import explain, load_explanations
from cerebx.report.registry import Check, Figure, FigureSpec
from cerebx.report.runs import Run, RunSet
from cerebx.report.stats import interval, t975
from cerebx.report.studies import REPLICA, group, load_studies, plan

DOCS = Path(__file__).resolve().parents[3] / "docs"


def test_interval_is_students_t_on_the_seed_values():
    iv = interval([1.0, 2.0, 3.0], paper=2.5)
    # mean 2, s = 1, t(0.975, 2) = 4.303: 2 ± 4.303 / sqrt(3)
    assert iv.mean == 2.0 and iv.n == 3
    assert iv.low == pytest.approx(2 - 4.303 / np.sqrt(3)) and iv.high == pytest.approx(2 + 4.303 / np.sqrt(3))
    assert iv.paper_in_ci == "yes"
    assert interval([1.0, 1.1, 0.9], paper=5.0).paper_in_ci == "no"
    assert interval([1.0, 1.1, 0.9], paper=(1.05, 9.0)).paper_in_ci == "yes"  # a paper range overlapping it


def test_one_seed_has_no_interval_and_no_verdict():
    iv = interval([0.02], paper=0.024)
    assert not iv.has_interval and iv.paper_in_ci == "–" and iv.text() == "0.020"
    assert interval([0.02, float("nan"), None]).n == 1  # non-finite values are left out
    with pytest.raises(ValueError):
        interval([])
    assert t975(1) == 12.706 and t975(1000) == 1.960


def test_paper_vs_cerebx_rows_carry_the_interval_columns():
    fig = Figure([], "", [["quantity", "paper", "cerebx"], ["ratio", "3 to 4×", "3.5"], ["other", "1", "1"]],
                 intervals={"ratio": interval([3.2, 3.6, 3.4], paper=(3.0, 4.0))})
    rows = [paper_row("f", fig, row) for row in fig.table[1:]]
    assert PAPER_HEADER[-4:] == ["seeds", "ci_low", "ci_high", "paper_in_ci"]
    assert rows[0][:4] == ["f", "ratio", "3 to 4×", "3.5"] and rows[0][5] == "3"
    assert float(rows[0][6]) < 3.4 < float(rows[0][7]) and rows[0][8] == "yes"
    assert rows[1][5:] == ["1", "–", "–", "–"]


def _studies(tmp_path: Path, text: str):
    f = tmp_path / "studies.yaml"
    f.write_text(text)
    return load_studies(f)


def test_a_study_learned_from_several_seeds_runs_one_replica_per_further_seed(tmp_path):
    studies = _studies(tmp_path, "studies:\n"
                       "  learn:\n    args: [+experiment=learn_circle_ch3]\n"
                       "    quick: {trials: 1}\n    full: {trials: 2, seeds: 3}\n"
                       "  evaluate:\n    args: [+experiment=fig3_4_snn]\n    init_from: learn\n"
                       "    quick: {trials: 1}\n    full: {trials: 2, seeds: 2}\n")
    assert [j.name for j in plan("quick", tmp_path, studies=studies)][0] == "learn/run"
    jobs = plan("full", tmp_path, ["evaluate"], studies=studies)
    by = {j.name: j for j in jobs}
    assert {"learn/run", f"learn{REPLICA}1/run", f"learn{REPLICA}2/run"} <= set(by)
    one = by[f"evaluate{REPLICA}1/delay.total_ms=40"]
    assert "seed=1" in one.overrides()
    assert one.run_dir == tmp_path / "full" / f"evaluate{REPLICA}1" / "delay.total_ms=40"
    assert one.deps[0].name == f"learn{REPLICA}1/run"  # seed 1 is evaluated from seed 1's learned state
    assert "seed=1" not in by["evaluate/delay.total_ms=40"].overrides()  # the first seed is the preset's
    assert not any(j.study == f"evaluate{REPLICA}2" for j in jobs)  # two seeds asked for: one replica
    assert {s.name for s in group(jobs)} >= {f"learn{REPLICA}2", f"evaluate{REPLICA}1"}


def test_a_study_cannot_both_set_its_seed_and_ask_for_seeds(tmp_path):
    with pytest.raises(ConfigError, match="full.seeds: the study sets its seed itself"):
        _studies(tmp_path, "studies:\n  a:\n    args: [+experiment=learn_circle_ch3, seed=4]\n"
                 "    quick: {trials: 1}\n    full: {trials: 2, seeds: 3}\n")


def _run(tmp_path: Path, name: str, seed: int, trials: int = 3) -> Run:
    d = tmp_path / name
    d.mkdir()
    (d / "summary.json").write_text("{}")
    return Run(d, {"seed": seed, "status": "completed", "trials_completed": trials})


def test_figures_draw_the_first_seed_and_group_the_others(tmp_path):
    runs = RunSet([_run(tmp_path, "b", 1), _run(tmp_path, "a", 0), _run(tmp_path, "c", 2)])
    assert runs.best().seed == 0
    assert list(runs.seeds()) == [0, 1, 2] and all(len(v) == 1 for v in runs.seeds().values())


def test_a_failing_check_links_to_its_explanation_a_passing_one_does_not(tmp_path):
    f = tmp_path / "explanations.yaml"
    f.write_text("explanations:\n"
                 "  - {figure: figx, claim: 'ANN below', at: 'reproductions/thesis-ch3.md#fig3_4', profiles: [full]}\n")
    known = load_explanations(f)
    fig = Figure([], "", checks=[Check("ANN below SNN at 40 ms", False), Check("ANN below PD", True),
                                 Check("other", False)])
    explain("figx", fig, "full", known)
    assert [c.explained_at for c in fig.checks] == ["docs/reproductions/thesis-ch3.md#fig3_4", None, None]
    explain("figx", fig, "quick", known)  # not said for the quick profile
    assert fig.checks[0].explained_at is None
    bad = tmp_path / "bad.yaml"
    bad.write_text("explanations:\n  - {figure: figx, claim: c, at: 'no anchor.md'}\n")
    with pytest.raises(ConfigError, match="bad.yaml: explanations.0.at"):
        load_explanations(bad)


def test_every_registered_explanation_points_at_a_docs_heading():
    """Each plugin's explanation names a page of docs/ and a heading on it (MkDocs' anchor of that heading)."""
    for e in load_explanations():
        page, anchor = e.at.split("#")
        text = (DOCS / page).read_text()
        anchors = {re.sub(r"[^\w\- ]", "", h.strip().lower()).replace(" ", "-")
                   for h in re.findall(r"^#+ (.+)$", text, re.M)}
        anchors |= set(re.findall(r"\{ *#([\w-]+) *\}", text))
        assert anchor in anchors, f"{e.figure}: {e.at}: no such heading"
        assert e.figure in registry.all_figures(), e.figure


def test_figures_json_and_shapes_csv_carry_explained_at_and_intervals(tmp_path, monkeypatch):
    def draw(runs, stem):
        return Figure([], "cap", [["quantity", "paper", "cerebx"], ["q", "0.02", "0.021"]],
                      checks=[Check("SNN below PD", False, "1 vs 0")],
                      intervals={"q": interval([0.02, 0.021, 0.022], paper=0.02)})

    spec = FigureSpec("figx", "a figure", ("s",), draw)
    monkeypatch.setattr("cerebx.report.build.all_figures", lambda: {"figx": spec})
    f = tmp_path / "explanations.yaml"
    f.write_text("explanations:\n  - {figure: figx, claim: SNN below, at: 'reproductions/thesis-ch3.md#fig3_5'}\n")
    monkeypatch.setattr("cerebx.report.build.load_explanations", lambda: load_explanations(f))
    build_from(RunSet(), tmp_path / "out", profile="full")
    made = json.loads((tmp_path / "out" / "figures.json").read_text())
    entry = made["figures"][0]
    assert entry["checks"][0]["explained_at"] == "docs/reproductions/thesis-ch3.md#fig3_5"
    assert entry["intervals"]["q"]["n"] == 3 and entry["intervals"]["q"]["paper_in_ci"] == "yes"
    with open(tmp_path / "out" / "paper_vs_cerebx.csv") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == PAPER_HEADER and rows[1][-1] == "yes"
    with open(tmp_path / "out" / "shapes.csv") as fh:
        shapes = list(csv.reader(fh))
    assert shapes[0][-1] == "explained_at" and shapes[1][-1] == "docs/reproductions/thesis-ch3.md#fig3_5"


def test_a_plan_can_run_only_the_first_seeds(tmp_path):
    studies = _studies(tmp_path, "studies:\n"
                       "  learn:\n    args: [+experiment=learn_circle_ch3]\n"
                       "    quick: {trials: 1}\n    full: {trials: 2, seeds: 3}\n")
    assert [j.study for j in plan("full", tmp_path, studies=studies, max_seeds=1)] == ["learn"]
    assert [j.study for j in plan("full", tmp_path, studies=studies, max_seeds=2)] == ["learn", f"learn{REPLICA}1"]
    assert len(plan("full", tmp_path, studies=studies)) == 3


def test_a_check_decided_on_numpy_values_is_written_as_a_boolean():
    """Capolei's Fig. 5 compared two numpy floats: figures.json said "True" (a string), and the table of checks
    counted it as undecided."""
    from dataclasses import asdict

    c = Check("IV's drop larger on joint 2", np.float64(49.0) > np.float64(47.0), "49 vs 47 %")
    assert c.holds is True and json.loads(json.dumps(asdict(c), default=str))["holds"] is True
    assert Check("cannot tell", None).holds is None
