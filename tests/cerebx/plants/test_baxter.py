"""Behavioural tests of the MuJoCo Baxter left arm against the reference values in
docs/provenance.md#baxter-gravity-torques."""

from __future__ import annotations

from types import SimpleNamespace

import mujoco
import numpy as np
import pytest

from cerebx.controllers.base import ControlInput, SensorMsg
from cerebx.controllers.position import PositionServo
from cerebx.loop.phases import all_finite
from cerebx.plants.base import PlantEvent
from cerebx.plants.baxter import JOINTS, BaxterArm, baxter_model, kinematic_model
from cerebx.plants.mujoco_arm import _saturate, without_step_timers
from cerebx.schema.controller import PositionController
from cerebx.schema.plant import BaxterConfig

REF = np.array([0.0, -0.55, 0.0, 1.28, 0.0, 0.26])
CTX = SimpleNamespace(cfg=None, plant=None)


def make(**kw) -> BaxterArm:
    plant = BaxterArm(BaxterConfig(**kw), CTX)
    plant.reset(REF, np.random.default_rng(0))
    return plant


def hold(plant: BaxterArm, steps: int, kp=200.0, kd=10.0, q_des=REF) -> np.ndarray:
    """PD hold (no gravity feed-forward); returns the joint positions after ``steps`` control steps."""
    for _ in range(steps):
        q, qd = plant.sensors()
        plant.apply(kp * (q_des - q) - kd * qd)
        plant.step()
    return plant.true_state()[0]


def test_forward_kinematics_matches_urdf_reference_pose():
    plant = make()
    np.testing.assert_allclose(plant.end_effector(), [0.6396, 0.8346, 0.0827], atol=1e-3)
    _, rot = plant.cartesian_pose(REF)
    np.testing.assert_allclose(rot[:, 2], [0.388, 0.388, -0.836], atol=1e-3)  # hand approach axis
    pos, _ = plant.cartesian_pose(np.zeros(6))
    np.testing.assert_allclose(pos, [0.7975, 0.9925, 0.3210], atol=1e-3)


def test_arm_mass_matches_urdf():
    plant = make()
    assert plant.model.body_subtreemass[plant.model.body("left_upper_shoulder").id] == pytest.approx(
        19.7108, abs=1e-3
    )


@pytest.mark.parametrize(
    "overrides, pendulum, counts, mass",
    [
        ({}, True, (12, 9, 1), 19.710821),  # + the idle pendulum bob (1 mg)
        ({}, False, (11, 6, 1), 19.71082),
        ({"sea": {"enabled": True}}, True, (18, 15, 7), 19.716821),  # + six 1 g rotors and their tendons
        ({"gripper_mass_kg": 0.36, "gravity_compensation": True}, False, (12, 6, 1), 20.07082),
    ],
    ids=["default", "no_pendulum", "sea", "gripper_gravcomp"],
)
def test_model_layout_per_option(overrides, pendulum, counts, mass):
    """What the config adds to baxter.xml: bodies, degrees of freedom, tendons and total mass; the six
    controlled joints come first and each has a motor (on its rotor with SEA); w2 is gone."""
    m = baxter_model(BaxterConfig(**overrides), pendulum)
    assert (m.nbody, m.nv, m.ntendon) == counts
    assert m.body_subtreemass[0] == pytest.approx(mass, abs=1e-9)
    assert [m.joint(i).name for i in range(6)] == list(JOINTS) and m.nu == 6
    targets = [m.joint(m.actuator_trnid[a, 0]).name for a in range(6)]
    assert targets == [f"rotor_{j}" if "sea" in overrides else j for j in JOINTS]
    assert mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "w2") == -1
    assert (m.body_gravcomp[1:] > 0).sum() == (9 if overrides.get("gravity_compensation") else 0)
    assert kinematic_model(w2=True).nq == 7 and kinematic_model().nq == 6


def test_holding_torques_match_the_reference_table():
    np.testing.assert_allclose(
        make().gravity_torque(REF), [0, -45.065, 0.026, -11.022, 0.150, -0.883], atol=0.01
    )
    np.testing.assert_allclose(make().gravity_torque(np.zeros(6))[[1, 3]], [-52.876, -15.609], atol=0.01)
    gripper = make(gripper_mass_kg=0.36).gravity_torque(REF)
    np.testing.assert_allclose(gripper[[1, 3, 5]], [-47.744, -12.476, -1.376], atol=0.02)


def test_zero_torque_arm_falls_without_gravity_compensation():
    plant = make()
    for _ in range(100):  # 0.2 s
        plant.apply(np.zeros(6))
        plant.step()
    dq = plant.true_state()[0] - REF
    assert dq[1] == pytest.approx(0.495, abs=0.03)  # s1 positive = down (docs/provenance.md#baxter-limits)
    assert dq[3] == pytest.approx(-0.394, abs=0.03)


