"""Run the experiment studies a report needs (conf/report/studies.yaml), reusing finished runs.

A study is an experiment preset run as a Hydra multirun (``cerebx run -m``): once, or over the sweep
the preset declares (``hydra.sweeper.params``; the only place a sweep is defined), through whatever
launcher the report is given (``-o hydra/launcher=slurm``, ``joblib`` …). Each job lands in
``runs/report/<profile>/<study>/<job>`` (``run``, or the swept overrides, e.g. ``delay.total_ms=20``).
Jobs run with ``resume=auto``: a job whose folder holds a completed summary with enough trials, made
from the configuration its presets compose to now and after the run it starts from, is reused, one that
left a checkpoint continues from it, anything else runs again. Studies run ``jobs``
at a time, each after the study whose learned state it starts from.

A study whose profile asks for ``seeds: n`` is learned n times independently: its first seed (the preset's)
in its own folder, seed k (k = 1 .. n − 1) as the study ``<study>~seed<k>`` in ``<profile>/<study>~seed<k>``,
each starting from the same seed of the study it starts from (or from that study's first seed when it has
fewer). The figures draw their curves from the first seed and take their headline numbers over all of them.
"""

from __future__ import annotations

import functools
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Iterable
from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, wait
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

import yaml
from hydra.core.override_parser.overrides_parser import OverridesParser
from hydra.errors import HydraException
from pydantic import ValidationError

from cerebx import runfiles
from cerebx.config import compose_with_choices, expand_sweep, load, preset_sweep_params, to_plain
from cerebx.errors import CerebxError, ConfigError
from cerebx.loop.resume import stale
from cerebx.loop.runner import run_experiment
from cerebx.recording.summary import read_summary
from cerebx.report.convergence import PlateauRule
from cerebx.report.registry import STUDY_FILES, load_reports
from cerebx.report.schema import PROFILES, ProfileSpec, StudiesFile, StudySpec
from cerebx.schema.base import Strict
from cerebx.schema.experiment import RecordingConfig, format_errors, validate
from cerebx.schema.window import TrialWindow

M = TypeVar("M", bound=Strict)


def study_recording(spec: StudySpec, profile: str) -> tuple[TrialWindow | None, bool]:
    """The window (``recording.trials``; None: every trial) and ``recording.joint_states`` the runs of study
    ``spec`` record in ``profile``, from its overrides (the last one given wins, as in Hydra)."""
    window, joints = None, True
    parser = OverridesParser.create()
    for arg in [*spec.args, *getattr(spec, profile).args]:
        key = _key(arg)
        if key in ("recording.trials", "recording.joint_states"):
            value = parser.parse_overrides([arg])[0].value()
            if key == "recording.joint_states":
                joints = bool(value)
            else:
                window = RecordingConfig(trials=value).trials
    return window, joints


def load_studies(*paths: Path, only: Iterable[str] | None = None) -> dict[str, StudySpec]:
    """The studies of ``paths`` (default: every plugin's registered studies file), one name space.
    ``only``: check the sweeps of just these studies and those they start from against their sources'
    (each check composes both presets, ~0.15 s: a report of one figure need not compose every study)."""
    if not paths:
        load_reports()
        paths = tuple(STUDY_FILES)
    studies: dict[str, StudySpec] = {}
    where: dict[str, Path] = {}
    for path in paths:
        for name, spec in _read_studies(path).items():
            if name in studies:
                raise ConfigError(f"{path}: studies.{name}: already defined in {where[name]}")
            studies[name], where[name] = spec, path
    for name, s in studies.items():
        if s.full.from_full:
            raise ConfigError(f"{where[name]}: studies.{name}.full.from_full: only the quick profile can draw on "
                              "the full profile's runs")
        for prof in PROFILES:
            if getattr(s, prof).seeds > 1 and any(_key(a) == "seed" for a in [*s.args, *getattr(s, prof).args]):
                raise ConfigError(f"{where[name]}: studies.{name}.{prof}.seeds: the study sets its seed itself "
                                  "(give seeds or seed=, not both)")
    for name in studies if only is None else _with_sources(studies, only):
        s = studies[name]
        for prof in PROFILES:
            src = _init_from(s, prof)
            if src is not None and (src not in studies or _sweep_of(studies[src], prof) not in (
                    [[]], _sweep_of(s, prof))):
                raise ConfigError(f"{where[name]}: studies.{name}.init_from: {src!r} is not a single-run study "
                                  "or one with the same sweep")
    return studies


