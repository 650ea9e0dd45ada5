"""The delay presets in conf/delay: each validates, its samples match the statistics documented in
its YAML header, messages never reorder, and percentile tables are reproduced."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from cerebx import registry
from cerebx.build import BuildContext
from cerebx.delay_channel import DelayChannel
from cerebx.guard import conf_roots
from cerebx.loop.delays import Percentiles
from cerebx.report.studies import preset_sweep

ROOT = Path(__file__).resolve().parents[2]

# name: (r2c mean, r2c std, c2r mean, c2r std, round-trip mean, round-trip std) in ms, as documented
# in each preset's header (4e5-sample estimates, or exact for percentile tables and the trace file).
DOCUMENTED = {
    "gamma15": (6.4, 3.18, 6.4, 3.18, 12.81, 6.35),
    "gamma25": (11.4, 3.18, 11.4, 3.18, 22.8, 6.36),
    "gamma35": (16.4, 3.18, 16.4, 3.18, 32.8, 6.36),
    "gamma45": (21.4, 3.18, 21.4, 3.18, 42.8, 6.36),
    "gamma55": (26.4, 3.18, 26.4, 3.18, 52.8, 6.36),
    "gamma65": (31.4, 3.18, 31.4, 3.18, 62.8, 6.36),
    "gamma78": (37.34, 2.15, 37.34, 2.15, 74.69, 4.29),
    "asym_r2c8_c2r40": (4.95, 3.31, 36.15, 2.78, 41.10, 4.32),
    "asym_r2c39_c2r9": (36.15, 2.77, 4.98, 3.33, 41.13, 4.33),
    "cloud": (9.18, 0.95, 9.18, 0.95, 18.37, 1.34),
    "wifi_cloud": (12.49, 2.26, 29.39, 2.51, 41.88, 3.38),
    "trace": (13.16, 1.36, 29.92, 1.43, 43.08, 2.44),
    "wifi15": (6.55, 2.55, 20.96, 4.47, 27.51, 5.15),
    "wifi30": (10.53, 3.75, 21.46, 4.47, 31.98, 5.84),
    "wifi54": (16.66, 5.76, 21.96, 4.47, 38.62, 7.29),
}
THESIS_ROUND_TRIP_MS = {
    "gamma15": 15,
    "gamma25": 25,
    "gamma35": 35,
    "gamma45": 45,
    "gamma55": 55,
    "gamma65": 65,
    "gamma78": 78,
}


@pytest.fixture(autouse=True)
def _at_root(monkeypatch):
    monkeypatch.chdir(ROOT)  # the trace preset names its file relative to the repository root


def _model(load, name: str, seed: int = 0):
    cfg = load(["+experiment=demo", f"delay={name}", f"seed={seed}"])
    return cfg.delay, registry.delays.build(cfg.delay, BuildContext(cfg=cfg))


def _samples(model, n: int = 10_000) -> tuple[np.ndarray, np.ndarray]:
    """Draw as the loop does: each step the R2C message, then the C2R one."""
    r, c = np.empty(n), np.empty(n)
    for i in range(n):
        r[i], c[i] = model.r2c.next_ms(), model.c2r.next_ms()
    return r, c


def test_every_preset_is_covered():
    presets = {p.stem for root in conf_roots() for p in (root / "delay").glob("*.yaml")} - {"none", "constant"}
    assert presets == set(DOCUMENTED)


@pytest.mark.parametrize("name", sorted(DOCUMENTED))
def test_samples_match_documented_statistics(load, name):
    _, model = _model(load, name)
    r, c = _samples(model)
    want = DOCUMENTED[name]
    got = (r.mean(), r.std(), c.mean(), c.std(), (r + c).mean(), (r + c).std())
    np.testing.assert_allclose(got, want, rtol=0.05, err_msg=f"{name}: (r2c m, s, c2r m, s, rt m, s)")


@pytest.mark.parametrize("name", sorted(THESIS_ROUND_TRIP_MS))
def test_symmetric_set_sits_just_under_the_thesis(load, name):
    """The original's symmetric mechanism (one limited round-trip draw, half per path): the round
    trip lies 2-6 ms under the thesis figure, which also held the lab's base latency."""
    delay, model = _model(load, name)
    assert delay.symmetric and delay.r2c == delay.c2r and delay.monotonic
    r, c = _samples(model)
    assert 2.0 < THESIS_ROUND_TRIP_MS[name] - (r + c).mean() < 6.5


@pytest.mark.parametrize("name", sorted(DOCUMENTED))
def test_messages_never_reorder(load, name):
    _, model = _model(load, name, seed=3)
    r2c, c2r = DelayChannel(model.r2c), DelayChannel(model.c2r)
    outs: tuple[list[int], list[int]] = ([], [])
    for tick in range(5000):
        for ch, out in zip((r2c, c2r), outs):
            ch.send(tick, tick)
            out += ch.receive(tick)
    for ch, out in zip((r2c, c2r), outs):
        out += ch.receive(10**9)
        assert out == list(range(5000))


@pytest.mark.parametrize("name", ["cloud", "wifi_cloud"])
def test_percentile_sampler_reproduces_its_table(load, name):
    delay, _ = _model(load, name)
    for points in (delay.r2c_percentiles, delay.c2r_percentiles):
        s = Percentiles(points, np.random.default_rng(5))
        x = np.array([s.next_ms() for _ in range(100_000)])
        p, v = np.array(points).T
        inner = (p > 0) & (p < 100)
        np.testing.assert_allclose(np.percentile(x, p[inner]), v[inner], atol=0.1)
        assert x.min() >= v[0] and x.max() <= v[-1]


def test_cloud_percentiles_are_the_thesis_figures(load):
    """Thesis §3.3.4: 50/90/99th percentiles 9/10/12 ms (cloud, both paths); Wi-Fi cloud 12/14/20 ms
    (R2C) and 29/32/36 ms (C2R)."""
    cloud = _model(load, "cloud")[0]
    wifi = _model(load, "wifi_cloud")[0]
    pick = lambda pts: [v for p, v in pts if p in (50, 90, 99)]  # noqa: E731
    assert pick(cloud.r2c_percentiles) == pick(cloud.c2r_percentiles) == [9.0, 10.0, 12.0]
    assert pick(wifi.r2c_percentiles) == [12.0, 14.0, 20.0]
    assert pick(wifi.c2r_percentiles) == [29.0, 32.0, 36.0]


def test_fig3_6_moves_the_pathway_delay_with_the_kernel(load):
    """As the original's bio-delay launches: kernel peak 2D + 50 ms, onset 2D + 20 ms, pathway delay D."""
    jobs = preset_sweep(["+experiment=fig3_6_kernels"])
    assert len(jobs) == 9
    peaks = []
    for job in jobs:
        cfg = load(["+experiment=fig3_6_kernels", *job])
        rule = cfg.controller.network.projections["pf_pc"].plasticity
        d = cfg.controller.pathway_delay_ms
        assert rule.kernel_peak_ms == 2 * d + 50 and rule.kernel_onset_ms == 2 * d + 20
        peaks.append(rule.kernel_peak_ms)
    assert peaks == [90, 110, 130, 150, 170, 190, 210, 230, 250]
