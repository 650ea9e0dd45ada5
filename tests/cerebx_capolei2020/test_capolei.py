"""Capolei 2020 cerebellar modules and PID: known answers for k(y), each plasticity rule's direction,
the granular layer learning a linear map, the PID law, the learning/correction schedule, and a short
closed loop in which architecture IV tracks better than the PID alone."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from cerebx.loop.runner import run_experiment
from cerebx.schema.controller import PIDVelocity
from cerebx.signals import Frame
from cerebx.stages.pid import PIDVelocityStage
from cerebx_capolei2020.modules.circuit import ModularCerebellarCircuit, k
from cerebx_capolei2020.modules.controller import ForwardModuleStage
from cerebx_capolei2020.modules.schema import CapoleiForward, CapoleiInverse

pytestmark = pytest.mark.integration

CTX = SimpleNamespace(cfg=SimpleNamespace(control_dt_ms=2.0))


def test_k_is_the_papers_sigmoid():
    assert k(0.0) == 0.0
    np.testing.assert_allclose(k([1.0, -2.0]), np.tanh([1.0, -2.0]), rtol=1e-12)
    assert k(1.0) == pytest.approx(2.0 / (1.0 + np.exp(-2.0)) - 1.0)


def _circuit(**over) -> ModularCerebellarCircuit:
    return ModularCerebellarCircuit(CapoleiInverse(**over))


def test_plasticity_directions_follow_the_io_signal():
    """No error: PF-PC potentiates by LTP, IO-DCN depresses by MTD. Saturated error (|io| = 1):
    PF-PC depresses by LTD (alpha >= 70 makes 1/2^alpha vanish), IO-DCN potentiates by MTP."""
    c = _circuit()
    mf, x = np.zeros(6), np.zeros(3)
    c.step(mf, x, np.zeros((3, 2)), learn=True)
    np.testing.assert_allclose(c.w_pf_pc, np.asarray(c.cfg.pf_pc.ltp))
    np.testing.assert_allclose(c.w_io_dcn, -np.asarray(c.cfg.io_dcn.ltd))
    c = _circuit()
    big = np.full((3, 2), 10.0)  # beyond io_range: |io| = 1
    c.step(mf, x, big, learn=True)
    np.testing.assert_allclose(c.w_pf_pc, np.asarray(c.cfg.pf_pc.ltp) / 2.0 ** np.asarray(c.cfg.pf_pc.alpha)
                               - np.asarray(c.cfg.pf_pc.ltd))
    assert np.all(c.w_pf_pc < 0)
    mtp, mtd, a = (np.asarray(v) for v in (c.cfg.io_dcn.ltp, c.cfg.io_dcn.ltd, c.cfg.io_dcn.alpha))
    np.testing.assert_allclose(c.w_io_dcn, mtp - mtd / 2.0**a)
    assert np.all(c.w_io_dcn > 0)
    # the IO-DCN path then drives the DCN with the sign of the error
    out = c.step(mf, x, big, learn=False)
    assert np.all(out > 0)
    out = c.step(mf, x, -big, learn=False)
    assert np.all(out < 0)


def test_no_learning_leaves_every_weight_and_the_granular_layer_alone():
    c = _circuit()
    for _ in range(20):
        c.step(np.ones(6), np.ones(3), np.ones((3, 2)), learn=False)
    for name in ("w_pf_pc", "w_pc_dcn", "w_mf_dcn", "w_io_dcn"):
        assert not getattr(c, name).any()
    assert c.granular.n_receptive_fields == [0, 0, 0]


def test_granular_layer_learns_a_fixed_linear_map():
    rng = np.random.default_rng(0)
    A = rng.uniform(-1.0, 1.0, (3, 6))
    c = _circuit()
    for _ in range(3000):
        mf = rng.uniform(-0.3, 0.3, 6)
        c.step(mf, A @ mf, np.zeros((3, 2)), learn=True)
    test = rng.uniform(-0.25, 0.25, (50, 6))
    err = []
    for mf in test:
        c.step(mf, A @ mf, np.zeros((3, 2)), learn=False)
        err.append(c.x_pf - A @ mf)
    assert np.sqrt(np.mean(np.square(err))) < 0.05 * np.std(test @ A.T)


def test_pid_law_on_a_constant_velocity_error():
    cfg = PIDVelocity(rate_hz=50.0)
    pid = PIDVelocityStage(cfg, CTX)
    pid.reset(np.random.default_rng(0))
    e = np.array([0.1, -0.2, 0.05])
    taus = []
    for tick in range(30):  # 3 updates at ticks 0, 10, 20
        frame = Frame(tick, tick * 0.002, {"ref.qd": e.copy(), "joint.qd": np.zeros(3)})
        pid.step(frame)
        taus.append(frame.signals["joint.torque"])
    kp, ki = np.asarray(cfg.kp), np.asarray(cfg.ki)
    np.testing.assert_allclose(taus[0], kp * e + ki * e * 0.02)
    np.testing.assert_allclose(taus[9], taus[0])  # held between updates
    np.testing.assert_allclose(taus[25], kp * e + ki * e * 0.06)


def test_forward_module_learns_and_corrects_on_schedule():
    stage = ForwardModuleStage(CapoleiForward(learn_from_trial=1, correct_from_trial=2), CTX)
    stage.reset(np.random.default_rng(0))

    def run_trial():
        out = None
        for tick in range(0, 200, 10):
            sig = {"ref.q": np.full(3, 0.2), "ref.qd": np.full(3, 0.1), "joint.q": np.zeros(3),
                   "joint.qd": np.zeros(3)}
            frame = Frame(tick, tick * 0.002, sig)
            stage.step(frame)
            sig["joint.torque"] = np.full(3, 0.1)
            out = frame.signals["capolei.qd_correction"]
        return out

    assert not run_trial().any() and stage.circuit.granular.n_updates == 0
    stage.end_trial(0)
    assert not run_trial().any() and stage.circuit.granular.n_updates == 20
    stage.end_trial(1)
    assert run_trial().any()


def test_module_and_pid_states_round_trip_and_refuse_each_other(tmp_path):
    from cerebx.errors import StateMismatchError

    a = ForwardModuleStage(CapoleiForward(learn_from_trial=0), CTX)
    a.reset(np.random.default_rng(0))
    for tick in range(0, 100, 10):
        sig = {"ref.q": np.full(3, 0.2), "ref.qd": np.full(3, 0.1), "joint.q": np.zeros(3), "joint.qd": np.zeros(3)}
        a.step(Frame(tick, tick * 0.002, sig))
    a.save_state(tmp_path / "fwd.npz")
    b = ForwardModuleStage(CapoleiForward(), CTX)
    b.load_state(tmp_path / "fwd.npz")
    for name, value in a.circuit.state().items():
        np.testing.assert_array_equal(b.circuit.state()[name], value)
    pid = PIDVelocityStage(PIDVelocity(), CTX)
    pid.integral[:] = [0.1, 0.2, 0.3]
    pid.save_state(tmp_path / "pid.npz")
    other = PIDVelocityStage(PIDVelocity(), CTX)
    other.load_state(tmp_path / "pid.npz")
    np.testing.assert_array_equal(other.integral, [0.1, 0.2, 0.3])
    with pytest.raises(StateMismatchError, match="not a capolei_forward state"):
        b.load_state(tmp_path / "pid.npz")
    with pytest.raises(StateMismatchError, match="not a pid_velocity state"):
        other.load_state(tmp_path / "fwd.npz")
    (tmp_path / "bad.npz").write_bytes(b"PK\x03\x04 truncated")
    with pytest.raises(StateMismatchError, match="not a readable cerebx"):
        b.load_state(tmp_path / "bad.npz")


def test_a_part_state_of_another_kind_is_refused_at_validation(load, tmp_path, capsys):
    from cerebx.cli import main

    assert run_experiment(load(["+experiment=capolei2020_arch4", "trials=1"]), tmp_path / "iv")["status"] == "completed"
    assert main(["validate", "+experiment=capolei2020_arch1", f"init_from={tmp_path / 'iv'}"]) == 2
    assert capsys.readouterr().err.strip().endswith(
        "controller_state.part0.npz was saved by a 'capolei_forward' controller (controller.parts.0 is 'pid_velocity')")


def test_architecture_iv_beats_the_pid_alone(load, tmp_path):
    """Gravity makes the PID leave a pitch offset; the cerebellar modules remove most of it."""
    base = ["trials=14", "recording.joint_states=false"]
    pid = run_experiment(load(["+experiment=capolei2020_arch1", *base]), tmp_path / "i")
    both = run_experiment(load(["+experiment=capolei2020_arch4", *base]), tmp_path / "iv")
    assert pid["status"] == both["status"] == "completed"
    assert both["mae_per_trial"][:7] == pytest.approx(pid["mae_per_trial"][:7])  # identical until corrections
    assert both["mae_per_trial"][-1] < 0.7 * pid["mae_per_trial"][-1]


def test_encoder_samples_stay_on_the_50hz_grid_past_188_s():
    """The encoders are sampled every 10th control tick for as long as the run lasts. MuJoCo's clock is a
    running sum of 0.5 ms steps; before the sample times were counted, its 2e-9 s drift after ~188 s moved
    every later sample one tick late, and every architecture's error stepped at trial 48 of case A."""
    from cerebx_capolei2020.schema import ICubWristConfig
    from cerebx_capolei2020.wrist import ICubWrist

    plant = ICubWrist(ICubWristConfig(ball=False))
    plant.reset(np.zeros(3), np.random.default_rng(0))
    changed, last = [], None
    for tick in range(96_000):  # 192 s
        q, _ = plant.sensors()
        if last is not None and not np.array_equal(q, last):
            changed.append(tick)
        last = q
        plant.apply(0.05 * np.sin([tick * 0.002, tick * 0.003 + 1.0, tick * 0.0025 + 2.0]))
        plant.step()
    assert plant.time_s > 188.0
    gaps = np.diff(changed)
    assert len(changed) > 9000 and set(gaps.tolist()) == {10}
    assert changed[-1] % 10 == 0