def _with_sources(studies: dict[str, StudySpec], names: Iterable[str]) -> list[str]:
    """``names`` (a replica's by its study's) and the studies they start from in any profile, known ones only."""
    out: list[str] = []
    todo = [n.split(REPLICA)[0] for n in names]
    while todo:
        n = todo.pop()
        if n in studies and n not in out:
            out.append(n)
            todo += [src for prof in PROFILES if (src := _init_from(studies[n], prof)) is not None]
    return out


REPLICA = "~seed"  # <study>~seed<k>: seed k of a study learned from several seeds


def with_replicas(studies: dict[str, StudySpec], profile: str, max_seeds: int | None = None) -> dict[str, StudySpec]:
    """``studies`` and, after each whose ``profile`` asks for several seeds, one study per further seed (the
    same arguments and ``seed=k``, starting from seed k of the study it starts from when that has one);
    ``max_seeds``: at most that many seeds of any study (its first seeds)."""
    out: dict[str, StudySpec] = {}
    for name, s in studies.items():
        out[name] = s
        base = _init_from(s, profile)
        for k in range(1, min(getattr(s, profile).seeds, max_seeds or 10**6)):
            src = base
            if base is not None and base in studies and getattr(studies[base], profile).seeds > k:
                src = f"{base}{REPLICA}{k}"
            one = getattr(s, profile).model_copy(update={"seeds": 1, "init_from": src})
            out[f"{name}{REPLICA}{k}"] = s.model_copy(update={"args": [*s.args, f"seed={k}"], profile: one})
    return out


def profile_of(run_dirs: list[Path]) -> str | None:
    """The profile whose folder (``<root>/<profile>/<study>/<job>``) holds every one of ``run_dirs``, if one does."""
    found = {Path(d).parent.parent.name for d in run_dirs}
    return found.pop() if len(found) == 1 and found <= set(PROFILES) else None


def study_plateau(name: str) -> PlateauRule:
    """The plateau test of study ``name``'s learning curves, from the plugins' studies files: its full
    profile's trials (where the paper's shape appears) and its ``plateau`` settings.

    Parameters
    ----------
    name : str
        The study's name in a studies file.
    """
    load_reports()
    for path in STUDY_FILES:
        spec = _read_studies_cached(path).get(name)
        if spec is not None:
            return PlateauRule(spec.full.trials, **spec.plateau.model_dump())
    raise ConfigError(f"study {name!r}: no plugin defines it")


@functools.lru_cache(maxsize=32)
def _read_studies_cached(path: Path) -> dict[str, StudySpec]:
    return _read_studies(path)


def read_yaml_model(path: Path, model: type[M]) -> M:
    """``path``'s YAML validated as ``model``; any problem is a ConfigError of lines ``path: problem``."""
    try:
        raw = yaml.safe_load(Path(path).read_text())
        return model.model_validate(raw if raw is not None else {})
    except OSError as err:
        raise ConfigError(f"{path}: {err.strerror}") from None
    except yaml.YAMLError as err:
        raise ConfigError(f"{path}: not valid YAML ({str(err).splitlines()[0]})") from None
    except ValidationError as err:
        raise ConfigError([f"{path}: {line}" for line in format_errors(err)]) from None


def _read_studies(path: Path) -> dict[str, StudySpec]:
    return read_yaml_model(path, StudiesFile).studies


def _key(override: str) -> str:
    return override.split("=", 1)[0].lstrip("+~")


