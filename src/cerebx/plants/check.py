"""Contract checker for plants, run over every registered plant kind (like Gymnasium's ``check_env``).
A joint-torque plant is driven through ``apply``; a plant commanded with other signals (muscle
excitations) through ``actuate`` with values within the bounds its command signals declare."""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from cerebx.plants.base import Plant, PlantEvent
from cerebx.schema.events import AttachPayload, DetachPayload, ElasticBand, ForcePulse, RemoveBand

ROLLOUT_STEPS = 100

_EVENTS = {
    "attach_payload": AttachPayload(mass_kg=2.0, rod_length_m=0.0).model_dump(),
    "elastic_band": ElasticBand(stiffness_N_per_m=500.0, anchor_offset_m=(0.0, 0.0, -0.3)).model_dump(),
    "force_pulse": ForcePulse(force_N=(30.0, 30.0, 30.0), duration_ms=50.0).model_dump(),
}
_UNDO = {
    "detach_payload": ("attach_payload", DetachPayload().model_dump()),
    "remove_band": ("elastic_band", RemoveBand().model_dump()),
}


class PlantContractError(AssertionError):
    """A plant breaks the :class:`Plant` contract."""


def _require(cond: bool, msg: str) -> None:
    if not cond:
        raise PlantContractError(msg)


def _start(plant: Plant) -> np.ndarray:
    lo, hi = plant.joint_limits()
    return 0.5 * (lo + hi)


def _torques(plant: Plant, seed: int, steps: int) -> np.ndarray:
    """Random torques in a modest band around zero, the same for every plant built by a factory."""
    rng = np.random.default_rng(seed)
    probe = plant.apply(np.full(plant.n_joints, 1e9))
    return rng.uniform(-0.2, 0.2, (steps, plant.n_joints)) * probe


def _torque_plant(plant: Plant) -> bool:
    return "joint.torque" in plant.command_signals()


def _commands(plant: Plant, seed: int, steps: int) -> list[dict[str, np.ndarray]]:
    """Random commands: torques in a modest band around zero, other command signals uniform within
    their declared bounds (e.g. muscle excitations in [0, 1])."""
    if _torque_plant(plant):
        return [{"joint.torque": tau} for tau in _torques(plant, seed, steps)]
    rng = np.random.default_rng(seed)
    out: list[dict[str, np.ndarray]] = [{} for _ in range(steps)]
    for name, sig in plant.command_signals().items():
        lo, hi = sig.bounds()
        _require(bool(np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))),
                 f"command signal {name} must declare finite bounds")
        for row, v in zip(out, rng.uniform(lo, hi, (steps, sig.size))):
            row[name] = v
    return out


def _check_commands(plant: Plant) -> None:
    """A plant commanded with other signals than joint torques clips each to its declared bounds."""
    for name, sig in plant.command_signals().items():
        lo, hi = sig.bounds()
        for probe, want in ((hi + 1e9, hi), (lo - 1e9, lo), (0.5 * (lo + hi), 0.5 * (lo + hi))):
            got = plant.actuate({name: probe})
            _require(got.shape == (sig.size,) and bool(np.all(np.isfinite(got))),
                     f"actuate() must return finite {sig} values")
            _require(np.allclose(got, want), f"actuate() must clip {name} to its bounds and pass values within them")


def _rollout(plant: Plant, commands: Sequence[dict[str, np.ndarray]], seed: int,
             events: Sequence[PlantEvent] = ()) -> np.ndarray:
    plant.reset(_start(plant), np.random.default_rng(seed))
    for ev in events:
        plant.handle_event(ev)
    rows = []
    for command in commands:
        q, qd = plant.sensors()
        plant.actuate(command)
        plant.step()
        rows.append(np.concatenate([q, qd]))
    q, qd = plant.true_state()
    rows.append(np.concatenate([q, qd]))
    return np.array(rows)


