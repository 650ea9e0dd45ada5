"""Upper-limb tasks (thesis Fig. 4.4, constructed paths): bell-shaped velocity profiles, consistent
positions and velocities, the circle really is a circle of the plant's hand."""

from __future__ import annotations

import numpy as np

from cerebx.plants.upper_limb import UpperLimb
from cerebx.schema.arm_tasks import FlexionExtensionTask, VerticalCircleTask
from cerebx.schema.plant import UpperLimbConfig
from cerebx.tasks.upper_limb import SHOULDER_WORLD_M, FlexionExtension, VerticalCircle


def _bell(speed: np.ndarray) -> None:
    """One smooth peak: zero at both ends, rising to a single maximum in the middle, then falling."""
    k = int(np.argmax(speed))
    assert speed[0] < 1e-4 * speed[k] and speed[-1] < 0.01 * speed[k]
    assert 0.4 < k / len(speed) < 0.6
    assert np.all(np.diff(speed[: k + 1]) >= -1e-12) and np.all(np.diff(speed[k:]) <= 1e-12)


def test_flexion_extension_out_and_back_with_bell_shaped_speed():
    task = FlexionExtension(FlexionExtensionTask())
    ref = task.trial(0, np.random.default_rng(0))
    assert ref.steps == 1500 and task.period_s == 3.0
    assert np.allclose(ref.q[0], (0.1, 0.3)) and np.allclose(ref.q[750], (0.8, 1.5))
    for half in (ref.qd[:750, 1], -ref.qd[750:, 1]):
        _bell(half)
    # peak speed of a minimum-jerk move: 1.875 x distance / duration
    assert np.isclose(ref.qd[:, 1].max(), 1.875 * 1.2 / 1.5, rtol=1e-3)
    assert np.allclose(np.gradient(ref.q, 0.002, axis=0)[1:-1], ref.qd[1:-1], atol=2e-3)


def test_vertical_circle_is_a_circle_of_the_hand_and_fast_is_twice_as_quick():
    slow, fast = VerticalCircle(VerticalCircleTask()), VerticalCircle(VerticalCircleTask(period_s=1.5))
    rs, rf = slow.trial(0, np.random.default_rng(0)), fast.trial(0, np.random.default_rng(0))
    assert (rs.steps, rf.steps) == (1500, 750)
    arm = UpperLimb(UpperLimbConfig())
    centre = SHOULDER_WORLD_M + np.array([0.22, 0.0, -0.28])
    for i in range(0, rs.steps, 50):
        arm.reset(rs.q[i], np.random.default_rng(0))
        assert np.allclose(arm.hand(), rs.xyz[i], atol=1e-6)  # the plant's hand is on the path
        assert np.isclose(np.linalg.norm(rs.xyz[i] - centre), 0.07, atol=2e-3)
    speed = np.linalg.norm(np.gradient(rs.xyz, 0.002, axis=0), axis=1)
    _bell(speed)
    assert np.isclose(np.abs(rf.qd).max() / np.abs(rs.qd).max(), 2.0, rtol=1e-3)
    assert np.allclose(np.gradient(rs.q, 0.002, axis=0)[1:-1], rs.qd[1:-1], atol=2e-3)
