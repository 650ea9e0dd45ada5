"""Random and listed connection rules of the spiking network (docs/models.md#connectors): the builders of the
connector kinds whose schemas (and the weight and delay distributions') are in :mod:`cerebx.snn.schema`.

A connector is a registered kind (``registry.connectors``): its schema says how many synapses it makes
(:meth:`synapse_count`: the expectation and the tolerance a declared count must be within; 0 = exact, or a
``ValueError`` naming what cannot be built) and its builder draws them, ``builder(rule, n_pre, n_post, same,
rng) -> Synapses`` (``same``: pre and post are one population, where autapses are meaningful). The generator
is seeded from the run's seed and the projection's name (:func:`projection_rng`), so the same seed gives the
same synapses and two projections are independent. Only numpy is used here: the schema layer stays light.
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass

import numpy as np

# the connectors' schemas live with the network's; their names here are those older checkpoints pickled them by
from cerebx.snn.schema import (  # noqa: F401
    SIGMAS,
    Distribution,
    FixedIndegree,
    FixedOutdegree,
    FixedProbability,
    FromFile,
    LogNormal,
    Normal,
    Uniform,
)

CHUNK = 1 << 22  # random numbers drawn at a time by the dense draws (memory bound, not a result)


@dataclass(frozen=True)
class Synapses:
    """Drawn synapses, local indices (pre, post), with per-synapse weight (nS) and delay (ms) when the rule
    gives them (``from_file``), else None.

    Attributes
    ----------
    pre, post : numpy.ndarray
        Presynaptic and postsynaptic neuron of each synapse, indices within their populations.
    weight_nS : numpy.ndarray or None
        Each synapse's initial weight (nS); None: the projection's ``weight_nS``.
    delay_ms : numpy.ndarray or None
        Each synapse's delay (ms); None: the projection's ``delay_ms``.
    """

    pre: np.ndarray
    post: np.ndarray
    weight_nS: np.ndarray | None = None
    delay_ms: np.ndarray | None = None


def projection_rng(seed: int, projection: str) -> np.random.Generator:
    """The generator of projection ``projection``: independent per projection, the same for the same seed.

    Parameters
    ----------
    seed : int
        The run's seed (the network's).
    projection : str
        The projection's name in the network table.

    Returns
    -------
    numpy.random.Generator
        A generator that a connector or a weight/delay distribution draws from.
    """
    return np.random.default_rng(np.random.SeedSequence([seed, zlib.crc32(f"network.{projection}".encode())]))


# --------------------------------------------------------------------------- builders
def _draw_k(rng: np.random.Generator, rows: int, n: int, k: int, no_self: bool, multapses: bool) -> np.ndarray:
    """[rows, k] indices into range(n) per row: distinct unless ``multapses``, never the row's own index when
    ``no_self``."""
    if multapses:
        if not no_self:
            return rng.integers(0, n, (rows, k))
        x = rng.integers(0, n - 1, (rows, k))
        return x + (x >= np.arange(rows)[:, None])
    out = np.empty((rows, k), dtype=np.int64)
    block = max(1, CHUNK // max(n, 1))
    for a in range(0, rows, block):
        b = min(rows, a + block)
        keys = rng.random((b - a, n))
        if no_self:
            i = np.arange(a, b)
            keys[i - a, i] = np.inf
        part = np.argpartition(keys, k - 1, axis=1)[:, :k] if k < n else np.argsort(keys, axis=1)[:, :k]
        out[a:b] = np.sort(part, axis=1)
    return out


def fixed_indegree(rule: FixedIndegree, n_pre: int, n_post: int, same: bool, rng: np.random.Generator) -> Synapses:
    pre = _draw_k(rng, n_post, n_pre, rule.indegree, same and not rule.allow_autapses, rule.allow_multapses)
    return Synapses(pre.ravel(), np.repeat(np.arange(n_post), rule.indegree))


def fixed_outdegree(rule: FixedOutdegree, n_pre: int, n_post: int, same: bool,
                    rng: np.random.Generator) -> Synapses:
    post = _draw_k(rng, n_pre, n_post, rule.outdegree, same and not rule.allow_autapses, rule.allow_multapses)
    return Synapses(np.repeat(np.arange(n_pre), rule.outdegree), post.ravel())


def fixed_probability(rule: FixedProbability, n_pre: int, n_post: int, same: bool,
                      rng: np.random.Generator) -> Synapses:
    pres, posts = [], []
    block = max(1, CHUNK // max(n_post, 1))
    for a in range(0, n_pre, block):
        b = min(n_pre, a + block)
        hit = rng.random((b - a, n_post)) < rule.p
        if same and not rule.allow_autapses:
            i = np.arange(a, min(b, n_post))
            hit[i - a, i] = False
        r, c = np.nonzero(hit)
        pres.append(r + a)
        posts.append(c)
    return Synapses(np.concatenate(pres), np.concatenate(posts))


def from_file(rule: FromFile, n_pre: int, n_post: int, same: bool, rng: np.random.Generator) -> Synapses:
    data = rule.arrays()
    return Synapses(data["pre"].astype(np.int64), data["post"].astype(np.int64), data.get("weight_nS"),
                    data.get("delay_ms"))

