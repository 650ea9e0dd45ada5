"""What each cerebx kind becomes in NEST 3.10 and PyNN 0.13, one registry entry per kind.

Three registries, keyed by the ``kind`` of the network schema:

- :data:`NEURONS`: neuron kind -> :class:`NeuronMap` (NEST and PyNN model, parameter translation, receptors, the
  checks of what the model cannot do) or :class:`Refused`.
- :data:`CONNECTORS`: connection-rule kind -> the NEST/PyNN rule that draws the same *kind* of wiring. The export
  never re-draws: it writes the synapses cerebx built (``snn/topology.py``), so an entry only documents the
  equivalent rule; a rule without an entry is refused, so a new kind is exported only once someone has looked.
- :data:`PLASTICITY`: plasticity kind -> :class:`PlasticityMap` (NEST synapse model and parameters) or
  :class:`Refused` (then ``--static`` exports the current weights as static synapses, with a note).

:func:`plan` applies them to a network: the model and parameters of each population, the receptor and sign of each
projection, the notes on what differs, and the problems (refusals), each one line naming the kind.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from cerebx import registry
from cerebx.snn.schema import LIFNeuron, NetworkConfig


@dataclass(frozen=True)
class Refused:
    """A kind the target simulator cannot express, and why (one line).

    Attributes
    ----------
    reason : str
        Why, named in the export's one-line refusal.
    """

    reason: str


@dataclass(frozen=True)
class NeuronMap:
    """One neuron kind in NEST and PyNN.

    Attributes
    ----------
    nest_model, pynn_model : str
        The NEST model and the PyNN cell type.
    nest_params, pynn_params : callable
        ``(neuron, h_ms) -> dict``: the model's parameters from the neuron's schema (``h_ms``: its integration
        step); NEST takes pF, nS, mV, ms and PyNN nF, µS, mV, ms.
    receptors : dict
        cerebx receptor -> (PyNN receptor type, sign of the NEST weight), or :class:`Refused`.
    check : callable or None
        ``(neuron, receptors_in, h_ms) -> (problems, notes)``: what the model does not do (``receptors_in``: the
        receptors the population's current-carrying inputs use).
    """

    nest_model: str
    pynn_model: str
    nest_params: Callable[[Any, float], dict[str, float]]
    pynn_params: Callable[[Any, float], dict[str, float]]
    receptors: dict[str, tuple[str, int] | Refused] = field(default_factory=dict)
    check: Callable[[Any, set[str], float], tuple[list[str], list[str]]] | None = None


@dataclass(frozen=True)
class PlasticityMap:
    """A plasticity kind as a NEST synapse model and a PyNN synapse type.

    Attributes
    ----------
    nest_synapse, pynn_synapse : str
        The NEST synapse model and the PyNN synapse type.
    nest_params : callable
        ``(rule, w_max) -> dict``: the synapse model's parameters (``w_max``: the projection's upper weight bound
        in nS, with the sign of its NEST weights).
    post_params : callable or None
        ``rule -> dict``: parameters the rule sets on the post neuron (NEST keeps some there, e.g. ``tau_minus``).
    check : callable or None
        ``(rule, projection) -> (problems, notes)``: what the NEST model computes differently.
    """

    nest_synapse: str
    pynn_synapse: str
    nest_params: Callable[[Any, float], dict[str, float]]
    post_params: Callable[[Any], dict[str, float]] | None = None
    check: Callable[[Any, Any], tuple[list[str], list[str]]] | None = None


def _t_ref(nrn: LIFNeuron, h: float) -> float:
    """The refractory time cerebx applies: t_ref rounded to whole integration steps h."""
    return round(nrn.t_ref_ms / h) * h


def _iaf_nest(nrn: LIFNeuron, h: float) -> dict[str, float]:
    return {"C_m": nrn.C_m_pF, "g_L": nrn.g_L_nS, "E_L": nrn.E_L_mV, "V_reset": nrn.E_L_mV, "V_m": nrn.E_L_mV,
            "V_th": nrn.V_thr_mV, "t_ref": _t_ref(nrn, h), "E_ex": nrn.E_AMPA_mV, "E_in": nrn.E_GABA_mV,
            "tau_syn_ex": nrn.tau_AMPA_ms, "tau_syn_in": nrn.tau_GABA_ms, "I_e": 0.0}


def _iaf_pynn(nrn: LIFNeuron, h: float) -> dict[str, float]:
    """PyNN's standard cell takes nF, ms, mV, nA (NEST takes pF and nS)."""
    return {"cm": nrn.C_m_pF / 1000.0, "tau_m": nrn.C_m_pF / nrn.g_L_nS, "v_rest": nrn.E_L_mV,
            "v_reset": nrn.E_L_mV, "v_thresh": nrn.V_thr_mV, "tau_refrac": _t_ref(nrn, h),
            "e_rev_E": nrn.E_AMPA_mV, "e_rev_I": nrn.E_GABA_mV, "tau_syn_E": nrn.tau_AMPA_ms,
            "tau_syn_I": nrn.tau_GABA_ms, "i_offset": 0.0}