def is_sweep(override: str) -> bool:
    """Whether an override gives several values (``seed=0,1,2``, ``x=range(3)``), as ``cerebx run -m`` reads it."""
    try:
        return OverridesParser.create().parse_overrides([override])[0].is_sweep_override()
    except HydraException:
        return False


def preset_sweep(args: list[str]) -> list[list[str]]:
    """The job overrides of the sweep the preset in ``args`` declares (``hydra.sweeper.params``), less the
    keys ``args`` sets to one value, with the values of the keys ``args`` sweeps itself; ``[[]]`` when there
    is none (one job)."""
    return [list(c) for c in _preset_sweep(tuple(args))]


@functools.lru_cache(maxsize=256)
def _preset_sweep(args: tuple[str, ...]) -> tuple[tuple[str, ...], ...]:
    given = [a for a in args if is_sweep(a)]
    args = [a for a in args if not is_sweep(a)]
    try:
        params = preset_sweep_params(args)
    except HydraException as err:
        raise ConfigError(f"study {' '.join(args)}: {str(err).splitlines()[0]}") from None
    fixed = {_key(a) for a in [*args, *given]}
    sweep = [f"{k}={v}" for k, v in params.items() if _key(k) not in fixed] + given
    return tuple(tuple(sorted(c)) for c in expand_sweep(sweep)) if sweep else ((),)


def _sweep_of(s: StudySpec, profile: str) -> list[list[str]]:
    return preset_sweep([*s.args, *getattr(s, profile).args])


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

    sweep_args: list[str] = field(default_factory=list)  # this job's point of its preset's sweep
    sweeps: list[str] = field(default_factory=list)  # the study's args that sweep several values (seed=0,1,2)
    borrowed: bool = False  # a full-profile run a quick report draws on (from_full): used if done, never run

    def overrides(self) -> list[str]:
        return [*self.common(), *self.sweep_args]

    def common(self, sweeps: bool = False) -> list[str]:
        """The overrides every job of the study shares (``sweeps``: with the args that sweep several values,
        as the study's ``cerebx run -m`` gives them)."""
        out = [*self.args, *(self.sweeps if sweeps else []), f"trials={self.trials}"]
        if self.after is not None:
            out.append(f"init_from='{self.deps[0].run_dir}'")
        return out

    def prepare(self) -> None:
        if self.run_dir.exists():
            shutil.rmtree(self.run_dir)  # an unfinished earlier attempt

    def describe(self) -> str:
        s = read_summary(self.run_dir)
        mae = s.get("final_mae")
        return f"final MAE {mae if mae is None else round(mae, 4)} rad, {s.get('wall_seconds', 0):.0f} s"

    def done(self) -> bool:
        """A completed run with enough trials, made from this job's configuration as the presets give it
        now and after the run it starts from (else ``resume=auto`` runs it again: a preset changed since)."""
        try:
            s = read_summary(self.run_dir)
        except CerebxError:
            return False
        if s.get("status") != "completed" or (s.get("trials_completed") or 0) < self.trials:
            return False
        return self._plain is not None and stale(self.run_dir, self._plain, s) is None

    @functools.cached_property
    def _plain(self) -> dict | None:
        """This job's composed configuration (None when it does not compose: the run will say why)."""
        try:
            return load(self.overrides())[1]
        except CerebxError:
            return None


