"""Ziegler-Nichols tuning: the envelope detector on known signals, and the whole procedure on the
planar arm (finite K_u/T_u, and the tuned PD tracks the joint sinusoid better than the hold PD)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import yaml

from cerebx.loop.runner import run_experiment
from cerebx.tuning import envelope, main, tune_pd

pytestmark = pytest.mark.integration

DEMO = ["+experiment=demo"]


def test_envelope_on_known_signals():
    t = np.arange(2000) * 0.002
    steady = envelope(0.01 * np.sin(2 * np.pi * t / 0.05 + 0.3))
    assert steady.period_s == pytest.approx(0.05, abs=0.002)
    assert steady.ratio == pytest.approx(1.0, abs=0.01)
    decaying = envelope(0.01 * np.exp(-t / 0.5) * np.sin(2 * np.pi * t / 0.1 + 0.3))
    assert decaying.period_s == pytest.approx(0.1, abs=0.004)
    assert decaying.ratio < 0.7
    assert envelope(0.01 * np.exp(-t / 0.05)).ratio == 0.0  # no oscillation at all


def test_zn_on_planar2(load, tmp_path):
    out = tmp_path / "pd_zn.yaml"
    results, tuned = tune_pd(DEMO, out=out)
    assert [r.joint for r in results] == ["shoulder", "elbow"]
    for r in results:
        assert math.isfinite(r.k_u) and math.isfinite(r.t_u) and r.k_u > 0 and r.t_u > 0.004
        assert r.kp == pytest.approx(0.8 * r.k_u) and r.kd == pytest.approx(r.kp * r.t_u / 8)
    text = out.read_text()
    assert "K_u" in text and "T_u" in text
    data = yaml.safe_load(text)
    ctrl = data["controller"]
    assert ctrl["kind"] == "pd" and ctrl["tau_max_Nm"] == [30.0, 20.0] and data["robot"] == [{"kind": "hold"}]
    assert ctrl["kp"] == pytest.approx([r.kp for r in results], rel=1e-4)

    base = load([*DEMO, "trials=2"])
    zn = base.model_copy(update={"controller": tuned})
    s_zn = run_experiment(zn, tmp_path / "zn")
    s_hold = run_experiment(base, tmp_path / "hold")
    assert s_zn["status"] == "completed"
    assert s_zn["final_mae"] < 0.01 and s_zn["final_mae"] < 0.5 * s_hold["final_mae"]


def test_main_rejects_a_non_pd_hold(capsys):
    assert main(["+task=circle", "controller=ann", "--out", "-"]) == 2
    assert "hold controller must be a PD" in capsys.readouterr().out