def _iaf_check(nrn: LIFNeuron, receptors_in: set[str], h: float) -> tuple[list[str], list[str]]:
    """What cerebx's lif_cond does that iaf_cond_exp does not, as refusals or notes."""
    problems, notes = [], []
    reversal = {"ampa": nrn.E_AMPA_mV, "nmda": nrn.E_AMPA_mV, "gaba": nrn.E_GABA_mV}
    if nrn.clamp_at_rest:
        below = sorted(r for r in receptors_in if reversal[r] < nrn.E_L_mV)
        if below:
            problems.append(f"clamp_at_rest with {'/'.join(below)} input (reversal below E_L): iaf_cond_exp does "
                            "not clamp V >= E_L")
        else:
            notes.append("clamp_at_rest has no effect here (every input reverses above E_L, so V stays >= E_L)")
    if abs(_t_ref(nrn, h) - nrn.t_ref_ms) > 1e-9:
        notes.append(f"t_ref {nrn.t_ref_ms} ms is exported as {_t_ref(nrn, h)} ms (cerebx rounds it to whole "
                     f"{h} ms steps)")
    integ = nrn.integration
    fixed = f"{integ.method} at {h} ms" + (f", bifixed {integ.bifixed_substeps}" if integ.bifixed_substeps > 1
                                           else "")
    notes.append(f"integrator: cerebx {fixed}; NEST adaptive RKF45 (abs. error 1e-3 mV) within each "
                 "resolution step (docs: cerebx and NEST)")
    return problems, notes


def _stdp_nest(rule: Any, w_max: float) -> dict[str, float]:
    return {"lambda": rule.lam, "alpha": rule.alpha, "mu_plus": rule.mu_plus, "mu_minus": rule.mu_minus,
            "tau_plus": rule.tau_plus_ms, "Wmax": w_max}


def _stdp_check(rule: Any, proj: Any) -> tuple[list[str], list[str]]:
    """stdp_synapse's delay is dendritic and its weights are bounded below by 0."""
    problems = []
    if rule.delay != "dendritic":
        problems.append("delay: axonal pairs Δt = t_post − t_pre − d, NEST's stdp_synapse t_post − t_pre + d (NEST "
                        "3.10 has no axonal delay for it): set delay: dendritic to compute NEST's rule")
    w_lo = proj.weight_range_nS[0]
    if w_lo != 0.0:
        problems.append(f"weight_range_nS starts at {w_lo} nS: stdp_synapse bounds weights at 0")
    return problems, []


NEURONS: dict[str, NeuronMap | Refused] = {
    "lif_cond": NeuronMap(
        "iaf_cond_exp", "IF_cond_exp", _iaf_nest, _iaf_pynn,
        receptors={"ampa": ("excitatory", 1), "gaba": ("inhibitory", -1),
                   "nmda": Refused("iaf_cond_exp has no NMDA receptor with Mg block (no standard NEST model has "
                                   "an exponential NMDA conductance; iaf_bw_2001's saturates)")},
        check=_iaf_check),
    "input": NeuronMap("spike_train_injector", "SpikeSourceArray", lambda n, h: {}, lambda n, h: {}),
}
"""Neuron kind -> its NEST and PyNN model (or why there is none)."""

CONNECTORS: dict[str, str] = {
    "all_to_all": "all_to_all / AllToAllConnector (exported with cerebx's weight matrix)",
    "one_to_one": "one_to_one / OneToOneConnector (exported as the synapse list)",
    "joint_combinations": "no NEST rule (exported as the synapse list: one_to_one over arrays / FromListConnector)",
    "fixed_indegree": "fixed_indegree / FixedNumberPreConnector (exported as the synapse list cerebx drew)",
    "fixed_outdegree": "fixed_outdegree / FixedNumberPostConnector (exported as the synapse list cerebx drew)",
    "fixed_probability": "pairwise_bernoulli / FixedProbabilityConnector (exported as the synapse list cerebx drew)",
    "from_file": "one_to_one over arrays / FromListConnector (exported as the file's synapse list)",
}
"""Connection-rule kind -> the equivalent NEST / PyNN rule (the export writes cerebx's built synapses either way)."""

