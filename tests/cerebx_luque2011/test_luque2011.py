"""Luque et al. 2011: the LTD kernel, the RBF encoder, the IO spike law, the crude inverse dynamics, the
lwr3 plant and eight task, the learning estimators (Eq. 8-11) and a short closed loop that learns."""

from __future__ import annotations

import math
from types import SimpleNamespace

import mujoco
import numpy as np
import pytest

from cerebx import metrics
from cerebx_luque2011.cerebellum import kernels as k

pytestmark = pytest.mark.integration

# ---- kernel (Eq. 5) ---------------------------------------------------------------------------------------


def test_kernel_peaks_at_100_ms_with_a_small_second_bump():
    t = np.arange(0.0, 600.0, 0.01)
    kern = k.ltd_kernel(t, 100.0)
    assert t[np.argmax(kern)] == pytest.approx(100.0, abs=0.02)
    assert kern.max() == pytest.approx(1.0, abs=1e-9)
    period = math.pi * 100.0 / math.atan(20.0)  # sin^20 repeats every pi in x
    assert k.ltd_kernel(np.array([period]), 100.0)[0] == pytest.approx(0.0, abs=1e-12)  # zero between the bumps
    late = t > period
    assert t[late][np.argmax(kern[late])] == pytest.approx(100.0 + period, abs=0.02)
    assert kern[late].max() == pytest.approx(math.exp(-math.pi), rel=1e-6)  # 4.3 % of the first bump
    assert k.ltd_kernel(np.array([-5.0]), 100.0)[0] == 0.0


def test_kernel_peak_moves_with_its_setting():
    t = np.arange(0.0, 800.0, 0.01)
    assert t[np.argmax(k.ltd_kernel(t, 170.0))] == pytest.approx(170.0, abs=0.02)
    table = k.kernel_table(100.0, 0.25)
    assert np.argmax(table) == 400 and len(table) * 0.25 > 100.0 + math.pi * 100.0 / math.atan(20.0)


def test_ltd_on_pf_io_pairing_at_the_kernel_peak():
    kern = k.kernel_table(100.0, 0.25)
    w = np.full((4, 3), 15.0)
    hist = np.full((3, 8), -1, np.int64)
    now = 1000
    hist[0, 0] = now - 400  # a PF spike 100 ms before the IO spike: the kernel's peak
    hist[1, 0] = now - 200  # 50 ms before
    io = np.array([False, True, False, False])
    k._depress(w, io, 0.075, kern, hist, now)
    assert w[1, 0] == pytest.approx(15.0 - 0.075)
    assert w[1, 1] == pytest.approx(15.0 - 0.075 * k.ltd_kernel(np.array([50.0]), 100.0)[0])
    assert w[1, 2] == 15.0 and np.all(w[[0, 2, 3]] == 15.0)  # silent PF, PCs without an IO spike: unchanged


# ---- encoder (Eq. 2) and inferior olive (Eq. 7) --------------------------------------------------------------


def test_rbf_response_at_a_centre():
    centres = np.concatenate([np.linspace(0.0, 1.9, 20), np.linspace(-1.0, 0.9, 20)])
    sigma = np.array([0.1, 0.1])
    x = np.array([centres[7], centres[20 + 12]])
    i = k.rbf_currents(x, centres, sigma, 20)
    assert i[7] == pytest.approx(1.0) and i[20 + 12] == pytest.approx(1.0)
    assert i[6] == pytest.approx(math.exp(-0.5)) and i[8] == pytest.approx(math.exp(-0.5))  # one spacing away
    assert i[9] == pytest.approx(math.exp(-2.0))
    assert np.argmax(i[:20]) == 7


def test_io_spike_probability_law():
    p = k.io_probability(np.array([0.05, -0.2, 0.0]), 0.1, 10.0, 0.002)
    # + and - group per joint: half scale -> 5 Hz, beyond full scale -> 10 Hz, wrong sign or zero -> 0
    assert p == pytest.approx([0.01, 0.0, 0.0, 0.02, 0.0, 0.0])
    rng = np.random.default_rng(1)
    spikes = np.zeros(48, np.bool_)
    count = np.zeros(48)
    eps = np.array([0.05, -0.2, 0.0])
    for _ in range(50_000):
        k._olive(eps, rng.random(48), 0.1, 0.02, 8, spikes)
        count += spikes
    rate_hz = count / (50_000 * 0.002)
    assert rate_hz[:8].mean() == pytest.approx(5.0, rel=0.05)  # joint 1, + group
    assert rate_hz[24:32].mean() == pytest.approx(10.0, rel=0.05)  # joint 2, - group
    assert rate_hz[8:24].sum() == 0 and rate_hz[32:].sum() == 0


