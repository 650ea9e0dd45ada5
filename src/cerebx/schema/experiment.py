"""The whole experiment: assembled from the component registries, with cross-field checks."""

from __future__ import annotations

import functools
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import BaseModel, Field, ValidationError, create_model, model_validator

from cerebx import registry, runfiles
from cerebx.errors import ConfigError
from cerebx.registry import Plugin
from cerebx.schema.base import CONTROL_DT_MS, NonNegFloat, Strict
from cerebx.schema.init_state import init_from_problems
from cerebx.schema.live import LiveConfig
from cerebx.schema.window import WindowValue, trial_window
from cerebx.wiring import BODY_SLOTS, wire


def clock_problems(exp: object) -> list[str]:
    """Cross-field checks of ``link`` and ``clock`` for the experiment validator."""
    link, clock = exp.link, exp.clock  # type: ignore[attr-defined]
    if link.real and clock != "wall":
        return [f"clock: link={link.kind} crosses processes and runs in wall-clock time (add clock=wall)"]
    if not link.real and clock == "wall":
        return ["clock: wall-clock pacing needs a real link (link=zenoh or link=udp)"]
    return []

class ScheduledEvent(Strict):
    """An event at a time (``at_s``) or at the start of a trial (``at_trial``)."""

    at_s: NonNegFloat | None = None
    at_trial: int | None = Field(None, ge=0)
    action: Plugin("event") = Field(description="what happens (a registered event kind)")

    @model_validator(mode="after")
    def _one_time(self) -> ScheduledEvent:
        if (self.at_s is None) == (self.at_trial is None):
            raise ValueError("give exactly one of at_s or at_trial")
        return self


MAX_TRIALS = 100_000
"""The largest run cerebx accepts (the longest report study has 1,000 trials); a larger one is a typo."""


class RecordingConfig(Strict):
    """What goes into run.mcap and how the run reports progress."""

    joint_states: bool = True
    decimation: int = Field(1, ge=1, description="record every n-th control step")
    chunk_size_kb: int = Field(256, ge=4, description="smaller chunks lose less on a hard kill")
    compression: Literal["zstd", "lz4", "none"] = "zstd"
    progress: Literal["auto", "on", "off"] = "auto"
    save_state: bool = True
    checkpoint_every: int = Field(
        10, ge=0, description="trials between checkpoints of the whole loop (resume=RUN_DIR continues from the "
        "last one; a completed run deletes it); 0: none")
    phase_times: bool = Field(
        False, description="add where the run's wall and CPU time went, per phase, to summary.json (phase_times); "
        "cerebx bench's learning runs turn it on (a few microseconds per control step)")
    scene_every: int | None = Field(
        None, ge=0, description="control steps between frames of the plant's 3-D scene in run.mcap (/scene/*); "
        "null: every 10 steps when live.enabled, else none; 0: none")
    trials: WindowValue = Field(
        None, description="the trials whose control steps are recorded (joint states, /control, spikes, scene), "
        "e.g. {first: 10, last: 20, every: 100, ranges: [[149, 160]]}; null or all: every trial, none: no trial; "
        "per-trial data (/trial_metrics, /events, /weights, summary.json) are recorded for every trial")


def _union(reg: registry.Registry) -> Any:
    schemas = reg.schemas()
    if len(schemas) == 1:
        return schemas[0]
    return Annotated[tuple_union(schemas), Field(discriminator="kind")]


def tuple_union(types: tuple[type, ...]) -> Any:
    out = types[0]
    for t in types[1:]:
        out = out | t
    return out


def complete(data: Any) -> Any:
    """The experiment with its controller's context-dependent values filled in (its kind's
    ``complete`` hook), before validation."""
    if not isinstance(data, dict):
        return data
    ctrl = data.get("controller")
    kind = ctrl.get("kind") if isinstance(ctrl, dict) else None
    registry.load_plugins()
    if isinstance(kind, str) and kind in registry.controllers:
        return registry.controllers[kind].schema.complete(data)
    return data


