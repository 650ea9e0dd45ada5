"""Shared building blocks for the configuration schemas."""

from __future__ import annotations

import difflib
from typing import Annotated, Any

from pydantic import AfterValidator, BaseModel, ConfigDict, Field, ModelWrapValidatorHandler, model_validator
from pydantic_core import InitErrorDetails, PydanticCustomError, ValidationError

from cerebx.signals import joint_signals

JOINTS_BAXTER = ("s0", "s1", "e0", "e1", "w0", "w1")


class Strict(BaseModel):
    """Base of every config model: unknown keys are errors and values are immutable."""

    model_config = ConfigDict(extra="forbid", frozen=True, validate_default=True)

    @model_validator(mode="wrap")
    @classmethod
    def _suggest_known_keys(cls, data: Any, handler: ModelWrapValidatorHandler) -> Any:
        """An unknown key of this model is "unknown key", naming the closest known ones (``kpp``: did you mean
        kp?)."""
        try:
            return handler(data)
        except ValidationError as err:
            errors = err.errors()
            if not any(map(_own_extra, errors)):
                raise
            raise ValidationError.from_exception_data(err.title, [
                _detail(e, _unknown_key(str(e["loc"][0]), cls.model_fields) if _own_extra(e) else e["msg"])
                for e in errors]) from None


def _own_extra(error: Any) -> bool:
    return error["type"] == "extra_forbidden" and len(error["loc"]) == 1


def _unknown_key(name: str, known: Any) -> str:
    close = closest(name, known)
    return "unknown key" + (f"; did you mean {' or '.join(close)}?" if close else "")


def closest(name: str, known: Any) -> list[str]:
    """The known names closest to a mistyped ``name`` (at most three, best first; none if nothing is close)."""
    return difflib.get_close_matches(name, list(known), n=3, cutoff=0.7)


def _detail(error: Any, msg: str) -> InitErrorDetails:
    """``error`` again with message ``msg`` (its type and location kept; the message is not formatted again)."""
    return InitErrorDetails(type=PydanticCustomError(error["type"], "{msg}", {"msg": msg}), loc=error["loc"],
                            input=error["input"])


CONTROL_DT_MS = 2.0
"""The control step (500 Hz) every loop runs at."""

PositiveFloat = Annotated[float, Field(gt=0)]


def _divides_control_step(ms: float) -> float:
    n = CONTROL_DT_MS / ms
    if abs(n - round(n)) > 1e-9:
        raise ValueError(f"{ms} ms does not divide the {CONTROL_DT_MS} ms control step")
    return ms


PhysicsStepMs = Annotated[float, Field(gt=0, description="MuJoCo timestep; must divide 2 ms"),
                          AfterValidator(_divides_control_step)]
NonNegFloat = Annotated[float, Field(ge=0)]
PerJoint = tuple[float, ...]
"""One value per controlled joint, in joint order; length is checked against the plant."""


class PlantSchema(Strict):
    """Base of plant schemas: the signals a plant of this config senses and is commanded with.
    The defaults are a joint-torque plant; a plant with other signals overrides both."""

    def sensor_signals(self) -> dict:
        s = joint_signals(self.n_joints)  # type: ignore[attr-defined]
        return {"joint.q": s["joint.q"], "joint.qd": s["joint.qd"]}

    def command_signals(self) -> dict:
        limit = getattr(self, "torque_limit_Nm", None)
        return {"joint.torque": joint_signals(self.n_joints, limit)["joint.torque"]}  # type: ignore[attr-defined]
