"""The Poisson (rate-coded) mossy-fibre encoder: rates by the receptive-field formula, Bernoulli per 2 ms step
from a seeded generator."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from pydantic import ValidationError

from cerebx import registry
from cerebx.snn.encoders import PoissonMossyEncoder
from cerebx.snn.schema import PoissonEncoder

LO, HI = -np.ones((2, 4)), np.ones((2, 4))
X = (np.array([0.3, -0.9]), np.array([-0.2, 1.7]), np.array([0.0, 0.55]), np.array([-1.0, 0.95]))
"""Two joints' q_des, q, qd_des, qd; 1.7 is outside [-1, 1] and is clipped to 1."""


def expected_rates(cfg: PoissonEncoder) -> np.ndarray:
    """rate = r_min + (r_max - r_min) RF(z), z = (x - c_k) / (width_factor step), by local index 4F j + F s + k."""
    F = cfg.fibers_per_signal
    step = 2.0 / (F - 1)
    out = []
    for j in range(2):
        for s in range(4):
            x = min(max(X[s][j], -1.0), 1.0)
            for k in range(F):
                z = (x - (-1.0 + k * step)) / (cfg.width_factor * step)
                rf = np.exp(-z * z / 2) if cfg.field == "gaussian" else float(abs(z) < 1)
                out.append(cfg.rate_min_hz + (cfg.rate_max_hz - cfg.rate_min_hz) * rf)
    return np.array(out)


@pytest.mark.parametrize("cfg", [
    PoissonEncoder(fibers_per_signal=8, rate_min_hz=5.0, rate_max_hz=150.0),
    PoissonEncoder(fibers_per_signal=6, field="box", width_factor=0.75, rate_min_hz=2.0, rate_max_hz=300.0),
])
def test_mean_rates_follow_the_receptive_fields_within_binomial_bounds(cfg):
    """20 000 steps (40 s) of fixed signals: every fibre's spike count n is Binomial(N, p = rate x 2 ms); it lies
    within 4.5 standard deviations of N p (each fibre outside that with probability 7e-6: 4.5 sigma for 64 fibres
    leaves a seeded run a 5e-4 chance to fail), and the pooled count within 4.5 sigma of its sum."""
    enc = PoissonMossyEncoder(cfg, LO, HI, np.random.default_rng(11))
    want = expected_rates(cfg)
    np.testing.assert_allclose(enc.rates(*X), want, rtol=1e-12)
    N = 20_000
    counts = np.zeros(enc.n_fibers)
    for _ in range(N):
        idx = enc.active(*X)
        assert idx.dtype == np.int32 and (np.diff(idx) > 0).all()
        counts[idx] += 1
    p = want * 0.002
    sd = np.sqrt(N * p * (1 - p))
    assert (np.abs(counts - N * p) <= 4.5 * sd + 1e-9).all()
    assert abs(counts.sum() - N * p.sum()) <= 4.5 * np.sqrt((N * p * (1 - p)).sum())
    if cfg.field == "box":  # far from every box only r_min fires: the centre fibre alone is at r_max
        assert sorted(set(np.round(want, 9))) == [2.0, 300.0]


def test_the_same_seed_gives_the_same_spikes():
    cfg = PoissonEncoder(fibers_per_signal=10)
    a, b, c = (PoissonMossyEncoder(cfg, LO, HI, np.random.default_rng(s)) for s in (4, 4, 5))
    sa = [a.active(*X) for _ in range(500)]
    sb = [b.active(*X) for _ in range(500)]
    sc = [c.active(*X) for _ in range(500)]
    assert all(np.array_equal(x, y) for x, y in zip(sa, sb, strict=True))
    assert not all(np.array_equal(x, y) for x, y in zip(sa, sc, strict=True))
    assert sum(len(x) for x in sa) > 100


def test_the_encoder_is_a_registered_mossy_kind_seeded_from_the_run():
    """``controller.mf: {kind: poisson}`` builds through the registry; the spiking controller gives it a generator
    from the run's seed (two controllers with one seed: the same fibres)."""
    from cerebx.build import BuildContext
    from cerebx.controllers.snn.controller import SNNControllerImpl
    from cerebx.controllers.snn.schema import SNNController
    from cerebx.snn.presets import network as full_network

    registry.load_plugins()
    assert registry.encoders["poisson"].schema is PoissonEncoder

    class Task:
        def envelope(self):
            z = np.zeros(6)
            return z - 0.5, z + 0.5, z - 1.0, z + 1.0

    def ctrl(seed):
        c = SNNController(network=full_network(fibers=5, per_joint=10), mf=PoissonEncoder(fibers_per_signal=5))
        return SNNControllerImpl(c, BuildContext(cfg=SimpleNamespace(controller=c, seed=seed), task=Task()))

    a, b, c = ctrl(3), ctrl(3), ctrl(4)
    z = np.zeros(6)
    sa, sb, sc = ([x.mf.active(z, z, z, z) for _ in range(50)] for x in (a, b, c))
    assert all(np.array_equal(x, y) for x, y in zip(sa, sb, strict=True))
    assert not all(np.array_equal(x, y) for x, y in zip(sa, sc, strict=True))


def test_rates_are_checked():
    with pytest.raises(ValidationError, match="rate_min_hz"):
        PoissonEncoder(rate_min_hz=50.0, rate_max_hz=40.0)
    with pytest.raises(ValidationError, match="rate_max_hz"):
        PoissonEncoder(rate_max_hz=600.0)
