"""Cartesian Baxter tasks: IK joint paths reproduce their Cartesian paths (SPEC §2)."""

from __future__ import annotations

from types import SimpleNamespace

import mujoco
import numpy as np
import pytest

from cerebx import registry
from cerebx.plants.baxter import JOINT_RANGE, kinematic_mjcf
from cerebx.registry import load_plugins
from cerebx.schema import task as T
from cerebx.tasks import cartesian
from cerebx.tasks.ik import SiteIK, rotation_angle

load_plugins()
LO = np.array([r[0] for r in JOINT_RANGE])
HI = np.array([r[1] for r in JOINT_RANGE])
CONFIGS = {
    "circle": T.CircleTask(),
    "eight": T.EightTask(),
    "inclined_circle": T.InclinedCircleTask(),
    "circle_eight": T.CircleEightTask(),
    "reaching": T.ReachingTask(),
}
R = 0.12


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return tmp_path_factory.mktemp("ik_cache")


@pytest.fixture(scope="module")
def tasks(cache):
    ctx = SimpleNamespace(cache_dir=cache, plant=None)
    return {k: registry.tasks.build(cfg, ctx) for k, cfg in CONFIGS.items()}


@pytest.fixture(scope="module")
def fk():
    ik = SiteIK(mujoco.MjModel.from_xml_string(kinematic_mjcf()), "end_effector", 6, LO, HI)
    return ik.fk


@pytest.mark.parametrize("kind", list(CONFIGS))
def test_joint_paths_reproduce_cartesian_paths(kind, tasks, fk):
    task = tasks[kind]
    for v in range(task.variants):
        q, xyz = task._q[v], task._xyz[v]
        pos_err = max(np.linalg.norm(fk(qi)[0] - xi) for qi, xi in zip(q[::5], xyz[::5], strict=True))
        rot_err = max(rotation_angle(fk(qi)[1], task.orientation) for qi in q[::5])
        assert pos_err < 1e-3, f"{kind} variant {v}: {pos_err * 1e3:.3f} mm"
        assert np.rad2deg(rot_err) < 1.0
        assert np.all(q >= LO) and np.all(q <= HI)


@pytest.mark.parametrize("kind", list(CONFIGS))
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
    files = [f for f in cache.glob("ik_circle_*.npz") if not f.name.startswith("ik_circle_eight")]
    assert len(files) == 1
    monkeypatch.setattr(cartesian, "solve_paths", lambda *a: pytest.fail("IK was re-run despite the cache"))
    again = registry.tasks.build(CONFIGS["circle"], SimpleNamespace(cache_dir=cache))
    np.testing.assert_array_equal(again._q, tasks["circle"]._q)
    assert cartesian.cache_key(T.CircleTask(radius_m=0.1)) != cartesian.cache_key(CONFIGS["circle"])
