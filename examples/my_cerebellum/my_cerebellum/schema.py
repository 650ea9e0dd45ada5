"""The model's configuration: what a user may set, with units, bounds and defaults (validated before a run)."""

from __future__ import annotations

from typing import Any, Literal

from pydantic import Field, model_validator

from cerebx.api.schema import ControllerConfig


class AdaptiveFilterConfig(ControllerConfig):
    """A rate-coded cerebellar adaptive filter (Fujita 1982; Dean & Porrill 2010). Per joint, the granular layer
    is a bank of low-pass filters of the desired position and velocity (time constants spaced logarithmically
    from ``tau_min_ms`` to ``tau_max_ms``, plus a constant); the Purkinje output is their weighted sum, the
    joint torque; the climbing fibre carries the joint error e = k_pos (q_d - q) + k_vel (qd_d - qd), and each
    weight learns by the decorrelation rule dw = rate * e * g, with g the filter output at the time the error
    was measured. Writes ``joint.torque`` (add it to a feedback controller in a ``composite``)."""

    kind: Literal["adaptive_filter"] = "adaptive_filter"
    n_joints: int = Field(2, ge=1, description="controlled joints")
    filters: int = Field(8, ge=1, description="granule-cell filters per joint and signal")
    tau_min_ms: float = Field(20.0, gt=0, description="shortest filter time constant")
    tau_max_ms: float = Field(1000.0, gt=0, description="longest filter time constant")
    rate: float = Field(2.0, gt=0, description="learning rate (N·m per unit error per unit filter output, per s)")
    k_pos: float = Field(1.0, ge=0, description="error gain on q_d - q (1/rad)")
    k_vel: float = Field(0.1, ge=0, description="error gain on qd_d - qd (s/rad)")
    tau_max_Nm: float = Field(20.0, gt=0, description="output saturation")

    @model_validator(mode="after")
    def _taus(self) -> AdaptiveFilterConfig:
        if self.tau_min_ms >= self.tau_max_ms:
            raise ValueError("tau_min_ms must be below tau_max_ms")
        return self

    def cross_check(self, exp: Any) -> list[str]:
        n = exp.plant.n_joints
        return [] if n == self.n_joints else [f"n_joints: {self.n_joints}, but plant {exp.plant.kind} has {n}"]

    def state_problems(self, meta: dict[str, Any], exp: Any) -> str | None:
        if meta.get("kind") != self.kind:
            return f"was saved by a {meta.get('kind')!r} controller"
        if (meta.get("n_joints"), meta.get("filters")) != (self.n_joints, self.filters):
            return f"holds {meta.get('n_joints')} joints x {meta.get('filters')} filters, this model has " \
                   f"{self.n_joints} x {self.filters}"
        return None
