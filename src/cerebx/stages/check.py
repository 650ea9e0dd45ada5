"""Contract checker for controllers and stages, run over every registered kind (like ``check_plant``).

Each controller and stage of a built experiment is stepped for a few ticks on random valid input:
the signals it declares must be the ones it writes, finite and of the declared size; the same seed
must give the same outputs; state it saves must load. On the brain side the sensor signals are
absent in the first tick (nothing has arrived through the link yet).
"""

from __future__ import annotations

import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from cerebx.builders import BuildContext
from cerebx.signals import Frame, Message, Signal
from cerebx.stages.base import Receiver, Stage
from cerebx.wiring import reference_signals


class StageContractError(AssertionError):
    """A controller or stage breaks the stage contract."""


def _require(cond: bool, msg: str) -> None:
    if not cond:
        raise StageContractError(msg)


def _random_inputs(rng: np.random.Generator, available: dict[str, Signal]) -> dict[str, np.ndarray]:
    out = {}
    for name, sig in available.items():
        lo, hi = sig.bounds()
        lo, hi = np.where(np.isfinite(lo), lo, -0.5), np.where(np.isfinite(hi), hi, 0.5)
        out[name] = rng.uniform(lo, hi) * (0.5 if name != "ref.q" else 0.2)
    return out


def _run(stage: Stage, available: dict[str, Signal], ticks: int, seed: int, sensed_names: list[str],
         brain: bool) -> list[dict]:
    rng = np.random.default_rng(seed)
    stage.reset(np.random.default_rng(seed + 1))
    outs = []
    for k in range(ticks):
        t = k * 0.002
        values = _random_inputs(rng, available)
        sensed = Message(t, {n: values[n] for n in sensed_names if n in values}) if k or not brain else None
        signals = dict(values) if sensed is not None else {n: v for n, v in values.items() if n not in sensed_names}
        frame = Frame(k, t, signals, sensed)
        stage.step(frame)
        for sig in stage.writes:
            v = frame.signals.get(sig.name)
            _require(v is not None, f"{stage.name}: declares {sig} but did not write it")
            _require(np.shape(v) == (sig.size,), f"{stage.name}: wrote {sig.name} of shape {np.shape(v)}, "
                     f"declared {sig.size}")
            _require(bool(np.all(np.isfinite(v))), f"{stage.name}: wrote non-finite {sig.name}")
        _require(frame.stamp_s >= t - 1e-12, f"{stage.name}: stamped its output before the tick's time")
        outs.append({s.name: np.array(frame.signals[s.name]) for s in stage.writes})
    return outs


def _available(ctx: BuildContext, side: str, earlier: tuple[Signal, ...] = ()) -> dict[str, Signal]:
    """What a stage may read: the plant's sensors, the task's reference (brain side) or what crossed the
    link (robot side), and what the stages before it on its side wrote."""
    available = dict(ctx.plant.sensor_signals())
    if side == "brain":
        available.update(reference_signals(ctx.cfg))
    else:
        available.update({s.name: s for s in ctx.sent})
    available.update({s.name: s for s in earlier})
    return available


def check_receiver(stage: Receiver) -> None:
    """A receiver gives every signal it carries, finite and of its size, from a burst of arrivals."""
    msgs = [Message(k * 0.002, {s.name: np.full(s.size, float(k)) for s in stage.signals}) for k in range(5)]
    out = stage.receive(msgs, 0.0)
    for s in stage.signals:
        _require(np.shape(out[s.name]) == (s.size,), f"{stage.name}: receive() gave {s.name} of another size")
        _require(bool(np.all(np.isfinite(out[s.name]))), f"{stage.name}: receive() gave non-finite {s.name}")


def check_stage(ctx: BuildContext, stage: Stage, twin: Stage, side: str, ticks: int = 60,
                earlier: tuple[Signal, ...] = ()) -> None:
    """Step ``stage`` and ``twin`` (the same stage built again from the same config) over the same
    random valid input: declared outputs written, finite, of their size, and identical between the
    two; a saved state loads. ``earlier``: signals written by the stages before it on its side."""
    available = _available(ctx, side, earlier)
    for name in stage.reads:
        _require(name in available, f"{stage.name}: reads {name}, which the {side} side of this experiment lacks")
    sensors = list(ctx.plant.sensor_signals())
    first = _run(stage, available, ticks, 3, sensors, side == "brain")
    again = _run(twin, available, ticks, 3, sensors, side == "brain")
    for a, b in zip(first, again):
        for k in a:
            _require(np.array_equal(a[k], b[k]), f"{stage.name}: same seed and input gave different {k}")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "state.npz"
        if stage.save_state(path):
            twin.load_state(path)
    stage.end_trial(0)


def check_experiment(build: Callable[[], Any], ticks: int = 60) -> None:
    """Check the controller and every stage of an experiment against the stage contract: each is stepped
    over random valid input beside a second build of itself; declared outputs written, finite, of their size
    and identical between the two; a saved state loads. Raises on the first violation.

    Parameters
    ----------
    build : callable
        Builds the experiment afresh (e.g. ``lambda: build_components(cfg)``); called twice.
    ticks : int
        Ticks each stage is stepped.
    """
    ctx, twin = build(), build()
    earlier: tuple[Signal, ...] = ()
    for st, tw in zip(ctx.brain, twin.brain):
        check_stage(ctx, st, tw, "brain", ticks, earlier)
        earlier += tuple(st.writes)
    check_receiver(ctx.receiver)
    earlier = ()
    for st, tw in zip(ctx.robot, twin.robot):
        check_stage(ctx, st, tw, "robot", ticks, earlier)
        earlier += tuple(st.writes)
