"""Schema of the corrective spiking cerebellum of Luque et al. 2011 (added to a crude inverse dynamics
feed-forward torque, ``cerebx_luque2011.schema``).

Numbers from the paper (IEEE TSMC-B 2011, Sections II-C/D/E, Table I) are marked *paper*; numbers it
does not give are *constructed* (chosen here; docs/models.md#luque-lif, docs/models.md#luque-plasticity
and the sections after it)."""

from __future__ import annotations

from typing import Any, Literal

from pydantic import Field, model_validator

from cerebx.api.schema import ControllerConfig, NonNegFloat, PositiveFloat, Strict, TaskRanges


class ConductanceLIF(Strict):
    """Leaky integrate-and-fire neuron with exponentially decaying synaptic conductances (Eq. 3-4)."""

    capacitance_pF: PositiveFloat
    rest_conductance_nS: PositiveFloat
    rest_mV: float = -70.0
    threshold_mV: float
    refractory_ms: NonNegFloat
    tau_exc_ms: PositiveFloat
    tau_inh_ms: PositiveFloat
    e_exc_mV: float = Field(0.0, description="excitatory reversal potential (constructed: not in Table I)")
    e_inh_mV: float = Field(-80.0, description="inhibitory reversal potential (constructed: not in Table I)")

    @model_validator(mode="after")
    def _threshold(self) -> ConductanceLIF:
        if not self.rest_mV < self.threshold_mV < self.e_exc_mV:
            raise ValueError("threshold_mV must lie between rest_mV and e_exc_mV")
        return self


PC_TABLE_I = ConductanceLIF(capacitance_pF=500.0, rest_conductance_nS=16.0, threshold_mV=-52.0, refractory_ms=2.0,
                            tau_exc_ms=1.2, tau_inh_ms=9.3)
DCN_TABLE_I = ConductanceLIF(capacitance_pF=2.0, rest_conductance_nS=0.2, threshold_mV=-40.0, refractory_ms=1.0,
                             tau_exc_ms=0.5, tau_inh_ms=10.0)


class InputLayer(Strict):
    """RBF receptive fields driving LIF input cells (Eq. 2): tau dv/dt = -v + drive * exp(-(x - mu)^2 / 2 sigma^2),
    v in units of the firing threshold (spike and reset to 0 at 1)."""

    cells_per_signal: int = Field(20, ge=2, description="paper: 6 groups of 20 (desired q and qd of 3 joints)")
    tau_ms: PositiveFloat = Field(10.0, description="input-cell membrane time constant (constructed)")
    drive_at_centre: PositiveFloat = Field(
        1.5, description="R I at an RBF centre in units of the threshold (constructed: about 90 Hz there)"
    )
    sigma_spacing: PositiveFloat = Field(1.0, description="RBF sigma in units of the centre spacing (constructed)")
    ranges: TaskRanges = Field(TaskRanges(), description="centres span the task's desired envelope (+ margin)")


class LTDLTP(Strict):
    """PF-PC plasticity (Eq. 5-6): an IO spike depresses each PF-PC synapse by ``ltd_nS`` x the sum of
    k(t_IO - t_PF) over the PF's earlier spikes, k(s) = e^-x sin(x)^20, x = s atan(20) / peak (normalised to 1
    at its peak, ``kernel_peak_ms + arm_lag_ms``); every PF spike potentiates its synapses by ``ltp_nS``.

    ``kernel_peak_ms`` is the paper's setting, the teaching delay of the link; ``arm_lag_ms`` adds the plant's own
    response time, which the paper's kernel does not name: an IO spike reports an error that torques of
    link delay + arm lag ago caused. Set ``arm_lag_ms: 0`` for the paper's kernel as written."""

    enabled: bool = True
    ltd_nS: NonNegFloat = Field(0.075, description="paper's balanced LTD (Fig. 8); unit taken as nS")
    ltp_nS: NonNegFloat = Field(0.01, description="paper: below 0.015 for LTD 0.075 (Fig. 8)")
    kernel_peak_ms: PositiveFloat = Field(100.0, description="paper: 100 ms, the loop's teaching delay")
    arm_lag_ms: NonNegFloat = Field(
        70.0,
        description="constructed: the lwr3 arm's own lag, added to the kernel's peak (docs/models.md#luque-plasticity)",
    )
    weight_max_nS: PositiveFloat = Field(30.0, description="upper weight bound (constructed: twice the start)")


