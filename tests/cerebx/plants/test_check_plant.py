"""The plant contract checker, run over every registered plant kind."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from cerebx import registry
from cerebx.plants.check import PlantContractError, check_plant

registry.load_plugins()


def _factory(kind: str, **overrides):
    entry = registry.plants[kind]
    try:
        builder = entry.resolve()
    except ImportError as err:
        pytest.skip(f"plant {kind!r} does not import yet: {err}")
    cfg = entry.schema(**overrides)
    return lambda: builder(cfg, SimpleNamespace(cfg=None, plant=None, task=None))


@pytest.mark.parametrize("kind", registry.plants.kinds())
def test_registered_plant_satisfies_contract(kind):
    check_plant(_factory(kind))


@pytest.mark.parametrize(
    "overrides",
    [
        {"sea": {"enabled": True}},
        {"s1_spring": {"enabled": True}, "gravity_compensation": True},
        {"sensor_noise_rad": 0.002, "sensor_noise_rad_per_s": 0.01, "physics_dt_ms": 1.0},
    ],
    ids=["sea", "spring_gravcomp", "noise_1ms"],
)
def test_baxter_variants_satisfy_contract(overrides):
    check_plant(_factory("baxter", **overrides))


def test_checker_catches_a_plant_that_does_not_saturate():
    from cerebx.plants.baxter import BaxterArm

    class Unsaturated(BaxterArm):
        def apply(self, tau):
            self.data.ctrl[:] = tau
            return np.array(tau, dtype=float)

    with pytest.raises(PlantContractError, match="saturate"):
        check_plant(Unsaturated)


def test_checker_catches_nondeterminism():
    from cerebx.plants.baxter import BaxterArm

    class Jittery(BaxterArm):
        def sensors(self):
            q, qd = super().sensors()
            return q + np.random.default_rng().normal(0, 1e-6, 6), qd

    with pytest.raises(PlantContractError, match="identical"):
        check_plant(Jittery)


def test_lwr3_with_object_and_springs_satisfies_contract():
    check_plant(_factory("lwr3", object_mass_kg=0.5, stiffness_Nm_per_rad=(300.0, 300.0, 300.0),
                         spring_ref_rad=(0.0, 0.6, 0.6), damping_Nms_per_rad=15.0))
