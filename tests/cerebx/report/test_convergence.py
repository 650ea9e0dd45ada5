"""Convergence as data: the plateau test of learning curves drives a badge on the figure's images, the same
words in its caption, a column of paper_vs_cerebx.csv and the table index.html opens with."""

from __future__ import annotations

import csv
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from cerebx.report import registry  # noqa: E402
from cerebx.report.badge import BAND  # noqa: E402
from cerebx.report.build import build_from  # noqa: E402
from cerebx.report.convergence import Convergence, PlateauRule, learning_convergence, plateau  # noqa: E402
from cerebx.report.plot import save  # noqa: E402
from cerebx.report.registry import Check, Figure, figure  # noqa: E402
from cerebx.report.runs import Run, RunSet  # noqa: E402
from cerebx.report.studies import study_plateau  # noqa: E402

NEEDED = 100  # the trials at which the synthetic paper's shape appears
UNCONVERGED = "not converged: 40 of 100 learning trials; run --profile full"


def _curve(n: int, tau: float = 15.0) -> np.ndarray:
    """An exponential learning curve from 0.3 to 0.02 rad (levels off after ~5 tau trials)."""
    return 0.02 + 0.28 * np.exp(-np.arange(n) / tau)


def _run(root: Path, name: str, mae, learned_from: str | None = None, task: str = "circle") -> Run:
    summary = {"task": task, "controller": "snn", "plant": "baxter", "delay": "none", "seed": 0,
               "status": "completed", "trials_completed": len(mae), "mae_per_trial": list(mae),
               "final_mae": float(mae[-1]), "sim_seconds": 2.0 * len(mae)}
    return Run(root / name, summary, {"init_from": learned_from, "events": []})


def test_the_plateau_test_reads_the_curve_not_its_length():
    assert plateau(_curve(100), NEEDED).level  # two windows of 10 within 10 %
    falling = plateau(_curve(100, tau=60.0), NEEDED)  # as long, still learning
    assert not falling.level and "still falling" in falling.numbers()
    short = plateau(_curve(15), NEEDED)  # fewer than two windows of a tenth of NEEDED
    assert not short.level and short.before is None
    assert plateau(np.r_[_curve(80), np.full(20, 0.05)], NEEDED).level  # rising again: no longer learning
    assert not plateau(np.r_[_curve(90), np.full(10, np.nan)], NEEDED).level


def test_the_rule_is_the_study_data(tmp_path, monkeypatch):
    studies = tmp_path / "studies.yaml"
    studies.write_text("studies:\n"
                       "  toy_learn:\n    args: [+experiment=learn_circle]\n"
                       "    quick: {trials: 40}\n    full: {trials: 100}\n"
                       "    plateau: {window_fraction: 0.3, tolerance: 0.6}\n"
                       "  toy_default:\n    args: [+experiment=learn_circle]\n"
                       "    quick: {trials: 40}\n    full: {trials: 100}\n")
    registry.load_reports()
    monkeypatch.setattr(registry, "STUDY_FILES", [*registry.STUDY_FILES, studies.resolve()])
    monkeypatch.setattr("cerebx.report.studies.STUDY_FILES", registry.STUDY_FILES)
    rule = study_plateau("toy_learn")
    assert rule == PlateauRule(100, window_fraction=0.3, tolerance=0.6) and rule.window == 30
    assert study_plateau("toy_default") == PlateauRule(100)
    slow = _curve(100, tau=60.0)  # still falling by the default rule, level by the study's looser one
    assert not plateau(slow, study_plateau("toy_default")).level and plateau(slow, rule).level


def test_the_badge_says_how_many_trials_of_how_many():
    conv = Convergence((plateau(_curve(40), NEEDED, "a"), plateau(_curve(100), NEEDED, "b")))
    assert not conv.converged and conv.badge == UNCONVERGED
    assert conv.flag("anything") == "no (40 of 100 learning trials; run --profile full)"
    long = Convergence((plateau(_curve(100, tau=60.0), NEEDED, "slow"),))
    assert long.badge == "not converged: MAE still falling after 100 learning trials"
    done = Convergence((plateau(_curve(100), NEEDED),), rows=lambda q: q.startswith("SNN"))
    assert done.badge is None and done.flag("SNN MAE") == "yes" and done.flag("PD MAE") == "–"


