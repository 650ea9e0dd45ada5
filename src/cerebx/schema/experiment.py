"""The whole experiment: assembled from the component registries, with cross-field checks."""

from __future__ import annotations

import functools
from typing import Annotated, Any, Literal

from pydantic import BaseModel, Field, ValidationError, create_model, model_validator

from cerebx import registry
from cerebx.errors import ConfigError
from cerebx.schema.base import CONTROL_DT_MS, NonNegFloat, PositiveFloat, Strict
from cerebx.schema.network import NetworkConfig


class AttachPayload(Strict):
    """Attach a mass at the end-effector; with ``rod_length_m`` it hangs from a rod (conical pendulum)."""

    kind: Literal["attach_payload"] = "attach_payload"
    mass_kg: PositiveFloat
    rod_length_m: NonNegFloat = 0.0


class DetachPayload(Strict):
    kind: Literal["detach_payload"] = "detach_payload"


class ElasticBand(Strict):
    """A spring from the end-effector to a world anchor (offset from the start position)."""

    kind: Literal["elastic_band"] = "elastic_band"
    stiffness_N_per_m: PositiveFloat
    anchor_offset_m: tuple[float, float, float] = (0.0, 0.0, -0.3)
    rest_length_m: NonNegFloat = 0.0


class RemoveBand(Strict):
    kind: Literal["remove_band"] = "remove_band"


class ForcePulse(Strict):
    """A force on a body for a while (e.g. 20 N for 50 ms)."""

    kind: Literal["force_pulse"] = "force_pulse"
    force_N: tuple[float, float, float]
    duration_ms: PositiveFloat = 50.0
    body: str = "end_effector"


EventAction = Annotated[
    AttachPayload | DetachPayload | ElasticBand | RemoveBand | ForcePulse, Field(discriminator="kind")
]


class ScheduledEvent(Strict):
    """An event at a time (``at_s``) or at the start of a trial (``at_trial``)."""

    at_s: NonNegFloat | None = None
    at_trial: int | None = Field(None, ge=0)
    action: EventAction

    @model_validator(mode="after")
    def _one_time(self) -> ScheduledEvent:
        if (self.at_s is None) == (self.at_trial is None):
            raise ValueError("give exactly one of at_s or at_trial")
        return self


class RecordingConfig(Strict):
    """What goes into run.mcap and how the run reports progress."""

    joint_states: bool = True
    decimation: int = Field(1, ge=1, description="record every n-th control step")
    chunk_size_kb: int = Field(256, ge=4, description="smaller chunks lose less on a hard kill")
    compression: Literal["zstd", "lz4", "none"] = "zstd"
    progress: Literal["auto", "on", "off"] = "auto"
    save_state: bool = True


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


class _ExperimentBase(Strict):
    """Top-level keys shared by every experiment."""

    name: str = "run"
    seed: int = Field(0, ge=0)
    trials: int = Field(10, ge=1)
    control_dt_ms: Literal[2.0] = CONTROL_DT_MS
    network: NetworkConfig
    recording: RecordingConfig = RecordingConfig()
    events: list[ScheduledEvent] = Field(default_factory=list)
    init_from: str | None = Field(None, description="run folder whose learned state starts this run")
    warmup_trials: int = Field(
        0, ge=0, description="the first trials let a learned controller settle onto the path; they are run and "
        "logged like the others, and the report leaves them out of its statistics")
    start_at: Literal["home", "path"] = Field(
        "home", description="where the arm starts: the task's home pose, or at rest on the path's first sample "
        "(as consecutive trials do; used when a learned controller is evaluated)")

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
        if controller.kind == "snn":
            problems += _snn_fits_network(controller, self.network, n)
        if self.warmup_trials >= self.trials:
            problems.append(f"warmup_trials: {self.warmup_trials} leaves no measured trial of {self.trials}")
        if self.init_from is not None:
            from pathlib import Path

            state = Path(self.init_from) / "controller_state.npz"
            if not state.is_file():
                problems.append(f"init_from: {state} does not exist (give a run folder that saved its state)")
        if problems:
            raise ValueError("; ".join(problems))
        return self


def _snn_fits_network(controller: Any, net: NetworkConfig, n_joints: int) -> list[str]:
    """The encoders and decoder must match the population sizes they drive and read."""
    out = []
    pops, io = net.populations, net.io
    mf = pops.get(io.mossy)
    need = n_joints * 4 * controller.mf.fibers_per_signal
    if mf is not None and mf.size != need:
        out.append(f"controller.mf.fibers_per_signal: {controller.mf.fibers_per_signal} fibres x 4 signals x "
                   f"{n_joints} joints = {need}, but network population {io.mossy!r} has {mf.size}")
    for name in (io.climbing, io.output):
        p = pops.get(name)
        if p is not None and p.size % (2 * n_joints):
            out.append(f"network.populations.{name}.size: {p.size} is not an agonist/antagonist pair per joint "
                       f"({n_joints} joints)")
    return out


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
    """The experiment schema with every registered task/plant/controller/delay variant."""
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
               "box", "given", "from_task", "mean", "future_past", "tanh_bernoulli", "attach_payload",
               "detach_payload", "elastic_band", "remove_band", "force_pulse"}


def validate(data: dict[str, Any]) -> _ExperimentBase:
    """Validate a plain config mapping; raise :class:`ConfigError` with one line per problem."""
    try:
        return experiment_model().model_validate(data)
    except ValidationError as err:
        raise ConfigError(format_errors(err)) from None
