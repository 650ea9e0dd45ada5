"""The Ekeberg antagonist muscle stage (thesis Eq. 4.6, Table 4.1) and the SNN driving it through two
signals: known-answer torques, the passive torque's sign, the resting pose as an equilibrium, the
payload sag shrinking with cocontraction, and bad values refused with one line."""

from __future__ import annotations

import numpy as np
import pytest

from cerebx.cli import main
from cerebx.loop.runner import run_experiment
from cerebx.recording.reader import read_messages
from cerebx.report.runs import Run, RunSet
from cerebx.schema.muscles import EkebergConfig
from cerebx.signals import Frame
from cerebx.stages.muscles import Ekeberg, ekeberg_torque
from cerebx_thesis.report.baxter_muscles import fig4_6, payload_sag_cm

pytestmark = pytest.mark.integration

Q_REST = np.array([0.0, 0.22, 0.0, 1.34, 0.0, 0.0])


def torque(cfg: EkebergConfig, ag, at, q, qd) -> np.ndarray:
    stage = Ekeberg(cfg, 6)
    frame = Frame(0, 0.0, {"muscle.ag": np.asarray(ag, float), "muscle.at": np.asarray(at, float),
                           "joint.q": np.asarray(q, float), "joint.qd": np.asarray(qd, float)})
    stage.step(frame)
    return frame.signals["joint.torque"]


def test_table_4_1_defaults():
    cfg = EkebergConfig()
    assert cfg.alpha_Nm == (30.0, 40.0, 30.0, 30.0, 10.0, 10.0)
    assert set(cfg.beta_Nm_per_rad) == {1.0} and set(cfg.gamma) == {3.0} and set(cfg.delta_Nms_per_rad) == {-1.0}
    assert cfg.rest_pose_rad == tuple(Q_REST) and cfg.cocontraction_base == (1.5, 1.5, 1.5, 1.5, 0.5, 0.5)


def test_hand_computed_torque():
    # k = 5: c = 7.5 on J1-J4, 2.5 on J5-J6
    ag = [0.0, 0.5, 0.0, 0.0, 0.0, 0.0]
    at = [0.0, 0.25, 0.0, 0.0, 1.0, 0.0]
    q = [0.0, 0.32, 0.0, 1.34, -0.2, 0.0]
    qd = [0.0, 0.4, 0.0, 0.0, 0.0, -2.0]
    tau = torque(EkebergConfig(cocontraction=5.0), ag, at, q, qd)
    # J2: 40 (0.5 - 0.25) + 1 (0.5 + 0.25 + 2 x 7.5 + 3)(0.22 - 0.32) - 1 x 0.4 = 10 - 1.875 - 0.4
    assert tau[1] == pytest.approx(7.725, abs=1e-12)
    # J5: 10 (0 - 1) + 1 (0 + 1 + 2 x 2.5 + 3)(0 - (-0.2)) = -10 + 1.8
    assert tau[4] == pytest.approx(-8.2, abs=1e-12)
    # J6: only damping: -1 x (-2.0)
    assert tau[5] == pytest.approx(2.0, abs=1e-12)
    # J1, J3, J4 at rest with no command: nothing
    assert tau[[0, 2, 3]] == pytest.approx([0.0, 0.0, 0.0], abs=1e-15)


def test_the_compiled_step_gives_the_array_form_bit_for_bit():
    """The stage's one compiled call per tick against Eq. 4.6 as array operations: the same doubles, for random
    commands, states and cocontractions."""
    rng = np.random.default_rng(3)
    for k in (0.0, 1.0, 9.0, 12.0):
        cfg = EkebergConfig(cocontraction=k)
        stage = Ekeberg(cfg, 6)
        for _ in range(200):
            ag, at = rng.random(6), rng.random(6)
            q, qd = Q_REST + rng.normal(0, 0.5, 6), rng.normal(0, 3.0, 6)
            frame = Frame(0, 0.0, {"muscle.ag": ag, "muscle.at": at, "joint.q": q, "joint.qd": qd})
            stage.step(frame)
            active, passive = ekeberg_torque(ag, at, q, qd, stage.params)
            assert stage.active.tobytes() == active.tobytes() and stage.passive.tobytes() == passive.tobytes()
            assert frame.signals["joint.torque"].tobytes() == (active + passive).tobytes()


def test_passive_torque_pulls_towards_rest_and_damps():
    zero = np.zeros(6)
    for k in (0.0, 1.0, 12.0):
        cfg = EkebergConfig(cocontraction=k)
        above = torque(cfg, zero, zero, Q_REST + 0.1, zero)
        below = torque(cfg, zero, zero, Q_REST - 0.1, zero)
        assert (above < 0).all() and (below > 0).all()  # restoring
        assert (torque(cfg, zero, zero, Q_REST, np.full(6, 0.5)) < 0).all()  # damping opposes motion
    # stiffness grows with cocontraction: (2 c + gamma) beta per rad
    stiff = [-torque(EkebergConfig(cocontraction=k), zero, zero, Q_REST + 0.1, zero)[0] / 0.1 for k in (0, 1, 12)]
    np.testing.assert_allclose(stiff, [3.0, 6.0, 39.0])
    # a co-active pair stiffens the joint without moving its equilibrium
    both = torque(EkebergConfig(cocontraction=0.0), np.full(6, 0.5), np.full(6, 0.5), Q_REST + 0.1, zero)
    np.testing.assert_allclose(both, -0.1 * 4.0)


def test_resting_pose_is_an_equilibrium():
    zero = np.zeros(6)
    for k in (0.0, 1.0, 5.0, 12.0):
        assert (torque(EkebergConfig(cocontraction=k), zero, zero, Q_REST, zero) == 0).all()