class TeachingSignal(Strict):
    """IO teaching signal (Eq. 7): eps_j = kp_j (q_d - q) + kv_j (qd_d - qd), the measured state paired with
    the desired state of its own time stamp. Each IO cell of joint j's positive (negative) group fires in a
    2 ms step with probability rate_max x 2 ms x min(1, max(0, +-eps_j) / eps_full_scale)."""

    kp: tuple[float, float, float] = Field((1.0, 1.0, 1.0), description="position gains (constructed)")
    kv: tuple[float, float, float] = Field((0.1, 0.1, 0.1), description="velocity gains, s (constructed)")
    eps_full_scale: PositiveFloat = Field(0.1, description="eps at which the rate saturates (constructed)")
    rate_max_hz: PositiveFloat = Field(10.0, description="paper: IO fires at 0-10 Hz")


class CorrectiveOutput(Strict):
    """DCN activity averaged in a buffer: torque_j = gain_j (mean rate of the + group - of the - group)."""

    buffer_ms: PositiveFloat = Field(20.0, description="averaging window (constructed)")
    gain_Nm_per_hz: tuple[float, float, float] = Field(
        (0.1, 0.2, 0.1), description="N·m per Hz of DCN group-rate difference (constructed)"
    )


class Luque2011Cerebellum(ControllerConfig):
    """The corrective spiking cerebellum of Luque et al. 2011 (Section II-C): 120 input cells, 48 IO,
    48 PC (6 groups of 8) and 24 DCN (a + and a - group of 4 per joint); every input cell excites every
    PC (plastic, 15 nS at the start) and every DCN cell; each DCN cell is inhibited by the 2 PCs of its
    group that map to it. Writes a corrective ``joint.torque`` (added to the feed-forward in a composite)."""

    kind: Literal["luque2011_cerebellum"] = "luque2011_cerebellum"
    inputs: InputLayer = InputLayer()
    pc: ConductanceLIF = Field(PC_TABLE_I, description="Purkinje cells (Table I)")
    dcn: ConductanceLIF = Field(DCN_TABLE_I, description="DCN cells (Table I)")
    pf_pc_initial_nS: NonNegFloat = Field(15.0, description="paper: initial PF-PC conductance")
    pf_dcn_nS: NonNegFloat = Field(
        20.0, description="input cell -> DCN weight (constructed: the DCN fire ~150 Hz at the start, a bias both ways)"
    )
    pc_dcn_nS: NonNegFloat = Field(30.0, description="PC -> DCN weight (Table I: 30 nS x 1 synapse)")
    plasticity: LTDLTP = LTDLTP()
    teaching: TeachingSignal = TeachingSignal()
    output: CorrectiveOutput = CorrectiveOutput()
    substep_ms: PositiveFloat = Field(0.25, description="neuron integration step; must divide 2 ms")

    @model_validator(mode="after")
    def _substep(self) -> Luque2011Cerebellum:
        n = 2.0 / self.substep_ms
        if abs(n - round(n)) > 1e-9:
            raise ValueError(f"substep_ms: {self.substep_ms} ms does not divide the 2 ms control step")
        if self.pf_pc_initial_nS > self.plasticity.weight_max_nS:
            raise ValueError("pf_pc_initial_nS is above plasticity.weight_max_nS")
        return self

    def cross_check(self, exp: Any) -> list[str]:
        if exp.plant.n_joints != 3:
            return [f"kind: luque2011_cerebellum drives 3 joints, plant {exp.plant.kind} has "
                    f"{exp.plant.n_joints}"]
        return []
