"""A connection rule and a learning rule of the lab's own for spiking networks (docs/howto/network.md)."""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import Field

from cerebx.api.schema import PairingSpec, PositiveFloat, Strict, Synapses


# --8<-- [start:connector]
class RingConnector(Strict):
    """Pre neuron i reaches the ``width`` post neurons around its own position on a ring (i * n_post / n_pre):
    width * n_pre synapses."""

    kind: Literal["ring"] = "ring"
    width: int = Field(gt=0, description="post neurons per pre neuron")

    def synapse_count(self, n_pre: int, n_post: int, same: bool) -> tuple[float, float]:
        """(expectation, tolerance): exact, so the tolerance is 0. A ValueError is a validation error."""
        if self.width > n_post:
            raise ValueError(f"width {self.width} is more than the {n_post} post neurons")
        return float(self.width * n_pre), 0.0


def ring(rule: RingConnector, n_pre: int, n_post: int, same: bool, rng: np.random.Generator) -> Synapses:
    centre = np.arange(n_pre) * n_post // n_pre
    post = (centre[:, None] + np.arange(rule.width) - rule.width // 2) % n_post
    return Synapses(pre=np.repeat(np.arange(n_pre), rule.width), post=post.ravel())
# --8<-- [end:connector]


# --8<-- [start:rule]
class ExpTeacher(Strict):
    """A fixed change per pre spike and, at each teaching spike, kernel * (t/peak) e^(1 - t/peak) for each pre spike
    t earlier (EDLUT's ExpAdditiveKernel shape)."""

    kind: Literal["exp_teacher"] = "exp_teacher"
    fixed_nS: float = Field(0.001, description="change at each pre spike")
    kernel_nS: float = Field(-0.01, description="scale of the change at a teaching spike")
    peak_ms: PositiveFloat = Field(100.0, description="time after a pre spike where the kernel is largest")
    window_ms: PositiveFloat = Field(500.0, description="pre spikes further back do not count")
    teacher: str = Field(description="projection whose arrivals at the post neuron teach")


def exp_teacher(rule: ExpTeacher, dt_ms: float) -> PairingSpec:
    """The rule as the engine's pairing family: tables over the age (in steps of dt_ms) of the spikes paired."""
    t = np.arange(int(rule.window_ms / dt_ms)) * dt_ms
    at_teacher = rule.kernel_nS * (t / rule.peak_ms) * np.exp(1 - t / rule.peak_ms)
    at_pre = np.zeros(1)  # teaching spikes before a pre spike change nothing
    return PairingSpec(fixed_nS=rule.fixed_nS, k_pre=at_pre, k_post=at_teacher, teacher=rule.teacher)
# --8<-- [end:rule]