def test_arm_stays_at_rest_with_zero_commands_and_no_gravity(load, tmp_path):
    """The weight-compensated arm at Q_r with M_ag = M_at = 0: nothing moves."""
    cfg = load(["+experiment=fig4_6b", "events=[]", "trials=1", "muscle.cocontraction=0"])
    s = run_experiment(cfg, tmp_path)
    assert s["status"] == "completed", s
    q = np.array([[j["position"] for j in m["joints"]] for topic, _, m in read_messages(tmp_path)
                  if topic == "/joint_states/actual"])
    assert len(q) == 1000 and np.abs(q - Q_REST).max() < 1e-6


def test_payload_sags_less_with_more_cocontraction_and_fig4_6_shows_it(load, tmp_path):
    runs = RunSet()
    for k in (0, 12):
        cfg = load(["+experiment=fig4_6b", f"muscle.cocontraction={k}"])
        assert run_experiment(cfg, tmp_path / str(k))["status"] == "completed"
        runs.append(Run.load(tmp_path / str(k)))
    sag = [payload_sag_cm(r) for r in runs]
    assert sag[0] > 2 * sag[1] > 0
    # by hand from the log: z before the payload (attached at 1 s) minus the mean z of the last second
    t, z = zip(*[(m["t"], m["ee"][2]) for topic, _, m in read_messages(tmp_path / "0") if topic == "/control"])
    t, z = np.array(t), np.array(z)
    assert sag[0] == pytest.approx(100 * (z[t < 1.0][-1] - z[t >= t[-1] - 1.0].mean()))
    fig = fig4_6(runs, tmp_path / "fig4_6")
    rows = {row[0]: row[1:] for row in fig.table}
    assert rows["B: sag Δz with 2 kg at c = x0 (cm)"] == ["9.9", f"{sag[0]:.1f}"]
    assert rows["B: sag falls monotonically with c"] == ["yes", "yes"]
    assert fig.notes == ["panel A: no SNN runs of the eight from a learned state with the muscles (study fig4_6a)"]


def test_snn_drives_the_muscles_through_two_signals(load, tmp_path):
    cfg = load(["+task=eight", "+experiment=small_snn", "plant=baxter_muscles", "muscle=ekeberg", "trials=1",
                "controller.output=agonist_antagonist", "controller.decoder.spikes_full_scale=10"])
    s = run_experiment(cfg, tmp_path)
    assert s["status"] == "completed", s
    ctrl = [m for topic, _, m in read_messages(tmp_path) if topic == "/control"]
    ag, at = np.array([m["muscle.ag"] for m in ctrl]), np.array([m["muscle.at"] for m in ctrl])
    assert ag.shape == at.shape == (1000, 6)
    assert ag.min() >= 0 and at.min() >= 0 and ag.max() <= 1 and at.max() <= 1 and ag.max() > 0
    assert "tau_muscle_passive" in ctrl[0] and "tau_controller" not in ctrl[0]


BAD = {
    "muscle.cocontraction=-1": "muscle.cocontraction: Input should be greater than or equal to 0",
    "muscle.alpha_Nm=[30.0,40.0,30.0,30.0,10.0]": "muscle: rows need one value per joint each, got alpha_Nm 5, "
                                                  "beta_Nm_per_rad 6, gamma 6, delta_Nms_per_rad 6, rest_pose_rad 6, "
                                                  "cocontraction_base 6",
    "muscle.gamma=[3.0,3.0]": "muscle: rows need one value per joint each, got alpha_Nm 6, beta_Nm_per_rad 6, "
                              "gamma 2, delta_Nms_per_rad 6, rest_pose_rad 6, cocontraction_base 6",
    # the preset caps M (saturate); without the cap a full scale below the DCN limit is refused
    "controller.decoder.saturate=false controller.decoder.spikes_full_scale=99":
        "controller.decoder.spikes_full_scale: 99 spikes, but one side of a joint of 'dcn' can fire 100 in a 2 ms "
        "step (M would exceed 1, unless controller.decoder.saturate caps it)",
    "controller.decoder.spikes_full_scale=[40.0,40.0]":
        "controller.decoder.spikes_full_scale: 2 values given but the plant has 6 joints",
}


@pytest.mark.parametrize("override", BAD)
def test_bad_values_refused_with_one_line(override, capsys):
    code = main(["validate", "+experiment=fig4_6a_learn", *override.split()])
    lines = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and lines == [BAD[override]]


def test_table_for_another_arm_refused_with_one_line_per_row(capsys):
    rows = ["alpha_Nm", "beta_Nm_per_rad", "gamma", "delta_Nms_per_rad", "rest_pose_rad", "cocontraction_base"]
    code = main(["validate", "+experiment=fig4_6a_learn", *[f"muscle.{r}=[1.0,1.0]" for r in rows]])
    lines = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and lines == [f"muscle.{r}: 2 values given but the plant has 6 joints" for r in rows]


def test_fig4_6a_learns_from_the_chapter_2_eight_error_gains(load):
    """The thesis's own gains (its chapter 2 eight, the [B] launch; also the lab's muscle eight), not
    chapter 3's: with w1's kpos 1.5 the IO fired too little for the DCN to hold w1 at x9."""
    error = load(["+experiment=fig4_6a_learn"]).controller.error
    assert error == load(["+experiment=learn_eight"]).controller.error
    assert (error.kpos[5], error.kvel[5]) == (3.0, 0.5)
    assert load(["+experiment=fig4_6a"]).controller.error == error


def test_muscles_without_muscle_commands_refused(capsys):
    code = main(["validate", "+experiment=fig4_6a_learn", "controller.output=torque"])
    lines = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and lines[0].startswith("muscle (ekeberg): reads muscle.ag, but the link")