def test_zero_torque_arm_holds_with_gravity_compensation():
    plant = make(gravity_compensation=True)
    for _ in range(500):  # 1 s
        plant.apply(np.zeros(6))
        plant.step()
    assert np.abs(plant.true_state()[0] - REF).max() < 1e-4
    assert np.abs(plant.gravity_torque(REF)).max() < 1e-3


def test_gravity_torque_feedforward_holds_the_arm():
    plant = make()
    for _ in range(500):
        plant.apply(plant.gravity_torque(plant.true_state()[0]))
        plant.step()
    assert np.abs(plant.true_state()[0] - REF).max() < 2e-3


def test_torque_saturation():
    plant = make()
    applied = plant.apply(np.array([99.0, -300.0, 1.0, 60.0, -20.0, 3.0]))
    np.testing.assert_allclose(applied, [50.0, -100.0, 1.0, 50.0, -15.0, 3.0])
    plant50 = make(torque_limit_Nm=(50.0, 50.0, 50.0, 50.0, 15.0, 15.0))
    assert plant50.apply(np.full(6, -80.0))[1] == -50.0


def test_physics_step_must_divide_control_step():
    with pytest.raises(ValueError, match="divide"):
        BaxterArm(BaxterConfig(physics_dt_ms=0.3), CTX)


def test_payload_increases_pd_tracking_error():
    base = np.abs(hold(make(gravity_compensation=True), 300) - REF)
    plant = make(gravity_compensation=True)
    plant.handle_event(PlantEvent(0.0, "attach_payload", {"mass_kg": 2.0, "rod_length_m": 0.0}))
    loaded = np.abs(hold(plant, 300) - REF)
    # 2 kg 0.6 m out from s1 needs about 12 N·m: with kp = 200 that is a sag of about 0.06 rad.
    assert loaded[1] > base[1] + 0.02
    plant.handle_event(PlantEvent(0.6, "detach_payload", {}))
    assert np.abs(hold(plant, 2000) - REF).max() < 1e-3


def test_conical_pendulum_payload_hangs_below_end_effector():
    plant = make(gravity_compensation=True)
    plant.handle_event(PlantEvent(0.0, "attach_payload", {"mass_kg": 1.0, "rod_length_m": 0.3}))
    bob = plant.data.xipos[plant.model.body("payload_pendulum").id]
    np.testing.assert_allclose(bob, plant.end_effector() + [0, 0, -0.3], atol=1e-9)
    point = make(gravity_compensation=True)
    point.handle_event(PlantEvent(0.0, "attach_payload", {"mass_kg": 1.0, "rod_length_m": 0.0}))
    # a bob hanging still loads the arm exactly like the same mass at the pivot
    np.testing.assert_allclose(plant.gravity_torque(REF), point.gravity_torque(REF), atol=1e-4)
    assert point.gravity_torque(REF)[1] < -5.0
    q = hold(plant, 250)
    assert np.all(np.isfinite(q)) and plant.is_diverged() is None


def test_force_pulse_displaces_end_effector_and_ends():
    plant = make(gravity_compensation=True)
    ee0 = plant.end_effector()
    plant.handle_event(
        PlantEvent(
            0.0, "force_pulse", {"force_N": (20.0, 0.0, 0.0), "duration_ms": 50.0, "body": "end_effector"}
        )
    )
    hold(plant, 25)  # 50 ms
    assert plant.end_effector()[0] - ee0[0] > 2e-3
    assert np.all(plant.data.xfrc_applied == 0.0)
    hold(plant, 1500)
    np.testing.assert_allclose(plant.end_effector(), ee0, atol=1e-3)


def test_elastic_band_pulls_toward_anchor():
    plant = make(gravity_compensation=True)
    ee0 = plant.end_effector()
    plant.handle_event(
        PlantEvent(
            0.0,
            "elastic_band",
            {"stiffness_N_per_m": 200.0, "anchor_offset_m": (0.0, 0.0, -0.3), "rest_length_m": 0.0},
        )
    )
    hold(plant, 250)
    assert plant.end_effector()[2] < ee0[2] - 5e-3
    plant.handle_event(PlantEvent(0.5, "remove_band", {}))
    hold(plant, 1500)
    np.testing.assert_allclose(plant.end_effector(), ee0, atol=1e-3)


