"""Cartesian Baxter tasks: IK joint paths reproduce their Cartesian paths (docs/models.md#cartesian-tasks)."""

from __future__ import annotations

import os
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from cerebx import registry
from cerebx.plants.baxter import JOINT_RANGE, W2_RANGE, kinematic_model
from cerebx.registry import load_plugins
from cerebx.schema import task as T
from cerebx.tasks import cartesian
from cerebx.tasks.ik import SiteIK, rotation_angle

pytestmark = pytest.mark.integration

load_plugins()
LO = np.array([r[0] for r in JOINT_RANGE])
HI = np.array([r[1] for r in JOINT_RANGE])
CONFIGS = {
    "circle": T.CircleTask(),
    "eight": T.EightTask(),
    "inclined_circle": T.InclinedCircleTask(),
    "circle_eight": T.CircleEightTask(),
    "reaching": T.ReachingTask(),
    "reaching_joint": T.ReachingTask(space="joint", profile="ramp_linear"),
}
R = 0.12


# the IK of the reaching targets takes a minute or more: in `make test-slow`
SLOW = {"reaching"}


def kinds(names):
    return [pytest.param(k, marks=pytest.mark.slow) if k in SLOW else k for k in names]


class Tasks(dict):
    """The tasks of CONFIGS, each built (and its IK solved or read from the cache) when first asked for."""

    def __init__(self, cache_dir: Path):
        super().__init__()
        self.ctx = SimpleNamespace(cache_dir=cache_dir, plant=None)

    def __missing__(self, kind: str):
        self[kind] = task = registry.tasks.build(CONFIGS[kind], self.ctx)
        return task


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    """The run's IK cache when the test command names one (make test does), so runs and these tests
    solve each path once; a fresh folder otherwise."""
    shared = os.environ.get("CEREBX_CACHE")
    return Path(shared) if shared else tmp_path_factory.mktemp("ik_cache")


@pytest.fixture(scope="module")
def tasks(cache):
    return Tasks(cache)


@pytest.fixture(scope="module")
def fk():
    ik = SiteIK(kinematic_model(), "end_effector", 6, LO, HI)
    return ik.fk


@pytest.fixture(scope="module")
def fk7():
    lo, hi = np.append(LO, W2_RANGE[0]), np.append(HI, W2_RANGE[1])
    return SiteIK(kinematic_model(w2=True), "end_effector", 7, lo, hi).fk


@pytest.mark.parametrize("kind", kinds(CONFIGS))
def test_joint_paths_reproduce_cartesian_paths(kind, tasks, fk, fk7):
    """The 6-joint path (w2 dropped) puts the hand on the Cartesian path; the 7-joint solution also
    holds the orientation, and dropping w2 only turns the hand about the w2 axis."""
    task = tasks[kind]
    for v in range(task.variants):
        q, q7, xyz = task._q[v], task._q7[v], task._xyz[v]
        np.testing.assert_array_equal(q, q7[:, :6])
        pos_err = max(np.linalg.norm(fk(qi)[0] - xi) for qi, xi in zip(q[::5], xyz[::5], strict=True))
        assert pos_err < 1e-3, f"{kind} variant {v}: {pos_err * 1e3:.3f} mm"
        if kind != "reaching_joint":  # joint-space legs hold the orientation only at home and target
            rot_err = max(rotation_angle(fk7(qi)[1], task.orientation) for qi in q7[::5])
            assert np.rad2deg(rot_err) < 1.0
        # without w2 the hand differs from the held orientation exactly by the w2 angle
        turn = [rotation_angle(fk(qi[:6])[1], fk7(qi)[1]) for qi in q7[::25]]
        np.testing.assert_allclose(turn, np.abs(q7[::25, 6]), atol=1e-6)
        assert np.all(q >= LO) and np.all(q <= HI)


