"""Controller schemas: baselines, the spiking cerebellum and its encoders/decoders, and the
composite controller whose parts' outputs add up. The robot-side torque filters and the supervisor
are stages (``schema/stages.py``)."""

from __future__ import annotations

import math
from typing import Annotated, Any, ClassVar, Literal

import numpy as np
from pydantic import Field, model_validator

from cerebx.registry import Plugin
from cerebx.schema.base import NonNegFloat, PositiveFloat, Strict
from cerebx.signals import Signal, StageIO, torque_controller_io


class ControllerConfig(Strict):
    """Base of every controller schema (a brain-side part of the loop)."""

    def cross_check(self, exp: Any) -> list[str]:
        """Problems that involve other parts of the experiment (one ``path: message`` line each)."""
        return []

    def io(self, n_joints: int) -> StageIO:
        """The signals this controller reads and writes (default: a joint-torque controller)."""
        return torque_controller_io(n_joints)


class PDController(ControllerConfig):
    """tau = kp (q_d - q) + kd (qd_d - qd), saturated at +-tau_max (facts §6)."""

    kind: Literal["pd"] = "pd"
    kp: tuple[float, ...] = (45.0, 50.0, 17.0, 50.0, 22.0, 27.0)
    kd: tuple[float, ...] = (15.0, 5.0, 3.0, 4.0, 2.5, 3.0)
    tau_max_Nm: tuple[PositiveFloat, ...] = (12.0, 19.5, 3.75, 10.5, 3.0, 3.75)

    @model_validator(mode="after")
    def _lengths(self) -> PDController:
        if not len(self.kp) == len(self.kd) == len(self.tau_max_Nm):
            raise ValueError("kp, kd and tau_max_Nm need the same number of joints")
        return self

    @property
    def n_joints(self) -> int:
        return len(self.kp)


class PositionController(ControllerConfig):
    """Stiff position servo with gravity compensation (stands in for Baxter's factory controller)."""

    kind: Literal["position"] = "position"
    kp: tuple[float, ...] = (700.0, 1000.0, 450.0, 550.0, 100.0, 90.0)
    kd: tuple[float, ...] = (25.0, 40.0, 10.0, 12.0, 2.0, 2.0)
    gravity_compensation: bool = True
    velocity_feedforward: bool = Field(
        True, description="track the desired velocity; off = position-only commands (damping toward rest)"
    )
    tau_max_Nm: tuple[PositiveFloat, ...] = (50.0, 100.0, 50.0, 50.0, 15.0, 15.0)

    @property
    def n_joints(self) -> int:
        return len(self.kp)


class GivenRanges(Strict):
    """Encoder ranges per joint for each of the four MF signals (facts §3 launch-file tables)."""

    kind: Literal["given"] = "given"
    q_min: tuple[float, ...]
    q_max: tuple[float, ...]
    qd_des_min: tuple[float, ...]
    qd_des_max: tuple[float, ...]
    qd_min: tuple[float, ...]
    qd_max: tuple[float, ...]

    @model_validator(mode="after")
    def _non_empty(self) -> GivenRanges:
        for lo_name, hi_name in (("q_min", "q_max"), ("qd_des_min", "qd_des_max"), ("qd_min", "qd_max")):
            lo, hi = getattr(self, lo_name), getattr(self, hi_name)
            if len(lo) != len(hi):
                raise ValueError(f"{lo_name} and {hi_name} need the same length")
            bad = [j for j, (a, b) in enumerate(zip(lo, hi)) if not a < b]
            if bad:
                raise ValueError(f"{lo_name} must be below {hi_name} (empty range at joint {bad[0]})")
        return self

    def bounds(self, n_joints: int, task: Any = None) -> tuple[np.ndarray, np.ndarray]:
        """(lo, hi), each (n_joints, 4) for q_d, q, qd_d, qd: as configured (q_d and q share the
        position range, as in the original)."""
        if min(len(self.q_min), len(self.qd_min), len(self.qd_des_min)) < n_joints:
            raise ValueError(f"controller ranges: given ranges cover fewer than the {n_joints} controlled joints")
        qlo, qhi = np.asarray(self.q_min, float), np.asarray(self.q_max, float)
        lo = np.stack([qlo, qlo, np.asarray(self.qd_des_min, float), np.asarray(self.qd_min, float)], axis=1)
        hi = np.stack([qhi, qhi, np.asarray(self.qd_des_max, float), np.asarray(self.qd_max, float)], axis=1)
        return lo[:n_joints], hi[:n_joints]


