"""Schema of the cerebellar spiking controller: its encoders, error gains, decoder and network.

Its code is ``controllers/snn/controller.py``; the network engine is ``cerebx.snn``."""

from __future__ import annotations

import math
from typing import Any, ClassVar, Literal

from pydantic import Field, model_validator

from cerebx.registry import Plugin
from cerebx.schema.base import NonNegFloat, PositiveFloat, Strict
from cerebx.schema.controller import ControllerConfig, muscle_command_signals
from cerebx.signals import StageIO, torque_controller_io
from cerebx.snn import sizing
from cerebx.snn.schema import BoxEncoder, CFEncoder, NetworkConfig, layout_problem

DELAYED_RECEIVER = {"kind": "future_past", "min_future_samples": 2, "past_samples": 10, "decay_per_step": 0.998}
"""What ``efferent: auto`` puts in place of a ``mean`` receiver when the link delays."""


class ErrorGains(Strict):
    """Teaching error e = kpos (q_d - q) + kvel (qd_d - qd) (Eq. 2.1)."""

    kpos: tuple[float, ...] = (1.5, 2.0, 3.0, 2.0, 2.0, 1.5)
    kvel: tuple[float, ...] = (1.5, 1.0, 3.0, 1.0, 2.0, 1.5)


class DCNDecoderConfig(Strict):
    """Torque = alpha_j (agonist - antagonist DCN spikes per 2 ms) (Eq. 2.16-2.17, 3.5); with the
    controller's ``output: agonist_antagonist`` the two sides are kept apart instead:
    M = spikes of the side in the 2 ms step / ``spikes_full_scale`` (capped at 1 with ``saturate``)."""

    alpha_Nm_per_spike: tuple[PositiveFloat, ...] = (0.75, 1.1, 0.375, 0.63, 0.078, 0.078)
    spikes_full_scale: PositiveFloat | tuple[PositiveFloat, ...] = Field(
        100.0, description="agonist_antagonist output: DCN spikes of one side of one joint in one 2 ms step "
        "that give M = 1 (one value, or one per joint); without saturate it must be at least the most that "
        "side can fire (cells x spikes per cell per step allowed by the refractory period: 50 x 2 in the "
        "full-size networks), so M stays in [0, 1]. Unused for torque output")
    saturate: bool = Field(
        False, description="agonist_antagonist output: M = min(1, spikes / full scale), the saturation of "
        "the cerebellar output; allows a full scale below the most a side can fire")

    def full_scale(self, n_joints: int) -> tuple[float, ...]:
        fs = self.spikes_full_scale
        return tuple(fs) if isinstance(fs, tuple) else (float(fs),) * n_joints


