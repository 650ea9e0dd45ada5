"""Checkpoints and resumption of a run (``recording.checkpoint_every``, ``resume=RUN_DIR``).

Every ``checkpoint_every`` trials the run writes, into its folder,

- the learned state, as at the end of a run (``controller_state.npz``, each stage's ``save_state``), so
  ``init_from`` may start from it, and
- ``checkpoint.pkl``: the whole live loop (plant, task, stages, link with the messages in flight, every
  random generator, the tick and trial counters, the per-trial metrics so far), pickled with cloudpickle,
  written atomically.

``resume=RUN_DIR`` rebuilds the loop from that file and continues with the next trial; the recorder is
not in the pickle (the continuation logs into a new segment, ``recording/segments.py``), so everything
logged before stays as it was. Because the generators and the messages in flight are restored too, the
continued trials equal those of a run that was never interrupted (same code, same seed).

A completed run deletes its checkpoint (it is as large as the network) and keeps the learned state.
"""

from __future__ import annotations

import json
import logging
import os
import pickle
from pathlib import Path
from typing import Any

import cloudpickle

from cerebx import __version__
from cerebx.errors import CerebxError, ConfigError
from cerebx.loop.loop import ClosedLoop
from cerebx.recording.recorder import Recorder
from cerebx.recording.segments import FIRST, add_segment

log = logging.getLogger("cerebx")

CHECKPOINT = "checkpoint.pkl"
AUTO = "auto"  # resume=auto: reuse, continue or start the run in its own output folder
_LOOP_FIELDS = ("tick", "trials_done", "metrics", "_sensed", "_task_rng", "_events")
_RECORDER = "recorder"  # persistent id of the run's recorder inside the pickle


NOT_SHARED = frozenset({"resume", "trials", "recording"})  # what a continued or reused run may differ in


def same_config(cfg: Any) -> dict:
    """The part of a config a continuation must share with the run it continues (not the trial count,
    how it is logged, or where it resumes from)."""
    return cfg.model_dump(mode="json", exclude=set(NOT_SHARED))


class _Pickler(cloudpickle.Pickler):
    def persistent_id(self, obj: Any) -> str | None:
        return _RECORDER if isinstance(obj, Recorder) else None


class _Unpickler(pickle.Unpickler):
    def __init__(self, fh, recorder: Recorder | None):
        super().__init__(fh)
        self.recorder = recorder

    def persistent_load(self, pid: str) -> Any:
        if pid != _RECORDER:
            raise pickle.UnpicklingError(f"unknown persistent id {pid!r}")
        return self.recorder


def recorder_path(cfg: Any, run_dir: Path) -> Path:
    """The file this run logs into: ``run.mcap``, or the next segment when it continues a run."""
    if cfg.resume is None:
        return run_dir / FIRST
    return add_segment(run_dir, _checkpoint_head(run_dir)["start_ns"])


def _checkpoint_head(run_dir: Path) -> dict:
    try:
        return json.loads((run_dir / (CHECKPOINT + ".json")).read_text())
    except FileNotFoundError:
        raise CerebxError(f"resume: {run_dir / CHECKPOINT} does not exist (the run saved no checkpoint)") from None


def save(loop: ClosedLoop, run_dir: Path, wall_seconds: float) -> None:
    """Write the checkpoint (pickle + a small JSON head naming its trial) and the learned state."""
    state = {"version": __version__, "config": same_config(loop.cfg), "ctx": loop.ctx,
             "loop": {f: getattr(loop, f) for f in _LOOP_FIELDS}, "wall_seconds": wall_seconds}
    tmp = run_dir / (CHECKPOINT + ".tmp")
    with open(tmp, "wb") as fh:
        _Pickler(fh, protocol=pickle.HIGHEST_PROTOCOL).dump(state)
        fh.flush()
        os.fsync(fh.fileno())
    os.replace(tmp, run_dir / CHECKPOINT)
    head = {"version": __version__, "config": state["config"], "trials_done": loop.trials_done, "tick": loop.tick,
            "start_ns": int(round(loop.tick * loop.dt_s * 1e9)), "wall_seconds": wall_seconds}
    tmp_head = run_dir / (CHECKPOINT + ".json.tmp")
    tmp_head.write_text(json.dumps(head))
    os.replace(tmp_head, run_dir / (CHECKPOINT + ".json"))
    if loop.cfg.recording.save_state:
        from cerebx.loop.runner import STATE_FILE

        loop.controller.save_state(run_dir / STATE_FILE)


