"""Run the experiment studies a report needs (conf/report/studies.yaml), reusing finished runs.

A study is an experiment preset run once or as a sweep. Each job lands in
``runs/report/<profile>/<study>/<job>``; a job whose folder holds a completed summary with enough
trials is reused, anything else (missing, failed, interrupted) is run again. Jobs run as
``cerebx run`` subprocesses, ``jobs`` at a time, each after the study it starts from.
"""

from __future__ import annotations

import itertools
import json
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, wait
from dataclasses import dataclass, field
from pathlib import Path

import yaml
from pydantic import Field, ValidationError

from cerebx.errors import ConfigError
from cerebx.schema.base import Strict
from cerebx.schema.experiment import format_errors

STUDIES_FILE = Path(__file__).resolve().parents[1] / "conf" / "report" / "studies.yaml"
PROFILES = ("quick", "full")


class ProfileSpec(Strict):
    """How a study runs in one profile."""

    trials: int = Field(ge=1, description="trials of every job")
    args: list[str] = Field(default_factory=list, description="extra overrides in this profile")
    init_from: str | None = Field("inherit", description="start from this study's run instead (null: scratch)")


class StudySpec(Strict):
    """One experiment preset run once or as a sweep."""

    args: list[str] = Field(min_length=1, description="overrides of every job, the experiment preset first")
    sweep: dict[str, list[str | int | float]] = Field(
        default_factory=dict, description="override key -> values; one job per combination")
    init_from: str | None = Field(
        None, description="study whose learned state starts each job: a single-run study, or one with the same "
        "sweep (each job then starts from the job of the same sweep values)")
    quick: ProfileSpec = Field(description="the quick profile (< 30 min on 2 cores in all)")
    full: ProfileSpec = Field(description="the full profile (the thesis's trial counts)")


class StudiesFile(Strict):
    studies: dict[str, StudySpec] = Field(description="study name -> study")


def load_studies(path: Path = STUDIES_FILE) -> dict[str, StudySpec]:
    try:
        raw = yaml.safe_load(path.read_text())
        studies = StudiesFile.model_validate(raw).studies
    except OSError as err:
        raise ConfigError(f"{path}: {err.strerror}") from None
    except yaml.YAMLError as err:
        raise ConfigError(f"{path}: not valid YAML ({str(err).splitlines()[0]})") from None
    except ValidationError as err:
        raise ConfigError([f"{path}: {line}" for line in format_errors(err)]) from None
    for name, s in studies.items():
        for prof in PROFILES:
            src = _init_from(s, prof)
            if src is not None and (src not in studies or studies[src].sweep not in ({}, s.sweep)):
                raise ConfigError(f"{path}: studies.{name}.init_from: {src!r} is not a single-run study "
                                  "or one with the same sweep")
    return studies


def _init_from(s: StudySpec, profile: str) -> str | None:
    p: ProfileSpec = getattr(s, profile)
    return s.init_from if p.init_from == "inherit" else p.init_from


@dataclass
class Job:
    study: str
    label: str
    args: list[str]
    trials: int
    run_dir: Path
    after: str | None  # the study whose run this one starts from
    deps: list[Job] = field(default_factory=list, repr=False)

    @property
    def name(self) -> str:
        return f"{self.study}/{self.label}"

    def overrides(self) -> list[str]:
        out = [*self.args, f"trials={self.trials}"]
        if self.after is not None:
            out.append(f"init_from='{self.deps[0].run_dir}'")
        return out

    def done(self) -> bool:
        try:
            s = json.loads((self.run_dir / "summary.json").read_text())
        except (OSError, json.JSONDecodeError):
            return False
        return s.get("status") == "completed" and (s.get("trials_completed") or 0) >= self.trials


def plan(profile: str, root: Path, names: list[str] | None = None,
         studies: dict[str, StudySpec] | None = None) -> list[Job]:
    """Every job of the named studies (all by default) and of the studies they start from, in order."""
    if profile not in PROFILES:
        raise ConfigError(f"--profile: {profile!r} is not one of {', '.join(PROFILES)}")
    studies = load_studies() if studies is None else studies
    wanted: list[str] = []

    def want(n: str) -> None:
        if n not in studies:
            raise ConfigError(f"study {n!r}: not in {STUDIES_FILE.name} (known: {', '.join(studies)})")
        src = _init_from(studies[n], profile)
        if src is not None:
            want(src)
        if n not in wanted:
            wanted.append(n)

    for n in names if names is not None else list(studies):
        want(n)
    jobs: list[Job] = []
    single: dict[str, Job] = {}
    by_label: dict[tuple[str, str], Job] = {}
    for n in wanted:
        s = studies[n]
        p: ProfileSpec = getattr(s, profile)
        keys = list(s.sweep)
        combos = itertools.product(*(s.sweep[k] for k in keys)) if keys else [()]
        src = _init_from(s, profile)
        for combo in combos:
            sweep_args = [f"{k}={v}" for k, v in zip(keys, combo)]
            label = ",".join(a.lstrip("+") for a in sweep_args) or "run"
            job = Job(n, label, [*s.args, *p.args, *sweep_args], p.trials, root / profile / n / label, src)
            if src is not None:
                job.deps = [single[src] if src in single else by_label[src, label]]
            if not keys:
                single[n] = job
            by_label[n, label] = job
            jobs.append(job)
    return jobs


