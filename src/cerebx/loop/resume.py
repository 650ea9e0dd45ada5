"""Checkpoints and resumption of a run (``recording.checkpoint_every``, ``resume=RUN_DIR``).

Every ``checkpoint_every`` trials the run writes, into its folder, the whole live loop (plant, task, stages,
link with the messages in flight, every random generator, the tick and trial counters, the per-trial metrics
so far): ``checkpoint.pkl`` with its head (also copied to ``checkpoint.pkl.json``), and the large learned
arrays beside it (``persistence/checkpoint.py``: written by a thread of its own while the run goes on, atomically,
only what changed since the last checkpoint). The learned state itself (``controller_state.npz``, what
``init_from`` starts from) is written when the run ends, also when it is interrupted or fails; a run killed
outright (SIGKILL, OOM) is continued from its checkpoint instead.

``resume=RUN_DIR`` rebuilds the loop from the checkpoint and continues with the next trial; the recorder is
not in the pickle (the continuation logs into a new segment, ``recording/segments.py``), so everything
logged before stays as it was. Because the generators and the messages in flight are restored too, the
continued trials equal those of a run that was never interrupted (same code, same seed).

A completed run deletes its checkpoint (it is as large as the network) and keeps the learned state.
"""

from __future__ import annotations

import json
import logging
import os
from pathlib import Path
from typing import Any

import yaml

from cerebx import __version__, runfiles
from cerebx.errors import CerebxError, ConfigError
from cerebx.loop.loop import ClosedLoop
from cerebx.persistence import checkpoint
from cerebx.recording.reader import read_metadata
from cerebx.recording.recorder import Recorder
from cerebx.recording.segments import FIRST, add_segment
from cerebx.schema.legacy import upgrade
from cerebx.schema.window import trial_window

log = logging.getLogger("cerebx")

CHECKPOINT = runfiles.CHECKPOINT
AUTO = "auto"  # resume=auto: reuse, continue or start the run in its own output folder
_LOOP_FIELDS = ("tick", "trials_done", "metrics", "_sensed", "_task_rng", "_events", "window", "_last_held")
_RECORDER = "recorder"  # persistent id of the run's recorder inside the pickle


NOT_SHARED = frozenset({"resume", "trials", "recording", "live"})  # what a continued or reused run may differ in


def same_config(cfg: Any) -> dict:
    """The part of a config a continuation must share with the run it continues (not the trial count,
    how it is logged, or where it resumes from)."""
    return cfg.model_dump(mode="json", exclude=set(NOT_SHARED))


def recorder_path(cfg: Any, run_dir: Path) -> Path:
    """The file this run logs into: ``run.mcap``, or the next segment when it continues a run."""
    if cfg.resume is None:
        return run_dir / FIRST
    return add_segment(run_dir, checkpoint_head(run_dir)["start_ns"])


def checkpoint_head(run_dir: Path) -> dict:
    """The head of the checkpoint in ``run_dir`` (version, config, trials done, tick, ...)."""
    try:
        return checkpoint.read_head(run_dir)
    except FileNotFoundError:
        raise CerebxError(f"resume: {run_dir / CHECKPOINT} does not exist (the run saved no checkpoint)") from None
    except (OSError, ValueError) as err:
        raise CerebxError(f"resume: {run_dir / CHECKPOINT} cannot be read ({type(err).__name__})") from None