def due(loop: ClosedLoop) -> bool:
    every = loop.cfg.recording.checkpoint_every
    return every > 0 and loop.trials_done % every == 0 and loop.trials_done < loop.cfg.trials


def load(cfg: Any, run_dir: Path, recorder: Recorder) -> tuple[ClosedLoop, float]:
    """The loop of the checkpoint in ``run_dir``, logging into ``recorder``; and the wall time spent so far."""
    path = run_dir / CHECKPOINT
    try:
        with open(path, "rb") as fh:
            state = _Unpickler(fh, recorder).load()
    except FileNotFoundError:
        raise CerebxError(f"resume: {path} does not exist (the run saved no checkpoint)") from None
    except Exception as err:  # any unpickling problem: a file from other code or a damaged one
        raise CerebxError(f"resume: {path} cannot be read ({type(err).__name__}: {err})") from None
    check(cfg, run_dir)  # again: the pickle may be newer than when the run started
    ctx = state["ctx"]
    ctx.cfg = cfg  # the trial count (and logging options) may change on resumption
    loop = ClosedLoop(ctx, recorder)
    for f, v in state["loop"].items():
        setattr(loop, f, v)
    log.info("resuming %s at trial %d (tick %d)", run_dir, loop.trials_done, loop.tick)
    return loop, float(state["wall_seconds"])


def check(cfg: Any, run_dir: Path) -> None:
    """Refuse (one line) a continuation that cannot continue the checkpoint in ``run_dir``: another cerebx
    version, another config, or no trial left to run."""
    head = _checkpoint_head(run_dir)
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
    saved = run_dir / ".hydra" / "overrides.yaml"
    try:
        import yaml

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
    for name in (CHECKPOINT, CHECKPOINT + ".json"):
        (run_dir / name).unlink(missing_ok=True)


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


# Options added since runs were first recorded, with the value that does what runs without them did
# (CHANGELOG: their recorded data did not change). A config that lacks one counts as having that value.
ADDED_WITHOUT_EFFECT: dict[str, Any] = {"controller.output": "torque", "controller.decoder.spikes_full_scale": 100.0,
                                        "link": {"kind": "sim"}, "clock": "sim"}


def _with_added(config: dict) -> dict:
    out = json.loads(json.dumps(config))
    for dotted, value in ADDED_WITHOUT_EFFECT.items():
        *parents, last = dotted.split(".")
        node = out
        for part in parents:
            node = node.get(part) if isinstance(node, dict) else None
        if isinstance(node, dict) and last not in node:
            node[last] = value
    return out


def stale(run_dir: Path, plain: dict, summary: dict) -> str | None:
    """Why the completed run in ``run_dir`` cannot stand for the run ``plain`` asks for now, or None: its
    recorded configuration must equal ``plain`` (but for the trial count, logging and resumption), and
    the run it started from (``init_from``) must not have been written since it started."""
    from cerebx.recording.reader import read_metadata

    try:
        old = json.loads(read_metadata(run_dir)["config"]["json"])
    except (CerebxError, KeyError, OSError, ValueError):
        return "its recorded configuration cannot be read"
    try:
        _check_same(*({k: v for k, v in _with_added(d).items() if k not in NOT_SHARED} for d in (old, plain)),
                    whose="its")
    except ConfigError as err:
        return f"the configuration changed: {err}"
    source = plain.get("init_from")
    if source:
        try:
            written = (Path(source) / "summary.json").stat().st_mtime
        except OSError:
            return None  # validation reports a missing init_from run
        if written > float(summary.get("started_at") or 0.0):
            return f"the run it starts from ({source}) was written after it started"
    return None


def _completed(run_dir: Path) -> dict | None:
    try:
        s = json.loads((run_dir / "summary.json").read_text())
    except (OSError, ValueError):
        return None
    return s if s.get("status") == "completed" else None


def _clear(run_dir: Path) -> None:
    """Drop what an unfinished attempt without a usable checkpoint left (a fresh run writes it anew)."""
    for p in [*run_dir.glob("run.*.mcap"), run_dir / "segments.json", run_dir / CHECKPOINT,
              run_dir / (CHECKPOINT + ".json"), run_dir / "summary.json"]:
        p.unlink(missing_ok=True)
