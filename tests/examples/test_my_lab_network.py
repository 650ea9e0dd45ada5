"""The network how-to's plugin code (docs/howto/network.md, examples/my_lab/my_lab/network.py): its connector and
learning rule validate, build and run in the engine with known answers."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from pydantic import ValidationError

from cerebx import registry
from cerebx.registry import Entry
from cerebx.snn.network import Network
from cerebx.snn.presets import DCN
from cerebx.snn.schema import NetworkConfig

sys.path.insert(0, str(Path(__file__).parents[2] / "examples" / "my_lab"))
from my_lab.network import ExpTeacher, RingConnector, exp_teacher, ring  # noqa: E402


@pytest.fixture(autouse=True)
def registered(monkeypatch):
    registry.load_plugins()
    monkeypatch.setitem(registry.connectors._entries, "ring", Entry("ring", RingConnector, ring, "my_lab"))
    monkeypatch.setitem(registry.plasticity_rules._entries, "exp_teacher",
                        Entry("exp_teacher", ExpTeacher, exp_teacher, "my_lab"))


def cfg(width: int = 3, synapses: int = 12) -> NetworkConfig:
    return NetworkConfig.model_validate({
        "name": "ring", "dt_ms": 0.5,
        "populations": {"mf": {"size": 4, "neuron": {"kind": "input"}}, "pc": {"size": 4, "neuron": {"kind": "input"}},
                        "dcn": {"size": 8, "neuron": DCN}},
        "projections": {
            "mf_dcn": {"pre": "mf", "post": "dcn", "rule": {"kind": "ring", "width": width}, "receptor": "ampa",
                       "synapses": synapses, "weight_nS": 0.5, "weight_range_nS": [0.0, 1.0], "delay_ms": 1.0,
                       "plasticity": {"kind": "exp_teacher", "teacher": "pc_dcn"}},
            "pc_dcn": {"pre": "pc", "post": "dcn", "rule": {"kind": "ring", "width": 2}, "receptor": "gaba",
                       "synapses": 8, "weight_nS": 0.1, "delay_ms": 1.0}},
        "io": {"mossy": "mf", "climbing": "pc", "output": "dcn", "purkinje": ["pc"], "granule": "dcn"}})


def test_the_ring_connector_is_counted_and_built():
    net = Network(cfg(), parallel=False)
    pre, post, _ = net.sparse_weights("mf_dcn")
    assert sorted(zip(pre.tolist(), post.tolist(), strict=True))[:3] == [(0, 0), (0, 1), (0, 7)]
    assert (np.bincount(pre) == 3).all()
    with pytest.raises(ValidationError, match="declared 13 but rule ring gives 12"):
        cfg(synapses=13)
    with pytest.raises(ValidationError, match="width 9 is more than the 8 post neurons"):
        cfg(width=9, synapses=36)


def test_the_rule_changes_a_weight_by_its_kernel():
    """MF 0 at t = 0 and PC 0 at t = 50 ms (both arrive 1 ms later) onto DCN 0: fixed + kernel (50/100) e^(1/2)."""
    net = Network(cfg(), parallel=False)
    for k in range(30):
        inputs = [0] if k == 0 else [4] if k == 25 else []  # mf 0, pc 0 (global index 4)
        net.step(np.array(inputs, dtype=np.int32))
    pre, post, w = net.sparse_weights("mf_dcn")
    w0 = {(int(j), int(i)): float(x) for j, i, x in zip(pre, post, w, strict=True)}
    want = 0.5 + 0.001 - 0.01 * 0.5 * np.exp(0.5)
    assert w0[0, 0] == pytest.approx(want, abs=1e-6) and w0[0, 7] == pytest.approx(want, abs=1e-6)  # pc 0: dcn 7, 0
    assert w0[0, 1] == pytest.approx(0.5 + 0.001, abs=1e-7)  # no teaching spike at dcn 1
    assert w0[1, 2] == 0.5  # silent MF