# docs/provenance.md#original-trajectories: per-joint min/max (s0..w1) of the original's joint paths
FACTS_ENVELOPE = {
    "circle": ([-0.9645, -0.4745, 0.0101, 0.5934, -0.0652, 0.2496], [-0.5591, -0.0393, 0.0352, 1.7914, 0.0180, 1.0145]),
    "eight": ([-0.9495, -0.4231, -0.0220, 1.0062, -0.0185, 0.4140], [-0.5446, -0.2194, 0.0105, 1.5791, 0.0361, 0.7834]),
    "inclined_circle": ([-0.9632, -0.3396, 0.0100, 0.9123, -0.0629, 0.2603],
                        [-0.5636, -0.2716, 0.0328, 1.6141, 0.0214, 0.9291]),
    "reaching": ([-0.9619, -0.4745, 0.0, 0.5944, -0.0626, 0.2499], [-0.5664, -0.0398, 0.0344, 1.7909, 0.0162, 1.0140]),
    "reaching_joint": ([-0.9619, -0.4745, 0.0, 0.5944, -0.0626, 0.2499],
                       [-0.5664, -0.0398, 0.0344, 1.7909, 0.0162, 1.0140]),
}


@pytest.mark.parametrize("kind", kinds(FACTS_ENVELOPE))
def test_joint_envelopes_match_the_original_paths(kind, tasks):
    qmin, qmax, _, _ = tasks[kind].envelope()
    lo, hi = (np.array(a) for a in FACTS_ENVELOPE[kind])
    assert np.abs(qmin - lo).max() < 0.05, f"{kind} min {np.round(qmin, 3)} vs {lo}"
    assert np.abs(qmax - hi).max() < 0.05, f"{kind} max {np.round(qmax, 3)} vs {hi}"


def test_circle_paths_close_and_stay_slow(tasks):
    """The redundancy is resolved towards home, so the circle closes; e0 and w0 move by a few
    hundredths of a radian at ~0.1 rad/s (the 6-joint IK swung them by ~0.5 rad at ~2 rad/s)."""
    task = tasks["circle"]
    q = task._q[0]
    assert np.abs(q[-1] - q[0]).max() < 0.01
    qd = task._qd[0]
    assert np.abs(qd[:, [2, 4]]).max() < 0.3


def test_joint_reaching_ramp_matches_the_original_velocity_ranges(tasks):
    """The [B] launch file's velocity ranges are the envelope of the original reaching file."""
    _, _, qdmin, qdmax = tasks["reaching_joint"].envelope()
    b = np.array([0.27, 0.39, 0.043, 0.95, 0.079, 0.556])
    assert np.all(np.maximum(-qdmin, qdmax) <= b + 0.01)
    np.testing.assert_allclose(qdmax[[1, 3, 5]], b[[1, 3, 5]], atol=0.02)


@pytest.mark.parametrize("kind", kinds(CONFIGS))
def test_shape_period_and_velocity(kind, tasks):
    task = tasks[kind]
    ref = task.trial(0, np.random.default_rng(0))
    assert ref.q.shape == (task.steps_per_trial, 6) == ref.qd.shape
    assert ref.xyz.shape == (task.steps_per_trial, 3)
    assert task.steps_per_trial == round(CONFIGS[kind].period_s / 0.002)
    # velocity is the periodic derivative of the position path
    np.testing.assert_allclose(ref.qd, (np.roll(ref.q, -1, 0) - np.roll(ref.q, 1, 0)) / 0.004)
    # continuity, including the wrap from the last sample to the first (back-to-back trials)
    step = np.linalg.norm(np.diff(np.vstack([ref.xyz, ref.xyz[:1]]), axis=0), axis=1)
    assert step.max() < 2 * np.pi * R / 1000 * 2.5
    np.testing.assert_allclose(task.start_position(), CONFIGS[kind].home_q_rad)