# ---- crude inverse dynamics --------------------------------------------------------------------------------

PENDULUM = """<mujoco><option gravity="0 0 -9.81"/><worldbody><body>
  <joint type="hinge" axis="0 -1 0" damping="0.3"/>
  <inertial pos="0.4 0 0" mass="2.0" diaginertia="0.01 0.02 0.01"/></body></worldbody></mujoco>"""


def test_inverse_dynamics_reproduces_a_single_joint_torque():
    from cerebx_luque2011.inverse_dynamics import inverse_torque

    model = mujoco.MjModel.from_xml_string(PENDULUM)
    data = mujoco.MjData(model)
    m, lever, i_yy, b, g = 2.0, 0.4, 0.02, 0.3, 9.81
    for q, qd, qdd in [(0.0, 0.0, 0.0), (0.7, 1.5, -3.0), (-1.2, -0.4, 5.0)]:
        expected = m * g * lever * math.cos(q) + (m * lever**2 + i_yy) * qdd + b * qd
        got = inverse_torque(model, data, np.array([q]), np.array([qd]), np.array([qdd]))
        assert got[0] == pytest.approx(expected, rel=1e-9, abs=1e-9)


def _lwr3(**kw):
    from cerebx_luque2011.arm import LWR3Arm
    from cerebx_luque2011.schema import LWR3Config

    return LWR3Arm(LWR3Config(**kw))


def test_crude_model_ignores_exactly_the_object():
    from cerebx.signals import Frame
    from cerebx_luque2011.inverse_dynamics import CrudeInverseDynamicsStage
    from cerebx_luque2011.schema import CrudeInverseDynamics

    plant = _lwr3(object_mass_kg=2.0)
    stage = CrudeInverseDynamicsStage(CrudeInverseDynamics(), SimpleNamespace(plant=plant))
    q, zero = np.array([0.3, 0.6, 0.6]), np.zeros(3)
    frame = Frame(0, 0.0, {"ref.q": q, "ref.qd": zero, "ref.qdd": zero})
    stage.step(frame)
    d = mujoco.MjData(plant.model)
    d.qpos[:] = q
    mujoco.mj_inverse(plant.model, d)
    mujoco.mj_kinematics(plant.model, d)
    mujoco.mj_comPos(plant.model, d)
    jacp = np.zeros((3, 3))
    obj = plant.model.body("object").id
    mujoco.mj_jacBody(plant.model, d, jacp, None, obj)
    object_gravity = jacp.T @ np.array([0.0, 0.0, 2.0 * 9.81])  # torque that holds the 2 kg object
    np.testing.assert_allclose(d.qfrc_inverse - frame.signals["joint.torque"], object_gravity, atol=1e-9)


# ---- plant and task ----------------------------------------------------------------------------------------


def test_lwr3_holds_an_attached_object():
    plant = _lwr3()
    plant.reset(np.array([0.0, 0.6, 0.6]), np.random.default_rng(0))
    assert plant.object_mass_kg() == 0.0
    plant.attach_payload(1.5)
    assert plant.object_mass_kg() == 1.5
    with pytest.raises(ValueError, match="rod_length_m"):
        plant.attach_payload(1.0, 0.2)
    plant.detach_payload()
    assert plant.object_mass_kg() == 0.0
    assert plant.nominal_model().body_mass[plant.model.body("object").id] == 0.0


def _crossings(p: np.ndarray) -> int:
    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    n, count = len(p), 0
    for i in range(n):
        a, b = p[i], p[(i + 1) % n]
        for j in range(i + 2, n - (i == 0)):
            c, d = p[j], p[(j + 1) % n]
            if cross(a, b, c) * cross(a, b, d) < 0 and cross(c, d, a) * cross(c, d, b) < 0:
                count += 1
    return count


