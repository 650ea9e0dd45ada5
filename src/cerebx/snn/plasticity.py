"""Learning rules of sparse (CSR) projections (docs/models.md#plasticity): the two rule families the engine
runs on them and the builders of the built-in rule kinds (their schemas are in :mod:`cerebx.snn.schema`).

A plasticity kind is registered (``registry.plasticity_rules``) with a builder ``builder(rule, dt_ms) -> spec``
that turns its parameters into one of the engine's families, so a plugin's rule runs in the compiled kernels
without code of its own in them:

- :class:`TraceSpec`: pair-based STDP with all-to-all pairing through exponential traces, NEST
  ``stdp_synapse``'s update (multiplicative with exponents mu_plus, mu_minus; additive at 0).
- :class:`PairingSpec`: a per-pre-spike increment plus two kernel tables over the age of the partner's
  spikes (a teaching projection's arrivals at the post neuron, or the post neuron's own spikes): at a pre
  arrival Δw = fixed + Σ k_pre(t − t_partner), at a partner event Δw = Σ k_post(t − t_pre). EDLUT's
  symmetric-cosine rules (MF–DCN, PC–DCN) are of this form; a kernel with a bounded window is exact.

The PF–PC rule (:class:`~cerebx.snn.schema.KernelSTDP`) keeps its own dense path. Only numpy is used here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# the rules' schemas live with the network's; their names here are those older checkpoints pickled them by
from cerebx.snn.schema import PairSTDP, SymmetricCos, SymmetricCosSTDP  # noqa: F401

HISTORY_MAX = 64
"""Spikes kept per neuron for a pairing rule: enough for a window of 64 spikes (e.g. 100 ms at 640 Hz); older
spikes still inside the window are dropped and counted (``Network.pairing_lost``)."""


@dataclass(frozen=True)
class TraceSpec:
    """Pair STDP with traces (NEST ``stdp_synapse``). At a post spike: w/W += lam (1 − w/W)^mu_plus · x_pre;
    at a pre arrival: w/W −= alpha · lam (w/W)^mu_minus · y_post; x_pre (y_post) decays with tau_plus_ms
    (tau_minus_ms) and jumps by 1 at each pre arrival (post spike). W: the projection's upper weight bound.

    Attributes
    ----------
    lam : float
        Step size of potentiation (NEST ``lambda``).
    alpha : float
        Depression / potentiation ratio.
    mu_plus, mu_minus : float
        Weight-dependence exponents of potentiation and depression (0: additive, 1: multiplicative).
    tau_plus_ms, tau_minus_ms : float
        Time constants of the presynaptic and postsynaptic traces (ms).
    dendritic : bool
        The synapse's delay d is dendritic (NEST's convention): a post spike reaches the synapse d after it
        happened, so it pairs with the pre arrivals as a post spike 2 d later would under the axonal convention.
    """

    lam: float
    alpha: float
    mu_plus: float
    mu_minus: float
    tau_plus_ms: float
    tau_minus_ms: float
    dendritic: bool = False


@dataclass(frozen=True)
class PairingSpec:
    """Kernel pairing. ``k_pre[m]``: added (nS) at a pre arrival per partner event m steps of dt earlier (m = 0:
    the same step); ``k_post[m]``: added at a partner event per pre arrival m steps earlier (m >= 1: a same-step
    pair counts once, at the pre arrival). ``teacher``: the projection whose arrivals at the post neuron are the
    partner events, or None for the post neuron's own spikes.

    Attributes
    ----------
    fixed_nS : float
        Change (nS) at every pre arrival, whatever the timing.
    k_pre : numpy.ndarray
        Change (nS) at a pre arrival per partner event m network steps earlier, m = 0, 1, ...
    k_post : numpy.ndarray
        Change (nS) at a partner event per pre arrival m network steps earlier (m >= 1).
    teacher : str or None
        The projection whose arrivals are the partner events; None: the post neuron's own spikes.
    """

    fixed_nS: float
    k_pre: np.ndarray
    k_post: np.ndarray
    teacher: str | None


def cos_kernel(tau_ms: float, n: float, dt_ms: float) -> np.ndarray:
    """k(Δ) = exp(−n|Δ|/τ) cos²(π|Δ|/(2τ)) for |Δ| < τ (0 beyond), sampled at Δ = m dt."""
    d = np.arange(int(np.ceil(tau_ms / dt_ms))) * dt_ms
    return np.where(d < tau_ms, np.exp(-n * d / tau_ms) * np.cos(np.pi * d / (2 * tau_ms)) ** 2, 0.0)


def pair_stdp(rule: PairSTDP, dt_ms: float) -> TraceSpec:
    return TraceSpec(rule.lam, rule.alpha, rule.mu_plus, rule.mu_minus, rule.tau_plus_ms, rule.tau_minus_ms,
                     rule.delay == "dendritic")


def symmetric_cos(rule: SymmetricCos | SymmetricCosSTDP, dt_ms: float) -> PairingSpec:
    k = rule.kernel_nS * cos_kernel(rule.tau_ms, rule.n, dt_ms)
    k_post = k.copy()
    k_post[0] = 0.0  # a same-step pair is counted at the pre arrival
    return PairingSpec(rule.fixed_nS, k, k_post, getattr(rule, "teacher", None))
