"""Ziegler-Nichols PD tuning on the simulated plant (how a PD baseline is commonly tuned on a robot).

Per joint: the arm is first settled at a posture with the hold PD (the configured PD controller); the
settled torque is kept as a feedforward so gravity stays balanced. Then the joint under test runs
P-only, tau_j = tau_ff,j + K (q*_j + step - q_j), while the other joints keep their hold PD. K is
raised until a small step no longer dies out: the oscillation envelope (peak |error| per half
cycle) stops shrinking. K_u is the smallest such gain (found by bisection), T_u the oscillation
period there, and the classic ZN PD rule gives kp = 0.8 K_u, kd = kp T_u / 8.

Each test steps the closed loop itself (``loop/loop.py``) with the test's torque law as the
controller and the configured delay model on the link, so a tuning with ``delay=...`` sees the same
latency as a run.
"""

from __future__ import annotations

import argparse
import dataclasses
import datetime
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from cerebx.build import BuildContext, build_components
from cerebx.config import load
from cerebx.controllers.base import ControlInput, Controller, TorqueMsg
from cerebx.delay_channel import Link
from cerebx.errors import CerebxError, Diverged
from cerebx.loop.loop import ClosedLoop
from cerebx.schema.controller import PDController
from cerebx.signals import torque_controller_io
from cerebx.stages.receivers import Hold

STEP_S = 0.002
DEFAULT_OUT = Path(__file__).resolve().parents[2] / "conf" / "controller" / "pd_zn.yaml"


@dataclass(frozen=True)
class JointTuning:
    """Ultimate gain K_u (Nm/rad), period T_u (s) and the ZN PD gains for one joint."""

    joint: str
    k_u: float
    t_u: float
    kp: float
    kd: float


@dataclass(frozen=True)
class Oscillation:
    """Envelope summary of a step response: peak |error| per half cycle and its trend."""

    peaks: np.ndarray
    half_periods_s: np.ndarray

    @property
    def ratio(self) -> float:
        """Envelope of the last quarter of the half cycles over the quarter before it: below 1 the
        oscillation still decays; about 1 it is sustained (a limit cycle once torque saturates)."""
        k = len(self.peaks) // 4
        if k < 2:
            return 0.0
        return float(self.peaks[-k:].mean() / max(self.peaks[-2 * k : -k].mean(), 1e-12))

    @property
    def period_s(self) -> float:
        if len(self.half_periods_s) < 2:
            return math.nan
        return float(2.0 * np.mean(self.half_periods_s))