def test_finger_push_is_a_half_sine_at_the_end_effector():
    plant = make(gravity_compensation=True)
    ee0 = plant.end_effector()
    plant.handle_event(PlantEvent(0.0, "finger_push", {"force_N": (0.0, 4.0, 0.0), "duration_ms": 500.0}))
    peak = []
    for _ in range(250):  # 500 ms
        peak.append(plant.data.xfrc_applied[plant.model.body("left_hand").id, 1])
        hold(plant, 1, kp=20.0, kd=2.0)
    peak = np.array(peak)
    assert peak[0] < 0.1 and peak.max() == pytest.approx(4.0, abs=0.01) and 120 <= peak.argmax() <= 130
    assert plant.end_effector()[1] - ee0[1] > 1e-3  # a soft arm yields to 4 N
    hold(plant, 5, kp=20.0, kd=2.0)
    assert np.all(plant.data.xfrc_applied == 0.0)


def test_grab_drags_through_a_soft_spring_then_lets_go():
    from cerebx.plants.interaction import grab_anchor

    plant = make(gravity_compensation=True)
    ee0 = plant.end_effector()
    k, disp = 100.0, np.array([0.0, 0.0, 0.2])
    plant.handle_event(PlantEvent(0.0, "grab", {"stiffness_N_per_m": k, "displacement_m": tuple(disp),
                                                "drag_ms": 400.0, "hold_ms": 400.0}))
    hold(plant, 300, kp=20.0, kd=2.0)  # 600 ms: dragged up, the spring pulls with k (anchor - ee)
    anchor = plant.hand_interactions.band.anchor_m
    np.testing.assert_allclose(anchor, grab_anchor(0.6, ee0, disp, 0.4), atol=1e-9)
    np.testing.assert_allclose(anchor, ee0 + disp, atol=1e-9)
    ee = plant.end_effector()
    assert ee[2] - ee0[2] > 0.01  # a soft joint servo is dragged along
    assert plant.hand_interactions.band.stiffness_N_per_m == k
    hold(plant, 150, kp=20.0, kd=2.0)  # past 800 ms: let go
    assert plant.hand_interactions.band.stiffness_N_per_m == 0.0
    hold(plant, 1500)  # nothing pulls any more: the stiff servo brings the hand back
    np.testing.assert_allclose(plant.end_effector(), ee0, atol=1e-3)


def test_unknown_event_refused():
    with pytest.raises(ValueError):
        make().handle_event(PlantEvent(0.0, "teleport", {}))


def test_s1_spring_is_gravity_opposing_and_nonlinear():
    plant = make(s1_spring={"enabled": True})
    taus = [plant.s1_spring_torque(q) for q in (-1.5, -0.55, 0.0, 1.0)]
    assert all(t < 0 for t in taus)
    assert taus[2] == pytest.approx(-(15.5 * 2.147**2 - 4.5 * 2.147**3), rel=1e-9)
    # the spring carries part of the holding torque
    assert plant.gravity_torque(REF)[1] == pytest.approx(-45.065 - taus[1], abs=0.01)
    plant.apply(np.zeros(6))
    plant.step()
    assert plant.data.qfrc_spring[1] == pytest.approx(taus[1], abs=0.05)


def test_sea_deflection_carries_the_holding_torque():
    plant = make(sea={"enabled": True})
    servo = PositionServo(PositionController(), SimpleNamespace(plant=plant))
    for k in range(1000):
        q, qd = plant.sensors()
        msg = servo.control(ControlInput(k, k * 0.002, REF, np.zeros(6), SensorMsg(k * 0.002, q, qd)))
        plant.apply(msg.tau)
        plant.step()
    q, qd = plant.true_state()
    assert np.abs(q - REF).max() < 2e-3 and np.abs(qd).max() < 1e-2
    rotor = plant.data.qpos[plant._rotor_q]
    deflection = rotor - q
    # static spring torque = holding torque: 45.07 N·m / 1500 N·m/rad = 0.030 rad on s1
    assert deflection[1] == pytest.approx(-45.065 / 1500.0, rel=0.02)
    assert deflection[3] == pytest.approx(-11.022 / 1000.0, rel=0.02)


def test_sensor_noise_is_seeded():
    a = make(sensor_noise_rad=0.01)
    b = make(sensor_noise_rad=0.01)
    qa = np.array([a.sensors()[0] for _ in range(200)])
    qb = np.array([b.sensors()[0] for _ in range(200)])
    np.testing.assert_array_equal(qa, qb)
    assert np.std(qa - REF) == pytest.approx(0.01, rel=0.15)
    np.testing.assert_array_equal(a.true_state()[0], REF)


def test_position_servo_holds_and_outputs_zero_without_sensor():
    plant = make()
    servo = PositionServo(PositionController(), SimpleNamespace(plant=plant))
    msg = servo.control(ControlInput(0, 0.0, REF, np.zeros(6), None))
    assert msg.stamp_s == 0.0 and np.all(msg.tau == 0.0)
    for k in range(500):
        q, qd = plant.sensors()
        plant.apply(servo.control(ControlInput(k, k * 0.002, REF, np.zeros(6), SensorMsg(k * 0.002, q, qd))).tau)
        plant.step()
    assert np.abs(plant.true_state()[0] - REF).max() < 1e-3


