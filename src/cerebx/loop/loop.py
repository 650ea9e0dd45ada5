"""The closed loop: one tick order for every experiment, stepped by ``cerebx run``,
``cerebx tune`` and ``cerebx bench`` alike.

One tick (2 ms, integer tick counter, simulated time = tick x control step):

====================  ========================================================================
phase                 what happens
====================  ========================================================================
events                scheduled plant events whose time has come fire
sense                 the plant's sensor signals are read (measured, possibly noisy)
uplink                they go into the link's robot-to-controller channel; what has arrived
                      leaves it, the newest message is what the brain side sees
brain                 brain stages in order (the controller's parts first) write their outputs
downlink              the signals the robot side needs go into the controller-to-robot channel
robot                 the receiver turns what arrived into this tick's command; robot stages in
                      order (supervisor, muscles, ...) read it and the plant's readings
actuate               the plant takes its command signals (saturated)
measure               true state, end-effector and command into the trial's metrics
record                one ``/control`` and two joint-state messages (every ``decimation`` ticks of
                      the trials ``recording.trials`` holds); the 3-D scene when one is recorded
                      or served (``scene``)
physics               the plant advances one control step
====================  ========================================================================
"""

from __future__ import annotations

from collections import deque
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from cerebx.loop.phases import DIVERGENCE_CHECK_TICKS, brain_phase, check_diverged, control_message, robot_phase
from cerebx.metrics import TrialAccumulator, TrialMetrics
from cerebx.recording.cdr import JOINT_STATE
from cerebx.recording.recorder import Recorder, stamps_ns, to_ns
from cerebx.schema.window import trial_window
from cerebx.signals import Message

if TYPE_CHECKING:
    from cerebx.build import BuildContext

PHASES = ("events", "sense", "uplink", "brain", "downlink", "robot", "actuate", "measure", "record", "physics")

DESIRED = "/joint_states/desired"

# how brain-side output signals are named in /control (kept from the first recordings)
RECORD_AS = {"joint.torque": "tau_controller"}


