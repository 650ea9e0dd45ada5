"""The robot side of a wall-clock run (``cerebx robot``): plant, receiver, body slots, robot stages,
events, metrics and its own log, paced at the control rate by the monotonic clock.

One tick k starts at t0 + k x 2 ms on this host's monotonic clock; its simulated time is k x 2 ms:

========  =====================================================================================
phase     what happens
========  =====================================================================================
pace      sleep, then spin, to the tick's start (lateness: how late it woke)
events    scheduled plant events whose time has come fire
sense     the plant's sensor signals go to the brain side (SENSOR stamped with the tick's time)
wait      up to ``link.command_wait_ms`` for the command the brain side computes for this tick
receive   the commands that arrived go through the receiver; without a new command for
          ``safe_stop_after_ms`` the previous command decays by ``safe_stop_decay_per_step`` per
          tick (the original's safe stop), after ``hold_pose_after_ms`` a supervisor holds the pose
          the arm had then; each transition is a link event
robot     robot stages in order (supervisor, muscles, ...)
actuate   as in simulated time, then measure, record (with ``/timing``), physics
========  =====================================================================================

The robot side ends when its trials are done (BYE to the brain side), when the brain side says it
stopped, or when no command came from it for ``link_lost_after_ms`` (status interrupted, reason link
lost; only the session's data packets count as a sign of life, not its control packets).

Before it writes anything it pairs (``link/pairing.py``): it builds its parts after the first matching
HELLO, answers every matching HELLO with a session of its own, and opens its run folder only once the
brain side has signed a packet with one of them and asked to start.
"""

from __future__ import annotations

import argparse
import json
import logging
import sys
import time
from datetime import datetime
from pathlib import Path
from typing import Any

import numpy as np

from cerebx import registry
from cerebx.build import BuildContext
from cerebx.config import load
from cerebx.errors import CerebxError, LinkLost, PeerEnded
from cerebx.link.auth import Signer, require_key
from cerebx.link.channel import POLL_BUDGET, Arrived, LinkEnd
from cerebx.link.clock import host_identity, host_steal_ms, now_ns, pace, realtime_process
from cerebx.link.pairing import (
    START_LEAD_S,
    NotPaired,
    RemoteController,
    fingerprint,
    gave_up,
    of_this_config,
    pong,
    strangers_line,
    wait_for_hello,
    welcome,
)
from cerebx.link.stats import describe
from cerebx.link.wire import Kind, Packet
from cerebx.loop.lifecycle import RunLifecycle
from cerebx.loop.phases import DIVERGENCE_CHECK_TICKS, all_finite, check_diverged, control_message, robot_phase
from cerebx.loop.realtime import LinkEvents, TickLog, side_summary
from cerebx.metrics import TrialAccumulator, TrialMetrics, _put_row
from cerebx.plants.mujoco_arm import _saturate
from cerebx.recording.recorder import Recorder
from cerebx.recording.summary import trial_fields
from cerebx.schema.stages import SupervisorConfig
from cerebx.signals import Message
from cerebx.stages.muscles import _ekeberg
from cerebx.stages.receivers import _push_mean
from cerebx.stages.supervisor import Supervisor, _correct
from cerebx.wiring import wire

log = logging.getLogger("cerebx")

RUNNING, SAFE_STOP, HOLD_POSE = "running", "safe_stop", "hold_pose"
STALL_MS = 5.0  # a tick that starts this late begins a stall (counted in the timing summary)


def build_robot_parts(cfg: Any, facts: dict[str, Any], run_dir: Path | None) -> BuildContext:
    """The robot half of ``build_components``: plant, task (for the reference the metrics need), receiver,
    body slots, robot stages and events; the controller is known only by what the brain side told."""
    wiring = wire(cfg)
    ctx = BuildContext(cfg=cfg, run_dir=run_dir)
    ctx.plant = registry.plants.build(cfg.plant, ctx)
    ctx.task = registry.tasks.build(cfg.task, ctx)
    ctx.controller = RemoteController(facts)
    ctx.sent = wiring.sent
    ctx.receiver = registry.stages.build(wiring.receiver, ctx, ctx.sent)
    ctx.robot = [registry.stages.build(s, ctx) for s in wiring.robot]
    ctx.events = [(ev, registry.events.build(ev.action, ctx.plant)) for ev in cfg.events]
    return ctx


