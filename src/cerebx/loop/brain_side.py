"""The brain side of a wall-clock run (``cerebx run ... link=zenoh clock=wall``): the task reference,
the controller and the brain stages, stepped as the robot side's sensor messages arrive.

Brain tick k belongs to the robot's tick k (the same time on the robot's clock, through the estimated
offset). It is computed as soon as the sensor message of tick k arrives, or ``link.brain_wait_ms``
after the tick started when it has not (a delayed or lost message): the brain stages then see the
newest sensor message that has arrived, as in simulated time. A sensor message of a later tick waits
for its own tick. The output goes back as COMMAND stamped as the controller stamps it.

Without sensor messages for ``sensor_timeout_ms`` the brain side holds the last one and says so; after
``link_lost_after_ms`` without a sensor message of the session the run ends (interrupted, link lost).
The watchdog (``link/shedding.py``) sheds work when the brain side finishes its ticks late. A robot side
that reports all its trials completed (its BYE) ends the run as completed even when it arrives before
the brain side's last tick: the brain side then computes its remaining ticks without waiting.

``cerebx run`` starts the robot side (``cerebx robot``, its files in ``RUN_DIR/robot``) and the delay
relay (``cerebx relay``, in ``RUN_DIR/relay``) itself unless ``link.spawn_robot=false``; their addresses
(and the robot side's key) go to them as one JSON line on their stdin, not on their command line. A run
that does not pair (no answer, a refusal, a port taken, a host that does not resolve) ends with one line
and exit code 2, and leaves no run folder behind.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from cerebx import registry, runfiles
from cerebx.build import build_components
from cerebx.builders import BuildContext
from cerebx.errors import CerebxError, LinkLost, PeerEnded, outcome
from cerebx.link import clock
from cerebx.link.auth import Signer, key_from_env, new_key, require_key
from cerebx.link.channel import Arrived, LinkEnd
from cerebx.link.clock import now_ns
from cerebx.link.pairing import NotPaired, Pings, controller_facts, fingerprint, hello, new_run_id, within
from cerebx.link.shedding import Watchdog, prepare_real_time, shed_targets
from cerebx.link.stats import describe
from cerebx.link.transport import with_free_ports
from cerebx.link.wire import Kind, Packet
from cerebx.loop.lifecycle import RunLifecycle
from cerebx.loop.loop import RECORD_AS
from cerebx.loop.phases import brain_phase
from cerebx.loop.realtime import ROBOT_DIR, LinkEvents, TickLog, side_summary
from cerebx.metrics import TrialMetrics
from cerebx.recording.recorder import Recorder
from cerebx.recording.summary import read_summary, trial_fields
from cerebx.signals import Message

CHILD_DROPS = ("init_from", "resume", "link.robot", "link.brain", "link.relay", "link.spawn_robot",
               "recording.progress")
BYE_WAIT_S = 5.0  # after the last tick, for the robot side's last trial and its BYE


class BrainSide:
    """Steps the brain half of the loop as sensor messages arrive."""

    def __init__(self, ctx: BuildContext, rec: Recorder, end: LinkEnd, t0_robot_ns: int, events: LinkEvents):
        cfg = ctx.cfg
        self.cfg, self.ctx, self.rec, self.end = cfg, ctx, rec, end
        self.link = cfg.link
        self.task, self.brain = ctx.task, ctx.brain
        self.t0_robot = t0_robot_ns
        self.dt_s = cfg.control_dt_ms / 1000.0
        self.dt_ns = int(round(cfg.control_dt_ms * 1e6))
        self.wait_ns = int(cfg.link.brain_wait_ms * 1e6)
        self._sent = tuple(s.name for s in ctx.sent)
        self._record_as = tuple((name, RECORD_AS.get(name, name)) for name in self._sent)
        self.decimation = cfg.recording.decimation
        self.events = events
        self.tick = 0
        self._task_rng = ctx.rng("task")
        self._pending: list[Arrived] = []
        self._sensed: Message | None = None
        self._r2c_ms = float("nan")
        self.r2c_delays: list[float] = []
        self._last_sensor_ns = self.t0()
        self._last_packet_ns = self.t0()
        self.holding = False
        self.trials: dict[int, dict[str, Any]] = {}
        self.robot_bye: dict[str, Any] | None = None
        self.watchdog = Watchdog(cfg.link.shedding, shed_targets(ctx.brain))
        ticks = cfg.trials * ctx.task.steps_per_trial
        self.log = TickLog(ticks, ("lag_ms", "compute_ms"))
        self.pings = Pings(end)
        self._next_sync_ns = self.t0() + int(cfg.link.resync_every_s * 1e9)
        self._pings_left = 0
        self.shared_clock = True
        self.robot_done = False
        self.clock_refused = 0
        self._dropped = end.dropped()

    def t0(self) -> int:
        """Tick 0 on this side's clock (follows the offset estimate)."""
        return self.t0_robot - self.end.offset_ns

    def start(self) -> None:
        for i, st in enumerate(self.brain):
            st.reset(self.ctx.rng("controller" if i == 0 else f"brain.{i}"))
        for st in self.brain:
            st.attach_recorder(self.rec)

    # ------------------------------------------------------------------ link
    def _control(self, pkt: Packet) -> None:
        if pkt.kind == Kind.PONG:
            self.pings.answer(pkt)
        elif pkt.kind == Kind.TRIAL:
            self.trials[pkt.info["trial"]] = pkt.info
        elif pkt.kind == Kind.BYE and self.robot_bye is None:
            self.robot_bye = pkt.info
            status = pkt.info["status"]
            if status == "completed" and pkt.info.get("trials_completed") == self.cfg.trials:
                self.robot_done = True  # its last tick may come before ours: ours are computed without waiting
                return
            raise PeerEnded(status, f"the robot side ended ({status}): {pkt.info.get('reason') or ''}")

    def _poll(self) -> None:
        data, control = self.end.poll()
        for pkt in control:
            self._control(pkt)
        if data:
            self._pending += data
            self._last_packet_ns = max(self._last_packet_ns, data[-1].recv_ns)

    def _resync(self, t: float, now: int) -> None:
        """One ping per tick while a burst is under way; an estimate when the burst is answered."""
        pings = self.pings
        if self._pings_left == 0 and now >= self._next_sync_ns:
            self._pings_left = self.link.pings
            pings.new_burst()
            self._next_sync_ns = now + int(self.link.resync_every_s * 1e9)
        if self._pings_left:
            self._pings_left -= 1
            pings.send(self._pings_left, self.end.offset_ns)
        elif pings.probes and len(pings.probes) >= max(1, self.link.pings // 2):
            est = clock.estimate(pings.probes, now)
            pings.probes = []
            if est is not None:
                method = "ping" if not self.shared_clock else "ping (check)"
                if not within(est, self.link.max_clock_uncertainty_ms):
                    self.clock_refused += 1
                    record_estimate(self.rec, t, est, method + " refused: uncertainty beyond "
                                    f"{self.link.max_clock_uncertainty_ms:g} ms")
                    return
                record_estimate(self.rec, t, est, method)
                if not self.shared_clock:
                    self.end.offset_ns = est.offset_ns

    # ------------------------------------------------------------------ one tick
    def step(self, q_des: np.ndarray, qd_des: np.ndarray, trial: int, extra: dict[str, np.ndarray] | None) -> None:
        rec, end = self.rec, self.end
        k = self.tick
        t = k * self.dt_s
        start_k = self.t0() + k * self.dt_ns
        until = start_k + self.wait_ns
        inbox = end.transport.inbox
        while True:
            self._poll()
            if self.robot_done or (self._pending and self._pending[-1].tick >= k):
                break
            now = now_ns()
            if now >= until:
                break
            inbox.wait((until - now) / 1e9)
        began = now_ns()
        lost0, refused0 = end.data.lost, sum(self._dropped.values())
        used = [a for a in self._pending if a.tick <= k]
        self._pending = [a for a in self._pending if a.tick > k]
        for a in used:
            self.r2c_delays.append(a.delay_ms)
            rec.write("/delays/r2c", "cerebx.LinkDelay", t,
                      {"seq": a.seq, "tick": a.tick, "used_tick": k, "delay_ms": round(a.delay_ms, 4)})
        if used:
            self._sensed, self._r2c_ms = used[-1].message, used[-1].delay_ms
            self._last_sensor_ns = self._last_packet_ns = used[-1].recv_ns
            if self.holding:
                self.holding = False
                self.events.add(t, "sensors_resumed")
        elif self.robot_done:
            pass
        elif not self.holding and began - self._last_sensor_ns > self.link.sensor_timeout_ms * 1e6:
            self.holding = True
            gap = (began - self._last_sensor_ns) / 1e6
            self.events.add(t, "holding", f"no sensor message for {gap:.0f} ms: holding the last one")
            print(f"brain side: no sensor message for {gap:.0f} ms at t = {t:.3f} s; holding the last one",
                  file=sys.stderr)
        if self._pending:
            self._last_packet_ns = max(self._last_packet_ns, self._pending[-1].recv_ns)
        if not self.robot_done and began - self._last_packet_ns > self.link.link_lost_after_ms * 1e6:
            raise LinkLost(f"link lost: no sensor message from the robot side for "
                           f"{(began - self._last_packet_ns) / 1e9:.1f} s")
        frame, signals = brain_phase(self.brain, k, t, q_des, qd_des, extra, self._sensed)
        out = {name: signals[name] for name in self._sent}
        end.send_message(Message(frame.stamp_s, out), k)
        sent = now_ns()
        lag_ms = (sent - start_k) / 1e6
        compute_ms = (sent - began) / 1e6
        self.log.put(k, lag_ms=lag_ms, compute_ms=compute_ms)
        change = self.watchdog.update(lag_ms, t)
        if change is not None:
            rec.write("/shedding", "cerebx.Shedding", t, change.__dict__)
        if k % self.decimation == 0:
            msg: dict[str, Any] = {"t": t, "trial": trial, "r2c_ms": self._r2c_ms}
            for name, field in self._record_as:
                msg[field] = out[name]
            rec.write("/control", "cerebx.Control", t, msg)
        dropped = end.dropped()
        rec.write("/timing/brain", "cerebx.BrainTiming", t,
                  {"t": t, "tick": k, "lag_ms": round(lag_ms, 4), "compute_ms": round(compute_ms, 4),
                   "sensors": len(used), "lost": end.data.lost - lost0,
                   "refused": sum(dropped.values()) - refused0,
                   "dropped": {r: n - self._dropped.get(r, 0) for r, n in dropped.items()
                               if n != self._dropped.get(r, 0)}, "level": self.watchdog.level})
        self._dropped = dropped
        self._resync(t, sent)
        self.tick += 1

    def run_trial(self, trial: int) -> None:
        ref = self.task.trial(trial, self._task_rng)
        extra = [(f"ref.{name}", v) for name, v in ref.extra.items()]
        for i in range(ref.steps):
            self.step(ref.q[i], ref.qd[i], trial, {name: v[i] for name, v in extra} if extra else None)
        out: dict[str, float] = {}
        for st in self.brain:
            out.update(st.end_trial(trial))
        if out:
            self.rec.write("/weights", "cerebx.WeightSummary", self.tick * self.dt_s, {"trial": trial, **out})

    def wait_for_end(self, timeout_s: float) -> None:
        """After the last tick: trial metrics and the robot side's BYE (returns when it completed all trials,
        raises PeerEnded with any other)."""
        deadline = time.monotonic() + timeout_s
        while not self.robot_done and time.monotonic() < deadline:
            self.end.transport.inbox.wait(0.05)
            self._poll()
        if self.robot_done:
            return
        raise LinkLost(f"link lost: the robot side did not finish within {timeout_s:g} s of the last tick")

    def metrics(self) -> list[TrialMetrics]:
        out = []
        for i in sorted(self.trials):
            m = self.trials[i]
            out.append(TrialMetrics(int(m["trial"]), float(m["mae"]), tuple(m["mae_per_joint"]), float(m["vel_mae"]),
                                    float(m["torque_variability_Nm_per_ms"]), m.get("ee_error_m")))
        return out

    def timing(self) -> dict[str, Any]:
        out = self.log.totals()
        out.update({"ticks": self.log.n, "sensors_lost": self.end.data.lost, "clock_refused": self.clock_refused,
                    "shedding": {"max_level": self.watchdog.max_level,
                                 "max_lead_ms": round(self.watchdog.max_lead_ms, 3),
                                 "changes": [c.__dict__ for c in self.watchdog.changes]}})
        return out


def record_estimate(rec: Recorder, t: float, est: clock.OffsetEstimate, method: str) -> dict[str, Any]:
    item = {"t": t, "offset_ms": est.offset_ns / 1e6, "uncertainty_ms": est.uncertainty_ns / 1e6, "method": method,
            "probes": est.probes}
    rec.write("/clock_sync", "cerebx.ClockSync", t, item)
    return item


SYNC_BURSTS = 3


def sync_clock(end: LinkEnd, cfg: Any, welcome: Packet) -> tuple[list[clock.OffsetEstimate], bool]:
    """The offset at pairing: shared clock on one host (unless told to ping), else up to :data:`SYNC_BURSTS`
    ping bursts until one gives an estimate within ``link.max_clock_uncertainty_ms`` (the last estimate; the
    list holds the refused ones before it)."""
    mine = clock.host_identity()
    same = bool(mine["boot_id"]) and welcome.info.get("boot_id") == mine["boot_id"]
    shared = cfg.link.clock_sync == "shared" or (cfg.link.clock_sync == "auto" and same)
    if shared:
        return [clock.shared(now_ns())], True
    pings = Pings(end)
    tried: list[clock.OffsetEstimate] = []
    deadline = time.monotonic() + cfg.link.pair_timeout_s
    while len(tried) < SYNC_BURSTS and time.monotonic() < deadline:
        pings.new_burst()
        for n in range(cfg.link.pings * 2):
            pings.send(n)
            end.transport.inbox.wait(0.01)
            _, control = end.poll()
            for p in control:
                if p.kind == Kind.PONG:
                    pings.answer(p)
            if len(pings.probes) >= cfg.link.pings or time.monotonic() > deadline:
                break
        time.sleep(0.02)
        _, control = end.poll()
        for p in control:
            if p.kind == Kind.PONG:
                pings.answer(p)
        est = clock.estimate(pings.probes, now_ns())
        if est is None:
            continue
        tried.append(est)
        if within(est, cfg.link.max_clock_uncertainty_ms):
            end.offset_ns = est.offset_ns
            return tried, False
    if not tried:
        raise NotPaired("link: no answer to the clock-offset pings")
    raise NotPaired(f"link: the clock offset is uncertain by {tried[-1].uncertainty_ns / 1e6:.2f} ms after "
                    f"{len(tried)} ping bursts, more than link.max_clock_uncertainty_ms="
                    f"{cfg.link.max_clock_uncertainty_ms:g}")


def start(end: LinkEnd, offset_ns: int, timeout_s: float) -> int:
    """Ask the robot side to start; tick 0's time on the robot's clock."""
    deadline = time.monotonic() + timeout_s
    next_ask = 0.0
    while time.monotonic() < deadline:
        if time.monotonic() >= next_ask:
            end.send_control(Kind.START, {"offset_ns": offset_ns})
            next_ask = time.monotonic() + 0.1
        end.transport.inbox.wait(0.02)
        _, control = end.poll()
        for pkt in control:
            if pkt.kind == Kind.START and "t0_ns" in pkt.info:
                return pkt.info["t0_ns"]
            if pkt.kind == Kind.BYE:
                status = str(pkt.info.get("status"))
                raise PeerEnded(status, f"the robot side ended ({status}): {pkt.info.get('reason')}")
    raise LinkLost(f"link lost: the robot side did not start within {timeout_s:g} s")


def child_overrides(overrides: list[str], link: Any) -> tuple[list[str], list[str]]:
    """The robot side's and the relay's overrides: (the run's own, for their command line; the resolved
    addresses, for the private setup line on their stdin)."""
    keep = [o for o in overrides if o.lstrip("+~").split("=", 1)[0] not in CHILD_DROPS
            and not o.lstrip("+~").startswith("hydra")]
    return keep + ["recording.progress=off"], [f"link.robot={link.robot}", f"link.brain={link.brain}",
                                               f"link.relay={link.relay}"]


CHILD_ENV_DROPS = ("CEREBX_LINK_KEY", "CEREBX_LINK_KEY_FILE")


def spawn(command: str, args: list[str], folder: Path, setup: dict[str, Any]) -> subprocess.Popen:
    """Start ``cerebx COMMAND ARGS`` with its output in ``folder/COMMAND.log`` and ``setup`` (addresses, the
    key) as one JSON line on its stdin, a pipe only the two processes hold; the pipe stays open (the relay
    stops when it closes)."""
    folder.mkdir(parents=True, exist_ok=True)
    logf = open(folder / f"{command}.log", "wb")
    full_env = {k: v for k, v in os.environ.items() if k not in CHILD_ENV_DROPS}
    full_env["PYTHONPATH"] = os.pathsep.join(p for p in sys.path if p)
    try:
        proc = subprocess.Popen([sys.executable, "-m", "cerebx.cli", command, *args], stdout=logf, stderr=logf,
                                stdin=subprocess.PIPE, env=full_env, start_new_session=True)
    finally:
        logf.close()
    try:
        proc.stdin.write(json.dumps(setup).encode() + b"\n")
        proc.stdin.flush()
    except OSError:
        pass  # it died at once: its exit code and log say why
    return proc


def _last_line(path: Path) -> str:
    try:
        lines = [ln for ln in path.read_text(errors="replace").splitlines() if ln.strip()]
    except OSError:
        return ""
    return lines[-1] if lines else ""


class Children:
    """The robot side and the relay this run started, and how they ended."""

    def __init__(self) -> None:
        self.procs: dict[str, tuple[subprocess.Popen, Path]] = {}
        self.codes: dict[str, int | None] | None = None

    def alive(self) -> bool:
        """False once the robot side this run started has exited (pairing waits no longer)."""
        p = self.procs.get("robot")
        return p is None or p[0].poll() is None

    def robot_exit_line(self) -> str:
        p = self.procs.get("robot")
        if p is None:
            return ""
        return f"the robot side exited with code {p[0].returncode}: {_last_line(p[1] / 'robot.log')}"

    def finish(self, timeout_s: float = 10.0) -> dict[str, int | None]:
        """Let them end (the relay when its pipe closes), then their exit codes; once."""
        if self.codes is not None:
            return self.codes
        out: dict[str, int | None] = {}
        for name, (proc, _folder) in self.procs.items():
            if proc.stdin is not None:
                try:
                    proc.stdin.close()
                except OSError:
                    pass
            try:
                out[name] = proc.wait(timeout=timeout_s)
            except subprocess.TimeoutExpired:
                proc.terminate()
                try:
                    out[name] = proc.wait(timeout=5)
                except subprocess.TimeoutExpired:
                    proc.kill()
                    out[name] = proc.wait()
        self.codes = out
        return out


def _signer(link: Any) -> Signer:
    """The run's key: from the environment, or (when this run starts the robot side itself) a new one."""
    signer = key_from_env()
    if signer is None:
        signer = new_key() if link.spawn_robot else require_key()
    return signer


def leave_nothing(run_dir: Path) -> None:
    """After a run that did not pair: remove what was written for it (Hydra's ``.hydra/`` and log, the robot
    side's and the relay's folders with their logs), unless the folder holds a run."""
    if any((run_dir / name).exists() for name in (runfiles.SUMMARY, runfiles.MCAP)):
        return
    for name in (".hydra", ROBOT_DIR, runfiles.RELAY):
        path = run_dir / name
        if path.is_dir() and all(p.suffix in (".log", ".yaml") for p in path.iterdir()):
            shutil.rmtree(path, ignore_errors=True)
    for log in run_dir.glob("*.log"):
        log.unlink(missing_ok=True)
    try:
        run_dir.rmdir()
    except OSError:
        pass


def run_brain_side(cfg: Any, run_dir: Path, resolved: dict | None = None, overrides: list[str] | None = None,
                   choices: dict[str, str] | None = None) -> dict[str, Any]:
    """The brain side of a wall-clock run into ``run_dir`` (starting the robot side and relay unless told not
    to); writes run.mcap, summary.json (with the robot side's metrics and timing) and the controller state.
    Raises :class:`NotPaired` (one line) when the sides did not pair."""
    run_dir = Path(run_dir)
    overrides = list(overrides or [])
    link = with_free_ports(cfg.link, udp=cfg.link.kind == "udp") if cfg.link.spawn_robot else cfg.link
    cfg = cfg.model_copy(update={"link": link})
    via_relay = link.relay_on(cfg.delay.kind)
    why = clock.realtime_process(link.rt_priority, "brain")
    if why:
        print(f"brain side: {why}", file=sys.stderr)
    children = Children()
    args, addresses = child_overrides(overrides, link)
    transport = None
    paired = False
    try:
        try:
            signer = _signer(link)
            transport = registry.links.build(link, "brain", via_relay)
            if link.spawn_robot:
                folder = run_dir / ROBOT_DIR
                children.procs["robot"] = (spawn("robot", ["--run-dir", str(folder), "--from-parent", *args], folder,
                                                 {"key": signer.hex(), "overrides": addresses}), folder)
            if via_relay:
                folder = run_dir / runfiles.RELAY
                children.procs["relay"] = (spawn("relay", ["--out", str(folder), "--parent-pipe", *args], folder,
                                                 {"overrides": addresses}), folder)
            ctx = build_components(cfg, run_dir)
            if cfg.init_from:
                state = Path(cfg.init_from) / runfiles.STATE
                if not state.exists():
                    raise CerebxError(f"init_from: {state} does not exist")
                ctx.brain[0].load_state(state)
            prepare_real_time(ctx.brain)
            expected = {name: s.size for name, s in cfg.plant.sensor_signals().items()}
            end = LinkEnd(transport, signer, "brain", expected, run_id=new_run_id(),
                          max_tick=cfg.trials * ctx.task.steps_per_trial)
            try:
                welcome = hello(end, fingerprint(cfg), controller_facts(ctx), cfg.link.pair_timeout_s,
                                children.alive)
            except CerebxError as err:
                if not children.alive():
                    raise NotPaired(f"link: {children.robot_exit_line()}") from None
                raise err
            estimates, shared = sync_clock(end, cfg, welcome)
        except NotPaired:
            raise
        except CerebxError as err:
            raise NotPaired(str(err)) from None
        paired = True
        return _run_paired(cfg, run_dir, ctx, end, welcome, (estimates, shared), resolved, overrides, choices,
                           children)
    finally:
        if transport is not None:
            transport.close()
        children.finish(10.0 if paired else 0.5)


def _run_paired(cfg: Any, run_dir: Path, ctx: BuildContext, end: LinkEnd, welcome: Packet,
                clock_sync: tuple[list[clock.OffsetEstimate], bool], resolved: dict | None, overrides: list[str],
                choices: dict[str, str] | None, children: Children) -> dict[str, Any]:
    """``clock_sync``: the estimates made at pairing (the refused ones first) and whether the clock is shared."""
    estimates, shared = clock_sync
    run_id = end.run_id or bytes(16)
    life = RunLifecycle(cfg, run_dir, compression=cfg.link.compression, overrides=overrides, resolved=resolved,
                        fields={"presets": dict(choices or {}), "side": "brain"},
                        metadata={"link": {"run_id": run_id.hex(), "side": "brain", "transport": cfg.link.kind,
                                           "fingerprint": fingerprint(cfg), "robot_dir": ROBOT_DIR,
                                           **{k: str(v) for k, v in end.transport.describe().items()}}})
    rec = life.rec
    rec.joint_names = tuple(ctx.plant.joint_names)
    events = LinkEvents("brain", rec)
    side: BrainSide | None = None
    sync: list[dict[str, Any]] = []

    @life.on_close
    def _close() -> None:
        if isinstance(life.error, LinkLost):
            print(f"brain side: {life.error} (status interrupted, {run_dir})", file=sys.stderr)
        if side is not None and (side.robot_bye is None or life.status != "completed"):
            _bye(end, life.summary)
        _finish(life, side, end, events, sync, children)

    with life:
        for i, est in enumerate(estimates):
            refused = i < len(estimates) - 1
            sync.append(record_estimate(rec, 0.0, est, est.method + (" refused: uncertainty beyond "
                                        f"{cfg.link.max_clock_uncertainty_ms:g} ms" if refused else "")))
        est = estimates[-1]
        t0 = start(end, est.offset_ns, cfg.link.pair_timeout_s)
        events.add(0.0, "paired", f"run {run_id.hex()} with {welcome.info.get('host')}")
        side = BrainSide(ctx, rec, end, t0, events)
        side.shared_clock = shared
        side.start()
        life.summary["controller_info"] = ctx.brain[0].describe()
        try:
            for trial in range(cfg.trials):
                side.run_trial(trial)
                life.progress(side.metrics(), side.tick * side.dt_s)
            side.wait_for_end(BYE_WAIT_S)
            life.completed()
        except PeerEnded as err:
            life.summary.update(outcome(err), status="diverged" if err.status == "diverged" else "interrupted")
    return life.summary


def _bye(end: LinkEnd, summary: dict[str, Any]) -> None:
    for _ in range(3):
        try:
            end.send_control(Kind.BYE, {"status": summary["status"], "reason": summary.get("error")})
        except (OSError, ValueError):
            return
        time.sleep(0.02)


def _finish(life: RunLifecycle, side: BrainSide | None, end: LinkEnd, events: LinkEvents,
            sync: list[dict[str, Any]], children: Children) -> None:
    """Fill the summary: the robot side's metrics (its own summary.json when it ran here), both sides'
    timing, the measured delays, the controller state."""
    cfg, run_dir, summary = life.cfg, life.run_dir, life.summary
    robot: dict[str, Any] = {}
    if side is not None and side.robot_bye is not None:
        robot = dict(side.robot_bye)
    codes = children.finish() if children.procs else {}
    robot_dir = run_dir / ROBOT_DIR
    metrics = side.metrics() if side is not None else []
    if (robot_dir / runfiles.SUMMARY).exists():
        try:
            rs = read_summary(robot_dir)
            robot.setdefault("timing", (rs.get("link") or {}).get("timing"))
            robot.setdefault("events", (rs.get("link") or {}).get("events"))
            robot.setdefault("packets", (rs.get("link") or {}).get("packets"))
            if len(rs.get("mae_per_trial") or []) >= len(metrics):
                summary.update({k: rs[k] for k in ("trials_completed", "mae_per_trial", "mae_per_joint_per_trial",
                                                   "vel_mae_per_trial", "torque_variability_per_trial",
                                                   "ee_error_per_trial", "final_mae")})
                metrics = []
        except CerebxError:
            pass
    sim = side.tick * side.dt_s if side is not None else 0.0
    if metrics:
        summary.update(trial_fields(metrics, sim))
    summary["sim_seconds"] = sim
    wall = robot.get("wall_seconds") or ((now_ns() - side.t0()) / 1e9 if side is not None else 0.0)
    summary["wall_seconds"] = wall
    summary["rt_factor"] = sim / wall if wall else None
    summary["setup_seconds"] = round(time.perf_counter() - life.wall0 - wall, 3)
    brain_timing = side.timing() if side is not None else {}
    summary["link"] = side_summary(
        cfg, "brain", end.run_id or bytes(16), end, {"brain": brain_timing, "robot": robot.get("timing")}, events,
        robot_packets=robot.get("packets"), robot_events=robot.get("events"), clock_sync=sync,
        robot_dir=ROBOT_DIR if cfg.link.spawn_robot else None, children=codes,
        delays={"r2c_ms": describe(side.r2c_delays if side is not None else []),
                "c2r_ms": (robot.get("timing") or {}).get("c2r_ms")})
    if side is not None and side.tick > 0:
        life.save_state(side.ctx.brain[0])