def check_plant(plant_factory: Callable[[], Plant], steps: int = ROLLOUT_STEPS) -> None:
    """Raise :class:`PlantContractError` (an AssertionError) on the first contract violation.

    Parameters
    ----------
    plant_factory : callable
        Builds the plant afresh (called more than once: determinism is checked on a second plant).
    steps : int
        Control steps of the rollouts.
    """
    plant = plant_factory()
    n = plant.n_joints
    _require(n > 0 and len(plant.joint_names) == n, "joint_names must name every joint")
    _require(
        plant.substeps >= 1 and abs(plant.substeps * plant.physics_dt_s - plant.control_dt_s) < 1e-12,
        "physics_dt_s must divide control_dt_s",
    )
    lo, hi = plant.joint_limits()
    _require(lo.shape == (n,) and hi.shape == (n,), "joint_limits() must return two (n_joints,) arrays")
    _require(bool(np.all(lo < hi)), "joint_limits(): every lower limit must be below its upper limit")

    q0 = _start(plant)
    plant.reset(q0, np.random.default_rng(0))
    _require(plant.time_s == 0.0, "reset() must set time to 0")
    q, qd = plant.sensors()
    _require(q.shape == (n,) and qd.shape == (n,), "sensors() must return two (n_joints,) arrays")
    tq, _ = plant.true_state()
    _require(np.allclose(tq, q0), "reset(q0) must put the plant at q0")

    sensed = plant.sense()
    declared = plant.sensor_signals()
    _require(set(sensed) == set(declared), f"sense() returns {sorted(sensed)}, sensor_signals() {sorted(declared)}")
    for name, sig in declared.items():
        _require(np.shape(sensed[name]) == (sig.size,), f"sense(): {name} must have {sig.size} values")

    if _torque_plant(plant):
        big = plant.apply(np.full(n, 1e9))
        _require(
            big.shape == (n,) and bool(np.all(np.isfinite(big))), "apply() must return finite (n_joints,) torques"
        )
        _require(bool(np.all(big < 1e9)) and bool(np.all(big > 0)), "apply() must saturate large torques")
        _require(np.allclose(plant.apply(-np.full(n, 1e9)), -big), "saturation must be symmetric")
        _require(np.allclose(plant.apply(0.5 * big), 0.5 * big), "apply() must pass torques within the limits")
    else:
        _check_commands(plant)

    commands = _commands(plant, 1, steps)
    base = _rollout(plant, commands, 7)
    _require(bool(np.all(np.isfinite(base))), "rollout with random commands produced non-finite states")
    _require(abs(plant.time_s - steps * plant.control_dt_s) < 1e-9, "step() must advance control_dt_s")
    _require(plant.is_diverged() is None, f"plant diverged in a short rollout: {plant.is_diverged()}")
    ee = plant.end_effector()
    _require(
        ee is None or (np.shape(ee) == (3,) and bool(np.all(np.isfinite(ee)))),
        "end_effector() must be None or a finite 3-vector",
    )

    again = _rollout(plant_factory(), commands, 7)
    _require(np.array_equal(base, again), "same seed must give an identical trajectory")

    supported = set()
    for kind, params in _EVENTS.items():
        try:
            traj = _rollout(plant, commands, 7, [PlantEvent(0.0, kind, dict(params))])
        except ValueError:
            continue
        supported.add(kind)
        _require(not np.allclose(traj, base), f"event {kind!r} was accepted but did not change the dynamics")
    for kind, (needs, params) in _UNDO.items():
        if needs not in supported:
            continue
        done = [PlantEvent(0.0, needs, dict(_EVENTS[needs])), PlantEvent(0.0, kind, dict(params))]
        try:
            traj = _rollout(plant, commands, 7, done)
        except ValueError:
            continue
        _require(np.allclose(traj, base, atol=1e-6), f"event {kind!r} must undo {needs!r}")
    try:
        plant.handle_event(PlantEvent(0.0, "no_such_event", {}))
    except ValueError:
        pass
    else:
        raise PlantContractError("an unknown event kind must be refused with ValueError")