def envelope(x: np.ndarray, dt_s: float = STEP_S, floor: float = 1e-5) -> Oscillation:
    """Split ``x`` (error about its settling value) into half cycles at its zero crossings."""
    x = x - np.mean(x[len(x) // 2 :])
    s = np.signbit(x)
    cross = np.flatnonzero(s[1:] != s[:-1]) + 1
    if len(cross) < 3:
        return Oscillation(np.zeros(0), np.zeros(0))
    peaks = np.array([np.abs(x[a:b]).max() for a, b in zip(cross[:-1], cross[1:], strict=True)])
    keep = peaks > floor
    return Oscillation(peaks[keep], np.diff(cross)[keep] * dt_s)


class _Law(Controller):
    """tau = tau_ff + kp (target - q) - kd qd from the newest delayed measurement (tau_ff before it)."""

    def __init__(self, target: np.ndarray, tau_ff: np.ndarray, kp: np.ndarray, kd: np.ndarray):
        self.target, self.tau_ff, self.kp, self.kd = target, tau_ff, kp, kd
        self.n_joints = len(kp)
        io = torque_controller_io(self.n_joints)
        self.name, self.reads, self.writes = "tuning", io.reads, io.writes

    def reset(self, rng: np.random.Generator) -> None:
        pass

    def control(self, inp: ControlInput) -> TorqueMsg:
        s = inp.sensor
        if s is None:
            return TorqueMsg(inp.t_s, self.tau_ff)
        return TorqueMsg(inp.t_s, self.tau_ff + self.kp * (self.target - s.q) - self.kd * s.qd)


class _Rig:
    """The plant and link of one config, stepped by the closed loop with a custom per-joint torque law."""

    def __init__(self, ctx: BuildContext, hold_kp: np.ndarray, hold_kd: np.ndarray):
        self.ctx, self.plant = ctx, ctx.plant
        self.n = self.plant.n_joints
        self.hold_kp, self.hold_kd = hold_kp, hold_kd

    def simulate(
        self,
        q0: np.ndarray,
        target: np.ndarray,
        tau_ff: np.ndarray,
        kp: np.ndarray,
        kd: np.ndarray,
        steps: int,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Run ``steps`` ticks of tau = tau_ff + kp (target - q) - kd qd from rest at ``q0``.

        Returns the true joint positions (steps, n) and the last applied torque.
        """
        ctx, plant = self.ctx, self.plant
        law = _Law(target, tau_ff, kp, kd)
        link = Link(ctx.link.r2c.sampler, ctx.link.c2r.sampler)  # fresh queues, the run's delay model
        loop = ClosedLoop(dataclasses.replace(ctx, brain=[law], link=link, receiver=Hold(ctx.sent), robot=[]), None)
        plant.reset(q0, ctx.rng("tuning.plant"))
        zeros = np.zeros(self.n)
        applied = np.zeros(self.n)
        qs = np.full((steps, self.n), np.nan)
        for tick in range(steps):
            try:
                applied = loop.step(target, zeros)
            except Diverged:
                break
            qs[tick] = plant.true_state()[0]
            if not np.all(np.isfinite(qs[tick])):
                qs[tick:] = np.nan
                break
        return qs, applied

    def settle(self, q_ref: np.ndarray, seconds: float = 1.5) -> tuple[np.ndarray, np.ndarray]:
        """Hold ``q_ref`` with the hold PD; returns the settled posture and its (gravity) torque."""
        zeros = np.zeros(self.n)
        qs, tau = self.simulate(q_ref, q_ref, zeros, self.hold_kp, self.hold_kd, int(seconds / STEP_S))
        if not np.all(np.isfinite(qs[-1])):
            raise CerebxError("tune: the hold PD cannot keep the arm still; give stiffer controller gains")
        return qs[-1].copy(), tau.copy()

    def p_test(
        self, j: int, k: float, q_star: np.ndarray, tau_ff: np.ndarray, step_rad: float, seconds: float
    ) -> Oscillation:
        kp, kd = self.hold_kp.copy(), self.hold_kd.copy()
        kp[j], kd[j] = k, 0.0
        target = q_star.copy()
        target[j] += step_rad
        qs, _ = self.simulate(q_star, target, tau_ff, kp, kd, int(seconds / STEP_S))
        x = qs[:, j] - target[j]
        if not np.all(np.isfinite(x)):
            return Oscillation(np.array([1.0, 1.0, 1.0, 2.0, 2.0, 2.0]), np.full(6, math.nan))
        skip = int(0.1 / STEP_S)  # the first 100 ms is the step's own transient
        return envelope(x[skip:], floor=1e-3 * step_rad)


def ultimate_gain(
    rig: _Rig,
    j: int,
    q_star: np.ndarray,
    tau_ff: np.ndarray,
    *,
    k_start: float = 1.0,
    k_max: float = 1e5,
    rel_tol: float = 0.03,
    step_rad: float = 0.002,
    seconds: float = 2.0,
    sustained: float = 0.97,
) -> tuple[float, float]:
    """(K_u, T_u) of joint ``j``: the smallest P gain whose oscillation envelope does not decay."""

    def grows(k: float) -> tuple[bool, Oscillation]:
        osc = rig.p_test(j, k, q_star, tau_ff, step_rad, seconds)
        return osc.ratio >= sustained, osc

    lo, hi = 0.0, k_start
    ok, osc_hi = grows(hi)
    while not ok:
        lo, hi = hi, hi * 2.0
        if hi > k_max:
            return math.inf, math.nan
        ok, osc_hi = grows(hi)
    if lo == 0.0:
        raise CerebxError(f"tune: joint {j} oscillates already at K = {k_start}; lower k_start")
    while hi / lo - 1.0 > rel_tol:
        mid = math.sqrt(lo * hi)
        ok, osc = grows(mid)
        if ok:
            hi, osc_hi = mid, osc
        else:
            lo = mid
    return hi, osc_hi.period_s


def tune_pd(
    overrides: list[str],
    *,
    out: str | Path | None = DEFAULT_OUT,
    joints: list[int] | None = None,
    step_rad: float = 0.002,
    seconds: float = 2.0,
    tau_max_Nm: list[float] | None = None,
    posture: str = "task_mean",
) -> tuple[list[JointTuning], Any]:
    """Ziegler-Nichols PD gains for the plant composed from ``overrides``.

    The composed controller must be a PD: its gains hold the joints not under test and its
    ``tau_max_Nm`` becomes the tuned preset's saturation (unless ``tau_max_Nm`` is given).
    ``posture``: 'task_mean' (mean desired posture) or 'task_start'. Writes a preset YAML to
    ``out`` unless it is None. Returns the per-joint results and the tuned PD schema.
    """
    cfg, _ = load(list(overrides))
    if not isinstance(cfg.controller, PDController):
        raise CerebxError(
            f"tune: the hold controller must be a PD (got controller.kind={cfg.controller.kind!r}); "
            "add controller=pd or controller=pd_planar2"
        )
    ctx = build_components(cfg)
    n = ctx.plant.n_joints
    hold = cfg.controller
    if len(hold.kp) < n:
        raise CerebxError(f"tune: the hold PD has {len(hold.kp)} joints, the plant {n}")
    rig = _Rig(ctx, np.asarray(hold.kp[:n], float), np.asarray(hold.kd[:n], float))
    ref = ctx.task.trial(0, ctx.rng("task"))
    q_ref = ref.q.mean(0) if posture == "task_mean" else np.asarray(ctx.task.start_position(), float)
    q_star, tau_ff = rig.settle(np.asarray(q_ref, float))
    names = list(getattr(ctx.plant, "joint_names", [f"j{i}" for i in range(n)]))[:n]
    kp, kd = list(hold.kp[:n]), list(hold.kd[:n])
    results: list[JointTuning] = []
    for j in joints if joints is not None else range(n):
        k_u, t_u = ultimate_gain(rig, j, q_star, tau_ff, step_rad=step_rad, seconds=seconds)
        if not math.isfinite(k_u) or not math.isfinite(t_u):
            raise CerebxError(f"tune: no sustained oscillation on joint {names[j]} up to the maximum gain")
        kp[j] = 0.8 * k_u
        kd[j] = kp[j] * t_u / 8.0
        results.append(JointTuning(names[j], k_u, t_u, kp[j], kd[j]))
    tau_max = tuple(tau_max_Nm) if tau_max_Nm is not None else tuple(hold.tau_max_Nm[:n])
    tuned = PDController(
        kp=tuple(round(v, 3) for v in kp), kd=tuple(round(v, 4) for v in kd), tau_max_Nm=tau_max
    )
    if out is not None:
        write_preset(Path(out), tuned, results, overrides, q_star)
    return results, tuned


def write_preset(
    path: Path, pd: Any, results: list[JointTuning], overrides: list[str], posture: np.ndarray
) -> None:
    """Write a ``controller`` preset whose header records K_u and T_u per joint and the date."""
    lines = [
        "# @package _global_",
        "# PD gains from Ziegler-Nichols tuning on the simulated plant (cerebx.tuning.tune_pd,",
        f"# {datetime.date.today().isoformat()}). Overrides: {' '.join(overrides) or '(none)'}.",
        f"# Settled posture under the hold PD (rad): [{', '.join(f'{v:.3f}' for v in posture)}].",
        "# ZN PD rule: kp = 0.8 K_u, kd = kp T_u / 8.",
        "# joint   K_u (Nm/rad)   T_u (s)     kp        kd",
    ]
    lines += [f"# {r.joint:<7} {r.k_u:12.2f} {r.t_u:9.4f} {r.kp:9.2f} {r.kd:9.4f}" for r in results]
    fmt = lambda xs: "[" + ", ".join(str(float(x)) for x in xs) + "]"  # noqa: E731
    lines += [
        "controller:",
        "  kind: pd",
        f"  kp: {fmt(pd.kp)}",
        f"  kd: {fmt(pd.kd)}",
        f"  tau_max_Nm: {fmt(pd.tau_max_Nm)}",
        "robot:",
        "  - {kind: hold}",
    ]
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(lines) + "\n")


def main(args: list[str] | None = None) -> int:
    """``cerebx tune [--out PATH] [--joints 0,1] OVERRIDES...``: print K_u, T_u, gains; write a preset."""
    p = argparse.ArgumentParser(prog="cerebx tune", description=__doc__.splitlines()[0])
    p.add_argument("overrides", nargs="*", help="Hydra overrides, e.g. +task=circle controller=pd")
    p.add_argument("--out", default=str(DEFAULT_OUT), help="preset to write ('-' = do not write)")
    p.add_argument("--joints", default=None, help="comma-separated joint indices (default: all)")
    p.add_argument("--step-rad", type=float, default=0.002, help="setpoint step that excites the oscillation")
    p.add_argument("--seconds", type=float, default=2.0, help="length of each P-only test")
    p.add_argument("--posture", choices=["task_mean", "task_start"], default="task_mean")
    a = p.parse_args(args)
    joints = [int(x) for x in a.joints.split(",")] if a.joints else None
    out = None if a.out == "-" else a.out
    try:
        results, _ = tune_pd(
            a.overrides, out=out, joints=joints, step_rad=a.step_rad, seconds=a.seconds, posture=a.posture
        )
    except CerebxError as err:
        print(f"error: {err}")
        return 2
    print(f"{'joint':<8}{'K_u Nm/rad':>12}{'T_u s':>10}{'kp':>10}{'kd':>10}")
    for r in results:
        print(f"{r.joint:<8}{r.k_u:12.2f}{r.t_u:10.4f}{r.kp:10.2f}{r.kd:10.4f}")
    if out is not None:
        print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
