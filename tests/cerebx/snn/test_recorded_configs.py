"""Runs recorded before connectors and plasticity became registered kinds (commit 354b163) are still the same
experiment: their recorded configuration equals today's composition, so completed runs are reused."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from cerebx.config import load
from cerebx.errors import ConfigError
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


def test_a_pair_stdp_rule_recorded_before_its_delay_option_is_the_same():
    """pair_stdp gained ``delay`` (axonal: what it computed before; dendritic: NEST's convention)."""
    _, plain = load(["+task=circle", "+experiment=small_snn"])
    rule = {"kind": "pair_stdp", "lam": 0.01, "alpha": 1.0, "mu_plus": 1.0, "mu_minus": 1.0, "tau_plus_ms": 20.0,
            "tau_minus_ms": 20.0}
    recorded = json.loads(json.dumps(plain))
    recorded["controller"]["network"]["projections"]["mf_dcn"].update(plasticity=rule, weight_range_nS=[0.0, 1.0])
    today = json.loads(json.dumps(recorded))
    today["controller"]["network"]["projections"]["mf_dcn"]["plasticity"]["delay"] = "axonal"
    old, new = ({k: v for k, v in upgrade(d).items() if k not in NOT_SHARED} for d in (recorded, today))
    _check_same(old, new, whose="its")
    today["controller"]["network"]["projections"]["mf_dcn"]["plasticity"]["delay"] = "dendritic"
    new = {k: v for k, v in upgrade(today).items() if k not in NOT_SHARED}
    with pytest.raises(ConfigError, match=r"mf_dcn\.plasticity\.delay: 'dendritic' differs from its 'axonal'"):
        _check_same(old, new, whose="its")
