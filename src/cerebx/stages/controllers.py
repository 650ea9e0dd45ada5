"""A controller of several parts: :class:`Composite` runs them in order on the same tick; outputs with the
same name add up (feedback + feed-forward corrective torque), and each part keeps its own learned state.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from cerebx import runfiles
from cerebx.signals import Frame, Signal
from cerebx.stages.base import Stage


class Composite(Stage):
    """Parts run in order; a signal written by more than one part is their sum."""

    name = "composite"

    def __init__(self, parts: list[Stage]):
        self.parts = parts
        written: dict[str, Signal] = {}
        reads: list[str] = []
        for part in parts:
            reads += [r for r in part.reads if r not in written and r not in reads]
            part.adds = frozenset(part.adds | {s.name for s in part.writes if s.name in written})
            written.update({s.name: s for s in part.writes})
        self.reads = tuple(reads)
        self.writes = tuple(written.values())

    def reset(self, rng: np.random.Generator) -> None:
        for i, part in enumerate(self.parts):
            part.reset(np.random.default_rng(rng.integers(2**63)) if i else rng)

    def step(self, frame: Frame) -> None:
        for part in self.parts:
            part.step(frame)

    def record(self) -> dict[str, Any]:
        out: dict[str, Any] = {}
        for part in self.parts:
            out.update(part.record())
        return out

    def end_trial(self, trial: int) -> dict[str, float]:
        out: dict[str, float] = {}
        for i, part in enumerate(self.parts):
            out.update({f"{i}.{k}" if len(self.parts) > 1 else k: v for k, v in part.end_trial(trial).items()})
        return out

    def attach_recorder(self, recorder: Any) -> None:
        for part in self.parts:
            part.attach_recorder(recorder)

    @staticmethod
    def part_path(path: Path, i: int) -> Path:
        """Where part ``i`` keeps its state beside the run's state file."""
        path = Path(path)
        return path.with_name(runfiles.part_state(path.name, i))

    def save_state(self, path: Path) -> bool:
        saved = []
        for i, part in enumerate(self.parts):
            p = self.part_path(path, i)
            # a part written to the older Controller shape returns None: its file says whether it saved
            saved.append(bool(part.save_state(p)) or p.exists())
        if not any(saved):
            return False
        np.savez(path, parts=np.array(saved))
        return True

    def load_state(self, path: Path) -> None:
        for i, part in enumerate(self.parts):
            p = self.part_path(path, i)
            if p.exists():
                part.load_state(p)

    def describe(self) -> dict[str, Any]:
        return {"parts": [{"kind": p.name, **p.describe()} for p in self.parts]}
