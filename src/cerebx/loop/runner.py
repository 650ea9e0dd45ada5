"""Runs one experiment: the fixed phase order on integer ticks (SPEC §1), per-trial metrics,
recording, and a summary that is written whatever happens (completed, interrupted, diverged,
failed)."""

from __future__ import annotations

import json
import logging
import os
import signal
import sys
import time
import traceback
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from cerebx import __version__
from cerebx.build import BuildContext, build_components
from cerebx.controllers.base import ControlInput, SensorMsg
from cerebx.errors import CerebxError, Diverged
from cerebx.loop.delays import DelayChannel
from cerebx.loop.plant_side import Supervisor, make_filter
from cerebx.metrics import TrialAccumulator, TrialMetrics, final_mae
from cerebx.plants.base import PlantEvent
from cerebx.recording.recorder import Recorder

log = logging.getLogger("cerebx")

STATE_FILE = "controller_state.npz"


class ClosedLoop:
    """Wires built components together and steps them in the fixed phase order."""

    def __init__(self, ctx: BuildContext, recorder: Recorder | None):
        cfg = ctx.cfg
        self.cfg, self.ctx, self.rec = cfg, ctx, recorder
        self.plant, self.task = ctx.plant, ctx.task
        self.controller = ctx.extras["controller"]
        delay = ctx.extras["delay"]
        self.r2c, self.c2r = DelayChannel(delay.r2c), DelayChannel(delay.c2r)
        n = self.plant.n_joints
        self.filter = make_filter(cfg.controller.output_filter, n)
        self.supervisor = None
        sup = cfg.controller.supervisor
        if sup is not None and sup.enabled:
            lo, hi = self.plant.joint_limits()
            if sup.bounds == "encoder" and hasattr(self.controller, "position_bounds"):
                lo, hi = self.controller.position_bounds()
            self.supervisor = Supervisor(sup, np.asarray(lo, float), np.asarray(hi, float))
        self.dt_s = cfg.control_dt_ms / 1000.0
        self.decimation = cfg.recording.decimation
        self.record_joints = recorder is not None and cfg.recording.joint_states
        self.metrics: list[TrialMetrics] = []
        self.trials_done = 0
        self.tick = 0
        self._sensor: SensorMsg | None = None  # newest sensor message delivered to the controller
        self._task_rng = ctx.rng("task")
        self._events = sorted(
            [e for e in cfg.events if e.at_s is not None], key=lambda e: e.at_s
        )
        self._trial_events = [e for e in cfg.events if e.at_trial is not None]

    def start(self) -> None:
        q0 = self.task.first_sample() if self.cfg.start_at == "path" else self.task.start_position()
        self.plant.reset(np.asarray(q0, float), self.ctx.rng("plant"))
        self.controller.reset(self.ctx.rng("controller"))
        if self.rec is not None:
            self.controller.attach_recorder(self.rec)

    def _fire(self, action: Any, t_s: float) -> None:
        params = action.model_dump(exclude={"kind"})
        self.plant.handle_event(PlantEvent(t_s, action.kind, params))
        if self.rec is not None:
            self.rec.write("/events", "cerebx.PlantEvent", t_s, {"t": t_s, "kind": action.kind, "params": params})

    def run_trial(self, trial: int) -> TrialMetrics:
        ref = self.task.trial(trial, self._task_rng)
        plant, ctrl, rec = self.plant, self.controller, self.rec
        acc = TrialAccumulator(plant.n_joints, ref.steps, self.cfg.control_dt_ms)
        for e in self._trial_events:
            if e.at_trial == trial:
                self._fire(e.action, self.tick * self.dt_s)
        if rec is not None and trial == 0 and ref.xyz is not None:
            rec.write("/task/cartesian_path", "cerebx.CartesianPath", 0.0,
                      {"x": ref.xyz[:, 0].copy(), "y": ref.xyz[:, 1].copy(), "z": ref.xyz[:, 2].copy()})
        sensor = self._sensor
        for i in range(ref.steps):
            tick = self.tick
            t = tick * self.dt_s
            while self._events and self._events[0].at_s <= t + 1e-12:
                self._fire(self._events.pop(0).action, t)
            q_des, qd_des = ref.q[i], ref.qd[i]
            # sensors -> R2C channel
            q_m, qd_m = plant.sensors()
            self.r2c.send(SensorMsg(t, q_m, qd_m), tick)
            arrived = self.r2c.receive(tick)
            if arrived:
                sensor = arrived[-1]
            # controller -> C2R channel
            cmd = ctrl.step(ControlInput(tick, t, q_des, qd_des, sensor))
            self.c2r.send(cmd, tick)
            # plant side: torque filter + supervisor, then physics
            tau = self.filter(self.c2r.receive(tick), t)
            tau_sup = self.supervisor(q_m, qd_m) if self.supervisor is not None else None
            if tau_sup is not None:
                tau = tau + tau_sup
            if not np.isfinite(tau).all():
                raise Diverged(f"trial {trial}, t = {t:.3f} s: non-finite torque command {tau.tolist()}")
            applied = plant.apply(tau)
            q, qd = plant.true_state()
            ee = plant.end_effector()
            ee_des = ref.xyz[i] if ref.xyz is not None else None
            acc.add(q_des, q, qd_des, qd, applied, ee_des, ee)
            if rec is not None and tick % self.decimation == 0:
                if self.record_joints:
                    rec.joint_states("/joint_states/desired", t, q_des, qd_des)
                    rec.joint_states("/joint_states/actual", t, q, qd, applied)
                msg = {"t": t, "trial": trial, "tau_controller": cmd.tau, "error": q_des - q,
                       "r2c_ms": self.r2c.last_delay_ms, "c2r_ms": self.c2r.last_delay_ms}
                if tau_sup is not None:
                    msg["tau_supervisor"] = tau_sup
                if ee is not None:
                    msg["ee"] = ee
                if ee_des is not None:
                    msg["ee_des"] = ee_des
                rec.write("/control", "cerebx.Control", t, msg)
            plant.step()
            self.tick += 1
            if tick % 50 == 0:
                why = plant.is_diverged()
                if why:
                    raise Diverged(f"trial {trial}, t = {t:.3f} s: {why}")
        self._sensor = sensor
        why = plant.is_diverged()
        if why:
            raise Diverged(f"trial {trial}: {why}")
        m = acc.finish(trial)
        self.metrics.append(m)
        self.trials_done = trial + 1
        if rec is not None:
            rec.write("/trial_metrics", "cerebx.TrialMetrics", self.tick * self.dt_s,
                      {**m.__dict__, "label": ref.label})
            extra = ctrl.end_trial(trial)
            if extra:
                rec.write("/weights", "cerebx.WeightSummary", self.tick * self.dt_s, {"trial": trial, **extra})
        else:
            ctrl.end_trial(trial)
        return m

    @property
    def sim_seconds(self) -> float:
        return self.tick * self.dt_s


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
    from tqdm import tqdm

    return tqdm(total=total, desc=f"{cfg.task.kind}/{cfg.controller.kind}", unit="trial", file=sys.stderr,
                dynamic_ncols=True)