PLASTICITY: dict[str, PlasticityMap | Refused] = {
    "kernel_stdp": Refused("CF-gated kernel LTD with LTP per PF spike has no NEST 3.10 synapse model "
                           "(stdp_dopamine_synapse only loosely approximates it)"),
    "symmetric_cos": Refused("a cosine kernel over the times to a teaching projection's arrivals has no NEST 3.10 "
                             "synapse model (stdp_cos_synapse belongs to an extension module, not to NEST)"),
    "symmetric_cos_stdp": Refused("a cosine kernel over the times to the post neuron's spikes has no NEST 3.10 "
                                  "synapse model (its STDP windows are exponential)"),
    "pair_stdp": PlasticityMap("stdp_synapse", "STDPMechanism(SpikePairRule, GutigWeightDependence)", _stdp_nest,
                               post_params=lambda rule: {"tau_minus": rule.tau_minus_ms}, check=_stdp_check),
}
"""Plasticity kind -> its NEST synapse model (or why there is none)."""


def register(table: dict[str, Any], kind: str, entry: Any) -> None:
    """Add ``kind`` to one of the registries above; a kind is registered once."""
    if kind in table:
        raise ValueError(f"export mapping for kind {kind!r} is already registered")
    table[kind] = entry


GROUPS: dict[str, dict[str, Any]] = {"neurons": NEURONS, "connectors": CONNECTORS, "plasticity": PLASTICITY}
"""The registries by group name, as :func:`register_export` takes them."""


def register_export(group: str, kind: str, entry: NeuronMap | PlasticityMap | Refused | str) -> None:
    """Say what a plugin's kind becomes in NEST and PyNN (``cerebx export``, ``cerebx crosscheck``), from the
    plugin's ``register()``: ``group`` ``"neurons"`` (a :class:`NeuronMap`), ``"plasticity"`` (a
    :class:`PlasticityMap`) or ``"connectors"`` (the equivalent NEST / PyNN rule, a string: the export writes the
    synapses cerebx drew either way); :class:`Refused` says why it has no counterpart (the export then names it
    in its one-line refusal). A kind without an entry is refused as unmapped; a kind is registered once.

    Parameters
    ----------
    group : str
        ``"neurons"``, ``"connectors"`` or ``"plasticity"``.
    kind : str
        The kind's name, as its schema's ``kind`` field.
    entry : NeuronMap, PlasticityMap, Refused or str
        What the kind becomes (a string: the equivalent connection rule's name).
    """
    table = GROUPS.get(group)
    if table is None:
        raise ValueError(f"export mapping group {group!r} is not one of {', '.join(GROUPS)}")
    want = {"neurons": NeuronMap, "plasticity": PlasticityMap, "connectors": str}[group]
    if not isinstance(entry, (want, Refused)):
        raise TypeError(f"export mapping of {group} kind {kind!r}: a {want.__name__} or Refused, not "
                        f"{type(entry).__name__}")
    register(table, kind, entry)


@dataclass
class PopulationPlan:
    kind: str
    size: int
    nest_model: str
    pynn_model: str
    nest_params: dict[str, float]
    pynn_params: dict[str, float]


@dataclass
class ProjectionPlan:
    pre: str
    post: str
    receptor: str
    sign: int  # of the NEST weight (iaf_cond_exp: negative = inhibitory)
    pynn_receptor: str
    delay_ms: float
    synapse: str  # NEST synapse model it copies
    synapse_params: dict[str, float]
    rule: str
    plastic: bool  # plastic in cerebx, exported static


@dataclass
class Plan:
    """A network as NEST / PyNN will build it: every population and exported projection, the projections left
    out, what differs (notes) and what cannot be expressed (problems: the export refuses while there are any)."""

    resolution_ms: float
    populations: dict[str, PopulationPlan]
    projections: dict[str, ProjectionPlan]
    dropped: dict[str, str]
    notes: list[str]
    problems: list[str]


def _integration_step(nrn: Any, dt: float) -> float:
    integ = getattr(nrn, "integration", None)
    return integ.dt_ms if integ is not None and integ.dt_ms is not None else dt