def _holder(ctx: BuildContext) -> Supervisor | None:
    """A supervisor to hold the pose: the gains of the one among the robot stages, else the defaults (first
    joints); None when the plant is not commanded with joint torques."""
    if "joint.torque" not in ctx.plant.command_signals():
        return None
    n = ctx.plant.n_joints
    sup = next((st for st in ctx.robot if isinstance(st, Supervisor)), None)
    if sup is not None:
        kp, kd = sup.kp, sup.kd
    else:
        d = SupervisorConfig()
        kp = np.resize(np.asarray(d.kp), n)
        kd = np.resize(np.asarray(d.kd), n)
    cfg = SupervisorConfig(kp=tuple(float(x) for x in kp), kd=tuple(float(x) for x in kd))
    return Supervisor(cfg, np.zeros(n), np.zeros(n))


class RobotSide:
    """Steps the robot half of the loop on wall-clock ticks."""

    def __init__(self, ctx: BuildContext, rec: Recorder, end: LinkEnd, t0_ns: int, events: LinkEvents):
        cfg = ctx.cfg
        self.cfg, self.ctx, self.rec, self.end, self.t0 = cfg, ctx, rec, end, t0_ns
        self.link = cfg.link
        self.plant, self.task, self.receiver, self.robot = ctx.plant, ctx.task, ctx.receiver, ctx.robot
        self._commands = tuple(ctx.plant.command_signals())
        self._n_command = ctx.plant.command_signals()[self._commands[0]].size
        self.dt_s = cfg.control_dt_ms / 1000.0
        self.dt_ns = int(round(cfg.control_dt_ms * 1e6))
        self.spin_ns = int(cfg.link.spin_us * 1000)
        self.wait_ns = int(cfg.link.command_wait_ms * 1e6)
        self.decimation = cfg.recording.decimation
        self.metrics: list[TrialMetrics] = []
        self.trials_done = 0
        self.tick = 0
        self.events = events
        self._task_rng = ctx.rng("task")
        self._plant_events = sorted([(e, f) for e, f in ctx.events if e.at_s is not None], key=lambda ef: ef[0].at_s)
        self._trial_events = [(e, f) for e, f in ctx.events if e.at_trial is not None]
        self.state = RUNNING
        self._first_command = False
        self._last_command_ns = t0_ns
        self.stops = 0  # times the safe stop started
        self._last_packet_ns = t0_ns
        self._applied: dict[str, np.ndarray] = {}
        self._holder = _holder(ctx)
        self._holding: Supervisor | None = None
        self._c2r_ms = float("nan")
        self._newest_tick = -1  # tick of the newest command that arrived
        self.c2r_delays: list[float] = []
        ticks = cfg.trials * ctx.task.steps_per_trial
        self.log = TickLog(ticks, ("lateness_ms", "compute_ms", "wait_ms"))
        self.overruns = 0
        self.late = 0
        self.ended_ns = t0_ns
        self._steal0 = host_steal_ms()
        self.welcome_facts: dict[str, Any] = {}
        self._dropped = end.dropped()

    def start(self) -> None:
        q0 = self.task.first_sample() if self.cfg.start_at == "path" else self.task.start_position()
        self.plant.reset(np.asarray(q0, float), self.ctx.rng("plant"))
        self.receiver.reset(self.ctx.rng("robot.receiver"))
        for i, st in enumerate(self.robot):
            st.reset(self.ctx.rng(f"robot.{i}"))

    def _fire(self, event: Any, fire: Any, t_s: float) -> None:
        fire()
        params = event.action.model_dump(exclude={"kind"})
        self.rec.write("/events", "cerebx.PlantEvent", t_s, {"t": t_s, "kind": event.action.kind, "params": params})

    # ------------------------------------------------------------------ link
    def _control(self, pkt: Packet) -> None:
        if pkt.kind == Kind.PING:
            pong(self.end, pkt)
        elif pkt.kind == Kind.START:  # our answer was lost: the same start time again
            self.end.send_control(Kind.START, {"t0_ns": self.t0})
        elif pkt.kind == Kind.HELLO and of_this_config(self.end, pkt, self.welcome_facts["fingerprint"]):
            welcome(self.end, pkt, self.welcome_facts)
        elif pkt.kind == Kind.BYE:
            raise PeerEnded(str(pkt.info.get("status", "interrupted")),
                            f"the brain side ended: {pkt.info.get('reason') or pkt.info.get('status')}")

    def _collect(self, k: int, until_ns: int) -> list[Arrived]:
        """Commands that arrived. While commands are current (the newest is of the tick before, or none has
        come yet), wait until ``until_ns`` at most for the one of tick ``k``; on a delayed link it cannot come
        that soon, and what arrived is taken at once."""
        end, inbox = self.end, self.end.transport.inbox
        got: list[Arrived] = []
        budget = POLL_BUDGET
        while True:
            data, control = end.poll(budget)
            budget -= len(data) + len(control)
            for pkt in control:
                self._control(pkt)
            if data:
                got += data
                self._last_packet_ns = max(self._last_packet_ns, data[-1].recv_ns)
                self._newest_tick = data[-1].tick
            if self._newest_tick >= k or self._newest_tick < k - 1 or budget <= 0:
                return got
            now = now_ns()
            if now >= until_ns:
                return got
            inbox.wait((until_ns - now) / 1e9)

    def _starvation(self, t: float, now: int, arrived: list[Arrived], q: np.ndarray) -> None:
        """The robot's state from the time without commands: running; safe stop (a receiver with its own,
        such as Eq. 3.6's, says when it is starved; for the others it starts after ``safe_stop_after_ms``);
        the pose held after ``hold_pose_after_ms``. Each change is a link event."""
        if arrived:
            self._first_command = True
            self._last_command_ns = arrived[-1].recv_ns
        if not self._first_command:
            return
        silent_ms = (now - self._last_command_ns) / 1e6
        if self.receiver.safe_stop:
            stopped = self.receiver.starved
        else:
            stopped = silent_ms >= self.link.safe_stop_after_ms
        new = RUNNING
        if silent_ms >= self.link.hold_pose_after_ms and self._holder is not None:
            new = HOLD_POSE
        elif stopped:
            new = SAFE_STOP
        if new == self.state:
            return
        if new == HOLD_POSE:
            self._holding = self._holder
            self._holding.lo, self._holding.hi = q.copy(), q.copy()
            self._holding.s[:] = 0.0
            detail = f"no command for {silent_ms:.1f} ms: the supervisor holds the pose"
        elif new == SAFE_STOP:
            self._holding = None
            if self.receiver.safe_stop:
                detail = f"too few future commands ({silent_ms:.1f} ms since the last): the receiver decays its output"
            else:
                detail = (f"no command for {silent_ms:.1f} ms: previous command x {self.link.safe_stop_decay_per_step}"
                          " per step")
        else:
            self._holding = None
            detail = f"{silent_ms:.1f} ms since the last command"
        self.events.add(t, new if new != RUNNING else "commands_resumed", detail)
        self.state = new
        self.stops += new == SAFE_STOP

    def _hold(self, robot: dict[str, Any]) -> None:
        """While the pose is held: the supervisor's correction added to the torque the stages left."""
        q, qd = robot["joint.q"], robot["joint.qd"]
        robot["joint.torque"] = robot["joint.torque"] + self._holding.correction(q, qd)

    # ------------------------------------------------------------------ one tick
    def step(self, q_des: np.ndarray, qd_des: np.ndarray, acc: TrialAccumulator, trial: int,
             ee_des: np.ndarray | None) -> None:
        plant, rec, end = self.plant, self.rec, self.end
        k = self.tick
        t = k * self.dt_s
        deadline = self.t0 + k * self.dt_ns
        woke = pace(deadline, self.spin_ns)
        while self._plant_events and self._plant_events[0][0].at_s <= t + 1e-12:
            self._fire(*self._plant_events.pop(0), t)
        sensed = plant.sense()
        end.send_message(Message(t, sensed), k)
        lost0, refused0 = end.data.lost, sum(self._dropped.values())
        waited0 = now_ns()
        arrived = self._collect(k, deadline + self.wait_ns)
        waited = now_ns() - waited0
        now = now_ns()
        if now - self._last_packet_ns > self.link.link_lost_after_ms * 1e6:
            raise LinkLost(f"link lost: no command from the brain side for {(now - self._last_packet_ns) / 1e9:.1f} s")
        values = self.receiver.receive([a.message for a in arrived], t)
        self._starvation(t, now, arrived, sensed["joint.q"] if "joint.q" in sensed else np.zeros(0))
        if self.state == RUNNING or self.receiver.safe_stop:
            self._applied = values
        else:
            decay = self.link.safe_stop_decay_per_step
            self._applied = {name: v * decay for name, v in self._applied.items()}
        robot = dict(self._applied)
        robot.update(sensed)
        command = robot_phase(self.robot, k, t, robot, self._commands, trial,
                              self._hold if self._holding is not None else None)
        applied = plant.actuate(command)
        q, qd = plant.true_state()
        ee = plant.end_effector()
        acc.add(q_des, q, qd_des, qd, applied, ee_des, ee)
        late = 0
        for a in arrived:
            late += a.message.stamp_s < t - 1e-9
            self.c2r_delays.append(a.delay_ms)
            rec.write("/delays/c2r", "cerebx.LinkDelay", t,
                      {"seq": a.seq, "tick": a.tick, "used_tick": k, "delay_ms": round(a.delay_ms, 4)})
        if arrived:
            self._c2r_ms = arrived[-1].delay_ms
        self.late += late
        if k % self.decimation == 0:
            if self.cfg.recording.joint_states:
                rec.joint_states("/joint_states/desired", t, q_des, qd_des)
                rec.joint_states("/joint_states/actual", t, q, qd, applied if applied.size == q.size else None)
            msg: dict[str, Any] = {"t": t, "trial": trial, "error": q_des - q, "c2r_ms": self._c2r_ms,
                                   "link_state": self.state}
            control_message(msg, self.robot, ee, ee_des)
            rec.write("/control", "cerebx.Control", t, msg)
        plant.step()
        done = now_ns()
        compute_ms = (done - woke - waited) / 1e6
        lateness_ms = (woke - deadline) / 1e6
        if done > deadline + self.dt_ns:
            self.overruns += 1
        self.log.put(k, lateness_ms=lateness_ms, compute_ms=compute_ms, wait_ms=waited / 1e6)
        dropped = end.dropped()
        rec.write("/timing", "cerebx.RobotTiming", t,
                  {"t": t, "tick": k, "lateness_ms": round(lateness_ms, 4), "compute_ms": round(compute_ms, 4),
                   "wait_ms": round(waited / 1e6, 4), "commands": len(arrived), "late": late,
                   "lost": end.data.lost - lost0, "refused": sum(dropped.values()) - refused0,
                   "dropped": {r: n - self._dropped.get(r, 0) for r, n in dropped.items()
                               if n != self._dropped.get(r, 0)},
                   "state": self.state})
        self._dropped = dropped
        self.ended_ns = done
        self.tick += 1
        if k % DIVERGENCE_CHECK_TICKS == 0:
            check_diverged(plant, trial, t)

    def run_trial(self, trial: int) -> TrialMetrics:
        ref = self.task.trial(trial, self._task_rng)
        acc = TrialAccumulator(self.plant.n_joints, ref.steps, self.cfg.control_dt_ms, n_command=self._n_command)
        for e, fire in self._trial_events:
            if e.at_trial == trial:
                self._fire(e, fire, self.tick * self.dt_s)
        if trial == 0 and ref.xyz is not None:
            self.rec.write("/task/cartesian_path", "cerebx.CartesianPath", 0.0,
                           {"x": ref.xyz[:, 0].copy(), "y": ref.xyz[:, 1].copy(), "z": ref.xyz[:, 2].copy()})
        xyz = ref.xyz
        for i in range(ref.steps):
            self.step(ref.q[i], ref.qd[i], acc, trial, xyz[i] if xyz is not None else None)
        check_diverged(self.plant, trial)
        m = acc.finish(trial)
        self.metrics.append(m)
        self.trials_done = trial + 1
        t = self.tick * self.dt_s
        self.rec.write("/trial_metrics", "cerebx.TrialMetrics", t, {**m.__dict__, "label": ref.label})
        self.end.send_control(Kind.TRIAL, {**m.__dict__, "label": ref.label}, tick=self.tick, stamp_s=t)
        return m

    def timing(self) -> dict[str, Any]:
        out = self.log.totals()
        late = self.log.series["lateness_ms"][:self.log.n]
        starts = np.flatnonzero((late > STALL_MS) & ~np.r_[False, late[:-1] > STALL_MS])
        out["stalls"] = {"count": int(starts.size), "longest_ms": round(float(late[starts].max()), 3) if starts.size
                         else 0.0, "threshold_ms": STALL_MS}
        out["host_steal_ms"] = round(host_steal_ms() - self._steal0, 1)
        out.update({"ticks": self.log.n, "overruns": self.overruns, "commands_late": self.late,
                    "commands_lost": self.end.data.lost, "safe_stops": self.stops, "c2r_ms": describe(self.c2r_delays)})
        return out

    @property
    def sim_seconds(self) -> float:
        return self.tick * self.dt_s