class TaskRanges(Strict):
    """Encoder ranges from the task's desired trajectory, widened by ``margin`` of the span."""

    kind: Literal["from_task"] = "from_task"
    margin: NonNegFloat = 0.1
    velocity_margin: NonNegFloat = 0.1

    def bounds(self, n_joints: int, task: Any = None) -> tuple[np.ndarray, np.ndarray]:
        """(lo, hi), each (n_joints, 4) for q_d, q, qd_d, qd: the task's desired envelope widened by
        ``margin`` (positions) and ``velocity_margin`` (velocities) of its span; actual and desired
        share the range."""
        if task is None:
            raise ValueError("controller ranges: 'from_task' needs a task to derive the encoder ranges")
        q_min, q_max, qd_min, qd_max = (np.asarray(a, dtype=float)[:n_joints] for a in task.envelope())
        qlo, qhi = _widen(q_min, q_max, self.margin)
        vlo, vhi = _widen(qd_min, qd_max, self.velocity_margin)
        return np.stack([qlo, qlo, vlo, vlo], axis=1), np.stack([qhi, qhi, vhi, vhi], axis=1)


def _widen(a: np.ndarray, b: np.ndarray, margin: float) -> tuple[np.ndarray, np.ndarray]:
    span = np.maximum(b - a, 1e-3)
    return a - margin * span, b + margin * span


class BoxEncoder(Strict):
    """MF interval coding (Eq. 2.12-2.15): per signal, 10 fibres with box receptive fields;
    the active fibre fires once per 2 ms step."""

    role: ClassVar[str] = "mossy"

    kind: Literal["box"] = "box"
    fibers_per_signal: int = Field(10, gt=1)
    width_factor: PositiveFloat = Field(0.500000000001, description="half-width in units of the centre step")
    ranges: Annotated[GivenRanges | TaskRanges, Field(discriminator="kind")] = TaskRanges()


class CFEncoder(Strict):
    """CF stochastic error coding (facts §3): agonist/antagonist split by error sign;
    rate = r_min + (r_max - r_min)(tanh((|e| - c_k)/w) + 1)/2, Bernoulli per 2 ms, bursts."""

    role: ClassVar[str] = "climbing"

    kind: Literal["tanh_bernoulli"] = "tanh_bernoulli"
    rate_min_hz: NonNegFloat = 1.0
    rate_max_hz: PositiveFloat = 10.0
    center_min: NonNegFloat = 0.001
    center_max: PositiveFloat = 0.01
    max_burst: int = Field(6, ge=1)

    @model_validator(mode="after")
    def _ranges(self) -> CFEncoder:
        if self.rate_min_hz >= self.rate_max_hz:
            raise ValueError("rate_min_hz must be below rate_max_hz")
        if self.center_min >= self.center_max:
            raise ValueError("center_min must be below center_max")
        return self


class ErrorGains(Strict):
    """Teaching error e = kpos (q_d - q) + kvel (qd_d - qd) (Eq. 2.1)."""

    kpos: tuple[float, ...] = (1.5, 2.0, 3.0, 2.0, 2.0, 1.5)
    kvel: tuple[float, ...] = (1.5, 1.0, 3.0, 1.0, 2.0, 1.5)


