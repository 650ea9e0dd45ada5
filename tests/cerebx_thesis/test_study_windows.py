"""Each report study records the control steps its figures read (studies.yaml ``recording.trials``), in both
profiles: the trials are computed here the way the figures compute them."""

from __future__ import annotations

import numpy as np
import pytest

from cerebx.report.delays import DELAY_TRIALS
from cerebx.report.studies import PROFILES, load_studies, study_recording, with_replicas
from cerebx_thesis.report import reaching, stages
from cerebx_thesis.report.constant_delays import FIG3_5_TRIALS

# only=[]: the studies as written, their sweeps not checked against their presets (the report's tests do that; it
# composes ~30 presets, ~6 s of every test worker's collection)
STUDIES = {p: with_replicas(load_studies(only=[]), p) for p in PROFILES}
WARMUP = 2  # the evaluation presets' warm-up trials


def _held(study: str, profile: str) -> tuple[set[int], int, bool]:
    spec = STUDIES[profile][study]
    n = getattr(spec, profile).trials
    window, joints = study_recording(spec, profile)
    return set(range(n)) if window is None else set(window.trials(n)), n, joints


@pytest.mark.parametrize("profile", PROFILES)
@pytest.mark.parametrize("study", ["learn_circle", "learn_eight", "learn_circle~seed1"])
def test_stage_figures_read_held_trials(study, profile):
    if study not in STUDIES[profile]:
        pytest.skip(f"{study} is not in the {profile} profile")
    held, n, joints = _held(study, profile)
    for k in stages.stage_trials(n):  # the stage itself, and /control ee of the 10 trials before it
        assert set(range(max(0, k - 10), k + 1)) <= held, (study, profile, k)
    assert joints


@pytest.mark.parametrize("profile", PROFILES)
def test_reaching_windows_are_held(profile):
    held, n, _ = _held("learn_reaching", profile)
    width = max(1, int(round(reaching.REACH_DENSITY * n)))
    for e in {max(1, int(round(f * n))) for f in reaching.REACH_STAGES}:
        assert set(range(max(0, e - width), e)) <= held, (profile, e)


@pytest.mark.parametrize("profile", PROFILES)
@pytest.mark.parametrize("study", [s for s in STUDIES["full"] if s.startswith("fig3_5_") and s != "fig3_5_position"])
def test_fig3_5_densities_are_held(study, profile):
    held, n, _ = _held(study, profile)
    picks = np.unique(np.linspace(WARMUP, n - 1, min(n - WARMUP, FIG3_5_TRIALS)).round().astype(int))
    assert set(picks.tolist()) <= held


@pytest.mark.parametrize("profile", PROFILES)
@pytest.mark.parametrize("study", ["fig3_4_snn", "fig3_4_ann", *(f"fig3_5_{c}_{t}" for c in ("snn", "ann")
                                                                   for t in ("circle", "inclined_circle",
                                                                             "circle_eight"))])
def test_torque_variability_runs_hold_every_trial_with_joint_states(study, profile):
    held, n, joints = _held(study, profile)
    assert held == set(range(n)) and joints


@pytest.mark.parametrize("profile", PROFILES)
@pytest.mark.parametrize("study", ["fig3_4_pd", "fig3_7_gamma", "fig3_8_wifi", "fig3_9_cloud", "fig3_10_multikernel",
                                   "realism_pd", "realism_snn", "luque2011_fig8", "luque2011_fig9", "luque2011_fig10",
                                   "luque2011_fig12"])
def test_delayed_runs_hold_the_trials_of_the_delay_table(study, profile):
    held, n, _ = _held(study, profile)
    assert set(range(min(n, DELAY_TRIALS))) <= held


@pytest.mark.parametrize("profile", PROFILES)
@pytest.mark.parametrize("study", ["interaction_snn", "interaction_baselines"])
def test_interactions_are_held(study, profile):
    held, _, _ = _held(study, profile)
    for at in (4, 8):  # conf/experiment/human_interaction.yaml: the push and the grab
        assert {at - 1, at, at + 1} <= held


@pytest.mark.parametrize("profile", PROFILES)
def test_reference_paths_and_the_payload_sag_are_held(profile):
    for study in ("baselines_circle", "fig3_5_position"):
        held, n, _ = _held(study, profile)
        assert n - 1 in held
    held, n, _ = _held("fig4_6b", profile)
    assert held == set(range(n))