def pair(end: LinkEnd, first: Packet, facts: dict[str, Any], timeout_s: float) -> None:
    """Answer every matching HELLO (each with its own session) and the PINGs of the session the brain side
    signs with, until that brain side asks to start (START, signed with its session key)."""
    welcome(end, first, facts)
    for cand in list(end.candidates.values()):  # any other HELLO that came with ``first``
        if cand.hello is not first:
            welcome(end, cand.hello, facts)
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        end.transport.inbox.wait(0.05)
        _, control = end.poll()
        for pkt in control:
            if pkt.kind == Kind.HELLO:  # another brain side's, a replayed one, or ours again (our WELCOME lost)
                if of_this_config(end, pkt, facts["fingerprint"]):
                    welcome(end, pkt, facts)
            elif pkt.kind == Kind.PING:
                pong(end, pkt)
            elif pkt.kind == Kind.START:
                return
            elif pkt.kind == Kind.BYE:
                raise NotPaired("link: the brain side ended before the start")
    raise gave_up(f"no brain side started within {timeout_s:g} s", end, facts["fingerprint"])


def prepare_real_time() -> None:
    """Before pairing: load (or on a new machine compile) the compiled helpers a robot-side tick calls (the
    command check, the arm's saturation, the mean filter, the supervisor, the muscles, the trial's rows), for
    the argument types a tick gives them, so that the paced loop's first ticks do not wait for them."""
    z, zz = np.zeros(1), np.zeros((1, 1))
    all_finite(z)
    _saturate(z, z, np.zeros(1))
    _push_mean(np.zeros((1, 1)), np.zeros(1), 0, z, 1, np.zeros(1))
    _ekeberg(z, z, z, z, (z, z, z, z, z, z), (np.zeros(1), np.zeros(1), np.zeros(1)))
    _correct(z, z, z, z, z, z, 0.0, np.zeros(1), np.zeros(1))
    _put_row(z, z, z, z, z, zz.copy(), zz.copy(), zz.copy(), 0)