def plan(profile: str, root: Path, names: list[str] | None = None,
         studies: dict[str, StudySpec] | None = None, max_seeds: int | None = None) -> list[Job]:
    """Every job of the named studies (all by default) and of the studies they start from, in order;
    ``max_seeds``: only the first seeds of studies learned from more (e.g. 1: every study's first seed)."""
    if profile not in PROFILES:
        raise ConfigError(f"--profile: {profile!r} is not one of {', '.join(PROFILES)}")
    given = load_studies(only=names) if studies is None else studies
    studies = with_replicas(given, profile, max_seeds)
    wanted: list[str] = []

    def want(n: str) -> None:
        if n not in studies:
            raise ConfigError(f"study {n!r}: no plugin defines it (known: {', '.join(studies)})")
        src = _init_from(studies[n], profile)
        if src is not None:
            want(src)
        if n not in wanted:
            wanted.append(n)
        for k in range(1, getattr(studies[n], profile).seeds):
            if f"{n}{REPLICA}{k}" in studies:
                want(f"{n}{REPLICA}{k}")

    for n in names if names is not None else list(studies):
        want(n)
    borrowed: list[str] = []  # from_full, or starting from a study that is: the full profile's runs
    for n in wanted:
        if getattr(studies[n], profile).from_full or _init_from(studies[n], profile) in borrowed:
            borrowed.append(n)
    jobs: list[Job] = []
    if borrowed:
        bases = list(dict.fromkeys(n.split(REPLICA)[0] for n in borrowed))
        jobs = plan("full", root, bases, given, max_seeds)
        for j in jobs:
            j.borrowed = True
        wanted = [n for n in wanted if n not in borrowed]
    single: dict[str, Job] = {}
    by_label: dict[tuple[str, str], Job] = {}
    for n in wanted:
        s = studies[n]
        p: ProfileSpec = getattr(s, profile)
        args = [*s.args, *p.args]
        src = _init_from(s, profile)
        fixed, sweeps = [a for a in args if not is_sweep(a)], [a for a in args if is_sweep(a)]
        for sweep_args in preset_sweep(args):
            label = ",".join(sweep_args) or "run"  # as Hydra's override_dirname names the job's folder
            job = Job(n, label, fixed, p.trials, root / profile / n / label, src, sweep_args=sweep_args,
                      sweeps=sweeps)
            if src is not None:
                job.deps = [single[src] if src in single else by_label[src, label]]
            if not sweep_args:
                single[n] = job
            by_label[n, label] = job
            jobs.append(job)
    return jobs


@dataclass
class Study:
    """The jobs of one study, run together as one ``cerebx run -m`` (or a part of them: see :func:`group`)."""

    name: str
    jobs: list[Job]
    deps: list[Study] = field(default_factory=list, repr=False)
    part: tuple[str, tuple[str, ...], int] | None = None  # (swept key, its values in this part, part number)

    @property
    def sweep_dir(self) -> Path:
        return self.jobs[0].run_dir.parent

    @property
    def trials(self) -> int:
        return self.jobs[0].trials * len(self.jobs)

    @property
    def run_dir(self) -> Path:  # where its log goes
        return self.sweep_dir

    @property
    def log_name(self) -> str:
        """Its ``cerebx run -m``'s log in :attr:`sweep_dir` (a part has its own: parts run side by side)."""
        return "study.log" if self.part is None else f"study.{self.part[2]}.log"

    def done(self) -> bool:
        return all(j.done() for j in self.jobs)

    def prepare(self) -> None:
        """Nothing to clear: each job reuses, resumes or restarts itself (resume=auto)."""

    def describe(self) -> str:
        maes = [read_summary(j.run_dir)["final_mae"] for j in self.jobs]
        text = ", ".join("-" if m is None else f"{m:.4f}" for m in maes)
        return f"{len(self.jobs)} job{'s' * (len(self.jobs) > 1)}, final MAE {text} rad"

    def overrides(self, extra: list[str] = ()) -> list[str]:
        """``cerebx run -m`` overrides: the shared ones, then where the jobs go, then ``extra`` (a launcher)."""
        common = self.jobs[0].common()
        swept = bool(self.jobs[0].sweep_args)
        shared = self.jobs[0].common(sweeps=True)
        if self.part is not None:  # this part's values of one swept key replace the study's (the preset's too:
            key, values, _ = self.part  # Hydra's basic sweeper lets the command line win)
            shared = [*(a for a in shared if _key(a) != _key(key)), f"{key}={','.join(values)}"]
        out = ["-m", *shared, "resume=auto", "recording.progress=off", f"hydra.sweep.dir='{self.sweep_dir}'"]
        if swept and self.name == self.jobs[0].name:  # one job of a paired study: its sweep point fixed
            out += [*self.jobs[0].sweep_args, f"hydra.sweep.subdir='{self.jobs[0].label}'"]
        elif swept:
            keys = sorted({_key(a) for a in [*common, "resume=", "recording.progress="]})
            out += ["hydra.sweep.subdir=${hydra.job.override_dirname}",
                    f"hydra.job.config.override_dirname.exclude_keys=[{','.join(keys)}]"]
        else:
            out.append("hydra.sweep.subdir=run")
        return [*out, *extra]