class SNNController(ControllerConfig):
    """The cerebellar spiking controller: MF and CF encoders feed a spiking ``network``, whose DCN output
    is decoded into a joint torque (or agonist/antagonist muscle commands); the PF-PC synapses learn from
    the CF error (docs/models.md#kernel-stdp). The network comes from the ``network`` config group."""

    # ``lumped``: a run recorded before it stepped every granule cell itself, with the same results (so it counts
    # as the same experiment as today's default)
    added_without_effect: ClassVar[dict[str, Any]] = {"output": "torque", "decoder.spikes_full_scale": 100.0,
                                                      "lumped": True}

    kind: Literal["snn"] = "snn"
    output: Literal["torque", "agonist_antagonist"] = Field(
        "torque", description="'torque': joint.torque = alpha (agonist - antagonist DCN spikes) (Eq. 3.5); "
        "'agonist_antagonist': the two sides as muscle.ag and muscle.at, each spikes / "
        "decoder.spikes_full_scale in [0, 1], no subtraction, for an antagonist muscle stage")
    mf: Plugin("encoder") = Field(BoxEncoder(), description="mossy-fibre encoder (registered kind, role mossy)")
    cf: Plugin("encoder") = Field(CFEncoder(), description="climbing-fibre encoder (registered kind, role climbing)")
    error: ErrorGains = ErrorGains()
    decoder: DCNDecoderConfig = DCNDecoderConfig()
    pathway_delay_ms: NonNegFloat = Field(50.0, description="afferent = efferent sensorimotor delay D")
    cf_pathway_delay_ms: NonNegFloat | None = Field(
        None, description="afferent delay of the CF (error) spikes; null = pathway_delay_ms (the original's "
        "first setup: 40 ms with 50 ms for the MF)")
    error_reference_lag_ms: NonNegFloat = Field(
        0.0, description="the CF error compares the measurement of stamp s with the desired sample of s - lag "
        "(the MF state coding keeps the desired sample of s): lag = pathway_delay_ms teaches the network to "
        "follow the path that much late, as the original's full-state node did (it paired them at now - "
        "sensorial delay - transmission delay). 0 = the path itself")
    efferent: Literal["auto", "hold", "stamp"] = Field(
        "hold",
        description="'hold': a torque is emitted D after the network computed it; 'stamp': it is sent at "
        "once, stamped with its application time (network time + D), for the plant-side future/past "
        "filter as in the original delay setup; 'auto' (the snn preset): 'stamp' with ``delayed_receiver`` as "
        "the robot's receiver whenever the experiment's delay is not 'none', else 'hold'",
    )
    delayed_receiver: dict[str, Any] = Field(
        default_factory=lambda: dict(DELAYED_RECEIVER),
        description="efferent auto with a delay: the receiver that replaces a 'mean' receiver (the mean of the "
        "nearest future and past stamped torques, decaying by 0.998 per step when starved)")
    plasticity: bool = True
    parallel: bool = Field(True, description="use numba threads in the network kernels (when not pipelined)")
    lumped: bool = Field(
        True,
        description="step a population of neurons with one kind of input (the granule layer) as classes of "
        "neurons with equal state (identical results; summary.json's integrators say which populations are lumped)",
    )
    pipeline: bool = Field(
        True,
        description="simulate the network one pathway-delay chunk ahead on a second thread "
        "(identical results; needs pathway_delay_ms > 0)",
    )
    record_spikes: list[str] = Field(default_factory=lambda: ["dcn"])
    weight_summary_every_trials: int = Field(
        10, ge=0, description="plastic-weight statistics every n trials (a pass over all weights); 0 = never"
    )
    network: NetworkConfig = Field(description="the spiking network (config group ``network``)")

    @model_validator(mode="after")
    def _encoder_roles(self) -> SNNController:
        for field, role in (("mf", "mossy"), ("cf", "climbing")):
            got = getattr(getattr(self, field), "role", None)
            if got != role:
                raise ValueError(f"{field}: kind {getattr(self, field).kind!r} is a {got} encoder, not a {role} one")
        if not hasattr(self.mf, "ranges"):
            raise ValueError(f"mf: encoder kind {self.mf.kind!r} has no 'ranges' field, from which the spiking "
                             "controller gives a mossy encoder the ranges of its signals (add one typed like "
                             "BoxEncoder.ranges)")
        return self

    @property
    def n_joints(self) -> int:
        return len(self.decoder.alpha_Nm_per_spike)

    @classmethod
    def complete(cls, experiment: dict[str, Any]) -> dict[str, Any]:
        """Size a ``per_joint`` network for the plant (:mod:`cerebx.snn.sizing`; then one-entry per-joint gains
        are given to every joint), and resolve ``efferent: auto``: with any delay other than ``none`` the
        torques are stamped and a ``mean`` receiver becomes ``delayed_receiver``; without delay the torques are
        held."""
        experiment = _sized_for_plant(experiment)
        ctrl, delay = experiment.get("controller"), experiment.get("delay")
        if not (isinstance(ctrl, dict) and ctrl.get("efferent") == "auto"):
            return experiment
        delayed = isinstance(delay, dict) and delay.get("kind", "none") != "none"
        out = {**experiment, "controller": {**ctrl, "efferent": "stamp" if delayed else "hold"}}
        robot = experiment.get("robot")  # not a list: left for the schema to refuse
        first = robot[0] if isinstance(robot, list) and robot else None
        if delayed and isinstance(first, dict) and first.get("kind") == "mean":
            receiver = ctrl.get("delayed_receiver", DELAYED_RECEIVER)
            out["robot"] = [dict(receiver) if isinstance(receiver, dict) else receiver, *robot[1:]]
        return out

    def state_problems(self, meta: dict[str, Any], exp: Any) -> str | None:
        """A learned state must come from a network of the same structure (sizes and connections)."""
        saved, want = meta.get("fingerprint"), self.network.fingerprint()
        if saved is None:
            return f"is not an SNN state (saved by a {meta.get('kind', 'different')!r} controller)"
        if saved != want:
            return (f"was saved from network {meta.get('network')!r} (fingerprint {saved}), but this run's network "
                    f"{self.network.name!r} has fingerprint {want}: sizes or connections differ")
        return layout_problem(meta.get("layout"), self.network)

    def io(self, n_joints: int) -> StageIO:
        if self.output == "torque":
            return torque_controller_io(n_joints)
        return StageIO(("ref.q", "ref.qd"), muscle_command_signals(n_joints))

    def cross_check(self, exp: Any) -> list[str]:
        """The encoders and decoder must match the population sizes they drive and read."""
        out = []
        n_joints = exp.plant.n_joints
        pops, io = self.network.populations, self.network.io
        mf = pops.get(io.mossy)
        fibres = getattr(self.mf, "fibers_per_signal", None)
        need = n_joints * 4 * fibres if fibres else None
        if mf is not None and need is not None and mf.size != need:
            out.append(f"controller.mf.fibers_per_signal: {fibres} fibres x 4 signals x {n_joints} joints = {need}, "
                       f"but network population {io.mossy!r} has {mf.size}")
        for name in (io.climbing, io.output):
            p = pops.get(name)
            if p is not None and p.size % (2 * n_joints):
                out.append(f"controller.network.populations.{name}.size: {p.size} is not an agonist/antagonist pair "
                           f"per joint ({n_joints} joints)")
        dcn = pops.get(io.output)
        if self.output == "agonist_antagonist" and dcn is not None and not dcn.size % (2 * n_joints):
            most = dcn.size // (2 * n_joints) * max_spikes_per_step(dcn.neuron, self.network.dt_ms)
            fs = self.decoder.spikes_full_scale
            low = min(self.decoder.full_scale(n_joints))
            if (not isinstance(fs, tuple) or len(fs) == n_joints) and not self.decoder.saturate and low < most:
                out.append(f"controller.decoder.spikes_full_scale: {low:g} "
                           f"spikes, but one side of a joint of {io.output!r} can fire {most} in a 2 ms step (M "
                           "would exceed 1, unless controller.decoder.saturate caps it)")
        return out


