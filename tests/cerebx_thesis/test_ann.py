"""The rate-based cerebellum: state coding, exact first-step outputs and weight changes, state
round trip, and a short closed loop on Baxter whose later trials track better than the first."""

from __future__ import annotations

import numpy as np
import pytest

from cerebx.build import build_components
from cerebx.controllers.base import ControlInput, SensorMsg
from cerebx.errors import StateMismatchError
from cerebx.loop.loop import ClosedLoop
from cerebx.schema.controller import GivenRanges
from cerebx_thesis.ann.controller import ANN
from cerebx_thesis.ann.schema import ANNController

pytestmark = pytest.mark.integration

NJ = 6
RANGES = GivenRanges(
    q_min=(-1.0,) * NJ,
    q_max=(1.0,) * NJ,
    qd_des_min=(-2.0,) * NJ,
    qd_des_max=(2.0,) * NJ,
    qd_min=(-2.0,) * NJ,
    qd_max=(2.0,) * NJ,
)


def _ann(**kw) -> ANN:
    return ANN(ANNController(ranges=RANGES, **kw))


def _inp(q_des, q, qd_des=None, qd=None) -> ControlInput:
    z = np.zeros(NJ)
    qd_des = z if qd_des is None else qd_des
    qd = z if qd is None else qd
    return ControlInput(0, 0.0, np.asarray(q_des, float), qd_des, SensorMsg(0.0, np.asarray(q, float), qd))


def test_state_coding_lists_16_cells_per_joint():
    ann = _ann()
    z = np.zeros(NJ)
    q = np.array([-0.9, -0.4, 0.1, 0.6, 0.99, 5.0])  # bins 0, 1, 2, 3, 3, clipped to 3
    cells = ann.active_cells(q, q, z, z)
    assert cells.shape == (NJ, 16)
    for j in range(NJ):
        row = cells[j] - 256 * j
        assert row.min() >= 0 and row.max() < 256
        assert len(set(row.tolist())) == 13  # the current state is listed once per signal
    # joint 0: q_d and q in bin 0, both velocities in bin 2 (0 in [-2, 2]) -> state 0*64 + 0*16 + 2*4 + 2
    base0 = 10
    assert np.count_nonzero(cells[0] == base0) == 4
    np.testing.assert_array_equal(cells[0, :4], [base0 + 64 * v for v in range(4)])
    assert np.count_nonzero(cells[5] == 5 * 256 + 3 * 64 + 3 * 16 + 10) == 4


def test_joint0_overwrite_quirk():
    ann = _ann(joint0_overwrite=True)
    z = np.zeros(NJ)
    q = np.linspace(-0.9, 0.9, NJ)
    cells = ann.active_cells(q, q, z, z)
    clean = _ann().active_cells(q, q, z, z)
    exact = [np.bincount(clean[j]).argmax() for j in range(1, NJ)]  # each joint's current state
    np.testing.assert_array_equal(cells[0, 1:6], exact)
    np.testing.assert_array_equal(cells[0, 6:], clean[0, 6:])
    np.testing.assert_array_equal(cells[1:], clean[1:])


def test_first_step_outputs():
    """all_joints: PC = 96 w_init = 1.2 silences the DCN; own_joint: PC = 0.2, tau = 0.2 gain clip(e)."""
    e_pos = np.array([0.05, -0.02, 0.0, 0.3, -0.5, 0.01])  # rad; errors = k_pos * e_pos
    inp = _inp(e_pos, np.zeros(NJ))
    tau_all = _ann(plasticity=False).control(inp).tau
    np.testing.assert_allclose(tau_all, 0.0, atol=1e-12)
    own = _ann(plasticity=False, pc_input="own_joint")
    e = np.asarray(own.cfg.k_pos) * e_pos
    np.testing.assert_allclose(own.control(inp).tau, 0.2 * np.asarray(own.cfg.gain_Nm) * np.clip(e, -1, 1))


def test_plasticity_one_step_exact():
    """dw = (LTP (1 - IO) - LTD IO) |e| per listing; the current state is listed 4 times."""
    ann = _ann(pc_input="own_joint")
    e_pos = np.zeros(NJ)
    e_pos[3] = 0.05  # joint e1: e = 8 * 0.05 = 0.4 -> IO_ag = 0.4, IO_an = 0
    z = np.zeros(NJ)
    cells = ann.active_cells(e_pos, z, z, z)
    ann.control(_inp(e_pos, z))
    c = ann.cfg
    e = c.k_pos[3] * 0.05
    w0 = ann.w_init
    base, other = np.bincount(cells[3]).argmax(), cells[3][0]
    d_ag = (c.ltp * (1 - e) - c.ltd * e) * e
    d_an = c.ltp * e
    assert ann.w[6, base] == pytest.approx(w0 + 4 * d_ag, rel=1e-12)
    assert ann.w[6, other] == pytest.approx(w0 + d_ag, rel=1e-12)
    assert ann.w[7, base] == pytest.approx(w0 + 4 * d_an, rel=1e-12)
    # joints with zero error and cells outside the active lists do not change
    changed = np.argwhere(ann.w != w0)
    assert set(changed[:, 0]) == {6, 7}
    assert set(changed[:, 1]) <= set(cells[3].tolist())