def test_circle_geometry(tasks, fk):
    task = tasks["circle"]
    centre = fk(np.array(CONFIGS["circle"].home_q_rad))[0]
    ref = task.trial(3, np.random.default_rng(1))
    np.testing.assert_allclose(np.linalg.norm(ref.xyz[:, :2] - centre[:2], axis=1), R, atol=1e-12)
    np.testing.assert_allclose(ref.xyz[:, 2], centre[2], atol=1e-12)
    np.testing.assert_allclose(ref.xyz[0], centre + [-R, 0, 0], atol=1e-12)  # Eq. 2.19 at t = 0
    np.testing.assert_allclose(ref.xyz[250], centre + [0, -R, 0], atol=1e-12)


def test_eight_and_inclined_geometry(tasks):
    c = tasks["eight"].centre
    xyz = tasks["eight"].trial(0, np.random.default_rng(0)).xyz - c
    np.testing.assert_allclose([xyz[:, 0].max(), xyz[:, 1].max()], [R / 2, R], atol=1e-6)
    xyz = tasks["inclined_circle"].trial(0, np.random.default_rng(0)).xyz - c
    tilt = np.deg2rad(30)
    np.testing.assert_allclose(xyz[:, 2], xyz[:, 0] * np.tan(tilt), atol=1e-12)
    np.testing.assert_allclose(xyz[:, 0].max(), R * np.cos(tilt), atol=1e-6)


@pytest.mark.slow
def test_reaching_targets_order_and_bell_velocity(tasks):
    task = tasks["reaching"]
    assert task.variants == 8
    labels = [task.trial(i, np.random.default_rng(s)).label for i, s in enumerate(range(40))]
    assert len(set(labels)) == 8
    rng_a, rng_b = np.random.default_rng(5), np.random.default_rng(5)
    assert [task.trial(i, rng_a).label for i in range(10)] == [task.trial(i, rng_b).label for i in range(10)]
    ref = task.trial(0, np.random.default_rng(0))
    d = np.linalg.norm(ref.xyz - task.centre, axis=1)
    assert d[0] == 0.0 and d[500] == pytest.approx(R) and d.max() == pytest.approx(R)
    speed = np.linalg.norm(np.diff(ref.xyz, axis=0), axis=1)
    assert np.argmax(speed[:500]) in (249, 250)  # minimum-jerk: peak speed at mid-reach
    assert speed[0] < 1e-3 * speed.max() and speed[499] < 1e-2 * speed.max()
    # targets every pi/4 on the circle, the first one where the circle starts
    ends = np.array([task._xyz[v, 500] - task.centre for v in range(8)])
    sector = np.arctan2(ends[:, 1], ends[:, 0]) / (np.pi / 4)
    np.testing.assert_allclose(sector, np.round(sector), atol=1e-9)
    assert sorted(np.mod(np.round(sector).astype(int), 8)) == list(range(8))
    np.testing.assert_allclose(ends[0], [-R, 0, 0], atol=1e-12)


@pytest.mark.slow
def test_envelope_covers_every_reaching_target(tasks):
    task = tasks["reaching"]
    qmin, qmax, qdmin, qdmax = task.envelope()
    for v in range(8):
        ref = cartesian.TrialReference(task._q[v], task._qd[v])
        assert np.all(ref.q >= qmin) and np.all(ref.q <= qmax)
        assert np.all(ref.qd >= qdmin) and np.all(ref.qd <= qdmax)
    one = task.trial(0, np.random.default_rng(0))
    assert np.any(qmax > one.q.max(0) + 1e-3)  # wider than a single target


def test_ik_is_cached_on_disk(cache, tasks, monkeypatch):
    first = tasks["circle"]
    assert (cache / f"ik_circle_{cartesian.cache_key(CONFIGS['circle'])}.npz").is_file()
    monkeypatch.setattr(cartesian, "solve_paths", lambda *a: pytest.fail("IK was re-run despite the cache"))
    monkeypatch.setattr(cartesian, "_arm_ik", lambda *a: pytest.fail("IK was re-run despite the cache"))
    again = registry.tasks.build(CONFIGS["circle"], SimpleNamespace(cache_dir=cache))
    np.testing.assert_array_equal(again._q, first._q)
    assert cartesian.cache_key(T.CircleTask(radius_m=0.1)) != cartesian.cache_key(CONFIGS["circle"])
