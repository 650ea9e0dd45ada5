"""Parameters of an LWPR model. Defaults are those of the reference library (Klanke & Vijayakumar,
LWPR v1.2, ``lwpr_init_model``; docs/provenance.md#lwpr-defaults)."""

from __future__ import annotations

from typing import Literal

from pydantic import Field, model_validator

from cerebx.schema.base import Strict


class LWPRParams(Strict):
    """Receptive-field creation, forgetting, PLS growth and distance-metric adaptation."""

    init_D: float = Field(25.0, gt=0, description="initial distance metric D = init_D * I (1/input_unit^2)")
    init_alpha: float = Field(50.0, gt=0, description="initial learning rate of every element of M")
    w_gen: float = Field(0.1, gt=0, lt=1, description="a new RF is created where no activation exceeds this")
    w_prune: float = Field(1.0, gt=0, le=1, description="prune one of two RFs both more active than this "
                           "(1.0 never prunes)")
    init_lambda: float = Field(0.999, gt=0, le=1, description="initial forgetting factor")
    final_lambda: float = Field(0.99999, gt=0, le=1, description="asymptotic forgetting factor")
    tau_lambda: float = Field(0.9999, ge=0, le=1, description="annealing rate of the forgetting factor")
    penalty: float = Field(1e-6, ge=0, description="gamma: penalty on large D (used as gamma / n_in)")
    diag_only: bool = Field(True, description="adapt only the diagonal of M")
    update_D: bool = Field(True, description="adapt the distance metric by gradient descent")
    add_threshold: float = Field(0.5, gt=0, le=1, description="a PLS direction is added when the CV error "
                                 "ratio of the last two directions drops below this")
    init_S2: float = Field(1e-10, gt=0, description="initial sum of squared projections (regulariser)")
    kernel: Literal["gaussian", "bisquare"] = "gaussian"
    cutoff: float = Field(0.001, ge=0, description="RFs below this activation are left out of predictions")
    norm_in: float | tuple[float, ...] = Field(1.0, description="inputs are divided by this (scalar or per input)")
    norm_out: float | tuple[float, ...] = Field(1.0, description="outputs are divided by this (scalar or per output)")
    initial_capacity: int = Field(16, ge=1, description="RF slots preallocated per output (doubles when full)")

    @model_validator(mode="after")
    def _positive_norms(self) -> LWPRParams:
        for name in ("norm_in", "norm_out"):
            v = getattr(self, name)
            if any(x <= 0 for x in (v if isinstance(v, tuple) else (v,))):
                raise ValueError(f"{name} must be > 0")
        return self