def test_weights_stay_in_bounds():
    ann = _ann(ltd=0.5, ltp=0.5)
    rng = np.random.default_rng(0)
    for _ in range(200):
        ann.control(
            _inp(
                rng.uniform(-1, 1, NJ), rng.uniform(-1, 1, NJ), rng.uniform(-2, 2, NJ), rng.uniform(-2, 2, NJ)
            )
        )
    assert ann.w.min() >= 0.0 and ann.w.max() <= 1.5 * 0.0125 + 1e-15
    assert ann.w.min() == 0.0 and ann.w.max() == pytest.approx(1.5 * 0.0125)


def test_state_round_trip(tmp_path):
    a = _ann()
    rng = np.random.default_rng(1)
    for _ in range(50):
        a.control(_inp(rng.uniform(-1, 1, NJ), rng.uniform(-1, 1, NJ)))
    a.save_state(tmp_path / "s.npz")
    b = _ann()
    b.load_state(tmp_path / "s.npz")
    np.testing.assert_array_equal(a.w, b.w)
    with pytest.raises(StateMismatchError):
        _ann(bins=3).load_state(tmp_path / "s.npz")


def _run(load, trials: int, *extra: str) -> list[float]:
    cfg = load(["+task=circle", "controller=ann", f"trials={trials}", *extra])
    loop = ClosedLoop(build_components(cfg), None)
    loop.start()
    return [loop.run_trial(i).mae for i in range(trials)]


def test_ann_learns_the_circle(load):
    """Later trials on Baxter's circle track better than the first ones, and only with plasticity."""
    mae = _run(load, 12)
    assert np.mean(mae[-3:]) < 0.6 * mae[1] and np.mean(mae[-3:]) < 0.5 * mae[0]
    frozen = _run(load, 4, "controller.plasticity=false")
    assert frozen[-1] > 2 * np.mean(mae[-3:])


def test_delayed_measurement_is_paired_with_the_newest_desired():
    """As the original analog_cerebellum.py: the newest arrived measurement (stamp t - d) against the
    newest desired sample (time t), in the error and in the state coding; 'sensor_stamp' aligns them."""
    ann = _ann(plasticity=False, pc_input="own_joint")
    aligned = _ann(plasticity=False, pc_input="own_joint", desired="sensor_stamp")
    z = np.zeros(NJ)
    old, new = np.full(NJ, -0.5), np.full(NJ, 0.02)
    for a in (ann, aligned):  # desired sample at tick 0 (t = 0), then at tick 5 (t = 10 ms)
        a.control(ControlInput(0, 0.0, old, z, None))
    meas = SensorMsg(0.0, np.zeros(NJ), z)  # measured at t = 0, arrives 10 ms later
    tau = ann.control(ControlInput(5, 0.010, new, z, meas)).tau
    e = np.asarray(ann.cfg.k_pos) * new
    np.testing.assert_allclose(tau, 0.2 * np.asarray(ann.cfg.gain_Nm) * np.clip(e, -1, 1))
    tau_aligned = aligned.control(ControlInput(5, 0.010, new, z, meas)).tau
    e_old = np.asarray(ann.cfg.k_pos) * old
    np.testing.assert_allclose(tau_aligned, 0.2 * np.asarray(ann.cfg.gain_Nm) * np.clip(e_old, -1, 1))


def test_weight_change_scales_with_the_granule_cells_joint_error():
    """The original updates every PC's weights from joint j's listed cells with |e_j| (its loop runs over
    the granule cells' joint): a PC of a joint without error still learns on another joint's cells."""
    ann = _ann()
    e_pos = np.zeros(NJ)
    e_pos[3] = 0.05  # only joint e1 has an error: e = 8 * 0.05 = 0.4
    z = np.zeros(NJ)
    cells = ann.active_cells(e_pos, z, z, z)
    ann.control(_inp(e_pos, z))
    c, w0 = ann.cfg, ann.w_init
    e = c.k_pos[3] * 0.05
    base = np.bincount(cells[3]).argmax()
    # PC 0 (s0 agonist, IO = 0) potentiates on e1's cells by LTP |e_e1|, and not at all on s0's own cells
    assert ann.w[0, base] == pytest.approx(w0 + 4 * c.ltp * e, rel=1e-12)
    assert np.all(ann.w[:, cells[0]] == w0)
    assert ann.w[6, base] == pytest.approx(w0 + 4 * (c.ltp * (1 - e) - c.ltd * e) * e, rel=1e-12)


def test_ann_preset_runs_without_supervisor_or_filter(load):
    """The original ANN launches send its torque, delayed, straight to the robot (as the PD's)."""
    cfg = load(["+task=circle", "controller=ann"])
    assert [s.kind for s in cfg.robot] == ["hold"]
    assert cfg.controller.desired == "newest" and cfg.controller.plasticity_error == "granule_joint"


def test_the_estimate_counts_the_ann_controllers_own_cost():
    """The ANN declares its CPU per simulated second (``cpu_per_sim_s``): its quick-profile runs took 82.6 ms per
    simulated s against PD's 31 (2026-11-28), and the estimate of a run says so without naming the plugin."""
    from cerebx.config import load
    from cerebx.estimate import estimate

    ann, _ = load(["+task=circle", "controller=ann", "trials=100"])
    pd, _ = load(["+task=circle", "controller=pd", "trials=100"])
    assert estimate(ann).cpu_s - estimate(pd).cpu_s == pytest.approx(0.050 * 200.0)
    assert "cpu_per_sim_s" not in ann.controller.model_dump()  # not a config value: recorded runs keep their config
