"""Random and listed connection rules of the spiking network (docs/models.md#connectors), and the weight and
delay distributions a projection may draw from.

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
from pathlib import Path
from typing import Annotated, Literal

import numpy as np
from pydantic import Field, model_validator

from cerebx.schema.base import NonNegFloat, Strict

SIGMAS = 5.0
"""A declared synapse count of a random rule must lie within this many binomial standard deviations of the
expectation (at 5 sigma a correct declaration is refused about once in 1.7 million draws)."""

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


# --------------------------------------------------------------------------- distributions
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


# --------------------------------------------------------------------------- connectors
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