def run_robot(cfg: Any, run_dir: Path, end: LinkEnd, ctx: BuildContext, facts: dict[str, Any],
              overrides: list[str]) -> dict[str, Any]:
    """Open the robot side's files (paired, asked to start), answer START and run; returns the summary."""
    run_id = end.run_id or bytes(16)
    life = RunLifecycle(cfg, run_dir, compression=cfg.link.compression, overrides=overrides,
                        fields={"side": "robot"},
                        metadata={"link": {"run_id": run_id.hex(), "side": "robot", "transport": cfg.link.kind,
                                           "fingerprint": fingerprint(cfg),
                                           **{k: str(v) for k, v in end.transport.describe().items()}}})
    rec = life.rec
    ctx.run_dir = run_dir
    events = LinkEvents("robot", rec)
    side: RobotSide | None = None

    @life.on_close
    def _close() -> None:
        summary = life.summary
        timing = side.timing() if side is not None else {}
        wall = (side.ended_ns - side.t0) / 1e9 if side is not None and side.tick else time.perf_counter() - life.wall0
        if side is not None:
            summary.update(trial_fields(side.metrics, side.sim_seconds))
        summary["wall_seconds"] = wall
        summary["rt_factor"] = summary["sim_seconds"] / wall if wall > 0 else None
        summary["setup_seconds"] = round(time.perf_counter() - life.wall0 - (wall if side is not None else 0), 3)
        summary["link"] = side_summary(cfg, "robot", run_id, end, timing, events)
        if not isinstance(summary.get("error"), str) or not summary["error"].startswith("the brain side ended"):
            _bye(end, summary, timing, side.tick if side is not None else 0)

    with life:
        rec.joint_names = tuple(ctx.plant.joint_names)
        t0 = now_ns() + int(START_LEAD_S * 1e9)
        end.send_control(Kind.START, {"t0_ns": t0})
        events.add(0.0, "paired", f"run {run_id.hex()}")
        if end.strangers:
            events.add(0.0, "refused_hello", strangers_line(end, facts["fingerprint"]) + " while waiting to pair")
        side = RobotSide(ctx, rec, end, t0, events)
        side.welcome_facts = facts
        side.start()
        for trial in range(cfg.trials):
            side.run_trial(trial)
            life.progress(side.metrics, side.sim_seconds)
        life.completed()
    return life.summary


