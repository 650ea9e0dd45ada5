"""Runs recorded before connectors and plasticity became registered kinds (commit 354b163) are still the same
experiment: their recorded configuration equals today's composition, so completed runs are reused."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from cerebx.config import load
from cerebx.loop.resume import NOT_SHARED, _check_same
from cerebx.schema.legacy import upgrade

RECORDED = json.loads((Path(__file__).parent / "recorded_before_connectors.json").read_text())
OVERRIDES = {"small_snn": ["+task=circle", "+experiment=small_snn"],
             "multikernel": ["+task=circle", "controller=snn", "network=multikernel"]}


@pytest.mark.parametrize("name", sorted(OVERRIDES))
def test_a_config_recorded_before_is_the_same_experiment(name):
    _, plain = load(OVERRIDES[name])
    old, new = ({k: v for k, v in upgrade(d).items() if k not in NOT_SHARED} for d in (RECORDED[name], plain))
    _check_same(old, json.loads(json.dumps(new)), whose="its")
