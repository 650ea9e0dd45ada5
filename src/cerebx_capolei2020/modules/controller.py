"""The Capolei et al. (2020) cerebellar modules as brain-side stages of a ``composite`` controller.

Order in one tick: ``capolei_forward`` (writes Delta qdot^c) -> the core's ``pid_velocity`` (tau^fb, e^tot) ->
``capolei_inverse`` (adds Delta tau^c). Each runs at its ``rate_hz`` (every k-th 2 ms tick, k whole)
and holds its output in between. The measured joint state comes from the newest sensor message; until
one arrives the parts output zeros. The efference copy tau^tot(t-1) is the joint torque the brain side
sent on the previous tick (the previous frame's summed ``joint.torque``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from cerebx.api import (
    VELOCITY_ERROR,
    BuildContext,
    Frame,
    Stage,
    StateMismatchError,
    load_state_npz,
    save_state_npz,
    updates_every,
)
from cerebx_capolei2020.modules.circuit import ModularCerebellarCircuit
from cerebx_capolei2020.modules.schema import QD_CORRECTION, CapoleiForward, CapoleiInverse


class _ModuleStage(Stage):
    """Common timing, learning schedule and state of the forward and inverse modules."""

    output: str

    def __init__(self, cfg: Any, ctx: BuildContext):
        self.cfg = cfg
        self.every = updates_every(cfg.rate_hz, ctx)
        self.n = cfg.n_joints
        self.circuit = ModularCerebellarCircuit(cfg)
        self.trial = 0
        self.correction = np.zeros(self.n)
        self.gain = np.asarray(cfg.output_gain, float)
        self._prev: dict[str, np.ndarray] | None = None  # the previous tick's signals (efference copy)

    def reset(self, rng: np.random.Generator) -> None:
        self.trial, self._prev = 0, None
        self.correction = np.zeros(self.n)

    def tau_previous(self) -> np.ndarray:
        prev = self._prev
        return prev["joint.torque"] if prev is not None and "joint.torque" in prev else np.zeros(self.n)

    def inputs(self, sig: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(MF, MF the teaching signal belongs to, teaching signal, [position, velocity] error per joint)."""
        raise NotImplementedError

    def step(self, frame: Frame) -> None:
        sig = frame.signals
        if frame.tick % self.every == 0 and "joint.q" in sig:
            mf, mf_train, x, err = self.inputs(sig)
            dcn = self.circuit.step(mf, x, err, self.trial >= self.cfg.learn_from_trial, mf_train)
            self.correction = self.gain * dcn if self.trial >= self.cfg.correct_from_trial else np.zeros(self.n)
        self._prev = sig
        self.emit(frame, self.output, self.correction.copy())

    def end_trial(self, trial: int) -> dict[str, float]:
        self.trial = trial + 1
        return self.circuit.summary()

    def save_state(self, path: Path) -> bool:
        save_state_npz(path, {"kind": self.cfg.kind}, trial=np.array(self.trial), **self.circuit.state())
        return True

    def load_state(self, path: Path) -> None:
        data, meta = load_state_npz(path, self.cfg.kind)
        if meta.get("kind") != self.cfg.kind:
            raise StateMismatchError(f"{path}: not a {self.cfg.kind} state (saved by {meta.get('kind')!r})")
        try:
            self.circuit.load({name: data[name] for name in data.files})
        except (KeyError, ValueError) as err:
            raise StateMismatchError(f"{path}: {err}") from None

    def describe(self) -> dict[str, Any]:
        return {"rate_hz": self.cfg.rate_hz, "learn_from_trial": self.cfg.learn_from_trial,
                "correct_from_trial": self.cfg.correct_from_trial, "output_gain": list(self.cfg.output_gain)}


class ForwardModuleStage(_ModuleStage):
    """Forward MCC: MF = [qdot_r, tau^tot(t-1)], learns qdot, IO = [eps, e^fb]; writes Delta qdot^c."""

    output = QD_CORRECTION

    def inputs(self, sig: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        qd = sig["joint.qd"]
        mf = np.concatenate([sig["ref.qd"], self.tau_previous()])
        err = np.stack([sig["ref.q"] - sig["joint.q"], sig["ref.qd"] - qd], axis=1)
        return mf, mf, qd, err


class InverseModuleStage(_ModuleStage):
    """Inverse MCC: MF = [qdot_r, qdot], learns tau^tot(t-1) at the MF of the previous update, IO = [eps, e^tot];
    adds Delta tau^c."""

    output = "joint.torque"

    def __init__(self, cfg: Any, ctx: BuildContext):
        super().__init__(cfg, ctx)
        self._mf_prev: np.ndarray | None = None

    def reset(self, rng: np.random.Generator) -> None:
        super().reset(rng)
        self._mf_prev = None

    def inputs(self, sig: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The torque of the previous update is paired with the state it was computed from."""
        mf = np.concatenate([sig["ref.qd"], sig["joint.qd"]])
        mf_train = mf if self._mf_prev is None else self._mf_prev
        self._mf_prev = mf
        err = np.stack([sig["ref.q"] - sig["joint.q"], sig[VELOCITY_ERROR]], axis=1)
        return mf, mf_train, self.tau_previous(), err


def build_forward(cfg: CapoleiForward, ctx: BuildContext) -> ForwardModuleStage:
    return ForwardModuleStage(cfg, ctx)


def build_inverse(cfg: CapoleiInverse, ctx: BuildContext) -> InverseModuleStage:
    return InverseModuleStage(cfg, ctx)