def test_luque_eight_is_an_eight_with_exact_derivatives():
    from cerebx_luque2011.schema import LuqueEightTask
    from cerebx_luque2011.task import LuqueEight, luque_eight

    cfg = LuqueEightTask()
    ref = LuqueEight(cfg).trial(0, np.random.default_rng(0))
    assert ref.q.shape == (500, 3) and set(ref.extra) == {"qdd"}
    h = 1e-5
    t = np.array([0.123, 0.6])
    qp, qdp, _ = luque_eight(cfg, t + h)
    qm, qdm, _ = luque_eight(cfg, t - h)
    _, qd, qdd = luque_eight(cfg, t)
    np.testing.assert_allclose((qp - qm) / (2 * h), qd, rtol=1e-6)
    np.testing.assert_allclose((qdp - qdm) / (2 * h), qdd, rtol=1e-6)
    plant = _lwr3()
    hand = []
    for q in ref.q[::5]:
        plant.data.qpos[:] = q
        mujoco.mj_kinematics(plant.model, plant.data)
        hand.append(plant.end_effector())
    hand = np.array(hand)
    assert _crossings(hand[:, :2]) == 1  # seen from above: one self-crossing, an eight
    assert np.ptp(hand[:, 0]) > 0.2 and np.ptp(hand[:, 1]) > 0.2


# ---- estimators (Eq. 8-11) -------------------------------------------------------------------------------------


def test_learning_estimators_on_a_known_curve():
    mae = [1.0, 0.8, 0.6, 0.4] + [0.2, 0.4] * 15  # last 30 trials: mean 0.3, std 0.1
    assert metrics.final_error(mae) == pytest.approx(0.3)
    assert metrics.accuracy_gain(mae) == pytest.approx(0.7)
    assert metrics.final_error_stability(mae) == pytest.approx(0.1)
    assert metrics.convergence_speed(mae) == 4  # first trial at or below 0.3
    assert metrics.improvement_pct(mae, 34) == pytest.approx(70.0)


# ---- closed loop -----------------------------------------------------------------------------------------------


def test_ref_qdd_reaches_the_brain_side(load):
    from cerebx.wiring import wire

    cfg = load(["+experiment=luque2011_eight"])
    wire(cfg)  # the crude inverse dynamics reads ref.qdd: validation passes
    with pytest.raises(Exception, match="ref.qdd"):
        load(["+experiment=luque2011_eight", "task=joint_sine", "task.offset_rad=[0,0,0]",
              "task.amplitude_rad=[0.1,0.1,0.1]", "task.phase_rad=[0,0,0]"])


def test_short_closed_loop_learns(load):
    from cerebx.build import build_components
    from cerebx.loop.loop import ClosedLoop

    cfg = load(["+experiment=luque2011_eight"])  # 1 kg object
    loop = ClosedLoop(build_components(cfg), None)
    loop.start()
    mae = [sum(loop.run_trial(i).mae_per_joint) for i in range(60)]
    assert np.mean(mae[-10:]) < 0.6 * mae[0]


def test_stage_kernel_peaks_at_teaching_delay_plus_arm_lag(load):
    from cerebx.build import build_components

    plasticity = "controller.parts.1.plasticity"
    for extra, peak in (([], 170.0), ([f"{plasticity}.arm_lag_ms=0"], 100.0),
                        ([f"{plasticity}.kernel_peak_ms=50", f"{plasticity}.arm_lag_ms=20"], 70.0)):
        stage = build_components(load(["+experiment=luque2011_eight", *extra])).brain[0].parts[1]
        assert stage.describe()["kernel_peak_ms"] == peak
        assert np.argmax(stage.kern) * stage.cfg.substep_ms == pytest.approx(peak, abs=0.25)


def test_a_checkpoints_positional_constants_still_run(load):
    """A circuit pickled before the constants were named carries them as arrays in field order: it loads with the
    same constants, named and typed (integers as integers, the learning switch a bool)."""
    from cerebx.build import build_components

    stage = build_components(load(["+experiment=luque2011_eight"])).brain[0].parts[1]
    named = stage.circuit.source
    old = named._replace(pars=np.array(named.pars, float), pc=named.pc._replace(par=np.array(named.pc.par, float)),
                         dcn=named.dcn._replace(par=np.array(named.dcn.par, float)))
    restored = k.circuit_state(old)
    assert restored.source.pars == named.pars and restored.source.dcn.par == named.dcn.par
    assert isinstance(restored.source.pars.n_sub, int) and restored.source.pars.learn is True