def plan(cfg: NetworkConfig, static: bool = False, approximate: bool = False) -> Plan:
    """Map ``cfg`` through the registries. ``static``: a plastic projection whose rule NEST cannot express is
    exported with static weights (a note), not refused. ``approximate``: a receptor the model lacks (NMDA) is
    left out and a check's refusal becomes a note, each said in ``notes``."""
    registry.load_plugins()  # a plugin's register() adds its kinds' entries (register_export)
    dt = cfg.dt_ms
    problems: list[str] = []
    notes: list[str] = []
    receptors_in: dict[str, set[str]] = {n: set() for n in cfg.populations}
    for p in cfg.projections.values():
        if not p.teaching:
            receptors_in[p.post].add(p.receptor)
    pops: dict[str, PopulationPlan] = {}
    maps: dict[str, NeuronMap] = {}
    for name, pop in cfg.populations.items():
        nrn = pop.neuron
        entry = NEURONS.get(nrn.kind)
        where = f"populations.{name}.neuron"
        if entry is None:
            problems.append(f"{where}: kind {nrn.kind!r} has no NEST/PyNN mapping (cerebx/export/mapping.py)")
            continue
        if isinstance(entry, Refused):
            problems.append(f"{where}: kind {nrn.kind!r} cannot be expressed: {entry.reason}")
            continue
        h = _integration_step(nrn, dt)
        if entry.check is not None:
            bad, said = entry.check(nrn, receptors_in[name], h)
            notes += [f"{where} ({nrn.kind}): {s}" for s in said]
            if approximate:
                notes += [f"{where} ({nrn.kind}): approximated: {s}" for s in bad]
            else:
                problems += [f"{where}: kind {nrn.kind!r} cannot be expressed: {s}" for s in bad]
        if h > dt and any(p.post == name and not p.teaching for p in cfg.projections.values()):
            notes.append(f"{where} ({nrn.kind}): cerebx integrates it in {h} ms steps and applies input arriving "
                         "inside a step at the step's end (decayed); NEST applies it on arrival")
        maps[name] = entry
        pops[name] = PopulationPlan(nrn.kind, pop.size, entry.nest_model, entry.pynn_model, entry.nest_params(nrn, h),
                                    entry.pynn_params(nrn, h))
    projs: dict[str, ProjectionPlan] = {}
    dropped: dict[str, str] = {}
    post_set: dict[str, dict[str, tuple[float, str]]] = {}
    for name, p in cfg.projections.items():
        where = f"projections.{name}"
        if p.rule.kind not in CONNECTORS:
            problems.append(f"{where}.rule: kind {p.rule.kind!r} has no NEST/PyNN mapping (cerebx/export/mapping.py)")
            continue
        target = maps.get(p.post)
        if target is None:
            continue
        rec = target.receptors.get(p.receptor)
        if rec is None:
            problems.append(f"{where}: {target.nest_model} ({p.post}) has no input receptor {p.receptor!r}")
            continue
        if isinstance(rec, Refused):
            if approximate or p.teaching:
                dropped[name] = f"receptor {p.receptor}: {rec.reason}"
                if not p.teaching:
                    notes.append(f"{where}: left out (approximated): {rec.reason}")
                continue
            problems.append(f"{where}: receptor {p.receptor!r} cannot be expressed: {rec.reason}")
            continue
        synapse, syn_params, plastic = "static_synapse", {}, False
        if p.plasticity is not None:
            rule = PLASTICITY.get(p.plasticity.kind)
            why = ""
            if isinstance(rule, PlasticityMap) and rule.check is not None:
                bad, said = rule.check(p.plasticity, p)
                notes += [f"{where}.plasticity ({p.plasticity.kind}): {x}" for x in said]
                if bad and approximate:
                    notes += [f"{where}.plasticity ({p.plasticity.kind}): approximated: {x}" for x in bad]
                elif bad:
                    why = "; ".join(bad)
            if rule is None or isinstance(rule, Refused) or why:
                why = why or (rule.reason if isinstance(rule, Refused)
                              else "no NEST/PyNN mapping (cerebx/export/mapping.py)")
                if static:
                    plastic = True
                    notes.append(f"{where}.plasticity: kind {p.plasticity.kind!r} exported with static weights "
                                 f"(--static): {why}")
                else:
                    problems.append(f"{where}.plasticity: kind {p.plasticity.kind!r} cannot be expressed: {why} "
                                    "(--static exports its weights static)")
                    continue
            else:
                w_hi = p.weight_range_nS[1]  # a plastic projection has one (schema)
                synapse, syn_params = rule.nest_synapse, rule.nest_params(p.plasticity, rec[1] * w_hi)
                if rule.post_params is not None:
                    for key, value in rule.post_params(p.plasticity).items():
                        have = post_set.setdefault(p.post, {}).setdefault(key, (value, name))
                        if have[0] != value:
                            problems.append(f"{where}.plasticity: {key} {value} differs from {have[0]} of "
                                            f"projections.{have[1]}: NEST keeps {key} on the post neuron")
                        pops[p.post].nest_params[key] = value
        delay = p.delay_ms if isinstance(p.delay_ms, float) else float("nan")  # drawn: per synapse (writer.py)
        projs[name] = ProjectionPlan(p.pre, p.post, p.receptor, rec[1], rec[0], delay, synapse, syn_params,
                                     p.rule.kind, plastic)
    return Plan(dt, pops, projs, dropped, notes, problems)