class ClosedLoop:
    """Steps the parts of a :class:`BuildContext` in the fixed phase order."""

    def __init__(self, ctx: BuildContext, recorder: Recorder | None):
        cfg = ctx.cfg
        self.cfg, self.ctx, self.rec = cfg, ctx, recorder
        self.plant, self.task = ctx.plant, ctx.task
        self.brain, self.receiver, self.robot, self.link = ctx.brain, ctx.receiver, ctx.robot, ctx.link
        self.controller = ctx.brain[0]
        self._sent = tuple(s.name for s in ctx.sent)
        self._commands = tuple(ctx.plant.command_signals())
        self._record_as = tuple((name, RECORD_AS.get(name, name)) for name in self._sent)
        self._n_command = ctx.plant.command_signals()[self._commands[0]].size  # what actuate() returns
        self.dt_s = cfg.control_dt_ms / 1000.0
        self.decimation = cfg.recording.decimation
        self.record_joints = recorder is not None and cfg.recording.joint_states
        self.window = trial_window(cfg.recording.trials)  # a resumed run keeps its checkpoint's (resume.py)
        self._steps_on = True  # whether this trial's control steps are recorded
        self._last_held: tuple[int, int] | None = None  # the newest recorded trial's steps (ns), for a resumption
        self.metrics: list[TrialMetrics] = []
        self._weights_due: deque[tuple[float, int, list[Mapping[str, float]]]] = deque()  # /weights not yet written
        self.trials_done = 0
        self.tick = 0
        self._sensed: Message | None = None  # newest sensor message delivered to the brain side
        self._task_rng = ctx.rng("task")
        self._events = sorted([(e, f) for e, f in ctx.events if e.at_s is not None], key=lambda ef: ef[0].at_s)
        self._trial_events = [(e, f) for e, f in ctx.events if e.at_trial is not None]
        self.scene: Any = None  # a recording.scene.SceneWriter, set by the runner when the scene is wanted

    def start(self) -> None:
        q0 = self.task.first_sample() if self.cfg.start_at == "path" else self.task.start_position()
        self.plant.reset(np.asarray(q0, float), self.ctx.rng("plant"))
        for i, st in enumerate(self.brain):
            st.reset(self.ctx.rng("controller" if i == 0 else f"brain.{i}"))
        self.receiver.reset(self.ctx.rng("robot.receiver"))
        for i, st in enumerate(self.robot):
            st.reset(self.ctx.rng(f"robot.{i}"))
        if self.rec is not None:
            for st in self.brain:
                st.attach_recorder(self.rec)

    def _fire(self, event: Any, fire: Any, t_s: float) -> None:
        action = event.action
        fire()
        if self.rec is not None:
            params = action.model_dump(exclude={"kind"})
            self.rec.write("/events", "cerebx.PlantEvent", t_s, {"t": t_s, "kind": action.kind, "params": params})
            if self.scene is not None:
                self.scene.note(t_s, f"event {action.kind} {params}")

    def step(self, q_des: np.ndarray, qd_des: np.ndarray, acc: TrialAccumulator | None = None, trial: int = 0,
             ee_des: np.ndarray | None = None, extra: dict[str, np.ndarray] | None = None,
             desired: bytes | None = None) -> np.ndarray:
        """One tick, every phase in the order of :data:`PHASES`; returns the applied command. ``extra``:
        further reference signals (``ref.<name>``) for the brain side; ``desired``: the desired joint-state
        message of this tick, encoded already (else it is encoded here)."""
        plant, link, rec = self.plant, self.link, self.rec
        tick = self.tick
        t = tick * self.dt_s
        while self._events and self._events[0][0].at_s <= t + 1e-12:
            self._fire(*self._events.pop(0), t)
        # sense, uplink
        sensed = plant.sense()
        link.r2c.send(Message(t, sensed), tick)
        arrived = link.r2c.receive(tick)
        if arrived:
            self._sensed = arrived[-1]
        # brain
        frame, signals = brain_phase(self.brain, tick, t, q_des, qd_des, extra, self._sensed)
        # downlink
        out = {name: signals[name] for name in self._sent}
        link.c2r.send(Message(frame.stamp_s, out), tick)
        # robot
        robot = dict(self.receiver.receive(link.c2r.receive(tick), t))
        robot.update(sensed)
        command = robot_phase(self.robot, tick, t, robot, self._commands, trial)
        # actuate, measure
        applied = plant.actuate(command)
        q, qd = plant.true_state()
        ee = plant.end_effector()
        if acc is not None:
            acc.add(q_des, q, qd_des, qd, applied, ee_des, ee)
        # record
        if rec is not None and self._steps_on and tick % self.decimation == 0:
            if self.record_joints:
                if desired is not None:
                    rec.log_encoded(DESIRED, JOINT_STATE, desired, to_ns(t))
                else:
                    rec.joint_states(DESIRED, t, q_des, qd_des)
                rec.joint_states("/joint_states/actual", t, q, qd, applied if applied.size == q.size else None)
            msg: dict[str, Any] = {"t": t, "trial": trial}
            for name, field in self._record_as:
                msg[field] = out[name]
            msg.update({"error": q_des - q, "r2c_ms": link.r2c.last_delay_ms, "c2r_ms": link.c2r.last_delay_ms})
            control_message(msg, self.robot, ee, ee_des)
            rec.write("/control", "cerebx.Control", t, msg)
        if self.scene is not None:
            self.scene.step(tick, t, ee, ee_des, self._steps_on)
        # physics
        plant.step()
        self.tick += 1
        if tick % DIVERGENCE_CHECK_TICKS == 0:
            check_diverged(plant, trial, t)
        return applied

    def run_trial(self, trial: int) -> TrialMetrics:
        ref = self.task.trial(trial, self._task_rng)
        rec = self.rec
        self._hold_steps(trial, ref.steps)
        acc = TrialAccumulator(self.plant.n_joints, ref.steps, self.cfg.control_dt_ms, n_command=self._n_command)
        for e, fire in self._trial_events:
            if e.at_trial == trial:
                self._fire(e, fire, self.tick * self.dt_s)
        if rec is not None and trial == 0 and ref.xyz is not None:
            rec.write("/task/cartesian_path", "cerebx.CartesianPath", 0.0,
                      {"x": ref.xyz[:, 0].copy(), "y": ref.xyz[:, 1].copy(), "z": ref.xyz[:, 2].copy()})
        if self.scene is not None:
            self.scene.start_trial(self.tick * self.dt_s, trial, ref.xyz, self._steps_on)
        xyz = ref.xyz
        extra = [(f"ref.{name}", v) for name, v in ref.extra.items()]
        desired: list[bytes] | list[None] = [None] * ref.steps
        if rec is not None and self.record_joints and self._steps_on:  # the trial's desired states, encoded at once
            desired = rec.joint_state_messages(DESIRED, stamps_ns(self.tick, ref.steps, self.dt_s), ref.q, ref.qd)
        for i in range(ref.steps):
            self.step(ref.q[i], ref.qd[i], acc, trial, xyz[i] if xyz is not None else None,
                      {name: v[i] for name, v in extra} if extra else None, desired[i])
        check_diverged(self.plant, trial)
        m = acc.finish(trial)
        self.metrics.append(m)
        self.trials_done = trial + 1
        ends = [st.end_trial(trial) for st in self.brain]
        if rec is not None:
            rec.write("/trial_metrics", "cerebx.TrialMetrics", self.tick * self.dt_s,
                      {**m.__dict__, "label": ref.label})
            self._weights_due.append((self.tick * self.dt_s, trial, ends))
            self._write_weights(wait=False)
        if self.scene is not None:
            self.scene.end_trial(self.tick * self.dt_s, m)
        return m

    def _hold_steps(self, trial: int, steps: int) -> None:
        """Whether ``trial``'s control steps are recorded (``recording.trials``); under a window the recorder
        learns the simulated times of each recorded trial, for what is logged after the loop's tick (the
        network's spikes)."""
        if self.window is None:
            return
        self._steps_on = self.window.holds(trial, self.cfg.trials)
        if self.rec is None:
            return
        if self.rec.held is None:  # a new recorder (a resumed run): the trial before may still log spikes
            self.rec.restrict_steps(self._last_held)
        if self._steps_on:
            start, end = stamps_ns(self.tick, steps + 1, self.dt_s)[[0, -1]]
            self._last_held = (int(start), int(end))
            self.rec.restrict_steps(self._last_held)

    def settle(self) -> None:
        """Write every trial's ``/weights`` still waiting for its values (before a checkpoint and at the end:
        a stage may still be computing them, see :class:`~cerebx.signals.Deferred`)."""
        self._write_weights(wait=True)

    def _write_weights(self, wait: bool) -> None:
        """The waiting ``/weights`` messages in trial order, each with its trial's end as its time; without
        ``wait`` only up to the first whose values are not ready yet."""
        while self._weights_due:
            t, trial, ends = self._weights_due[0]
            if not wait and not all(getattr(e, "ready", True) for e in ends):
                return
            self._weights_due.popleft()
            extra: dict[str, float] = {}
            for e in ends:
                extra.update(e)
            if extra and self.rec is not None:
                self.rec.write("/weights", "cerebx.WeightSummary", t, {"trial": trial, **extra})

    @property
    def sim_seconds(self) -> float:
        return self.tick * self.dt_s