def _bye(end: LinkEnd, summary: dict[str, Any], timing: dict[str, Any], ticks: int) -> None:
    info = {"status": summary["status"], "reason": summary.get("error"), "trials_completed":
            summary.get("trials_completed", 0), "wall_seconds": summary.get("wall_seconds"), "timing": timing,
            "packets": end.counts(), "events": summary["link"]["events"][-50:], "ticks": ticks}
    for _ in range(3):
        try:
            end.send_control(Kind.BYE, info)
        except (OSError, ValueError):
            return
        time.sleep(0.02)


def default_run_dir(cfg: Any) -> Path:
    return Path("runs") / datetime.now().strftime("%Y-%m-%d") / (
        datetime.now().strftime("%H-%M-%S-%f") + f"_{cfg.task.kind}_robot")


def from_parent() -> tuple[Signer, list[str]]:
    """Started by ``cerebx run``: the key and the addresses come as one JSON line on stdin, a pipe only the two
    processes hold (not on the command line or in the environment, which other processes may read)."""
    line = sys.stdin.buffer.readline(1 << 16)
    try:
        setup = json.loads(line)
        return Signer(bytes.fromhex(setup["key"])), [str(o) for o in setup["overrides"]]
    except (ValueError, KeyError, TypeError):
        raise CerebxError("robot: --from-parent: no setup line on stdin") from None


