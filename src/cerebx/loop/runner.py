"""Runs one experiment: builds the loop (``build.py``), steps it trial by trial (``loop/loop.py``),
records, and writes a summary whatever happens (completed, interrupted, diverged, failed)."""

from __future__ import annotations

import logging
import signal
import sys
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from tqdm import tqdm

from cerebx import phase_clock, runfiles
from cerebx.build import build_components
from cerebx.errors import CerebxError
from cerebx.loop import resume
from cerebx.loop.brain_side import run_brain_side
from cerebx.loop.instrument import instrument
from cerebx.loop.lifecycle import RunLifecycle
from cerebx.loop.loop import ClosedLoop
from cerebx.recording import live as live_view
from cerebx.recording.scene import scene_writer
from cerebx.recording.summary import trial_fields

log = logging.getLogger("cerebx")

SUMMARY_EVERY_S = 1.0
"""Wall seconds between the updates of a running run's summary.json (every trial cost a learning run of 200
short trials 1.5 % of its time: the whole per-trial history is rewritten each time)."""


@contextmanager
def _sigterm_as_interrupt():
    """SIGTERM (e.g. a cluster pre-emption) ends the run like Ctrl-C: cleanly, status interrupted."""
    def handler(signum, frame):
        raise KeyboardInterrupt
    try:
        old = signal.signal(signal.SIGTERM, handler)
    except ValueError:  # not in the main thread (joblib workers)
        yield
        return
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, old)


def _progress(cfg, total: int):
    mode = cfg.recording.progress
    enabled = mode == "on" or (mode == "auto" and sys.stderr.isatty())
    if not enabled:
        return None
    return tqdm(total=total, desc=f"{cfg.task.kind}/{cfg.controller.kind}", unit="trial", file=sys.stderr,
                dynamic_ncols=True)


def run_experiment(cfg: Any, run_dir: Path, resolved: dict | None = None,
                   overrides: list[str] | None = None, choices: dict[str, str] | None = None) -> dict:
    """Run ``cfg`` into ``run_dir``: writes run.mcap, summary.json and the controller state. Over a real link
    this is the brain side of a wall-clock run (``loop/brain_side.py``)."""
    if cfg.link.real:
        return run_brain_side(cfg, Path(run_dir), resolved, overrides, choices)
    run_dir = Path(run_dir)
    clock = phase_clock.PhaseClock("open") if cfg.recording.phase_times else None
    phase_clock.activate(clock)
    live = live_view.start(cfg)
    life = RunLifecycle(cfg, run_dir, log_path=resume.recorder_path(cfg, run_dir), overrides=overrides,
                        resolved=resolved, fields={"presets": dict(choices or {})}, live=live)
    loop: ClosedLoop | None = None
    ckpt = resume.Checkpointer(run_dir)
    bar = None
    wall_before = 0.0  # spent by the run this one continues

    @life.on_close
    def _close() -> None:
        summary = life.summary
        if clock is not None:
            clock.switch("finish")
        try:
            ckpt.close()  # the last checkpoint on the disk (or the previous one, whole, if writing it failed)
        except Exception as err:
            log.error("could not write the last checkpoint: %s", err)
        if bar is not None:
            bar.close()
        if loop is not None:
            try:
                loop.settle()  # the last trials' /weights
            except Exception as err:  # e.g. the network thread failed: the log must still be finished
                log.error("could not write the last weight summaries: %s", err)
        wall = wall_before + time.perf_counter() - life.wall0
        if loop is not None:
            summary.update(trial_fields(loop.metrics, loop.sim_seconds))
            if loop.trials_done > 0:
                life.save_state(loop.controller)
        summary["wall_seconds"] = wall
        summary["rt_factor"] = summary["sim_seconds"] / wall if wall > 0 else None
        summary["cpu_seconds"] = time.process_time() - life.cpu0
        if clock is not None:
            summary["phase_times"] = clock.report()  # closing the log comes after: untimed
            phase_clock.activate(None)

    with life, _sigterm_as_interrupt():
        rec = life.rec
        with phase_clock.span("build"):
            if cfg.resume is not None:
                loop, wall_before = resume.load(cfg, run_dir, rec)
            ctx = loop.ctx if loop is not None else build_components(cfg, run_dir)
        rec.joint_names = tuple(ctx.plant.joint_names)
        if cfg.init_from and loop is None:
            state = Path(cfg.init_from) / runfiles.STATE
            if not state.exists():
                raise CerebxError(f"init_from: {state} does not exist")
            ctx.brain[0].load_state(state)
        if loop is None:
            loop = ClosedLoop(ctx, rec)
            loop.start()
        if clock is not None:
            instrument(loop, clock)
            clock.switch("loop")
        loop.scene = scene_writer(cfg, ctx.plant, rec, live)
        life.summary["controller_info"] = ctx.brain[0].describe()
        with phase_clock.span("checkpoint"):
            ckpt.prime(loop)  # the learned arrays written ahead of the first checkpoint, off this thread
        bar = _progress(cfg, cfg.trials)
        if bar is not None:
            bar.update(loop.trials_done)
        summary_written = float("-inf")  # the first trial is always written
        for trial in range(loop.trials_done, cfg.trials):
            m = loop.run_trial(trial)
            if resume.due(loop):
                with phase_clock.span("checkpoint"):
                    loop.settle()  # the checkpoint holds no /weights message still to write
                    if loop.window is not None:  # few messages a trial: the log is on disk up to the checkpoint
                        rec.flush()
                    ckpt.save(loop, wall_before + time.perf_counter() - life.wall0)
            if bar is not None:
                bar.set_postfix_str(f"trial {trial + 1}/{cfg.trials}  MAE {m.mae:.4f} rad")
                bar.update(1)
            now = time.perf_counter()
            if now - summary_written >= SUMMARY_EVERY_S:  # the last one is written when the run ends
                with phase_clock.span("summary"):
                    life.progress(loop.metrics, loop.sim_seconds, wall_seconds=wall_before + now - life.wall0)
                summary_written = now
        life.completed()
    if life.status == "completed":
        resume.finish(run_dir)
    return life.summary