_PLAIN_VALUE = re.compile(r"[\w.+-]+")  # a sweep value that can be listed again with commas as it is


def split_sweep(jobs: list[Job], parts: int) -> list[tuple[str, tuple[str, ...]]]:
    """How a sweep's ``jobs`` share out over ``parts`` multiruns side by side: the swept key with the most
    values, its values dealt in turn (``seed=0,2,4…`` and ``seed=1,3,5…``), so that each part holds every
    value of the other keys and the parts take about as long. ``[]`` when it does not split (one part, fewer
    than two values, or values that cannot be written back as a comma list)."""
    values: dict[str, dict[str, None]] = {}
    for j in jobs:
        for arg in j.sweep_args:
            key, _, value = arg.partition("=")
            values.setdefault(key, {})[value] = None
    plain = {k: list(v) for k, v in values.items() if all(_PLAIN_VALUE.fullmatch(x) for x in v)}
    if parts < 2 or not plain:
        return []
    key = max(plain, key=lambda k: len(plain[k]))
    n = min(parts, len(plain[key]))
    return [(key, tuple(plain[key][i::n])) for i in range(n)] if n > 1 else []


def group(jobs: list[Job], parts: int = 1) -> list[Study]:
    """The jobs as studies (in plan order), each depending on the studies its jobs start from. A study whose
    jobs start from the jobs of the same sweep values of another (paired) runs each job as its own multirun
    of one job, as each has its own ``init_from``. ``parts``: a sweep is run as that many multiruns side by
    side into its folder (:func:`split_sweep`), so that one long sweep keeps every core busy."""
    studies: dict[str, Study] = {}
    of_job: dict[str, Study] = {}
    for j in jobs:
        paired = bool(j.sweep_args) and any(d.sweep_args for d in j.deps)
        st = studies.setdefault(j.name if paired else j.study, Study(j.name if paired else j.study, []))
        st.jobs.append(j)
    for name, st in list(studies.items()):
        split = split_sweep(st.jobs, parts) if st.jobs[0].sweep_args and st.name == st.jobs[0].study else []
        if split:
            del studies[name]
            for k, (key, values) in enumerate(split, 1):
                mine = [j for j in st.jobs if any(f"{key}={v}" in j.sweep_args for v in values)]
                studies[f"{name}:{k}/{len(split)}"] = Study(f"{name}:{k}/{len(split)}", mine, part=(key, values, k))
    for st in studies.values():
        for j in st.jobs:
            of_job[j.name] = st
    for st in studies.values():
        st.deps = list({id(of_job[d.name]): of_job[d.name] for j in st.jobs for d in j.deps
                        if d.name in of_job}.values())
    return list(studies.values())


def failure_cause(j: Job | Study, logname: str) -> str | None:
    """The line that says why ``j`` did not finish, for the report's own output (its log may be gone when that is
    read, e.g. on CI): a job's refusal (``error.txt``), else the last line of its log (a refused command's one
    line, a traceback's last)."""
    for job in j.jobs if isinstance(j, Study) else [j]:
        try:
            return f"{job.label}: {(job.run_dir / runfiles.ERROR).read_text().strip()}"
        except OSError:
            pass
    try:
        with open(j.run_dir / logname, "rb") as f:
            f.seek(max(0, f.seek(0, os.SEEK_END) - 4096))
            lines = [ln.strip() for ln in f.read().decode(errors="replace").splitlines() if ln.strip()]
    except OSError:
        return None
    return lines[-1][:300] if lines else None


Runner = Callable[[Any], int]  # runs one Job, or one Study