def main(argv: list[str]) -> int:
    """``cerebx robot [--run-dir DIR] OVERRIDES...``: the robot side of a wall-clock run."""
    ap = argparse.ArgumentParser(prog="cerebx robot", description="the robot side of a wall-clock run")
    ap.add_argument("--run-dir", help="folder for run.mcap and summary.json (default: runs/DATE/TIME_TASK_robot)")
    ap.add_argument("--from-parent", action="store_true", help=argparse.SUPPRESS)
    args, overrides = ap.parse_known_args(argv)
    signer = None
    if args.from_parent:
        signer, more = from_parent()
        overrides = overrides + more
    cfg, _ = load(overrides)
    if not cfg.link.real:
        raise CerebxError("robot: needs a real link (link=zenoh or link=udp) and clock=wall")
    signer = signer or require_key()
    why = realtime_process(cfg.link.rt_priority, "robot")
    if why:
        print(f"robot side: {why}", file=sys.stderr)
    via_relay = cfg.link.relay_on(cfg.delay.kind)
    transport = registry.links.build(cfg.link, "robot", via_relay)
    expected = {s.name: s.size for s in wire(cfg).sent}
    end = LinkEnd(transport, signer, "robot", expected)
    run_dir = Path(args.run_dir) if args.run_dir else default_run_dir(cfg)
    try:
        hello = wait_for_hello(end, fingerprint(cfg), cfg.link.pair_timeout_s)
        ctx = build_robot_parts(cfg, hello.info.get("controller") or {}, None)
        end.max_tick = cfg.trials * ctx.task.steps_per_trial
        prepare_real_time()
        facts = {"fingerprint": fingerprint(cfg), **host_identity()}
        pair(end, hello, facts, cfg.link.pair_timeout_s)
        if end.committed is not None and end.committed.hello.info.get("controller") != hello.info.get("controller"):
            ctx = build_robot_parts(cfg, end.committed.hello.info.get("controller") or {}, None)
        summary = run_robot(cfg, run_dir, end, ctx, facts, overrides)
    finally:
        transport.close()
    status = summary["status"]
    if status == "completed":
        print(f"robot side: completed {summary['trials_completed']} trials, final MAE "
              f"{summary['final_mae']:.4f} rad ({run_dir})")
        return 0
    print(f"robot side: {status}: {summary.get('error')} ({run_dir})", file=sys.stderr)
    return 130 if status == "interrupted" else 1