class Checkpointer:
    """Writes a run's checkpoints: the loop's thread pickles the state and copies what changed, a thread of
    its own writes it (``persistence/checkpoint.py``); :meth:`close` waits until the last one is on the disk."""

    def __init__(self, run_dir: Path):
        self.run_dir = Path(run_dir)
        self.store = checkpoint.ArrayStore()
        self.writer = checkpoint.Writer()

    def prime(self, loop: ClosedLoop) -> None:
        """Before the trials of this process: have the writer write the learned arrays ahead of the first
        checkpoint due, from the live arrays while the trials run (``checkpoint.prime``), so that the first
        checkpoint does not copy them whole on the loop's thread. Nothing when no checkpoint is due."""
        every = loop.cfg.recording.checkpoint_every
        if every <= 0:
            return
        first = (loop.trials_done // every + 1) * every  # the first trial count :func:`due` says yes to
        if first >= loop.cfg.trials:
            return
        job = checkpoint.prime(self.run_dir, first, _state(loop), self.store, {Recorder: _RECORDER})
        if job is not None:
            self.writer.submit(job)

    def save(self, loop: ClosedLoop, wall_seconds: float) -> None:
        self.writer.wait()  # the previous checkpoint first (and its error, if it failed)
        head = {"version": __version__, "config": same_config(loop.cfg), "trials_done": loop.trials_done,
                "tick": loop.tick, "start_ns": int(round(loop.tick * loop.dt_s * 1e9)), "wall_seconds": wall_seconds}
        self.writer.submit(checkpoint.prepare(self.run_dir, head, _state(loop), self.store, {Recorder: _RECORDER}))

    def close(self) -> None:
        try:
            self.writer.wait()
        finally:
            checkpoint.drop_ahead(self.store)  # written ahead of a first checkpoint that never came


def _state(loop: ClosedLoop) -> dict[str, Any]:
    return {"ctx": loop.ctx, "loop": {f: getattr(loop, f) for f in _LOOP_FIELDS}}


def save(loop: ClosedLoop, run_dir: Path, wall_seconds: float) -> None:
    """Write a checkpoint of ``loop`` into ``run_dir`` and wait until it is on the disk."""
    ckpt = Checkpointer(run_dir)
    ckpt.save(loop, wall_seconds)
    ckpt.close()


def due(loop: ClosedLoop) -> bool:
    every = loop.cfg.recording.checkpoint_every
    return every > 0 and loop.trials_done % every == 0 and loop.trials_done < loop.cfg.trials


def load(cfg: Any, run_dir: Path, recorder: Recorder) -> tuple[ClosedLoop, float]:
    """The loop of the checkpoint in ``run_dir``, logging into ``recorder``; and the wall time spent so far."""
    path = run_dir / CHECKPOINT
    try:
        head, state = checkpoint.load(run_dir, {_RECORDER: recorder})
    except FileNotFoundError:
        raise CerebxError(f"resume: {path} does not exist (the run saved no checkpoint)") from None
    except Exception as err:  # any unpickling problem: a file from other code or a damaged one
        raise CerebxError(f"resume: {path} cannot be read ({type(err).__name__}: {err})") from None
    check(cfg, run_dir)  # again: the pickle may be newer than when the run started
    ctx = state["ctx"]
    ctx.brain = checkpoint.unwrap_adapters(ctx.brain)  # a checkpoint from before controllers were stages
    ctx.cfg = cfg  # the trial count (and logging options) may change on resumption
    loop = ClosedLoop(ctx, recorder)
    for f, v in state["loop"].items():
        setattr(loop, f, v)
    if loop.window != trial_window(cfg.recording.trials):
        log.warning("resume: recording.trials stays as the run started (%s): a run keeps its windows",
                    "every trial" if loop.window is None else loop.window.model_dump(mode="json"))
    log.info("resuming %s at trial %d (tick %d)", run_dir, loop.trials_done, loop.tick)
    return loop, float(head["wall_seconds"])


def check(cfg: Any, run_dir: Path) -> None:
    """Refuse (one line) a continuation that cannot continue the checkpoint in ``run_dir``: another cerebx
    version, another config, or no trial left to run."""
    head = checkpoint_head(run_dir)
    if head.get("version") != __version__:
        raise ConfigError(f"resume: {run_dir / CHECKPOINT} was written by cerebx {head.get('version')}, "
                          f"this is {__version__}")
    _check_same(head.get("config"), same_config(cfg))
    if cfg.trials <= head["trials_done"]:
        raise ConfigError(f"trials: {cfg.trials}, but the checkpoint already has {head['trials_done']} trials done")


def expand_args(args: list[str]) -> list[str]:
    """``cerebx run resume=RUN_DIR [overrides]``: the overrides RUN_DIR was run with, then the given ones,
    with Hydra's output in RUN_DIR (its files of this attempt in ``.hydra.resumed``)."""
    given = [a for a in args if a.startswith("resume=")]
    if not given or given[-1] == f"resume={AUTO}":
        return args
    run_dir = Path(given[-1].split("=", 1)[1].strip("'\""))
    saved = run_dir / runfiles.OVERRIDES
    try:
        before = [str(o) for o in yaml.safe_load(saved.read_text()) or []]
    except (OSError, ValueError) as err:
        raise ConfigError(f"resume: cannot read the overrides of {run_dir} ({saved}: {type(err).__name__})") from None
    keys = {a.split("=", 1)[0].lstrip("+~") for a in args if "=" in a and not a.startswith("resume=")}
    kept = [o for o in before if o.split("=", 1)[0].lstrip("+~") not in keys | {"resume"}]
    rest = [a for a in args if not a.startswith("resume=")]
    return [*kept, *rest, f"resume={run_dir}", f"hydra.run.dir={run_dir}", "hydra.output_subdir=.hydra.resumed"]


def _check_same(old: Any, new: Any, where: str = "", whose: str = "the resumed run's") -> None:
    if isinstance(old, dict) and isinstance(new, dict):
        for k in sorted(set(old) | set(new)):
            _check_same(old.get(k), new.get(k), f"{where}.{k}" if where else k, whose)
    elif old != new:
        raise ConfigError(f"{where or 'config'}: {new!r} differs from {whose} {old!r}")


def finish(run_dir: Path) -> None:
    """The run completed: its checkpoint is no longer needed."""
    checkpoint.remove(run_dir)


def requeued_dir(run_dir: Path) -> Path | None:
    """``run_dir`` when this process is a requeued SLURM job whose earlier attempt left a checkpoint there."""
    if os.environ.get("SLURM_RESTART_COUNT", "0") not in ("", "0") and (run_dir / CHECKPOINT).exists():
        return run_dir
    return None


def continued(exp: Any, plain: dict, output_dir: Path) -> tuple[Any, Path, dict | None]:
    """The config and folder of a run, and the summary of a finished run it reuses (then nothing is run).

    ``resume=RUN_DIR`` continues in RUN_DIR; ``resume=auto`` (the report's jobs) reuses a completed run in
    ``output_dir`` that has enough trials, continues one that left a checkpoint, else starts afresh there;
    a requeued SLURM job continues in its own folder from its last checkpoint; any other run starts in
    ``output_dir``. Raises ConfigError (before anything is written) when a continuation is not possible.
    """
    output_dir = Path(output_dir)
    if exp.resume == AUTO:
        done = _completed(output_dir)
        if done is not None and (done.get("trials_completed") or 0) >= exp.trials:
            why = stale(output_dir, plain, done)
            if why is None:
                return exp, output_dir, done
            log.warning("not reusing %s: %s; running it again", output_dir, why)
        target = str(output_dir) if (output_dir / CHECKPOINT).exists() else None
        if target is not None:
            try:
                check(exp, output_dir)
            except ConfigError as err:
                log.warning("not resuming %s: %s", output_dir, err)
                target = None
        if target is None:
            _clear(output_dir)
        exp = exp.model_copy(update={"resume": target})
        plain["resume"] = target
    elif exp.resume is None and requeued_dir(output_dir) is not None:
        plain["resume"] = str(output_dir)
        exp = exp.model_copy(update={"resume": str(output_dir)})
    if exp.resume is None:
        return exp, output_dir, None
    check(exp, Path(exp.resume))
    return exp, Path(exp.resume), None


def stale(run_dir: Path, plain: dict, summary: dict) -> str | None:
    """Why the completed run in ``run_dir`` cannot stand for the run ``plain`` asks for now, or None: its
    recorded configuration must equal ``plain`` (but for the trial count, logging and resumption), and
    the run it started from (``init_from``) must not have been written since it started."""
    try:
        old = json.loads(read_metadata(run_dir)["config"]["json"])
    except (CerebxError, KeyError, OSError, ValueError):
        return "its recorded configuration cannot be read"
    try:
        _check_same(*({k: v for k, v in upgrade(d).items() if k not in NOT_SHARED} for d in (old, plain)),
                    whose="its")
    except ConfigError as err:
        return f"the configuration changed: {err}"
    source = plain.get("init_from")
    if source:
        try:
            written = (Path(source) / runfiles.SUMMARY).stat().st_mtime
        except OSError:
            return None  # validation reports a missing init_from run
        if written > float(summary.get("started_at") or 0.0):
            return f"the run it starts from ({source}) was written after it started"
    return None


def _completed(run_dir: Path) -> dict | None:
    try:
        s = json.loads((run_dir / runfiles.SUMMARY).read_text())
    except (OSError, ValueError):
        return None
    return s if s.get("status") == "completed" else None


def _clear(run_dir: Path) -> None:
    """Drop what an unfinished attempt without a usable checkpoint left (a fresh run writes it anew)."""
    for p in [*run_dir.glob("run.*.mcap"), run_dir / runfiles.SEGMENTS, run_dir / runfiles.SUMMARY]:
        p.unlink(missing_ok=True)
    checkpoint.remove(run_dir)
