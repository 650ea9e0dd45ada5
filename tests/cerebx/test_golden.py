"""Existing experiments keep their results (tests/golden/golden_runs.py): per-trial metrics within a
tolerance everywhere, and the exact recorded data on the platform that made the golden file."""

from __future__ import annotations

import json

import numpy as np
import pytest
from golden.golden_runs import ATOL, GOLDEN, METRICS, RTOL, RUNS, record, this_platform

pytestmark = pytest.mark.integration


@pytest.fixture(scope="module")
def golden() -> dict:
    return json.loads(GOLDEN.read_text())


@pytest.fixture(scope="module")
def recorded(tmp_path_factory) -> dict:
    """Each golden run, made once for both tiers."""
    cache: dict[str, dict] = {}

    def get(name: str) -> dict:
        if name not in cache:
            cache[name] = record(name, tmp_path_factory.mktemp(name) / "run")
        return cache[name]

    return get  # type: ignore[return-value]


@pytest.mark.parametrize("name", sorted(RUNS))
def test_metrics_within_tolerance(name, golden, recorded):
    """Tier 1 (any platform): the per-trial metrics and message counts of the run."""
    want, got = golden["runs"][name], recorded(name)
    for key in METRICS:
        np.testing.assert_allclose(np.asarray(got["summary"][key], float), np.asarray(want["summary"][key], float),
                                   rtol=RTOL, atol=ATOL, err_msg=f"{name}: {key} (metrics tier)")
    same = {k: v for k, v in want["summary"].items() if k not in METRICS}
    assert {k: got["summary"].get(k) for k in same} == same, f"{name}: summary fields (metrics tier)"
    assert {t: v["count"] for t, v in got["topics"].items()} == {t: v["count"] for t, v in want["topics"].items()}


@pytest.mark.parametrize("name", sorted(RUNS))
def test_exact_digest_on_the_golden_platform(name, golden, recorded):
    """Tier 2 (the platform that wrote the golden file): every recorded message bit for bit."""
    if this_platform() != golden["platform"]:
        pytest.skip(f"golden digests were made on {golden['platform']}; this is {this_platform()} "
                    "(the metrics tier still applies)")
    want, got = golden["runs"][name], recorded(name)
    assert got["summary"] == want["summary"], f"{name}: summary differs bit-wise (digest tier; metrics tier: see above)"
    diff = [t for t in want["topics"] if got["topics"].get(t) != want["topics"][t]]
    assert not diff, f"{name}: recorded data differs bit-wise on the golden platform in {diff} (digest tier)"
