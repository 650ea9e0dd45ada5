"""Existing experiments keep their results: recorded data equals the golden digests
(tests/golden/runs.json, made by tests/golden_runs.py) for a PD run, a small-network SNN run and an
SNN run with a gamma delay and the Eq. 3.6 filter."""

from __future__ import annotations

import json

import pytest
from golden_runs import GOLDEN, RUNS, record


@pytest.mark.parametrize("name", sorted(RUNS))
def test_recorded_data_matches_golden(name, tmp_path):
    want = json.loads(GOLDEN.read_text())[name]
    got = record(name, tmp_path / name)
    assert got["summary"] == want["summary"]
    assert got["topics"] == want["topics"]