def test_pendulum_body_only_when_an_experiment_schedules_one(load):
    from cerebx.build import build_components
    from cerebx.plants.base import PlantEvent

    plain = build_components(load(["+task=circle", "controller=pd"])).plant
    assert not plain.has_pendulum and plain.model.nv == 6
    with pytest.raises(ValueError, match="built without the pendulum"):
        plain.handle_event(PlantEvent(0.0, "attach_payload", {"mass_kg": 0.5, "rod_length_m": 0.3}))
    plain.handle_event(PlantEvent(0.0, "attach_payload", {"mass_kg": 0.5, "rod_length_m": 0.0}))
    cfg = load(["+task=circle", "controller=pd",
                "events=[{at_trial: 1, action: {kind: attach_payload, mass_kg: 0.5, rod_length_m: 0.3}}]"])
    swinging = build_components(cfg).plant
    assert swinging.has_pendulum and swinging.model.nv == 9


def test_torque_lag_is_first_order():
    plant = make(gravity_compensation=True, torque_lag_ms=10.0)
    tau = np.array([0.0, 0.0, 0.0, 0.0, 1.0, 0.0])
    produced = []
    for _ in range(5):  # 10 ms
        plant.apply(tau)
        plant.step()
        produced.append(plant.data.ctrl[4])
    np.testing.assert_allclose(produced, 1.0 - np.exp(-np.arange(1, 6) * 0.002 / 0.010), rtol=1e-9)
    instant = make(gravity_compensation=True)
    instant.apply(tau)
    instant.step()
    assert instant.data.ctrl[4] == 1.0


def test_saturation_is_numpy_s_clip_nan_and_infinities_included():
    rng = np.random.default_rng(4)
    limit = np.array([50.0, 50.0, 50.0, 50.0, 15.0, 15.0])
    for _ in range(200):
        tau = rng.normal(0.0, 40.0, 6)
        tau[rng.integers(0, 6)] = rng.choice([np.nan, np.inf, -np.inf, 50.0, -15.0, 0.0, -0.0])
        want = np.minimum(np.maximum(tau, -limit), limit)
        out = np.empty(6)
        _saturate(tau, limit, out)
        assert out.tobytes() == want.tobytes()
    loop_finite = all_finite(np.array([1.0, 2.0])), all_finite(np.array([1.0, np.nan])), all_finite(np.zeros(0))
    assert loop_finite == (True, False, True)
    assert not all_finite(np.array([[1.0], [-np.inf]]))


def _swing(arm: BaxterArm, n: int) -> np.ndarray:
    arm.reset(np.zeros(arm.n_joints), np.random.default_rng(0))
    out = []
    for k in range(n):
        arm.data.ctrl[:6] = -2.0 * arm.data.qpos[:6] + 0.5 * np.sin(0.05 * k)
        mujoco.mj_step(arm.model, arm.data, nstep=4)
        out.append(arm.data.qpos.copy())
    return np.array(out)


def test_mujoco_s_step_timers_are_off_the_motion_the_same_and_a_timer_of_your_own_kept():
    """An arm turns MuJoCo's per-stage clock reads off (``without_step_timers``): the steps are counted, no time
    is summed, and the arm moves exactly as with the timers on; a timer callback someone installed stays."""
    step = mujoco.mjtTimer.mjTIMER_STEP
    try:
        arm = BaxterArm(BaxterConfig(frictionloss_Nm=[0.3] * 4 + [0.1] * 2))
        off = _swing(arm, 200)
        assert arm.data.timer[step].number == 800 and arm.data.timer[step].duration == 0.0
        mujoco.set_mjcb_time(None)
        on = _swing(arm, 200)
        assert arm.data.timer[step].duration > 0.0
        assert np.array_equal(on, off)

        def own() -> float:
            return 1.0

        mujoco.set_mjcb_time(own)
        BaxterArm(BaxterConfig())
        assert mujoco.get_mjcb_time() is own
    finally:
        mujoco.set_mjcb_time(None)
        without_step_timers()


def test_an_unpickled_arm_turns_the_timers_off_again():
    """A resumed run unpickles its plant instead of building it: the timers are off there as well."""
    import pickle

    arm = BaxterArm(BaxterConfig())
    try:
        mujoco.set_mjcb_time(None)
        back = pickle.loads(pickle.dumps(arm))
        assert mujoco.get_mjcb_time() is not None
        mujoco.mj_step(back.model, back.data)
        assert back.data.timer[mujoco.mjtTimer.mjTIMER_STEP].duration == 0.0
    finally:
        without_step_timers()
