"""Schemas of the upper limb's robot-side stages between the cerebellum and the muscles:
the spinal cord (stretch reflex and reciprocal inhibition) and, without it, the cerebellum's agonist /
antagonist commands as the muscle activations directly; plus a brain-side split of a joint torque into
agonist/antagonist commands (lets a torque controller such as PD drive a muscle plant)."""

from __future__ import annotations

from typing import ClassVar, Literal

from pydantic import Field, model_validator

from cerebx.schema.base import NonNegFloat, PositiveFloat
from cerebx.schema.plant import MUSCLES_UPPER_LIMB
from cerebx.schema.stages import StageConfig
from cerebx.signals import Signal, StageIO

# Which joints' commands drive each muscle (bi-articular: the mean of both) and whether it
# takes the agonist (flexor) or antagonist (extensor) command.
JOINTS = {"deltoid": (0,), "biceps_long": (0, 1), "biceps_short": (1,), "brachialis": (1,),
          "triceps_long": (0, 1), "triceps_lateral": (1,), "triceps_medial": (1,)}
FLEXORS = ("deltoid", "biceps_long", "biceps_short", "brachialis")
# Antagonist pairs (constructed one-to-one; docs/models.md#spinal-cord): each muscle's MN is
# inhibited by the mean of its antagonists' Ia interneurons.
ANTAGONISTS = {"deltoid": ("triceps_long",), "biceps_long": ("triceps_long",),
               "biceps_short": ("triceps_lateral",), "brachialis": ("triceps_medial",),
               "triceps_long": ("deltoid", "biceps_long"), "triceps_lateral": ("biceps_short",),
               "triceps_medial": ("brachialis",)}


class _MuscleMap(StageConfig):
    """The muscles and which joint commands drive them (agonist = flexor command, antagonist = extensor)."""

    sides: ClassVar[tuple[str, ...]] = ("robot",)
    muscles: tuple[str, ...] = Field(MUSCLES_UPPER_LIMB, description="the plant's muscles, in command order")
    joints: dict[str, tuple[int, ...]] = Field(
        default_factory=lambda: dict(JOINTS), description="joints whose commands drive each muscle (mean)")
    flexors: tuple[str, ...] = Field(FLEXORS, description="muscles taking the agonist command; the rest the antagonist")

    @model_validator(mode="after")
    def _every_muscle_mapped(self):
        missing = [m for m in self.muscles if m not in self.joints]
        if missing:
            raise ValueError(f"joints: no joints given for {', '.join(missing)}")
        unknown = [m for m in (*self.joints, *self.flexors) if m not in self.muscles]
        if unknown:
            raise ValueError(f"unknown muscles {', '.join(sorted(set(unknown)))} (muscles: {', '.join(self.muscles)})")
        return self

    def io(self, n_joints: int) -> StageIO:
        return StageIO(("muscle.ag", "muscle.at"),
                       (Signal("muscle.activation", len(self.muscles), "", 0.0, 1.0),))


class DirectMusclesConfig(_MuscleMap):
    """No spinal cord: each muscle's activation command is its agonist or antagonist command
    (bi-articular muscles: the mean over both joints)."""

    kind: Literal["direct_muscles"] = "direct_muscles"


class SpinalCordConfig(_MuscleMap):
    """Spinal cord (docs/models.md#spinal-cord): per muscle one motor neuron (MN) and one Ia interneuron
    (Ia IN), leaky rate neurons tau_m dr/dt = -r + sigma(sum w_i r_i), sigma(x) = 1/(1 + exp(-k (x - x0))).
    MN input: w_exc (command + own Ia afferent) - w_inh (mean of the antagonists' Ia INs); Ia IN input:
    w_exc own Ia afferent. Ia afferent r = a |v|^p sign(v) + b l + c of the length/velocity measured
    ``afferent_delay_ms`` earlier, normalised to [0, 1] (see ``velocity_range_mm_per_s``). The MN rate is
    the muscle excitation; the plant's muscle integrates the activation dynamics (Eq. 4.4-4.5)."""

    kind: Literal["spinal_cord"] = "spinal_cord"
    tau_m_ms: PositiveFloat = Field(10.0, description="membrane time constant of MNs and Ia INs (Eq. 4.1)")
    w_exc: NonNegFloat = Field(1.0, description="weight of excitatory inputs (command, Ia afferent)")
    w_inh: NonNegFloat = Field(0.5, description="weight of the inhibitory Ia IN input")
    sigmoid_slope: PositiveFloat = Field(6.0, description="k in Eq. 4.2")
    sigmoid_centre: float = Field(0.5, description="x0 in Eq. 4.2")
    afferent_delay_ms: NonNegFloat = Field(30.0, description="tau_s: sensory delay of the Ia afferent (Eq. 4.3); "
                                           "a whole number of 2 ms steps")
    ia_velocity_gain: NonNegFloat = Field(4.3, description="a in Eq. 4.3 (per (mm/s)^p)")
    ia_velocity_exponent: PositiveFloat = Field(0.6, description="p in Eq. 4.3")
    ia_length_gain: NonNegFloat = Field(2.0, description="b in Eq. 4.3 (per mm)")
    ia_offset: float = Field(10.0, description="c in Eq. 4.3")
    velocity_range_mm_per_s: PositiveFloat = Field(
        5000.0, description="constructed: velocities are clipped to +-this (mm/s) and the rate's peak is taken here")
    normalise: Literal["peak", "range"] = Field(
        "peak", description="constructed: 'peak' divides the rate by its peak (longest length, +velocity range); "
        "'range' maps [rate at (shortest length, -range), rate at (longest length, +range)] onto [0, 1]; "
        "lengths from the plant's muscle.length bounds")
    antagonists: dict[str, tuple[str, ...]] = Field(
        default_factory=lambda: dict(ANTAGONISTS), description="whose Ia INs inhibit each muscle's MN (mean)")

    @model_validator(mode="after")
    def _antagonists_known(self):
        bad = [a for m, ants in self.antagonists.items() for a in (m, *ants) if a not in self.muscles]
        if bad:
            raise ValueError(f"antagonists: unknown muscles {', '.join(sorted(set(bad)))}")
        missing = [m for m in self.muscles if not self.antagonists.get(m)]
        if missing:
            raise ValueError(f"antagonists: none given for {', '.join(missing)}")
        steps = self.afferent_delay_ms / 2.0
        if abs(steps - round(steps)) > 1e-9:
            raise ValueError(f"afferent_delay_ms: {self.afferent_delay_ms} is not a whole number of 2 ms steps")
        return self

    def io(self, n_joints: int) -> StageIO:
        base = super().io(n_joints)
        return StageIO((*base.reads, "muscle.length", "muscle.velocity"), base.writes)


class SplitPairsConfig(StageConfig):
    """Brain side: a joint torque as agonist/antagonist commands, ag = clip(tau / full, 0, 1),
    at = clip(-tau / full, 0, 1) (a torque controller, e.g. PD, driving a muscle plant: a non-learning baseline)."""

    sides: ClassVar[tuple[str, ...]] = ("brain",)
    kind: Literal["split_pairs"] = "split_pairs"
    full_command_Nm: tuple[PositiveFloat, ...] = Field(
        (10.0, 10.0), description="torque giving a command of 1, per joint")

    def io(self, n_joints: int) -> StageIO:
        return StageIO(("joint.torque",), (Signal("muscle.ag", n_joints, "", 0.0, 1.0),
                                            Signal("muscle.at", n_joints, "", 0.0, 1.0)))
