"""The report: every registered figure drawn from tiny runs of every study, from the logs only;
missing and unreadable runs cost one line each; the study runner reuses finished runs."""

from __future__ import annotations

import json
import shutil
import signal
import sys

import matplotlib.image as mpimg
import pytest
from report_fixtures import make_fixture_runs

from cerebx.config import check
from cerebx.errors import ConfigError
from cerebx.report.build import main as report_main
from cerebx.report.registry import all_figures
from cerebx.report.runs import Run, RunSet
from cerebx.report.studies import Job, execute, load_studies, plan
from cerebx_thesis.report.plant_realism import realism_cells

pytestmark = pytest.mark.integration


@pytest.fixture(scope="module")
def fixture_runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("runs")
    failed = make_fixture_runs(root)
    assert failed == []
    return root / "quick"


def _valid_image(png):
    img = mpimg.imread(png)
    assert img.ndim == 3 and img.shape[0] > 100 and img.shape[1] > 100, png
    assert png.with_suffix(".svg").read_text().lstrip().startswith("<?xml"), png


@pytest.mark.slow  # every study of the quick profile, shortened: about 4 min of CPU
def test_every_figure_is_drawn_from_fixture_runs(fixture_runs, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert report_main([str(fixture_runs), str(tmp_path / "missing")]) == 0
    err = capsys.readouterr().err
    assert "missing/summary.json: no such file" in err  # one clear line; the rest is still built
    out = tmp_path / "reports"
    page = (out / "index.html").read_text()
    assert "Not drawn" not in page and "could not be drawn" not in page
    figures = all_figures()
    assert {"table2_3", "fig2_6", "fig2_7", "fig2_9", "fig2_10", "fig3_3", "fig3_4", "fig3_5", "fig3_6", "fig3_7",
            "fig3_8", "fig3_9", "fig3_10"} <= set(figures)
    for name in figures:
        pngs = sorted((out / "figures").glob(f"{name}*.png"))
        assert pngs, f"{name}: no image"
        for png in pngs:
            assert png.name in page
            _valid_image(png)
    paper = (out / "paper_vs_cerebx.csv").read_text()
    for name in figures:
        assert f"\n{name}," in paper, f"{name}: no paper-vs-cerebx rows"
    assert "0.019" in page and "0.000106" in page  # the paper's numbers beside ours
    assert "trial-averaged torque, as the paper (Eq. 3.13)" in paper  # Fig. 3.4's SNN/ANN torque variability
    made = json.loads((out / "figures.json").read_text())  # the same figures, machine-readable
    assert [e["name"] for e in made["figures"]] == list(figures) and made["runs"]["count"] > 0
    assert all((out / f).is_file() for e in made["figures"] for f in e["files"])
    assert made["command"].startswith("cerebx report ") and made["profile"] == "quick"


@pytest.mark.slow  # every study of the quick profile, shortened: about 4 min of CPU
def test_report_replots_given_runs_and_survives_unreadable_ones(fixture_runs, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    broken = tmp_path / "broken"
    shutil.copytree(fixture_runs / "fig3_4_pd" / "delay.total_ms=20", broken)
    (broken / "summary.json").write_text("{not json")
    damaged = tmp_path / "damaged"
    shutil.copytree(fixture_runs / "fig3_4_pd" / "delay.total_ms=40", damaged)
    data = (damaged / "run.mcap").read_bytes()
    (damaged / "run.mcap").write_bytes(data[: len(data) // 3])
    runs = [fixture_runs / "fig3_4_pd" / f"delay.total_ms={d}" for d in (0, 60, 80)]
    assert report_main([*map(str, runs), str(broken), str(damaged), "--figures", "fig3_4"]) == 0
    err = capsys.readouterr().err
    assert "broken/summary.json: not valid JSON" in err
    page = (tmp_path / "reports" / "index.html").read_text()
    assert "fig3_4.png" in page
    _valid_image(tmp_path / "reports" / "figures" / "fig3_4.png")


@pytest.mark.slow  # every study of the quick profile, shortened: about 4 min of CPU
def test_a_figure_without_its_runs_says_which_study_is_missing(fixture_runs, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert report_main([str(fixture_runs / "fig3_4_pd"), "--figures", "fig3_6,fig3_4"]) == 0
    err = capsys.readouterr().err
    assert "fig3_6:" in err and "fig3_6_kernels" in err
    assert (tmp_path / "reports" / "figures" / "fig3_4.png").exists()
    assert report_main(["--figures", "fig9_9"]) == 2
    assert "unknown figure" in capsys.readouterr().err


@pytest.mark.slow  # every study of the quick profile, shortened: about 4 min of CPU
def test_every_study_job_is_a_valid_experiment(fixture_runs):
    state = fixture_runs / "learn_circle" / "run"
    studies = load_studies()
    figures = all_figures()
    used = {s for f in figures.values() for s in f.studies}
    assert used <= set(studies), used - set(studies)
    seen = set()
    for profile in ("quick", "full"):
        for job in plan(profile, fixture_runs.parent):
            ov = [f"init_from={state}" if o.startswith("init_from=") else o for o in job.overrides()]
            # the profiles mostly differ in trials; seeds do not change what validates
            key = tuple(o for o in ov if not o.startswith(("trials=", "seed=")))
            if key not in seen:
                seen.add(key)
                # the fixture state stands in for every study's start (small SNN): it need not fit the job
                assert [p for p in check(ov) if not p.startswith(f"init_from: {state}/")] == [], (profile, job.name)


def _complete(job: Job) -> None:
    """Leave what a completed run of ``job`` leaves: its recorded configuration and summary."""
    from cerebx.config import load
    from cerebx.recording.recorder import Recorder

    job.run_dir.mkdir(parents=True, exist_ok=True)
    rec = Recorder(job.run_dir / "run.mcap")  # a run records the configuration it was made from
    rec.metadata("config", {"json": json.dumps(load(job.overrides())[1])})
    rec.close()
    (job.run_dir / "summary.json").write_text(json.dumps({
        "status": "completed", "task": "circle", "controller": "pd", "plant": "baxter", "delay": "none",
        "seed": 0, "trials": job.trials, "trials_completed": job.trials, "final_mae": 0.1, "wall_seconds": 1}))


def test_study_runner_reuses_finished_runs_and_skips_dependents_of_failures(tmp_path):
    ran: list[str] = []

    def fake(job: Job) -> int:
        ran.append(job.name)
        if job.study == "learn_circle_ch3":
            return 1
        _complete(job)
        return 0

    jobs = plan("quick", tmp_path, ["fig3_4_pd", "fig3_4_snn"])
    assert [j.study for j in jobs].count("fig3_4_pd") == 5 and "learn_circle_ch3" in [j.study for j in jobs]
    failed = execute(jobs, runner=fake, parallel=2, log=lambda line: None)
    assert sorted(ran) == sorted(["learn_circle_ch3/run"] + [j.name for j in jobs if j.study == "fig3_4_pd"])
    assert len(failed) == 6 and any("fig3_4_snn" in f and "learn_circle_ch3/run" in f for f in failed)
    ran.clear()
    execute(plan("quick", tmp_path, ["fig3_4_pd"]), runner=fake, log=lambda line: None)
    assert ran == []  # every fig3_4_pd run is complete: reused
    # a preset value changed since a run was made: that run is not reused
    jobs = plan("quick", tmp_path, ["fig3_4_pd"])
    jobs[0].args = [*jobs[0].args, "seed=7"]
    execute(jobs, runner=fake, log=lambda line: None)
    assert ran == [jobs[0].name]


def test_a_profile_can_sweep_fewer_values(tmp_path):
    from cerebx.report.studies import group

    f = tmp_path / "studies.yaml"
    f.write_text("studies:\n  a:\n    args: [+experiment=fig3_4_pd]\n"
                 "    quick: {trials: 1, args: ['delay.total_ms=0,40']}\n    full: {trials: 2}\n")
    studies = load_studies(f)
    quick = plan("quick", tmp_path, studies=studies)
    assert [j.label for j in quick] == ["delay.total_ms=0", "delay.total_ms=40"]
    assert "delay.total_ms=0,40" not in quick[0].overrides() and "delay.total_ms=40" in quick[1].overrides()
    ov = group(quick)[0].overrides()
    assert "delay.total_ms=0,40" in ov  # the multirun sweeps those values, not the preset's five
    assert "delay.total_ms" not in next(o for o in ov if o.startswith("hydra.job.config.override_dirname.exclude"))
    assert len(plan("full", tmp_path, studies=studies)) == 5


def test_bad_studies_file_is_one_line(tmp_path):
    bad = tmp_path / "studies.yaml"
    bad.write_text("studies:\n  a:\n    args: [+experiment=demo]\n    init_from: nowhere\n"
                   "    quick: {trials: 1}\n    full: {trials: 2}\n")
    with pytest.raises(ConfigError, match="init_from: 'nowhere' is not a single-run study"):
        load_studies(bad)
    bad.write_text("studies:\n  a:\n    args: []\n    quick: {trials: 0}\n    full: {trials: 2}\n")
    with pytest.raises(ConfigError) as err:
        load_studies(bad)
    assert all(line.startswith(str(bad)) for line in err.value.problems)


def test_ctrl_c_stops_the_study_runner_and_says_how_to_resume(tmp_path):
    import _thread
    import time

    def interrupted(job: Job) -> int:
        _thread.interrupt_main()  # Ctrl-C arrives while a job runs
        time.sleep(0.2)
        return 1

    lines: list[str] = []
    # interrupt_main does nothing while SIGINT is ignored (tests started in the background)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt):
            execute(plan("quick", tmp_path, ["fig3_4_pd"]), runner=interrupted, log=lines.append)
    finally:
        signal.signal(signal.SIGINT, previous)
    assert any("interrupted" in line and "run again to resume" in line for line in lines)


def test_a_job_is_judged_by_its_own_run_not_by_its_exit_code(tmp_path):
    """Paired multiruns share a folder; the sweep table of one also lists the others, so its exit code
    is not its job's outcome. A completed run is done; a non-zero exit without one is a failure."""
    def fake(job: Job) -> int:
        if job.name.endswith("=0"):
            _complete(job)
        return 1

    lines: list[str] = []
    failed = execute(plan("quick", tmp_path, ["fig3_4_pd"]), runner=fake, parallel=1, log=lines.append)
    assert len(failed) == 4 and not any("delay.total_ms=0:" in f for f in failed)
    assert any("done  fig3_4_pd/delay.total_ms=0" in line and "though it exited with 1" in line for line in lines)


def test_a_failed_job_says_why_in_the_report_s_own_output(tmp_path):
    """Its log may be gone when the report's output is read (CI keeps the output only): the failure line
    carries a job's refusal (error.txt), else its log's last line."""
    from cerebx.report.studies import _run_logged

    def refused(job: Job) -> int:
        job.run_dir.mkdir(parents=True)
        (job.run_dir / "error.txt").write_text("delay.total_ms: not a number\n")
        return 1

    def crashed(job: Job) -> int:
        job.run_dir.mkdir(parents=True, exist_ok=True)
        cmd = [sys.executable, "-c", "import sys; print('working'); sys.exit('hydra.sweep.dir: x: went wrong')"]
        return _run_logged(cmd, job.run_dir / "job.log", "w")

    jobs = plan("quick", tmp_path / "a", ["fig3_4_pd"])[:1]
    assert execute(jobs, runner=refused, log=lambda line: None) == [
        f"{jobs[0].name}: failed (exit code 1, see {jobs[0].run_dir / 'job.log'}): "
        f"{jobs[0].label}: delay.total_ms: not a number"]
    jobs = plan("quick", tmp_path / "b", ["fig3_4_pd"])[:1]
    assert execute(jobs, runner=crashed, log=lambda line: None)[0].endswith(
        "(exit code 1, see " + str(jobs[0].run_dir / "job.log") + "): hydra.sweep.dir: x: went wrong")


def test_studies_are_multiruns_of_their_presets(tmp_path):
    from cerebx.report.studies import group, preset_sweep

    assert preset_sweep(["+experiment=fig3_4_pd"]) == [[f"delay.total_ms={ms}"] for ms in (0, 20, 40, 60, 80)]
    assert preset_sweep(["+experiment=baselines", "controller=pd"]) == [[]]  # an arg fixes the swept key
    jobs = plan("quick", tmp_path, ["fig3_4_snn"])
    studies = group(jobs)
    assert [s.name for s in studies] == ["learn_circle_ch3", "fig3_4_snn"]
    assert studies[1].deps == [studies[0]] and len(studies[1].jobs) == 5
    assert jobs[1].run_dir == tmp_path / "quick" / "fig3_4_snn" / "delay.total_ms=0"
    ov = studies[1].overrides(["hydra/launcher=slurm"])
    assert ov[:2] == ["-m", "+experiment=fig3_4_snn"] and ov[-1] == "hydra/launcher=slurm"
    assert "resume=auto" in ov and f"hydra.sweep.dir='{tmp_path / 'quick' / 'fig3_4_snn'}'" in ov
    assert "hydra.sweep.subdir=${hydra.job.override_dirname}" in ov
    excluded = next(o for o in ov if o.startswith("hydra.job.config.override_dirname.exclude_keys="))
    assert "delay.total_ms" not in excluded and "init_from" in excluded and "trials" in excluded
    assert "hydra.sweep.subdir=run" in studies[0].overrides()


def test_init_from_a_study_with_the_same_sweep_pairs_jobs_by_sweep_value(tmp_path):
    from cerebx.report.studies import group

    jobs = plan("full", tmp_path, ["fig4_6a"], max_seeds=1)  # quick draws Fig. 4.6 A from full
    by_name = {j.name: j for j in jobs}
    for k in (0, 1, 5, 9, 10, 12):
        job = by_name[f"fig4_6a/muscle.cocontraction={k}"]
        assert [d.name for d in job.deps] == [f"fig4_6a_learn/muscle.cocontraction={k}"]
        assert f"init_from='{tmp_path}/full/fig4_6a_learn/muscle.cocontraction={k}'" in job.overrides()
    studies = group(jobs)
    assert [s.name for s in studies][0] == "fig4_6a_learn" and len(studies) == 7  # one multirun per paired job
    one = studies[3]
    assert one.name == "fig4_6a/muscle.cocontraction=5" and one.deps == [studies[0]]
    ov = one.overrides()
    assert "muscle.cocontraction=5" in ov and "hydra.sweep.subdir='muscle.cocontraction=5'" in ov
    assert f"init_from='{tmp_path}/full/fig4_6a_learn/muscle.cocontraction=5'" in ov
    assert f"hydra.sweep.dir='{tmp_path}/full/fig4_6a'" in ov
    bad = tmp_path / "studies.yaml"
    bad.write_text("studies:\n  a:\n    args: [+experiment=fig3_4_pd]\n"
                   "    quick: {trials: 1}\n    full: {trials: 2}\n"
                   "  b:\n    args: [+experiment=fig3_4_pd, 'delay.total_ms=0,40']\n    init_from: a\n"
                   "    quick: {trials: 1}\n    full: {trials: 2}\n")
    with pytest.raises(ConfigError, match="init_from: 'a' is not a single-run study or one with the same sweep"):
        load_studies(bad)
    # a report of some figures checks the sweeps of their studies and of those they start from, not every study's
    assert set(load_studies(bad, only=["a"])) == {"a", "b"}
    for wanted in (["b"], ["b~seed1"]):
        with pytest.raises(ConfigError, match="init_from: 'a' is not a single-run study"):
            load_studies(bad, only=wanted)


def test_plant_realism_takes_the_study_runs_not_chapter_3_runs_on_the_same_plant(tmp_path):
    def run(name, preset, peaks, trials, mae):
        kern = {f"pf_pc{i}": {"plasticity": {"kind": "kernel_stdp", "kernel_peak_ms": p}} for i, p in enumerate(peaks)}
        cfg = {"delay": {"total_ms": 0.0}, "init_from": "learned", "events": [],
               "controller": {"kind": "snn", "network": {"projections": kern}}}
        summary = {"task": "circle", "controller": "snn", "delay": "constant", "status": "completed",
                   "trials_completed": trials, "mae_per_trial": [mae] * trials, "sim_seconds": 2.0 * trials,
                   "presets": {"plant": "baxter", "controller": preset}}
        return Run(tmp_path / name, summary, cfg)

    study = run("realism", "snn", [150.0], 12, 0.022)
    runs = RunSet([study, run("fig3_4", "snn_delays", [150.0], 102, 0.019),
                   run("multikernel", "snn", [100.0, 150.0, 200.0], 102, 0.033)])
    assert realism_cells(runs) == {("baxter", "snn", 0.0): study}


def test_a_sweep_is_split_so_that_every_core_runs_part_of_it(tmp_path):
    """One long sweep would leave a core idle: with two parts, each multirun sweeps every other value of the
    key with the most values, into the same folder, with its own log, and the parts hold every job once."""
    from cerebx.report.studies import group, split_sweep

    f = tmp_path / "studies.yaml"
    f.write_text("studies:\n  a:\n    args: [+experiment=fig3_4_pd, 'seed=0,1,2']\n"
                 "    quick: {trials: 1}\n    full: {trials: 2}\n")
    jobs = plan("quick", tmp_path, studies=load_studies(f))
    assert len(jobs) == 15  # 5 delays x 3 seeds
    assert split_sweep(jobs, 2) == [("delay.total_ms", ("0", "40", "80")), ("delay.total_ms", ("20", "60"))]
    assert split_sweep(jobs, 1) == [] and split_sweep(jobs[:1], 2) == []
    parts = group(jobs, 2)
    assert [p.name for p in parts] == ["a:1/2", "a:2/2"]
    assert sorted(j.name for p in parts for j in p.jobs) == sorted(j.name for j in jobs)
    ov = parts[1].overrides()
    assert "delay.total_ms=20,60" in ov and "seed=0,1,2" in ov
    assert {p.sweep_dir for p in parts} == {tmp_path / "quick" / "a"}
    assert [p.log_name for p in parts] == ["study.1.log", "study.2.log"]
    assert group(jobs)[0].log_name == "study.log" and len(group(jobs)) == 1
    # the command-line values win over the preset's sweep: Hydra runs exactly this part's jobs
    from hydra._internal.core_plugins.basic_sweeper import BasicSweeper
    from hydra.core.override_parser.overrides_parser import OverridesParser

    parsed = OverridesParser.create().parse_overrides(["delay.total_ms=0,20,40,60,80", "delay.total_ms=20,60"])
    (batch,) = BasicSweeper.split_arguments(parsed, None)
    assert sorted(o[0] for o in batch) == ["delay.total_ms=20", "delay.total_ms=60"]


def test_a_split_sweep_over_an_appended_key_keeps_one_value_list_of_it(tmp_path):
    """A study sweeping a key it appends (``+task=a,b``, as fig4_5_learn) split in two: each part gives that key
    once, as its part's values (measured from an empty folder, both parts of fig4_5_learn failed with
    Hydra's "Multiple values for task" when the split appended ``+task=a`` beside the study's ``+task=a,b``)."""
    from cerebx.report.studies import group

    f = tmp_path / "studies.yaml"
    f.write_text("studies:\n  a:\n    args: [+experiment=upper_limb, '+task=flexion_extension,vertical_circle_slow',"
                 " 'spinal=cord,direct']\n    quick: {trials: 1}\n    full: {trials: 2}\n")
    jobs = plan("quick", tmp_path, studies=load_studies(f))
    parts = group(jobs, 2)
    assert len(parts) == 2
    for p, task in zip(parts, ("flexion_extension", "vertical_circle_slow"), strict=True):
        ov = p.overrides()
        assert [a for a in ov if a.lstrip("+").startswith("task=")] == [f"+task={task}"]
        assert "spinal=cord,direct" in ov
        # what Hydra's basic sweeper makes of the part's command line: its two jobs, each with one task
        from hydra._internal.core_plugins.basic_sweeper import BasicSweeper
        from hydra.core.override_parser.overrides_parser import OverridesParser

        parsed = OverridesParser.create().parse_overrides([a for a in ov[1:] if not a.startswith("hydra.")])
        (batch,) = BasicSweeper.split_arguments(parsed, None)
        assert sorted(sorted(x for x in job if "task=" in x or "spinal=" in x) for job in batch) == [
            [f"+task={task}", "spinal=cord"], [f"+task={task}", "spinal=direct"]]


def test_the_parts_of_a_split_sweep_run_side_by_side_and_its_dependents_wait(tmp_path):
    from cerebx.report.studies import group

    ran: list[str] = []

    def fake(study) -> int:
        ran.append(study.name)
        for job in study.jobs:
            _complete(job)
        return 0

    jobs = plan("full", tmp_path, ["fig4_6a"], max_seeds=1)
    studies = group(jobs, 2)
    learn = [s for s in studies if s.name.startswith("fig4_6a_learn:")]
    assert len(learn) == 2 and all(len(s.jobs) == 3 for s in learn)
    paired = next(s for s in studies if s.name == "fig4_6a/muscle.cocontraction=5")
    assert paired.deps == [next(s for s in learn if any(j.label == "muscle.cocontraction=5" for j in s.jobs))]
    execute(studies, runner=fake, parallel=2, log=lambda line: None)  # (the fake saves no state to start from)
    assert set(ran[:2]) == {s.name for s in learn} and len(ran) == 8  # both parts first, then the 6 that wait


def test_a_figure_is_not_drawn_without_a_study_it_borrows_from_the_full_profile(tmp_path):
    """Measured from an empty folder, the quick report drew Fig. 3.6 from the one 150 ms-kernel run it had (the
    chapter 3 learning, 654 trials) under a red badge. A figure needing a borrowed study that lacks is left out
    with a line; one whose missing study is optional (Fig. 4.5's sensitivity runs) is drawn from the rest."""
    from cerebx.report.build import build_from

    lines: list[str] = []
    _, missing, _ = build_from(RunSet([]), tmp_path, ["fig3_6", "fig4_5"], log=lines.append, profile="quick",
                               lacking=frozenset({"fig3_6_kernels", "fig4_5_learn_d50"}))
    assert missing[0] == ("fig3_6: drawn from the full profile's runs of fig3_6_kernels, which are missing "
                          "(cerebx report --profile full)")
    assert missing[1].startswith("fig4_5: no upper-limb SNN learning runs")  # drawn, from no runs at all here
    spec = all_figures()["fig4_5"]
    assert not spec.needs("fig4_5_learn_d50") and spec.needs("fig4_5_learn") and not spec.needs("fig3_6")


def test_a_quick_folder_given_to_the_report_draws_on_the_full_profile_beside_it(tmp_path):
    """CI's slow test gave the report a quick profile's folder: Fig. 3.10 was "Not drawn", its learning
    (from_full) lying in the full profile's folder beside it, where ``--profile quick`` finds it."""
    from cerebx.report.build import with_borrowed

    def run(*parts):
        d = tmp_path.joinpath(*parts)
        d.mkdir(parents=True)
        (d / "summary.json").write_text("{}")
        return d

    run("quick", "fig3_4_pd", "delay.total_ms=0")
    learned = run("full", "learn_multikernel", "run")
    lent, absent = with_borrowed(tmp_path / "quick")
    assert learned in lent and "learn_multikernel" not in absent
    assert "fig3_6_kernels" in absent  # its figure is left out with a line
    assert with_borrowed(tmp_path / "quick", ["fig3_4"]) == ([], frozenset())  # only the figures asked for


def test_a_study_that_cannot_converge_in_quick_is_drawn_from_the_full_profile(tmp_path, capsys):
    """from_full: the quick profile runs neither the study nor those starting from it; it draws on their
    full-profile runs when they exist, and the dry run says which are there and which lack."""
    from cerebx.report.build import dry_run
    from cerebx.report.studies import group

    f = tmp_path / "studies.yaml"
    f.write_text("studies:\n"
                 "  learn:\n    args: [+experiment=learn_circle_ch3]\n"
                 "    quick: {trials: 3, from_full: true}\n    full: {trials: 5}\n"
                 "  evaluate:\n    args: [+experiment=fig3_4_snn, delay.total_ms=0]\n    init_from: learn\n"
                 "    quick: {trials: 2}\n    full: {trials: 4}\n"
                 "  pd:\n    args: [+experiment=fig3_4_pd, delay.total_ms=0]\n"
                 "    quick: {trials: 2}\n    full: {trials: 4}\n")
    studies = load_studies(f)
    jobs = plan("quick", tmp_path, studies=studies)
    by = {j.study: j for j in jobs}
    assert by["learn"].borrowed and by["evaluate"].borrowed and not by["pd"].borrowed
    assert by["learn"].run_dir == tmp_path / "full" / "learn" / "run" and by["learn"].trials == 5
    assert by["evaluate"].trials == 4 and by["pd"].run_dir == tmp_path / "quick" / "pd" / "run"
    assert [s.name for s in group([j for j in jobs if not j.borrowed])] == ["pd"]
    dry_run(jobs, tmp_path / "quick", 2)
    out = capsys.readouterr().out
    assert f"lacks {tmp_path / 'full' / 'learn' / 'run'}" in out
    assert "cannot converge" in out and "learn, evaluate" in out
    _complete(by["learn"])
    dry_run(plan("quick", tmp_path, studies=studies), tmp_path / "quick", 2)
    assert f"full  {tmp_path / 'full' / 'learn' / 'run'}" in capsys.readouterr().out
    bad = tmp_path / "bad.yaml"
    bad.write_text("studies:\n  a:\n    args: [+experiment=fig3_4_pd]\n"
                   "    quick: {trials: 1}\n    full: {trials: 2, from_full: true}\n")
    with pytest.raises(ConfigError, match="full.from_full: only the quick profile"):
        load_studies(bad)


def test_a_learning_curve_without_any_trial_says_so_and_warns_nothing(tmp_path):
    import warnings

    from cerebx.report.figures import learning_curves

    failed = {"controller": "pd", "plant": "planar2", "delay": "none", "seed": 0, "mae_per_trial": []}
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # matplotlib's "No artists with labels found to put in legend"
        png = learning_curves([(tmp_path / "run", failed)], "circle", tmp_path / "learning_circle")
    assert png.exists() and png.stat().st_size > 0