class DCNDecoderConfig(Strict):
    """Torque = alpha_j (agonist - antagonist DCN spikes per 2 ms) (Eq. 2.16-2.17, 3.5); with the
    controller's ``output: agonist_antagonist`` the two sides are kept apart instead (thesis §4.6.2):
    M = spikes of the side in the 2 ms step / ``spikes_full_scale`` (capped at 1 with ``saturate``)."""

    alpha_Nm_per_spike: tuple[PositiveFloat, ...] = (0.75, 1.1, 0.375, 0.63, 0.078, 0.078)
    spikes_full_scale: PositiveFloat | tuple[PositiveFloat, ...] = Field(
        100.0, description="agonist_antagonist output: DCN spikes of one side of one joint in one 2 ms step "
        "that give M = 1 (one value, or one per joint); without saturate it must be at least the most that "
        "side can fire (cells x spikes per cell per step allowed by the refractory period: 50 x 2 in the "
        "thesis networks), so M stays in [0, 1]. Unused for torque output")
    saturate: bool = Field(
        False, description="agonist_antagonist output: M = min(1, spikes / full scale), the saturation of "
        "the cerebellar output the thesis names (§4.7); allows a full scale below the most a side can fire")

    def full_scale(self, n_joints: int) -> tuple[float, ...]:
        fs = self.spikes_full_scale
        return tuple(fs) if isinstance(fs, tuple) else (float(fs),) * n_joints


class SNNController(ControllerConfig):
    """The cerebellar spiking network (thesis §2.2.3-2.2.7, §3.2.2-3.2.4). The topology comes
    from the top-level ``network`` group."""

    kind: Literal["snn"] = "snn"
    output: Literal["torque", "agonist_antagonist"] = Field(
        "torque", description="'torque': joint.torque = alpha (agonist - antagonist DCN spikes) (Eq. 3.5); "
        "'agonist_antagonist': the two sides as muscle.ag and muscle.at, each spikes / "
        "decoder.spikes_full_scale in [0, 1], no subtraction (thesis §4.6.2), for a muscle stage")
    mf: Plugin("encoder") = Field(BoxEncoder(), description="mossy-fibre encoder (registered kind, role mossy)")
    cf: Plugin("encoder") = Field(CFEncoder(), description="climbing-fibre encoder (registered kind, role climbing)")
    error: ErrorGains = ErrorGains()
    decoder: DCNDecoderConfig = DCNDecoderConfig()
    pathway_delay_ms: NonNegFloat = Field(50.0, description="afferent = efferent sensorimotor delay D")
    cf_pathway_delay_ms: NonNegFloat | None = Field(
        None, description="afferent delay of the CF (error) spikes; null = pathway_delay_ms ([B]: 40 ms "
        "with 50 ms for the MF)")
    efferent: Literal["auto", "hold", "stamp"] = Field(
        "hold",
        description="'hold': a torque is emitted D after the network computed it; 'stamp': it is sent at "
        "once, stamped with its application time (network time + D), for the plant-side future/past "
        "filter (Eq. 3.6) as in the original delay setup; 'auto' (the snn preset): 'stamp' with the "
        "Eq. 3.6 receiver whenever the experiment's delay is not 'none', else 'hold'",
    )
    plasticity: bool = True
    parallel: bool = Field(True, description="use numba threads in the network kernels (when not pipelined)")
    pipeline: bool = Field(
        True,
        description="simulate the network one pathway-delay chunk ahead on a second thread "
        "(identical results; needs pathway_delay_ms > 0)",
    )
    record_spikes: list[str] = Field(default_factory=lambda: ["dcn"])
    weight_summary_every_trials: int = Field(
        10, ge=0, description="plastic-weight statistics every n trials (a pass over all weights); 0 = never"
    )

    @model_validator(mode="after")
    def _encoder_roles(self) -> SNNController:
        for field, role in (("mf", "mossy"), ("cf", "climbing")):
            got = getattr(getattr(self, field), "role", None)
            if got != role:
                raise ValueError(f"{field}: kind {getattr(self, field).kind!r} is a {got} encoder, not a {role} one")
        return self

    @property
    def n_joints(self) -> int:
        return len(self.decoder.alpha_Nm_per_spike)

    def io(self, n_joints: int) -> StageIO:
        if self.output == "torque":
            return torque_controller_io(n_joints)
        return StageIO(("ref.q", "ref.qd"), muscle_command_signals(n_joints))

    def cross_check(self, exp: Any) -> list[str]:
        """The encoders and decoder must match the population sizes they drive and read."""
        out = []
        n_joints = exp.plant.n_joints
        pops, io = exp.network.populations, exp.network.io
        mf = pops.get(io.mossy)
        fibres = getattr(self.mf, "fibers_per_signal", None)
        need = n_joints * 4 * fibres if fibres else None
        if mf is not None and need is not None and mf.size != need:
            out.append(f"controller.mf.fibers_per_signal: {fibres} fibres x 4 signals x {n_joints} joints = {need}, "
                       f"but network population {io.mossy!r} has {mf.size}")
        for name in (io.climbing, io.output):
            p = pops.get(name)
            if p is not None and p.size % (2 * n_joints):
                out.append(f"network.populations.{name}.size: {p.size} is not an agonist/antagonist pair per joint "
                           f"({n_joints} joints)")
        dcn = pops.get(io.output)
        if self.output == "agonist_antagonist" and dcn is not None and not dcn.size % (2 * n_joints):
            most = dcn.size // (2 * n_joints) * max_spikes_per_step(dcn.neuron, exp.network.dt_ms)
            fs = self.decoder.spikes_full_scale
            low = min(self.decoder.full_scale(n_joints))
            if (not isinstance(fs, tuple) or len(fs) == n_joints) and not self.decoder.saturate and low < most:
                out.append(f"controller.decoder.spikes_full_scale: {low:g} "
                           f"spikes, but one side of a joint of {io.output!r} can fire {most} in a 2 ms step (M "
                           "would exceed 1, unless controller.decoder.saturate caps it)")
        return out