ADDED_WITHOUT_EFFECT: dict[str, Any] = {"link": {"kind": "sim"}, "clock": "sim"}
"""Top-level keys added after runs were first recorded, with the value that does what those runs did (see
``schema/legacy.py``; controller kinds list theirs in ``added_without_effect``)."""


class _ExperimentBase(Strict):
    """Top-level keys shared by every experiment."""

    name: str = "run"
    seed: int = Field(0, ge=0)
    trials: int = Field(10, ge=1, le=MAX_TRIALS, description="trials to run (at most 100,000: 55 h of a 2 s task)")
    control_dt_ms: Literal[2.0] = CONTROL_DT_MS
    recording: RecordingConfig = RecordingConfig()
    live: LiveConfig = LiveConfig()
    events: list[ScheduledEvent] = Field(default_factory=list)
    brain: list[Plugin("stage")] = Field(
        default_factory=list, description="brain-side stages after the controller, in order (before the link)")
    robot: list[Plugin("stage")] = Field(
        default_factory=list, description="robot-side stages after the link, in order; the first may be a receiver "
        "(hold, mean, future_past: what to apply from the samples that arrived), else the newest sample is held")
    spinal: Plugin("stage") | None = Field(
        None, description="robot-side stage right after the receiver standing for the spinal cord (e.g. reflexes "
        "between the cerebellum's commands and the muscles); null: none")
    muscle: Plugin("stage") | None = Field(
        None, description="robot-side stage after the spinal cord standing for the muscles (e.g. an antagonist "
        "muscle law turning agonist/antagonist commands into joint torques); null: the commands drive the plant")
    init_from: str | None = Field(None, description="run folder whose learned state starts this run")
    resume: str | None = Field(
        None, description="run folder to continue from its last checkpoint (same config; trials may grow); the "
        "continuation logs into a further MCAP segment. 'auto': in the run's own output folder, reuse a completed "
        "run, continue from a checkpoint, else start afresh (the report's jobs)")
    warmup_trials: int = Field(
        0, ge=0, description="the first trials let a learned controller settle onto the path; they are run and "
        "logged like the others, and the report leaves them out of its statistics")
    link: Plugin("link") = Field(
        {"kind": "sim"}, description="the link between the brain side and the robot side: sim (the tick-grid link "
        "of one simulated-time process) or a transport between processes (zenoh, udp; see "
        "docs/guide/links.md)")
    clock: Literal["sim", "wall"] = Field(
        "sim", description="sim: simulated time, deterministic; wall: the robot side paced by the wall clock at the "
        "control rate (needs a real link)")
    start_at: Literal["home", "path"] = Field(
        "home", description="where the arm starts: the task's home pose, or at rest on the path's first sample "
        "(as consecutive trials do; used when a learned controller is evaluated)")

    @model_validator(mode="before")
    @classmethod
    def _complete(cls, data: Any) -> Any:
        return complete(data)

    @model_validator(mode="after")
    def _cross_checks(self) -> _ExperimentBase:
        problems: list[str] = []
        plant, task, controller = self.plant, self.task, self.controller  # type: ignore[attr-defined]
        steps = task.period_s * 1000 / CONTROL_DT_MS
        if abs(steps - round(steps)) > 1e-6:
            problems.append(f"task.period_s: {task.period_s} s is not a whole number of 2 ms steps")
        n = plant.n_joints
        if getattr(task, "n_joints", n) != n:
            problems.append(f"task: has {task.n_joints} joints but plant {plant.kind} has {n}")
        problems += _per_joint_lengths(controller, "controller", n)
        problems += controller.cross_check(self)
        for side in ("brain", "robot"):
            for i, st in enumerate(getattr(self, side)):
                problems += _per_joint_lengths(st, f"{side}.{i}", n)
                if side not in st.sides:
                    problems.append(f"{side}.{i}: stage {st.kind!r} runs on the {' or '.join(st.sides)} side")
                elif st.receiver and not (side == "robot" and i == 0):
                    problems.append(f"{side}.{i}: {st.kind!r} is a receiver, which can only be the first robot stage")
        for slot in BODY_SLOTS:
            st = getattr(self, slot)
            if st is None:
                continue
            problems += _per_joint_lengths(st, slot, n)
            if "robot" not in st.sides or st.receiver:
                problems.append(f"{slot}: stage {st.kind!r} cannot stand between the receiver and the plant")
        plant_cls = registry.plants[plant.kind].resolve()
        for i, ev in enumerate(self.events):
            method = getattr(ev.action, "plant_method", None)
            if method and not callable(getattr(plant_cls, method, None)):
                problems.append(f"events.{i}.action: plant {plant.kind} does not support event {ev.action.kind!r}")
        if not problems:
            try:
                wire(self)
            except ConfigError as err:
                problems += err.problems
        problems += clock_problems(self)
        if self.link.real and trial_window(self.recording.trials) is not None:
            problems.append("recording.trials: a wall-clock run over a real link records every trial (windows are "
                            "recorded by the simulated loop, link=sim)")
        if self.link.real and self.resume is not None:
            problems.append("resume: a wall-clock run over a real link cannot be continued from a checkpoint")
        if self.warmup_trials >= self.trials:
            problems.append(f"warmup_trials: {self.warmup_trials} leaves no measured trial of {self.trials}")
        if self.init_from is not None:
            problems += init_from_problems(self)
        if self.resume not in (None, "auto"):
            checkpoint = Path(self.resume) / runfiles.CHECKPOINT
            if not checkpoint.is_file():
                problems.append(f"resume: {checkpoint} does not exist (the run saved no checkpoint, or it completed)")
        if problems:
            raise ValueError("; ".join(problems))
        return self


