"""Stage schemas: the robot-side receivers (torque filters) and the safety supervisor.

Each schema's ``sides`` says where the stage may stand; a ``receiver`` may only be the first
robot-side stage (it turns the samples the link delivered into the command to apply).
"""

from __future__ import annotations

from typing import ClassVar, Literal

from pydantic import Field

from cerebx.schema.base import NonNegFloat, Strict
from cerebx.signals import Signal, StageIO


class StageConfig(Strict):
    """Base of every stage schema: where it may stand and the signals it reads and writes."""

    sides: ClassVar[tuple[str, ...]] = ("brain", "robot")
    receiver: ClassVar[bool] = False

    def io(self, n_joints: int) -> StageIO:
        """Signals read, written and added to (receivers pass on what the link delivers)."""
        return StageIO()


class HoldConfig(StageConfig):
    """Apply the newest command sample as it is."""

    sides: ClassVar[tuple[str, ...]] = ("robot",)
    receiver: ClassVar[bool] = True
    kind: Literal["hold"] = "hold"


class MeanFilterConfig(StageConfig):
    """Mean of the last ``taps`` command samples (15 taps = 30 ms)."""

    sides: ClassVar[tuple[str, ...]] = ("robot",)
    receiver: ClassVar[bool] = True
    kind: Literal["mean"] = "mean"
    taps: int = Field(15, gt=0, description="samples averaged (2 ms each)")


class FuturePastFilterConfig(StageConfig):
    """Mean over future and past stamped samples with a decaying safe stop
    (Eq. 3.6; docs/models.md#receiver-future-past)."""

    sides: ClassVar[tuple[str, ...]] = ("robot",)
    receiver: ClassVar[bool] = True
    kind: Literal["future_past"] = "future_past"
    past_samples: int = Field(10, gt=0, description="n: past samples kept (and future samples used, n + 1)")
    min_future_samples: int = Field(2, ge=0, description="fewer future samples than this + 1 starts the safe stop")
    decay_per_step: float = Field(0.998, gt=0, le=1, description="safe-stop decay of the output per 2 ms step")


class SupervisorConfig(StageConfig):
    """Watchdog PD acting only outside the joint bounds (docs/models.md#supervisor):
    tau = kp (bound - q) - s kd qd, s ramping by ``ramp_per_step`` to 1 while outside; added to the
    joint torque command."""

    sides: ClassVar[tuple[str, ...]] = ("robot",)
    kind: Literal["supervisor"] = "supervisor"
    kp: tuple[float, ...] = Field((20.0, 20.0, 20.0, 20.0, 3.0, 3.0), description="N·m/rad per joint")
    kd: tuple[float, ...] = Field((5.0, 5.0, 5.0, 5.0, 1.0, 1.0), description="N·m·s/rad per joint")
    ramp_per_step: float = Field(0.02, gt=0, le=1)
    bounds: Literal["encoder", "plant"] = Field(
        "encoder", description="'encoder': the controller's MF position ranges (as the original); 'plant': joint limits"
    )
    margin_rad: NonNegFloat = 0.0

    def io(self, n_joints: int) -> StageIO:
        torque = Signal("joint.torque", len(self.kp), "N·m")
        return StageIO(("joint.q", "joint.qd", "joint.torque"), (torque,), frozenset({"joint.torque"}))