def _write_json_atomic(path: Path, data: dict) -> None:
    tmp = path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(data, indent=2))
    os.replace(tmp, path)


def run_experiment(cfg: Any, run_dir: Path, resolved: dict | None = None,
                   overrides: list[str] | None = None, choices: dict[str, str] | None = None) -> dict:
    """Run ``cfg`` into ``run_dir``: writes run.mcap, summary.json and the controller state."""
    run_dir = Path(run_dir)
    run_dir.mkdir(parents=True, exist_ok=True)
    started = time.time()
    wall0 = time.perf_counter()
    summary: dict[str, Any] = {
        "status": "failed", "task": cfg.task.kind, "controller": cfg.controller.kind,
        "plant": cfg.plant.kind, "delay": cfg.delay.kind, "network": cfg.network.name,
        "seed": cfg.seed, "trials": cfg.trials, "warmup_trials": cfg.warmup_trials, "trials_completed": 0,
        "mae_per_trial": [],
        "final_mae": None, "sim_seconds": 0.0, "wall_seconds": 0.0, "rt_factor": None,
        "version": __version__, "overrides": list(overrides or []), "started_at": started, "error": None,
        "presets": dict(choices or {}),
    }
    rec = Recorder(run_dir / "run.mcap", chunk_size_kb=cfg.recording.chunk_size_kb,
                   compression=cfg.recording.compression)
    rec.metadata("cerebx", {"version": __version__, "overrides": json.dumps(list(overrides or []))})
    rec.metadata("config", {"json": json.dumps(resolved if resolved is not None else cfg.model_dump(mode="json"))})
    loop: ClosedLoop | None = None
    bar = None
    try:
        with _sigterm_as_interrupt():
            ctx = build_components(cfg, run_dir)
            rec.joint_names = tuple(ctx.plant.joint_names)
            if cfg.init_from:
                state = Path(cfg.init_from) / STATE_FILE
                if not state.exists():
                    raise CerebxError(f"init_from: {state} does not exist")
                ctx.extras["controller"].load_state(state)
            loop = ClosedLoop(ctx, rec)
            loop.start()
            summary["controller_info"] = ctx.extras["controller"].describe()
            bar = _progress(cfg, cfg.trials)
            for trial in range(cfg.trials):
                m = loop.run_trial(trial)
                if bar is not None:
                    bar.set_postfix_str(f"trial {trial + 1}/{cfg.trials}  MAE {m.mae:.4f} rad")
                    bar.update(1)
            summary["status"] = "completed"
    except KeyboardInterrupt:
        summary["status"] = "interrupted"
        summary["error"] = "interrupted by signal"
    except Diverged as err:
        summary["status"] = "diverged"
        summary["error"] = str(err)
    except CerebxError as err:
        summary["error"] = str(err)
    except Exception as err:  # record any crash, then re-raise for the caller's exit code
        summary["error"] = f"{type(err).__name__}: {err}"
        summary["traceback"] = traceback.format_exc()
    finally:
        if bar is not None:
            bar.close()
        wall = time.perf_counter() - wall0
        if loop is not None:
            ms = loop.metrics
            mae = [m.mae for m in ms]
            summary.update({
                "trials_completed": loop.trials_done,
                "mae_per_trial": mae,
                "mae_per_joint_per_trial": [list(m.mae_per_joint) for m in ms],
                "vel_mae_per_trial": [m.vel_mae for m in ms],
                "torque_variability_per_trial": [m.torque_variability_Nm_per_ms for m in ms],
                "ee_error_per_trial": [m.ee_error_m for m in ms],
                "final_mae": final_mae(mae),
                "sim_seconds": loop.sim_seconds,
            })
            if cfg.recording.save_state and loop.trials_done > 0:
                try:
                    loop.controller.save_state(run_dir / STATE_FILE)
                except Exception as err:  # the state is a bonus; the log must still be finished
                    log.error("could not save controller state: %s", err)
        summary["wall_seconds"] = wall
        summary["rt_factor"] = summary["sim_seconds"] / wall if wall > 0 else None
        try:
            rec.metadata("summary", {"json": json.dumps(summary)})
        finally:
            rec.close()
            _write_json_atomic(run_dir / "summary.json", summary)
    return summary