def subprocess_runner(job: Job) -> int:
    """``cerebx run`` in a child process; its output goes to ``<run_dir>/job.log``."""
    job.run_dir.mkdir(parents=True, exist_ok=True)
    cmd = [sys.executable, "-m", "cerebx", "run", *job.overrides(), f"hydra.run.dir='{job.run_dir}'",
           "recording.progress=off"]
    return _run_logged(cmd, job.run_dir / "job.log", "w")


_children: set[subprocess.Popen] = set()  # the `cerebx run` processes under way


def _run_logged(cmd: list[str], log_path: Path, mode: str) -> int:
    """Run ``cmd`` with its output (after the command line itself) in ``log_path``; its exit code."""
    with open(log_path, mode) as log:
        log.write(" ".join(cmd) + "\n")
        log.flush()
        proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT)
        _children.add(proc)
        try:
            return proc.wait()
        finally:
            _children.discard(proc)


def study_runner(extra: list[str] = ()) -> Runner:
    """Runs a :class:`Study` as one ``cerebx run -m`` child (``extra``: e.g. the launcher); its output goes
    to ``<study>/study.log``."""

    def run(study: Study) -> int:
        study.sweep_dir.mkdir(parents=True, exist_ok=True)
        cmd = [sys.executable, "-m", "cerebx", "run", *study.overrides(list(extra))]
        return _run_logged(cmd, study.sweep_dir / study.log_name, "a")

    return run


def in_process_runner(job: Job) -> int:
    """Run in this process (for tests: no interpreter start-up per job)."""
    cfg, choices = compose_with_choices(job.overrides())
    plain = to_plain(cfg)
    s = run_experiment(validate(plain), job.run_dir, plain, overrides=job.overrides(), choices=choices)
    return 0 if s["status"] == "completed" else 1


def execute(jobs: list[Any], runner: Runner = subprocess_runner, parallel: int = 2,
            log: Callable[[str], None] | None = None) -> list[str]:
    """Run every job (or :class:`Study`) that is not done, ``parallel`` at a time; returns one line per failed one.

    Ctrl-C stops the jobs under way (their runs end as ``interrupted``) and re-raises; finished runs
    are kept, so running again resumes.
    """
    return _Scheduler(jobs, runner, max(1, parallel), log or (lambda line: print(line, flush=True))).run()


class _Scheduler:
    def __init__(self, jobs: list[Job], runner: Runner, parallel: int, log: Callable[[str], None]):
        self.runner, self.parallel, self.log = runner, parallel, log
        self.multiruns = bool(jobs) and isinstance(jobs[0], Study)  # else Jobs (a sweep's multirun may be in parts)
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
        what = "multiruns" if self.multiruns else "jobs"
        self.log(f"studies: {self.reused + len(self.todo)} {what}, {self.reused} reused, {len(self.todo)} to run")
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
                j.prepare()
                self.log(f"[{self._clock()}] start {j.name} ({j.trials} trials)")
                self.running[pool.submit(self.runner, j)] = j

    def _record(self, j: Any, fut: Future) -> None:
        logname = j.log_name if isinstance(j, Study) else "job.log"
        try:
            rc, why = fut.result(), f"see {j.run_dir / logname}"
        except Exception as err:  # a runner that raises is a failed job, not a failed report
            rc, why = 1, f"{type(err).__name__}: {err}"
        if j.done():  # judged by its own runs: a multirun's exit code also counts other jobs in its folder
            self.finished.add(j.name)
            self.log(f"[{self._clock()}] done  {j.name}: {j.describe()} ({len(self.finished) - self.reused}/"
                     f"{len(self.todo)})" + (f", though it exited with {rc} ({why})" if rc else ""))
        else:
            cause = failure_cause(j, logname)
            self.failed[j.name] = f"{j.name}: failed (exit code {rc}, {why})" + (f": {cause}" if cause else "")
            self.log(self.failed[j.name])

    def _clock(self) -> str:
        s = int(time.monotonic() - self.t0)
        return f"{s // 60:02d}:{s % 60:02d}"
