"""Schemas of the cerebellar modules of Capolei et al. (2020) (Section II-D, Eq. 7-17, Table I): the forward
and inverse modules. Composed with the platform's velocity PID (``pid_velocity``, the paper's Eq. 3-6) as
parts of a ``composite`` controller in the order forward -> pid_velocity -> inverse; the forward module
writes ``capolei.qd_correction`` (Delta qdot^c), the PID reads it and writes ``joint.torque`` (tau^fb) and
``pid.velocity_error`` (e^tot), the inverse module adds Delta tau^c to ``joint.torque``."""

from __future__ import annotations

from typing import Any, Literal

from pydantic import Field, model_validator

from cerebx.api.schema import (
    VELOCITY_ERROR,
    ControllerConfig,
    LWPRParams,
    PositiveFloat,
    Signal,
    StageIO,
    Strict,
    periodic_part_problems,
)

QD_CORRECTION = "capolei.qd_correction"

PerJointPair = tuple[tuple[float, float], ...]
"""[ccm_1, ccm_2] per joint (Table I layout: one row per joint)."""


class SynapseKernel(Strict):
    """Plasticity parameters of one synapse type, [ccm_1, ccm_2] per joint (Table I). ``ltp``/``ltd`` are
    the potentiation/depression amplitudes per update (MTP/MTD for IO-DCN), ``alpha`` the kernel exponent."""

    ltp: PerJointPair
    ltd: PerJointPair
    alpha: PerJointPair

    @model_validator(mode="after")
    def _same_joints(self) -> SynapseKernel:
        if not len(self.ltp) == len(self.ltd) == len(self.alpha):
            raise ValueError("ltp, ltd and alpha need the same number of joints")
        return self


def _k(ltp, ltd, alpha) -> SynapseKernel:  # noqa: ANN001 - terse Table I rows below
    return SynapseKernel(ltp=ltp, ltd=ltd, alpha=alpha)


_E = 10.0 ** -3.3
_DCN = _k(((1e-4, 1e-4),) * 3, ((1e-4, 1e-4),) * 3, ((2.0, 2.0),) * 3)  # PC-DCN and MF-DCN, both models
FORWARD_PF_PC = _k(((1e-2, _E), (1e-2, _E), (1e-2, 1e-1)), ((1e-2, _E), (1e-2, _E), (1e-2, 1e-1)),
                   ((800.0, 170.0),) * 3)
INVERSE_PF_PC = _k(((1e-2, 1e-3),) * 3, ((1e-2, 1e-3),) * 3, ((300.0, 70.0), (300.0, 70.0), (500.0, 70.0)))
_MTP = ((1e-3, 1e-4), (1e-3, 1e-3), (1e-4, 1e-4))
_MTD = ((1e-4, 1e-5), (1e-4, 1e-4), (1e-5, 1e-5))
FORWARD_IO_DCN = _k(_MTP, _MTD, ((1000.0, 100.0), (600.0, 100.0), (300.0, 1000.0)))
INVERSE_IO_DCN = _k(_MTP, _MTD, ((100.0, 100.0), (100.0, 200.0), (500.0, 200.0)))

# granular layer: the authors' NRP controller (docs/provenance.md#lwpr-group-settings)
GRANULAR = LWPRParams(init_D=10.0, init_alpha=180.0, w_gen=0.4, w_prune=0.95, update_D=False)


class CerebellarModule(ControllerConfig):
    """One modular cerebellar circuit (MCC): per joint an ulm of M = 2 microcircuits (ccm_1 fed by the
    position error, ccm_2 by the velocity error), LWPR as the granular layer (Eq. 9), PF-PC, PC-DCN,
    MF-DCN and IO-DCN plasticity (Eq. 12-15) and the DCN output (Eq. 16-17)."""

    granular: LWPRParams = GRANULAR
    pf_pc: SynapseKernel
    pc_dcn: SynapseKernel = _DCN
    mf_dcn: SynapseKernel = _DCN
    io_dcn: SynapseKernel
    io_range: PerJointPair = Field(
        ((0.05, 0.2),) * 3, description="|error| mapped to |io| = 1 per joint, [position rad, velocity rad/s] "
        "(constructed)")
    signal_range: tuple[PositiveFloat, ...] = Field(
        (1.0, 1.0, 1.0), description="|PC| and |DCN| mapped to 1 before the PC-DCN rules, per joint (constructed)")
    output_gain: tuple[float, ...] = Field(
        (1.0, 1.0, 1.0), description="DCN output (in -1..1) to the correction's unit, per joint (constructed)")
    rate_hz: PositiveFloat = Field(50.0, description="update rate (the paper's f_samp); output held between")
    learn_from_trial: int = Field(5, ge=0, description="first trial (0-based) with LWPR and synaptic learning")
    correct_from_trial: int = Field(7, ge=0, description="first trial (0-based) whose output is applied")

    @model_validator(mode="after")
    def _joints(self) -> CerebellarModule:
        n = len(self.signal_range)
        for name in ("pf_pc", "pc_dcn", "mf_dcn", "io_dcn"):
            if len(getattr(self, name).ltp) != n:
                raise ValueError(f"{name}: {len(getattr(self, name).ltp)} joints, signal_range has {n}")
        if len(self.io_range) != n or len(self.output_gain) != n:
            raise ValueError(f"io_range and output_gain need {n} joints (as signal_range)")
        if any(v <= 0 for pair in self.io_range for v in pair):
            raise ValueError("io_range: every range must be > 0")
        return self

    @property
    def n_joints(self) -> int:
        return len(self.signal_range)

    def cross_check(self, exp: Any) -> list[str]:
        return periodic_part_problems("signal_range", self.n_joints, self.rate_hz, exp)


class CapoleiForward(CerebellarModule):
    """Forward MCC: MF = [qdot_r, tau^tot(t-1)] (Eq. 8), learns qdot, IO = [eps, e^fb] (Eq. 11); writes
    Delta qdot^c. Runs before the PID."""

    kind: Literal["capolei_forward"] = "capolei_forward"
    pf_pc: SynapseKernel = FORWARD_PF_PC
    io_dcn: SynapseKernel = FORWARD_IO_DCN
    output_gain: tuple[float, ...] = Field(
        (0.1, 0.1, 0.1), description="DCN output (in -1..1) to rad/s, per joint (constructed)")

    def io(self, n_joints: int) -> StageIO:
        return StageIO(("ref.q", "ref.qd"), (Signal(QD_CORRECTION, n_joints, "rad/s"),))


class CapoleiInverse(CerebellarModule):
    """Inverse MCC: MF = [qdot_r, qdot] (Eq. 7), learns tau^tot, IO = [eps, e^tot] (Eq. 10); adds Delta tau^c
    to the PID's torque (Eq. 6). Runs after the PID."""

    kind: Literal["capolei_inverse"] = "capolei_inverse"
    pf_pc: SynapseKernel = INVERSE_PF_PC
    io_dcn: SynapseKernel = INVERSE_IO_DCN
    output_gain: tuple[float, ...] = Field(
        (0.45, 0.65, 0.65), description="DCN output (in -1..1) to N·m, per joint (constructed: the iCub wrist "
        "effort limits)")

    def io(self, n_joints: int) -> StageIO:
        return StageIO(("ref.q", "ref.qd", VELOCITY_ERROR, "joint.torque"),
                       (Signal("joint.torque", n_joints, "N·m"),), frozenset({"joint.torque"}))