def muscle_command_signals(n_joints: int) -> tuple[Signal, Signal]:
    """The agonist and antagonist commands of an antagonist muscle pair per joint, each in [0, 1]."""
    return (Signal("muscle.ag", n_joints, "1", 0.0, 1.0), Signal("muscle.at", n_joints, "1", 0.0, 1.0))


def max_spikes_per_step(neuron: Any, network_dt_ms: float, step_ms: float = 2.0) -> int:
    """The most spikes one neuron can fire in a control step: it may fire at the end of any integration
    step h, then is held for round(t_ref / h) steps (as the kernels count it); an input fibre fires at
    most once per step."""
    if getattr(neuron, "kind", None) != "lif_cond":
        return 1
    h = neuron.integration.dt_ms or network_dt_ms
    steps = int(round(step_ms / h))
    return math.ceil(steps / (round(neuron.t_ref_ms / h) + 1))


class CompositeController(ControllerConfig):
    """Several brain-side parts run in order each tick; signals written by more than one part add up
    (e.g. a feed-forward torque plus a corrective one). Each part keeps its own learned state."""

    kind: Literal["composite"] = "composite"
    parts: list[Plugin("controller")] = Field(min_length=1, description="controller parts, in order")

    def cross_check(self, exp: Any) -> list[str]:
        return [f"controller.parts.{i}.{line}" for i, p in enumerate(self.parts) for line in p.cross_check(exp)]

    def io(self, n_joints: int) -> StageIO:
        """Reads what a part reads before an earlier part wrote it; writes every part's outputs."""
        written: dict[str, Any] = {}
        reads: list[str] = []
        for part in self.parts:
            pio = part.io(n_joints)
            reads += [r for r in pio.reads if r not in written and r not in reads]
            written.update({s.name: s for s in pio.writes})
        return StageIO(tuple(reads), tuple(written.values()))
