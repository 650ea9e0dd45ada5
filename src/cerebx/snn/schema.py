"""Spiking network topology as data: populations, projections, neuron models, connectors, weight and delay
distributions, plasticity rules, and the encoders' schemas (the code of each: snn/topology.py, connectors.py,
plasticity.py, encoders.py).

A network preset is a table of populations and projections (``conf/network``). Validation checks
that each projection's declared synapse count is what its connection rule produces from the
population sizes, so a typo in a table is caught before anything is built.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Annotated, Any, ClassVar, Literal

import numpy as np
from pydantic import Field, model_validator

from cerebx.registry import Plugin
from cerebx.schema.base import NonNegFloat, PositiveFloat, Strict
from cerebx.schema.controller import GivenRanges, TaskRanges


class Integration(Strict):
    """How a population's membrane equation is integrated (lif_cond, adex_cond: V_thr reads V_th for AdEx).
    Conductances always decay exactly (g <- g e^(-h/tau)); the integrator sees the exact conductance at its
    stage times."""

    method: Literal["rk4", "rk2", "euler"] = Field(
        "rk4", description="rk4: classical Runge-Kutta; rk2: Heun (explicit trapezoid, EDLUT RK2); "
        "euler: forward Euler"
    )
    dt_ms: PositiveFloat | None = Field(
        None, description="integration step (ms); a multiple of the network dt_ms that divides 2 ms. "
        "None = the network dt_ms. Spikes are emitted, and input arriving between two steps takes "
        "effect (with its exactly decayed conductance), at the step boundaries"
    )
    bifixed_substeps: int = Field(
        1, ge=1, description="EDLUT Bifixed: a step that starts with V above (E_L + V_thr)/2 (or whose "
        "one-step estimate ends above it) is integrated as this many equal sub-steps (1 = off)"
    )


class LIFNeuron(Strict):
    """Conductance-based leaky integrate-and-fire neuron (docs/models.md#conductance-lif)."""

    kind: Literal["lif_cond"] = "lif_cond"
    C_m_pF: PositiveFloat = Field(description="membrane capacitance")
    g_L_nS: PositiveFloat = Field(description="leak conductance")
    E_L_mV: float = Field(description="resting (and reset) potential")
    E_AMPA_mV: float = Field(0.0, description="excitatory reversal potential (AMPA and NMDA)")
    E_GABA_mV: float = Field(-80.0, description="inhibitory reversal potential")
    tau_AMPA_ms: PositiveFloat = Field(description="AMPA conductance decay time constant")
    tau_NMDA_ms: PositiveFloat = Field(14.0, description="NMDA conductance decay time constant")
    tau_GABA_ms: PositiveFloat = Field(10.0, description="GABA conductance decay time constant")
    V_thr_mV: float = Field(description="firing threshold")
    t_ref_ms: NonNegFloat = Field(description="refractory period (V held at E_L)")
    clamp_at_rest: bool = Field(
        False, description="clamp V >= E_L (EDLUT models 1_1 used for GC and PC do this)"
    )
    integration: Integration = Field(
        default_factory=Integration,
        description="integration method and step (default: RK4 at the network dt_ms)",
    )

    @model_validator(mode="after")
    def _threshold_above_rest(self) -> LIFNeuron:
        if self.V_thr_mV <= self.E_L_mV:
            raise ValueError(f"V_thr_mV ({self.V_thr_mV}) must be above E_L_mV ({self.E_L_mV})")
        return self


class AdExNeuron(Strict):
    """Adaptive exponential integrate-and-fire neuron with exponential conductances, NEST ``aeif_cond_exp``'s
    definition (docs/models.md#adex). Excitatory input (``ampa`` projections) opens g_ex, inhibitory input
    (``gaba``) g_in; ``nmda`` projections are refused."""

    kind: Literal["adex_cond"] = "adex_cond"
    C_m_pF: PositiveFloat = Field(281.0, description="membrane capacitance")
    g_L_nS: PositiveFloat = Field(30.0, description="leak conductance")
    E_L_mV: float = Field(-70.6, description="leak reversal (resting) potential")
    V_th_mV: float = Field(-50.4, description="spike initiation threshold (centre of the exponential term)")
    Delta_T_mV: NonNegFloat = Field(2.0, description="slope factor of the exponential term; 0 = plain LIF with "
                                    "spikes at V_th_mV")
    V_peak_mV: float = Field(0.0, description="spike detection threshold (used when Delta_T_mV > 0)")
    V_reset_mV: float = Field(-60.0, description="reset potential after a spike (V held there for t_ref)")
    t_ref_ms: NonNegFloat = Field(0.0, description="refractory period, rounded to whole integration steps")
    a_nS: float = Field(4.0, description="subthreshold adaptation conductance")
    b_pA: float = Field(80.5, description="spike-triggered adaptation increment of w")
    tau_w_ms: PositiveFloat = Field(144.0, description="adaptation time constant")
    E_ex_mV: float = Field(0.0, description="excitatory reversal potential")
    E_in_mV: float = Field(-85.0, description="inhibitory reversal potential")
    tau_syn_ex_ms: PositiveFloat = Field(0.2, description="excitatory conductance decay time constant")
    tau_syn_in_ms: PositiveFloat = Field(2.0, description="inhibitory conductance decay time constant")
    I_e_pA: float = Field(0.0, description="constant external input current")
    integration: Integration = Field(
        default_factory=Integration,
        description="integration method and step, as for lif_cond (bifixed refinement above (E_L + V_th)/2)",
    )

    EXP_MAX: ClassVar[float] = 60.0
    """Largest (V_peak - V_th) / Delta_T: e^60 times g_L Delta_T stays far inside float32 at any stage value."""

    @model_validator(mode="after")
    def _thresholds(self) -> AdExNeuron:
        if self.V_th_mV <= self.E_L_mV:
            raise ValueError(f"V_th_mV ({self.V_th_mV}) must be above E_L_mV ({self.E_L_mV})")
        if self.Delta_T_mV > 0:
            if self.V_peak_mV <= self.V_th_mV:
                raise ValueError(f"V_peak_mV ({self.V_peak_mV}) must be above V_th_mV ({self.V_th_mV})")
            ratio = (self.V_peak_mV - self.V_th_mV) / self.Delta_T_mV
            if ratio > self.EXP_MAX:
                raise ValueError(f"(V_peak_mV - V_th_mV) / Delta_T_mV is {ratio:.4g}, above {self.EXP_MAX:g}: the "
                                 "exponential term overflows at the peak (raise Delta_T_mV or lower V_peak_mV)")
        spike = self.V_peak_mV if self.Delta_T_mV > 0 else self.V_th_mV
        if self.V_reset_mV >= spike:
            raise ValueError(f"V_reset_mV ({self.V_reset_mV}) must be below the spike threshold ({spike})")
        return self


class InputFiber(Strict):
    """A fibre whose spikes are produced by an encoder (mossy or climbing fibre), not integrated."""

    kind: Literal["input"] = "input"


Neuron = Annotated[LIFNeuron | AdExNeuron | InputFiber, Field(discriminator="kind")]


RECEPTORS_OF: dict[str, set[str]] = {"adex_cond": {"ampa", "gaba"}}
"""Receptors a neuron kind takes when it does not take all three (ampa -> g_ex, gaba -> g_in)."""


class Population(Strict):
    """A group of identical neurons, optionally split into per-joint microcomplexes."""

    size: int = Field(gt=0, description="number of neurons")
    neuron: Neuron
    microcomplexes: int = Field(1, gt=0, description="equal blocks (one per joint); must divide size")
    description: str = ""

    @model_validator(mode="after")
    def _blocks_divide(self) -> Population:
        if self.size % self.microcomplexes:
            raise ValueError(
                f"microcomplexes ({self.microcomplexes}) must divide the population size ({self.size})"
            )
        return self


class AllToAll(Strict):
    """Every pre neuron reaches every post neuron: n_pre * n_post synapses."""

    kind: Literal["all_to_all"] = "all_to_all"


class OneToOne(Strict):
    """Pre neuron i reaches post neuron i: n synapses (sizes must be equal)."""

    kind: Literal["one_to_one"] = "one_to_one"


class JointCombinations(Strict):
    """Granular-layer state coding (docs/models.md#network): per joint, the pre population holds ``signals``
    subgroups of ``fibers_per_signal`` fibres; each post neuron takes one fibre from every subgroup
    of its joint, and the post population enumerates all fibers_per_signal**signals combinations.
    """

    kind: Literal["joint_combinations"] = "joint_combinations"
    joints: int = Field(gt=0)
    signals: int = Field(gt=0)
    fibers_per_signal: int = Field(gt=0)


SIGMAS = 5.0
"""A declared synapse count of a random rule must lie within this many binomial standard deviations of the
expectation (at 5 sigma a correct declaration is refused about once in 1.7 million draws)."""


# ---- weight and delay distributions ----
class _Dist(Strict):
    low_clip: float | None = Field(None, description="values below are set to this")
    high_clip: float | None = Field(None, description="values above are set to this")

    def draw(self, rng: np.random.Generator, n: int) -> np.ndarray:
        x = self._draw(rng, n)
        lo = -np.inf if self.low_clip is None else self.low_clip
        hi = np.inf if self.high_clip is None else self.high_clip
        return np.clip(x, lo, hi)

    @property
    def upper(self) -> float:
        """The largest value a draw can take (inf when unbounded)."""
        return np.inf if self.high_clip is None else self.high_clip


class Normal(_Dist):
    """Normal distribution (then clipped)."""

    dist: Literal["normal"] = "normal"
    mean: float
    std: NonNegFloat

    def _draw(self, rng, n):
        return rng.normal(self.mean, self.std, n)


class Uniform(_Dist):
    """Uniform on [low, high) (then clipped)."""

    dist: Literal["uniform"] = "uniform"
    low: float
    high: float

    @model_validator(mode="after")
    def _ordered(self) -> Uniform:
        if self.low > self.high:
            raise ValueError(f"low ({self.low}) is greater than high ({self.high})")
        return self

    def _draw(self, rng, n):
        return rng.uniform(self.low, self.high, n)

    @property
    def upper(self) -> float:
        return min(self.high, super().upper)


class LogNormal(_Dist):
    """exp(N(mu, sigma)) (then clipped)."""

    dist: Literal["lognormal"] = "lognormal"
    mu: float
    sigma: NonNegFloat

    def _draw(self, rng, n):
        return rng.lognormal(self.mu, self.sigma, n)


Distribution = Annotated[Normal | Uniform | LogNormal, Field(discriminator="dist")]


# ---- random and listed connectors (their builders: snn/connectors.py) ----
class FixedIndegree(Strict):
    """Each post neuron receives ``indegree`` synapses from pre neurons drawn at random (NEST fixed_indegree,
    PyNN FixedNumberPreConnector): indegree * n_post synapses."""

    kind: Literal["fixed_indegree"] = "fixed_indegree"
    indegree: int = Field(gt=0, description="synapses per post neuron")
    allow_autapses: bool = Field(True, description="a neuron may connect to itself (pre and post one population)")
    allow_multapses: bool = Field(False, description="a pair may be drawn twice (two synapses)")

    def synapse_count(self, n_pre: int, n_post: int, same: bool) -> tuple[float, float]:
        _room(self.indegree, n_pre, same and not self.allow_autapses, self.allow_multapses, "indegree", "pre")
        return float(self.indegree * n_post), 0.0


class FixedOutdegree(Strict):
    """Each pre neuron makes ``outdegree`` synapses onto post neurons drawn at random (NEST fixed_outdegree,
    PyNN FixedNumberPostConnector): outdegree * n_pre synapses."""

    kind: Literal["fixed_outdegree"] = "fixed_outdegree"
    outdegree: int = Field(gt=0, description="synapses per pre neuron")
    allow_autapses: bool = Field(True, description="a neuron may connect to itself (pre and post one population)")
    allow_multapses: bool = Field(False, description="a pair may be drawn twice (two synapses)")

    def synapse_count(self, n_pre: int, n_post: int, same: bool) -> tuple[float, float]:
        _room(self.outdegree, n_post, same and not self.allow_autapses, self.allow_multapses, "outdegree", "post")
        return float(self.outdegree * n_pre), 0.0


class FixedProbability(Strict):
    """Every (pre, post) pair is connected with probability ``p``, independently (NEST pairwise_bernoulli, PyNN
    FixedProbabilityConnector). The count is random: the declared ``synapses`` must be within 5 binomial
    standard deviations of the expectation; the built count is recorded in the run's summary."""

    kind: Literal["fixed_probability"] = "fixed_probability"
    p: float = Field(gt=0, le=1, description="connection probability per pair")
    allow_autapses: bool = Field(True, description="a neuron may connect to itself (pre and post one population)")

    def synapse_count(self, n_pre: int, n_post: int, same: bool) -> tuple[float, float]:
        pairs = n_pre * n_post - (min(n_pre, n_post) if same and not self.allow_autapses else 0)
        return pairs * self.p, SIGMAS * float(np.sqrt(pairs * self.p * (1 - self.p)))


class FromFile(Strict):
    """Synapses listed in an ``.npz`` file: int arrays ``pre`` and ``post`` (local indices), optionally
    ``weight_nS`` and ``delay_ms`` per synapse (they replace the projection's weight and delay). A relative path
    is taken from the working directory. Checked at validation: the file exists and every index is in range."""

    kind: Literal["from_file"] = "from_file"
    path: str = Field(description=".npz file with arrays pre, post [, weight_nS, delay_ms]")

    def arrays(self) -> dict[str, np.ndarray]:
        path = Path(self.path).expanduser()
        if not path.is_file():
            raise ValueError(f"path: {self.path} does not exist (relative paths start at {Path.cwd()})")
        with np.load(path, allow_pickle=False) as f:
            data = {k: f[k] for k in f.files}
        missing = [k for k in ("pre", "post") if k not in data]
        if missing:
            raise ValueError(f"path: {self.path} has no array {', '.join(missing)}")
        extra = sorted(set(data) - {"pre", "post", "weight_nS", "delay_ms"})
        if extra:
            raise ValueError(f"path: {self.path}: unknown arrays {', '.join(extra)}")
        n = len(data["pre"])
        for k, a in data.items():
            if a.ndim != 1 or len(a) != n:
                raise ValueError(f"path: {self.path}: {k} must be one-dimensional with {n} entries like pre")
        for k in ("pre", "post"):
            if not np.issubdtype(data[k].dtype, np.integer):
                raise ValueError(f"path: {self.path}: {k} must hold integers, not {data[k].dtype}")
        if "weight_nS" in data and (~np.isfinite(data["weight_nS"]) | (data["weight_nS"] < 0)).any():
            raise ValueError(f"path: {self.path}: weight_nS must be finite and >= 0")
        if "delay_ms" in data and (~np.isfinite(data["delay_ms"]) | (data["delay_ms"] <= 0)).any():
            raise ValueError(f"path: {self.path}: delay_ms must be finite and > 0")
        return data

    def synapse_count(self, n_pre: int, n_post: int, same: bool) -> tuple[float, float]:
        data = self.arrays()
        for k, n in (("pre", n_pre), ("post", n_post)):
            a = data[k]
            if len(a) and (a.min() < 0 or a.max() >= n):
                raise ValueError(f"path: {self.path}: {k} indices must be in [0, {n}), found "
                                 f"[{a.min()}, {a.max()}]")
        return float(len(data["pre"])), 0.0


def _room(k: int, n: int, no_self: bool, multapses: bool, what: str, side: str) -> None:
    room = n - (1 if no_self else 0)
    if not multapses and k > room:
        raise ValueError(f"{what} {k} is more than the {room} distinct {side} neurons (allow_multapses: true, or "
                         f"a smaller {what})")
    if room < 1:
        raise ValueError(f"{what}: no {side} neuron to draw from")


Rule = Plugin("connector")
"""Any registered connector kind (``registry.connectors``): those above (their builders: snn/topology.py for the
first three, snn/connectors.py) and a plugin's."""


# ---- learning rules of sparse projections (their engine form: snn/plasticity.py) ----
class PairSTDP(Strict):
    """Pair-based STDP, NEST ``stdp_synapse`` (Gütig et al. 2003 form; docs/models.md#pair-stdp): all-to-all
    pairing through a presynaptic trace (tau_plus) and a postsynaptic one (tau_minus, in NEST a parameter of the
    post neuron). Weights bounded by the projection's ``weight_range_nS`` (W = its upper end)."""

    kind: Literal["pair_stdp"] = "pair_stdp"
    added_without_effect: ClassVar[dict[str, Any]] = {"delay": "axonal"}
    """Fields added after runs were recorded, with the value that computes what those runs did
    (``schema/legacy.py``)."""
    lam: PositiveFloat = Field(0.01, description="NEST lambda: step size of potentiation")
    alpha: NonNegFloat = Field(1.0, description="depression / potentiation ratio")
    mu_plus: NonNegFloat = Field(1.0, description="weight dependence exponent of potentiation (0: additive)")
    mu_minus: NonNegFloat = Field(1.0, description="weight dependence exponent of depression (0: additive)")
    tau_plus_ms: PositiveFloat = Field(20.0, description="presynaptic trace time constant")
    tau_minus_ms: PositiveFloat = Field(20.0, description="postsynaptic trace time constant (NEST: the neuron's)")
    delay: Literal["axonal", "dendritic"] = Field(
        "axonal", description="where the projection's delay d sits for the pairing: axonal (a pre spike pairs "
        "on arrival with the post neuron's spikes as they happen: Δt = t_post − t_pre − d) or dendritic (NEST "
        "stdp_synapse: the post spike reaches the synapse d later: Δt = t_post − t_pre + d)")


class SymmetricCos(Strict):
    """MF–DCN rule of the distributed-plasticity models (docs/models.md#symmetric-cos): a fixed change per pre
    spike, and a change scaled by a symmetric cosine kernel of the time to each teaching spike (PC spikes
    arriving at the DCN): EDLUT SimetricCosAdditiveKernel, NEST stdp_cos_synapse."""

    kind: Literal["symmetric_cos"] = "symmetric_cos"
    fixed_nS: float = Field(0.001, description="change at each pre spike (EDLUT fixed_change; > 0: LTP)")
    kernel_nS: float = Field(-0.010, description="scale of the kernel term (EDLUT kernel_change; < 0: LTD)")
    tau_ms: PositiveFloat = Field(100.0, description="kernel half-width: k = 0 at |Δ| >= tau")
    n: NonNegFloat = Field(2.0, description="exponential sharpening of the kernel")
    teacher: str = Field(description="projection whose arrivals at the post neuron pair with the pre spikes")


class SymmetricCosSTDP(Strict):
    """PC–DCN rule of the distributed-plasticity models (docs/models.md#symmetric-cos): as ``symmetric_cos``
    with the post neuron's own spikes as the partner (EDLUT SimetricCosSTDPAdditiveKernel)."""

    kind: Literal["symmetric_cos_stdp"] = "symmetric_cos_stdp"
    fixed_nS: float = Field(0.001, description="change at each pre spike (EDLUT fixed_change)")
    kernel_nS: float = Field(-0.010, description="scale of the kernel term (EDLUT kernel_change)")
    tau_ms: PositiveFloat = Field(100.0, description="kernel half-width: k = 0 at |Δ| >= tau")
    n: NonNegFloat = Field(2.0, description="exponential sharpening of the kernel")


class KernelSTDP(Strict):
    """PF-PC plasticity (docs/models.md#kernel-stdp).

    LTP: +ltp_nS per presynaptic spike. LTD: at each teacher (CF) spike, ltd_nS * k(t_CF - t_PF)
    for every buffered PF spike, with k = 0 before the onset and k = (t'/tau) e^(1 - t'/tau),
    t' = t - onset, tau = peak - onset, so k(peak) = 1.
    """

    kind: Literal["kernel_stdp"] = "kernel_stdp"
    ltp_nS: NonNegFloat = Field(0.002, description="alpha: increment per PF spike")
    ltd_nS: float = Field(-0.0008, le=0, description="beta: scale of the decrement at a CF spike")
    kernel_peak_ms: PositiveFloat = Field(150.0, description="tau_LTD: time of the kernel maximum")
    kernel_onset_ms: NonNegFloat = Field(120.0, description="d_k: kernel is zero before this")
    kernel_cutoff: float = Field(0.01, gt=0, lt=1, description="kernel values below this are dropped")
    teacher: str = Field(description="name of the projection whose spikes trigger LTD (CF->PC)")

    @model_validator(mode="after")
    def _peak_after_onset(self) -> KernelSTDP:
        if self.kernel_peak_ms <= self.kernel_onset_ms:
            raise ValueError(
                f"kernel_peak_ms ({self.kernel_peak_ms}) must be greater than "
                f"kernel_onset_ms ({self.kernel_onset_ms})"
            )
        return self


class Projection(Strict):
    """Synapses from one population to another (one row of a network table)."""

    pre: str
    post: str
    rule: Rule = Field(description="connection rule (a registered connector kind)")
    receptor: Literal["ampa", "nmda", "gaba"]
    synapses: int = Field(gt=0, description="declared synapse count; must match the rule")
    weight_nS: NonNegFloat | Distribution = Field(
        description="initial weight: a constant, or a distribution ({dist: normal, mean, std} ...) drawn per "
        "synapse and clipped to weight_range_nS (else to >= 0)")
    weight_range_nS: tuple[NonNegFloat, NonNegFloat] | None = Field(
        None, description="[min, max] for plastic synapses"
    )
    delay_ms: PositiveFloat | Distribution = Field(
        1.0, description="synaptic delay: a constant (a multiple of dt_ms), or a distribution drawn per synapse, "
        "rounded to whole steps of dt_ms, at least one step")
    plasticity: Plugin("plasticity") | None = Field(None, description="learning rule (a registered kind)")
    teaching: bool = Field(False, description="carries a teaching signal only (no current)")

    @model_validator(mode="after")
    def _weights_in_range(self) -> Projection:
        if self.weight_range_nS is not None:
            lo, hi = self.weight_range_nS
            if lo > hi:
                raise ValueError(f"weight_range_nS min ({lo}) is greater than max ({hi})")
            if isinstance(self.weight_nS, float) and not lo <= self.weight_nS <= hi:
                raise ValueError(f"initial weight_nS ({self.weight_nS}) is outside weight_range_nS {[lo, hi]}")
        if self.plasticity is not None and self.weight_range_nS is None:
            raise ValueError("a plastic projection needs weight_range_nS")
        return self


class NetworkIO(Strict):
    """Which populations the encoders drive and the decoder reads."""

    mossy: str = "mf"
    climbing: str = "cf"
    output: str = "dcn"
    purkinje: list[str] = Field(default_factory=lambda: ["pc"])
    granule: str = "gc"


class NetworkConfig(Strict):
    """A whole cerebellar network: named populations and projections."""

    name: str
    dt_ms: PositiveFloat = Field(0.5, description="neuron integration step (divides 2 ms and the delays)")
    neurons: dict[str, LIFNeuron] = Field(
        default_factory=dict, description="named parameter sets that populations refer to"
    )
    populations: dict[str, Population]
    projections: dict[str, Projection]
    io: NetworkIO = NetworkIO()

    @model_validator(mode="after")
    def _consistent(self) -> NetworkConfig:
        problems: list[str] = []
        pops = self.populations
        for name, p in self.projections.items():
            where = f"projections.{name}"
            missing = [end for end in (p.pre, p.post) if end not in pops]
            if missing:
                problems.append(f"{where}: unknown population {', '.join(map(repr, missing))}")
                continue
            n_pre, n_post = pops[p.pre].size, pops[p.post].size
            expected = _rule_count(p.rule, n_pre, n_post, where, problems, p.pre == p.post)
            if isinstance(expected, tuple):
                mean, bound = expected
                if abs(p.synapses - mean) > bound:
                    problems.append(
                        f"{where}.synapses: declared {p.synapses:,} but rule {p.rule.kind} gives "
                        f"{mean:,.1f} ± {bound:,.1f} (5 sigma) for {n_pre:,} {p.pre} -> {n_post:,} {p.post}")
            elif expected is not None and expected != p.synapses:
                problems.append(
                    f"{where}.synapses: declared {p.synapses:,} but rule {p.rule.kind} gives "
                    f"{expected:,} for {n_pre:,} {p.pre} -> {n_post:,} {p.post}"
                )
            if isinstance(p.delay_ms, float) and abs(p.delay_ms / self.dt_ms - round(p.delay_ms / self.dt_ms)) > 1e-9:
                problems.append(f"{where}.delay_ms: {p.delay_ms} is not a multiple of dt_ms {self.dt_ms}")
            if p.plasticity is not None:
                problems += _plasticity_problems(where, p, self.projections)
        io = self.io
        for field, name in [("mossy", io.mossy), ("climbing", io.climbing), ("output", io.output),
                            ("granule", io.granule), *[("purkinje", n) for n in io.purkinje]]:
            if name not in pops:
                problems.append(f"io.{field}: unknown population {name!r}")
        if 2.0 / self.dt_ms != int(2.0 / self.dt_ms):
            problems.append(f"dt_ms: {self.dt_ms} does not divide the 2 ms control step")
        if problems:
            raise ValueError("; ".join(problems))
        return self

    @model_validator(mode="after")
    def _receptors_of_the_model(self) -> NetworkConfig:
        """A neuron model takes only the receptors it has (adex_cond: no NMDA)."""
        for name, p in self.projections.items():
            post = self.populations.get(p.post)
            takes = RECEPTORS_OF.get(post.neuron.kind) if post is not None else None
            if takes is not None and not p.teaching and p.receptor not in takes:
                raise ValueError(f"projections.{name}.receptor: {p.post!r} is a {post.neuron.kind} population, "
                                 f"which takes {' or '.join(sorted(takes))}, not {p.receptor!r}")
        return self

    def fingerprint(self) -> str:
        """Hash of what shapes the state arrays (sizes, rules, receptors), not of weights or kernels,
        so a learned state can be reloaded under a different learning-rule setting."""
        shape = {
            "dt_ms": self.dt_ms,
            "pops": {k: [p.size, p.neuron.kind] for k, p in self.populations.items()},
            "proj": {
                k: [p.pre, p.post, p.rule.model_dump(), p.receptor, p.synapses, p.plasticity is not None]
                for k, p in self.projections.items()
            },
        }
        return hashlib.sha256(json.dumps(shape, sort_keys=True).encode()).hexdigest()[:16]

    def layout(self) -> dict[str, list[str]]:
        """The order of the populations and projections, which the state arrays follow (neurons by population,
        weights by projection) and :meth:`fingerprint` leaves out; a learned state records it beside the
        fingerprint (:func:`layout_problem`)."""
        return {"populations": list(self.populations), "projections": list(self.projections)}

    @property
    def n_neurons(self) -> int:
        return sum(p.size for p in self.populations.values())

    @property
    def n_synapses(self) -> int:
        return sum(p.synapses for p in self.projections.values())

    @property
    def n_plastic(self) -> int:
        return sum(p.synapses for p in self.projections.values() if p.plasticity is not None)


def layout_problem(saved: Any, cfg: NetworkConfig) -> str | None:
    """Why a state whose metadata recorded the layout ``saved`` (:meth:`NetworkConfig.layout`) cannot be loaded
    into ``cfg`` of the same fingerprint: its arrays follow another order of populations or projections. A state
    saved before the layout was recorded (``saved`` None) is taken as before, in ``cfg``'s order."""
    if saved is None:
        return None
    want = cfg.layout()
    for key in ("populations", "projections"):
        if list(saved.get(key, want[key])) != want[key]:
            return (f"was saved with its {key} in the order {', '.join(saved[key])}, which its arrays follow, but "
                    f"network {cfg.name!r} lists them as {', '.join(want[key])}: list them in the saved order")
    return None


def _plasticity_problems(where: str, p: Projection, projections: dict[str, Projection]) -> list[str]:
    """What the network engine refuses of a plastic projection (``snn/topology.py``). ``kernel_stdp`` learns on a
    dense (all_to_all, current-carrying, constant delay and weight) projection, taught by a sparse one that targets
    the same population; every other rule runs on any current-carrying projection (built sparse), its teacher (if
    any) targeting the same population."""
    if not isinstance(p.plasticity, KernelSTDP):
        return _sparse_rule_problems(where, p, projections)
    out = []
    if not isinstance(p.rule, AllToAll):
        out.append(f"{where}: plasticity is supported on all_to_all projections only")
    elif not isinstance(p.delay_ms, float):
        out.append(f"{where}.delay_ms: kernel_stdp needs one delay (a constant delay_ms)")
    elif p.teaching:
        out.append(f"{where}: plasticity is supported on all_to_all projections only, not on a teaching one")
    name = p.plasticity.teacher  # type: ignore[union-attr]
    teacher = projections.get(name)
    if teacher is None:
        out.append(f"{where}.plasticity.teacher: unknown projection {name!r}")
    elif teacher.post != p.post:
        out.append(f"{where}.plasticity.teacher: {name!r} targets {teacher.post!r}, not {p.post!r}")
    elif isinstance(teacher.rule, AllToAll) and not teacher.teaching:
        out.append(f"{where}.plasticity.teacher: {name!r} must be a one_to_one or joint_combinations projection "
                   "(or a teaching one)")
    elif not isinstance(teacher.delay_ms, float):
        out.append(f"{where}.plasticity.teacher: {name!r} must have one delay (a constant delay_ms)")
    return out


def _sparse_rule_problems(where: str, p: Projection, projections: dict[str, Projection]) -> list[str]:
    out = []
    if p.teaching:
        out.append(f"{where}.plasticity: a teaching projection carries no current to learn (teaching: false)")
    if p.weight_range_nS is not None and p.weight_range_nS[1] <= 0:
        out.append(f"{where}.weight_range_nS: a plastic projection needs an upper weight bound above 0")
    name = getattr(p.plasticity, "teacher", None)
    if name is not None:
        teacher = projections.get(name)
        if teacher is None:
            out.append(f"{where}.plasticity.teacher: unknown projection {name!r}")
        elif teacher.post != p.post:
            out.append(f"{where}.plasticity.teacher: {name!r} targets {teacher.post!r}, not {p.post!r}")
        elif isinstance(teacher.plasticity, KernelSTDP):
            out.append(f"{where}.plasticity.teacher: {name!r} learns with kernel_stdp on a dense block, which "
                       "cannot teach a sparse rule")
    return out


def _rule_count(rule, n_pre: int, n_post: int, where: str, problems: list[str],
                same: bool = False) -> int | tuple[float, float] | None:
    """The synapse count of ``rule``: exact (int), (expectation, tolerance) for a random rule, None (a problem
    was appended) when the rule cannot connect these sizes."""
    if hasattr(rule, "synapse_count"):
        try:
            mean, bound = rule.synapse_count(n_pre, n_post, same)
        except ValueError as err:
            problems.append(f"{where}.rule.{err}" if isinstance(rule, FromFile) else f"{where}.rule: {err}")
            return None
        return int(round(mean)) if bound == 0 else (mean, bound)
    if isinstance(rule, AllToAll):
        return n_pre * n_post
    if isinstance(rule, OneToOne):
        if n_pre != n_post:
            problems.append(f"{where}.rule: one_to_one needs equal sizes, got {n_pre} -> {n_post}")
            return None
        return n_pre
    if not isinstance(rule, JointCombinations):
        problems.append(f"{where}.rule: connector kind {rule.kind!r} has no synapse_count (its plugin must give one)")
        return None
    r: JointCombinations = rule
    want_pre = r.joints * r.signals * r.fibers_per_signal
    want_post = r.joints * r.fibers_per_signal**r.signals
    if n_pre != want_pre or n_post != want_post:
        problems.append(
            f"{where}.rule: joint_combinations({r.joints} joints, {r.signals} signals, "
            f"{r.fibers_per_signal} fibres) needs {want_pre} pre and {want_post} post neurons, "
            f"got {n_pre} and {n_post}"
        )
        return None
    return n_post * r.signals


# ---- the encoders' schemas (their code: snn/encoders.py) ----

class BoxEncoder(Strict):
    """MF interval coding (Eq. 2.12-2.15): per signal, 10 fibres with box receptive fields;
    the active fibre fires once per 2 ms step."""

    role: ClassVar[str] = "mossy"

    kind: Literal["box"] = "box"
    fibers_per_signal: int = Field(10, gt=1)
    width_factor: PositiveFloat = Field(0.500000000001, description="half-width in units of the centre step")
    ranges: Annotated[GivenRanges | TaskRanges, Field(discriminator="kind")] = TaskRanges()


class PoissonEncoder(Strict):
    """MF rate coding (docs/models.md#mf-poisson-coding): per joint and signal, fibres with Gaussian (or box)
    receptive fields over the signal's range; each fires in a 2 ms step with probability rate x 2 ms,
    rate = rate_min_hz + (rate_max_hz - rate_min_hz) RF(value), from the run's seeded generator."""

    role: ClassVar[str] = "mossy"

    kind: Literal["poisson"] = "poisson"
    fibers_per_signal: int = Field(10, gt=1)
    field: Literal["gaussian", "box"] = Field(
        "gaussian", description="receptive field: gaussian exp(-z^2/2), or box 1 for |z| < 1, with z = "
        "(value - centre) / (width_factor x centre step)")
    width_factor: PositiveFloat = Field(1.0, description="gaussian sigma, or box half-width, in centre steps")
    rate_min_hz: NonNegFloat = Field(0.0, description="rate far from the receptive field")
    rate_max_hz: float = Field(100.0, gt=0, le=500, description="rate at the centre (at most one spike per "
                               "2 ms step: 500 Hz)")
    ranges: Annotated[GivenRanges | TaskRanges, Field(discriminator="kind")] = TaskRanges()

    @model_validator(mode="after")
    def _rates(self) -> PoissonEncoder:
        if self.rate_min_hz >= self.rate_max_hz:
            raise ValueError(f"rate_min_hz ({self.rate_min_hz}) must be below rate_max_hz ({self.rate_max_hz})")
        return self


class CFEncoder(Strict):
    """CF stochastic error coding (docs/models.md#cf-error-coding): agonist/antagonist split by error sign;
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