Runner = Callable[[Job], int]


def subprocess_runner(job: Job) -> int:
    """``cerebx run`` in a child process; its output goes to ``<run_dir>/job.log``."""
    job.run_dir.mkdir(parents=True, exist_ok=True)
    cmd = [sys.executable, "-m", "cerebx", "run", *job.overrides(), f"hydra.run.dir='{job.run_dir}'",
           "recording.progress=off"]
    with open(job.run_dir / "job.log", "w") as log:
        log.write(" ".join(cmd) + "\n")
        log.flush()
        proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT)
        _children.add(proc)
        try:
            return proc.wait()
        finally:
            _children.discard(proc)


_children: set[subprocess.Popen] = set()  # the `cerebx run` processes under way


def in_process_runner(job: Job) -> int:
    """Run in this process (for tests: no interpreter start-up per job)."""
    from cerebx.config import compose_with_choices, to_plain
    from cerebx.loop.runner import run_experiment
    from cerebx.schema.experiment import validate

    cfg, choices = compose_with_choices(job.overrides())
    plain = to_plain(cfg)
    s = run_experiment(validate(plain), job.run_dir, plain, overrides=job.overrides(), choices=choices)
    return 0 if s["status"] == "completed" else 1


def execute(jobs: list[Job], runner: Runner = subprocess_runner, parallel: int = 2,
            log: Callable[[str], None] | None = None) -> list[str]:
    """Run every job that is not done, ``parallel`` at a time; returns one line per failed job.

    Ctrl-C stops the jobs under way (their runs end as ``interrupted``) and re-raises; finished runs
    are kept, so running again resumes.
    """
    return _Scheduler(jobs, runner, max(1, parallel), log or (lambda line: print(line, flush=True))).run()


class _Scheduler:
    def __init__(self, jobs: list[Job], runner: Runner, parallel: int, log: Callable[[str], None]):
        self.runner, self.parallel, self.log = runner, parallel, log
        self.todo = [j for j in jobs if not j.done()]
        self.reused = len(jobs) - len(self.todo)
        self.finished = {j.name for j in jobs if j not in self.todo}
        self.failed: dict[str, str] = {}
        # the runs others start from go first (longest first), so the critical path starts at once
        dependents = {j.name: sum(d.name == j.name for k in self.todo for d in k.deps) for j in self.todo}
        self.pending = sorted(self.todo, key=lambda j: (-dependents[j.name], -j.trials))
        self.running: dict[Future, Job] = {}
        self.t0 = time.monotonic()

    def run(self) -> list[str]:
        self.log(f"studies: {self.reused + len(self.todo)} jobs, {self.reused} reused, {len(self.todo)} to run")
        with ThreadPoolExecutor(max_workers=self.parallel) as pool:
            try:
                while self.pending or self.running:
                    self._start_ready(pool)
                    if self.running:
                        done, _ = wait(list(self.running), return_when=FIRST_COMPLETED)
                        for fut in done:
                            self._record(self.running.pop(fut), fut)
            except KeyboardInterrupt:
                self.log("interrupted: stopping the jobs under way (their runs end as 'interrupted'); "
                         "run again to resume")
                for proc in list(_children):
                    proc.send_signal(signal.SIGINT)
                raise
        return list(self.failed.values())

    def _start_ready(self, pool: ThreadPoolExecutor) -> None:
        for j in list(self.pending):
            broken = [d.name for d in j.deps if d.name in self.failed]
            if broken:
                self.pending.remove(j)
                self.failed[j.name] = f"{j.name}: not run, the run it starts from ({broken[0]}) failed"
                self.log(self.failed[j.name])
            elif all(d.name in self.finished for d in j.deps) and len(self.running) < self.parallel:
                self.pending.remove(j)
                if j.run_dir.exists():
                    shutil.rmtree(j.run_dir)  # an unfinished earlier attempt
                self.log(f"[{self._clock()}] start {j.name} ({j.trials} trials)")
                self.running[pool.submit(self.runner, j)] = j

    def _record(self, j: Job, fut: Future) -> None:
        try:
            rc, why = fut.result(), f"see {j.run_dir / 'job.log'}"
        except Exception as err:  # a runner that raises is a failed job, not a failed report
            rc, why = 1, f"{type(err).__name__}: {err}"
        if rc == 0 and j.done():
            self.finished.add(j.name)
            s = json.loads((j.run_dir / "summary.json").read_text())
            mae = s.get("final_mae")
            self.log(f"[{self._clock()}] done  {j.name}: final MAE {mae if mae is None else round(mae, 4)} rad, "
                     f"{s.get('wall_seconds', 0):.0f} s ({len(self.finished) - self.reused}/{len(self.todo)})")
        else:
            self.failed[j.name] = f"{j.name}: failed (exit code {rc}, {why})"
            self.log(self.failed[j.name])

    def _clock(self) -> str:
        s = int(time.monotonic() - self.t0)
        return f"{s // 60:02d}:{s % 60:02d}"