def _sized_for_plant(experiment: dict[str, Any]) -> dict[str, Any]:
    ctrl = experiment.get("controller")
    net = ctrl.get("network") if isinstance(ctrl, dict) else None
    if not (isinstance(net, dict) and sizing.KEY in net):
        return experiment
    n = sizing.plant_joints(experiment)
    if n is None:
        return experiment
    ctrl = {**ctrl, "network": sizing.sized_network(net, n)}
    for group, fields in (("error", ("kpos", "kvel")), ("decoder", ("alpha_Nm_per_spike", "spikes_full_scale"))):
        part = ctrl.get(group)
        if isinstance(part, dict):
            ctrl[group] = {**part, **{f: sizing.broadcast_per_joint(part[f], n) for f in fields if f in part}}
    return {**experiment, "controller": ctrl}


def max_spikes_per_step(neuron: Any, network_dt_ms: float, step_ms: float = 2.0) -> int:
    """The most spikes one neuron can fire in a control step: it may fire at the end of any integration
    step h, then is held for round(t_ref / h) steps (as the kernels count it); an input fibre fires at
    most once per step."""
    if getattr(neuron, "kind", None) != "lif_cond":
        return 1
    h = neuron.integration.dt_ms or network_dt_ms
    steps = int(round(step_ms / h))
    return math.ceil(steps / (round(neuron.t_ref_ms / h) + 1))


