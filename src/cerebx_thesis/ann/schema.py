"""Schema of the rate-based (analog) cerebellum, the ANN baseline of thesis §3.2.6 / Annex S6."""

from __future__ import annotations

from typing import Annotated, Any, ClassVar, Literal

from pydantic import Field, model_validator

from cerebx.api.schema import ControllerConfig, GivenRanges, NonNegFloat, PositiveFloat, TaskRanges

CIRCLE_K_POS = (2.0, 6.0, 6.66, 8.0, 8.0, 6.0)
CIRCLE_K_VEL = (2.0, 1.66, 0.66, 0.66, 1.33, 0.66)
CIRCLE_GAIN_NM = (10.0, 22.0, 3.0, 15.0, 2.0, 3.5)


class ANNController(ControllerConfig):
    """Analog cerebellum (docs/models.md#ann-state-coding): a state-table granular layer, PC/IO/DCN
    agonist-antagonist pairs per joint and PF-PC plasticity dw = (LTP (1 - IO) - LTD IO) |e|.

    Per joint the four MF signals (q_d, q, qd_d, qd) are each quantised into ``bins`` bins; the
    granule cells are the bins**4 combinations and 4 * bins of them are active at a time (every bin
    of one signal with the other three at their current bins). The teaching error is
    e = k_pos (q_d - q) + k_vel (qd_d - qd); IO = e clipped to [0, 1], split by sign;
    DCN = clip(w_mf MF - w_pc PC + w_io IO, 0, 1); tau = gain (DCN_agonist - DCN_antagonist).
    """

    kind: Literal["ann"] = "ann"
    cpu_per_sim_s: ClassVar[float] = 0.050
    """CPU seconds per simulated second on top of the loop's, for the run's estimate (``cerebx.estimate``):
    measured 82.6 ms per simulated s for the ANN runs of the quick profile against 31 ms for PD (2026-11-28)."""
    bins: int = Field(4, ge=2, le=8, description="bins per MF signal (n); granule cells per joint = n**4")
    ranges: Annotated[GivenRanges | TaskRanges, Field(discriminator="kind")] = Field(
        TaskRanges(), description="MF ranges for the state coding; q_d shares the q range"
    )
    k_pos: tuple[float, ...] = Field(CIRCLE_K_POS, description="error gain on q_d - q (1/rad)")
    k_vel: tuple[float, ...] = Field(CIRCLE_K_VEL, description="error gain on qd_d - qd (s/rad)")
    gain_Nm: tuple[PositiveFloat, ...] = Field(CIRCLE_GAIN_NM, description="torque per unit DCN difference")
    ltp: NonNegFloat = Field(2.5e-6, description="PF-PC potentiation rate")
    ltd: NonNegFloat = Field(2.0e-5, description="PF-PC depression rate")
    w_init: PositiveFloat | None = Field(None, description="initial PF-PC weight; None = 0.2 / (4 bins)")
    w_max_factor: PositiveFloat = Field(
        1.5, description="w_max = w_max_factor * w_init; weights live in [0, w_max]"
    )
    mf_rate: NonNegFloat = Field(1.0, description="baseline MF activity (normalised rate)")
    w_mf_dcn: NonNegFloat = 1.0
    w_pc_dcn: NonNegFloat = Field(1.0, description="PC-DCN inhibition magnitude (the weight is -w_pc_dcn)")
    w_io_dcn: NonNegFloat = 0.2
    plasticity: bool = True
    pc_input: Literal["all_joints", "own_joint"] = Field(
        "all_joints",
        description="granule cells each PC sums: 'all_joints' as the original code (and Eq. 3.10, "
        "PC = f(PF)); 'own_joint' only its joint's 4n cells (then PC <= 0.3 and the learned torque is weak)",
    )
    desired: Literal["newest", "sensor_stamp"] = Field(
        "newest",
        description="desired sample the measured one is paired with (error and state coding): 'newest' as the "
        "original analog_cerebellum.py, which keeps the newest desired and the newest arrived measurement "
        "(misaligned by the sensor delay, as the PD); 'sensor_stamp' the desired sample of the measurement's own stamp",
    )
    plasticity_error: Literal["granule_joint", "pc_joint"] = Field(
        "granule_joint",
        description="whose |e| scales a PF-PC weight change: 'granule_joint' (the original: the error of the joint "
        "the active granule cell codes) or 'pc_joint' (the error of the Purkinje cell's own joint)",
    )
    joint0_overwrite: bool = Field(
        False,
        description="the original's indexing slip: entries 1-5 of joint 0's active list are overwritten by "
        "joints 1-5's exact states",
    )

    @model_validator(mode="after")
    def _lengths(self) -> ANNController:
        n = len(self.gain_Nm)
        if not len(self.k_pos) == len(self.k_vel) == n:
            raise ValueError(
                f"k_pos ({len(self.k_pos)}), k_vel ({len(self.k_vel)}) and gain_Nm ({n}) "
                "need one value per joint"
            )
        return self

    @property
    def n_joints(self) -> int:
        return len(self.gain_Nm)

    def state_problems(self, meta: dict[str, Any], exp: Any) -> str | None:
        return None if meta.get("kind") == "ann" else "is not an ANN state (saved by another controller)"

    @property
    def initial_weight(self) -> float:
        return self.w_init if self.w_init is not None else 0.2 / (4 * self.bins)