def _per_joint_lengths(model: BaseModel, path: str, n: int) -> list[str]:
    """Every tuple-of-floats field (per-joint values) must have one entry per plant joint."""
    out: list[str] = []
    for name, value in model:
        if isinstance(value, BaseModel):
            out += _per_joint_lengths(value, f"{path}.{name}", n)
        elif (isinstance(value, tuple) and value and all(isinstance(v, (int, float)) for v in value)
              and len(value) != n):
            out.append(f"{path}.{name}: {len(value)} values given but the plant has {n} joints")
    return out


@functools.cache
def experiment_model() -> type[_ExperimentBase]:
    """The experiment schema with every registered task/plant/controller/delay variant (stages, events
    and encoders are looked up by kind where they are used, through ``Plugin`` fields)."""
    registry.load_plugins()
    return create_model(
        "ExperimentConfig",
        __base__=_ExperimentBase,
        task=(_union(registry.tasks), ...),
        plant=(_union(registry.plants), ...),
        controller=(_union(registry.controllers), ...),
        delay=(_union(registry.delays), ...),
    )


def format_errors(err: ValidationError) -> list[str]:
    """One ``path: message`` line per problem; union tags are dropped from the path."""
    kinds = set()
    for reg in (registry.tasks, registry.plants, registry.controllers, registry.delays):
        kinds.update(reg.kinds())
    lines = []
    for e in err.errors():
        loc = [str(p) for p in e["loc"]]
        loc = [p for i, p in enumerate(loc) if not (i > 0 and p in kinds | _INNER_TAGS)]
        msg = e["msg"].removeprefix("Value error, ")
        if e["type"] == "missing" and len(loc) == 1 and loc[0] == "task":
            msg = "no task chosen; add +task=NAME (e.g. +task=circle)"
        for part in msg.split("; ") if e["type"] == "value_error" else [msg]:
            if ": " in part and not loc:
                lines.append(part)
            elif ": " in part and part.split(": ", 1)[0].replace(".", "").replace("_", "").isalnum():
                lines.append(f"{'.'.join(loc)}.{part}" if loc else part)
            else:
                lines.append(f"{'.'.join(loc) or '<root>'}: {part}")
    return lines


_INNER_TAGS = {"lif_cond", "input", "all_to_all", "one_to_one", "joint_combinations", "kernel_stdp",
               "given", "from_task"}


def validate(data: dict[str, Any]) -> _ExperimentBase:
    """Validate a plain config mapping; raise :class:`ConfigError` with one line per problem."""
    try:
        return experiment_model().model_validate(data)
    except ValidationError as err:
        raise ConfigError(format_errors(err)) from None
