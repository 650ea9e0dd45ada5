"""Shared building blocks for the configuration schemas."""

from __future__ import annotations

from typing import Annotated

from pydantic import BaseModel, ConfigDict, Field

JOINTS_BAXTER = ("s0", "s1", "e0", "e1", "w0", "w1")


class Strict(BaseModel):
    """Base of every config model: unknown keys are errors and values are immutable."""

    model_config = ConfigDict(extra="forbid", frozen=True, validate_default=True)


PositiveFloat = Annotated[float, Field(gt=0)]
NonNegFloat = Annotated[float, Field(ge=0)]
PerJoint = tuple[float, ...]
"""One value per controlled joint, in joint order; length is checked against the plant."""
