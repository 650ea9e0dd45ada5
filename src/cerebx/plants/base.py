"""The plant contract every registered plant satisfies (checked by :func:`check_plant`).

A plant owns a MuJoCo model and declares its signals: what it senses (``sensor_signals``, by
default ``joint.q`` and ``joint.qd``) and what it is commanded with (``command_signals``, by
default ``joint.torque``). The loop calls, once per 2 ms control step and in this order:
``sense()`` -> (brain side, link, robot-side stages) -> ``actuate(command)`` -> ``step()``.
``step`` advances ``control_dt_s`` in ``substeps`` physics steps with the command held constant
(zero-order hold). A joint-torque plant only implements ``sensors()`` and ``apply(tau)``; a plant
with other signals (muscle activations, muscle lengths) overrides the four signal methods.
Units are SI unless a signal declares otherwise: rad, rad/s, N·m, m, s.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, field

import numpy as np
from pydantic import ValidationError

from cerebx import registry
from cerebx.errors import CerebxError
from cerebx.signals import Signal, joint_signals


@dataclass(frozen=True)
class PlantEvent:
    """Something that happens to the plant at a scheduled time (payload, force pulse, ...).

    Parameters
    ----------
    time_s : float
        When it happens, s of simulated time.
    kind : str
        What happens.
    params : dict
        Its parameters.
    """

    time_s: float
    kind: str
    params: dict = field(default_factory=dict)


class Plant(ABC):
    """A torque-controlled mechanical system with ``n_joints`` controlled joints."""

    joint_names: tuple[str, ...]
    control_dt_s: float
    physics_dt_s: float

    @property
    def n_joints(self) -> int:
        return len(self.joint_names)

    @property
    def substeps(self) -> int:
        return int(round(self.control_dt_s / self.physics_dt_s))

    @abstractmethod
    def reset(self, q0: np.ndarray, rng: np.random.Generator) -> None:
        """Put the plant at rest at joint positions ``q0`` (time 0, events cleared)."""

    @abstractmethod
    def sensors(self) -> tuple[np.ndarray, np.ndarray]:
        """Measured joint positions and velocities (copies, possibly noisy)."""

    @abstractmethod
    def apply(self, tau: np.ndarray) -> np.ndarray:
        """Set the joint torque for the next step; returns the torque actually applied (saturated)."""

    @abstractmethod
    def step(self) -> None:
        """Advance the physics by one control step."""

    @property
    @abstractmethod
    def time_s(self) -> float:
        """Simulated time."""

    @abstractmethod
    def joint_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper joint position limits (rad)."""

    def true_state(self) -> tuple[np.ndarray, np.ndarray]:
        """Noise-free joint positions and velocities (for metrics); defaults to ``sensors()``."""
        return self.sensors()

    def end_effector(self) -> np.ndarray | None:
        """Cartesian end-effector position (m) in the world frame, if the plant has one."""
        return None

    # ---- signals --------------------------------------------------------------------------
    def torque_limits(self) -> np.ndarray | None:
        """Per-joint torque saturation (N·m), if the plant has one."""
        return None

    def sensor_signals(self) -> dict[str, Signal]:
        """What :meth:`sense` returns, by name."""
        s = joint_signals(self.n_joints)
        return {"joint.q": s["joint.q"], "joint.qd": s["joint.qd"]}

    def command_signals(self) -> dict[str, Signal]:
        """What :meth:`actuate` needs, by name."""
        return {"joint.torque": joint_signals(self.n_joints, self.torque_limits())["joint.torque"]}

    def sense(self) -> dict[str, np.ndarray]:
        """This step's sensor readings (measured: possibly noisy)."""
        q, qd = self.sensors()
        return {"joint.q": q, "joint.qd": qd}

    def actuate(self, command: dict[str, np.ndarray]) -> np.ndarray:
        """Set the command for the next step; returns what is actually applied (saturated)."""
        return self.apply(command["joint.torque"])

    def handle_event(self, event: PlantEvent) -> None:
        """Apply a plant event through the event registry; an unknown or unsupported kind raises ValueError."""
        registry.load_plugins()
        try:
            fire = registry.events.build(registry.events.parse({"kind": event.kind, **event.params}), self)
        except (ValidationError, CerebxError) as err:
            raise ValueError(f"{type(self).__name__}: event {event.kind!r}: {str(err).splitlines()[0]}") from None
        fire()

    def is_diverged(self) -> str | None:
        """A reason string when the state is non-finite or far outside the joint limits."""
        q, qd = self.true_state()
        if not (np.all(np.isfinite(q)) and np.all(np.isfinite(qd))):
            return "non-finite joint state"
        lo, hi = self.joint_limits()
        span = hi - lo
        if np.any(q < lo - span) or np.any(q > hi + span):
            return "joint position far outside its limits"
        return None