def test_a_run_from_a_learned_state_inherits_the_convergence_of_the_run_that_learned_it(tmp_path):
    origin = _run(tmp_path / "runs" / "learn", "run", _curve(40))
    # init_from as recorded: relative to the folder the run was started in (here tmp_path)
    evaluation = _run(tmp_path / "runs" / "eval", "delay=20", np.full(10, 0.03), learned_from="runs/learn/run")
    runs = RunSet([origin, evaluation])
    assert runs.origin(evaluation) is origin
    conv = learning_convergence([("SNN", evaluation, NEEDED)], runs)
    assert conv.badge == UNCONVERGED and "learnt in learn/run" in conv.curves[0].label
    own = learning_convergence([("SNN", evaluation, NEEDED)], runs, own=True)
    assert own.curves[0].trials == 10
    assert learning_convergence([("SNN", evaluation, NEEDED)], RunSet([evaluation])).curves == ()  # not found


@pytest.fixture
def learning_figures():
    """Two figures of the learning runs of one task each, registered for the test only."""
    def draw(task: str):
        def fn(runs: RunSet, stem: Path) -> Figure:
            run = runs.where(task=task).best()
            fig, ax = plt.subplots(figsize=(6, 3))
            ax.plot(run.mae)
            conv = learning_convergence([(task, run, NEEDED)], runs, rows=lambda q: q.startswith("SNN"))
            table = [["quantity", "paper", "cerebx"], ["SNN final MAE (rad)", "0.020", f"{run.mae[-1]:.3f}"],
                     ["PD MAE (rad)", "0.076", "0.076"]]
            checks = [Check("MAE falls", bool(run.mae[-1] < run.mae[0]), f"{run.mae[0]:.2f} → {run.mae[-1]:.2f}"),
                      Check("final MAE below 0.03 rad", bool(run.mae[-1] < 0.03), f"{run.mae[-1]:.3f}")]
            return Figure([save(fig, stem)], f"MAE per trial of the {task} run.", table, checks=checks,
                          convergence=conv)
        return fn

    names = {"test_converged": "circle", "test_unconverged": "eight"}
    for name, task in names.items():
        figure(name, f"synthetic {task}", studies=("none",))(draw(task))
    yield list(names)
    for name in names:
        registry.FIGURES.pop(name)


@pytest.mark.integration
def test_report_badges_unconverged_figures_in_image_caption_csv_and_top_table(tmp_path, learning_figures):
    runs = RunSet([_run(tmp_path, "circle", _curve(100), task="circle"),
                   _run(tmp_path, "eight", _curve(40), task="eight")])
    index, _, n = build_from(runs, tmp_path / "out", learning_figures)
    out = tmp_path / "out"
    assert n == 2
    # the badge: a red band above the unconverged figure only, its words in the SVG too
    red = np.array(matplotlib.colors.to_rgb(BAND))
    top = {name: plt.imread(out / "figures" / f"{name}.png")[5, :, :3] for name in learning_figures}
    assert np.allclose(top["test_unconverged"].mean(0), red, atol=0.02)
    assert not np.allclose(top["test_converged"].mean(0), red, atol=0.2)
    assert UNCONVERGED in (out / "figures" / "test_unconverged.svg").read_text()
    assert "not converged" not in (out / "figures" / "test_converged.svg").read_text()
    # the caption carries the same words
    page = index.read_text()
    unconv = page[page.index("<section id='test_unconverged'>"):]
    assert f"[{UNCONVERGED}] MAE per trial of the eight run." in unconv[:unconv.index("</section>")]
    conv = page[page.index("<section id='test_converged'>"):]
    assert "not converged" not in conv[:conv.index("</section>")]
    # the CSV: the existing columns, then whether the row's learning converged
    with open(out / "paper_vs_cerebx.csv") as fh:
        rows = list(csv.reader(fh))
    assert rows[0][:5] == ["figure", "quantity", "paper", "cerebx", "converged"]
    flags = {(r[0], r[1]): r[4] for r in rows[1:]}
    assert flags["test_unconverged", "SNN final MAE (rad)"] == "no (40 of 100 learning trials; run --profile full)"
    assert flags["test_converged", "SNN final MAE (rad)"] == "yes"
    assert flags["test_unconverged", "PD MAE (rad)"] == "–"  # a baseline: nothing learns
    # index.html opens with the table of figures: shape, convergence, the command that makes it converge
    summary = page[page.index("<table class=summary>"):]
    summary = summary[:summary.index("</table>")]
    assert page.index("<table class=summary>") < page.index("<section")
    assert "cerebx report --profile full --figures test_unconverged" in summary
    assert "cerebx report --profile full --figures test_converged" not in summary
    assert "holds (2 of 2)" in summary and "does not hold (1 of 2 fail, 0 explained)" in summary
    shapes = (out / "shapes.csv").read_text()
    assert "test_unconverged,final MAE below 0.03 rad,no," in shapes
