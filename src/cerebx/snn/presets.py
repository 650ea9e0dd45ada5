"""The ``full`` network (conf/network/full.yaml) built in code, scaled by fibres per signal.

conf/network/*.yaml are the user-facing presets; this module gives tests and the benchmark the
same topology without going through Hydra. ``fibers=10, per_joint=100`` is the full network.
"""

from __future__ import annotations

from typing import Any

from cerebx.snn.schema import NetworkConfig

# GC integration as EDLUT's GPU granule model (docs/provenance.md#original-neurons): RK2 with a 1 ms step,
# 3 sub-steps once V
# is above (E_rest + V_th)/2. GC_RK4 is the same neuron with the default RK4 at the network dt.
GC_RK4 = dict(kind="lif_cond", C_m_pF=2.0, g_L_nS=1.0, E_L_mV=-65.0, E_AMPA_mV=0.0, tau_AMPA_ms=1.0,
              V_thr_mV=-50.0, t_ref_ms=1.0, clamp_at_rest=True)
GC = dict(GC_RK4, integration={"method": "rk2", "dt_ms": 1.0, "bifixed_substeps": 3})
PC = dict(kind="lif_cond", C_m_pF=100.0, g_L_nS=6.0, E_L_mV=-70.0, E_AMPA_mV=0.0, tau_AMPA_ms=1.2,
          V_thr_mV=-52.0, t_ref_ms=2.0, clamp_at_rest=True)
DCN = dict(kind="lif_cond", C_m_pF=2.0, g_L_nS=0.2, E_L_mV=-70.0, E_AMPA_mV=0.0, E_GABA_mV=-80.0,
           tau_AMPA_ms=0.5, tau_NMDA_ms=14.0, tau_GABA_ms=10.0, V_thr_mV=-40.0, t_ref_ms=1.0)


def network_dict(joints: int = 6, fibers: int = 10, per_joint: int = 100, kernels: int = 1,
                 pf_weight: float = 2.0) -> dict[str, Any]:
    """The ``full`` topology; ``kernels`` > 1 gives the ``multikernel`` variant (one PC population per
    kernel, PC->DCN weight 1/kernels each)."""
    n_mf, n_gc, n_x = joints * 4 * fibers, joints * fibers**4, joints * per_joint
    pops: dict[str, Any] = {
        "mf": {"size": n_mf, "neuron": {"kind": "input"}, "microcomplexes": joints},
        "cf": {"size": n_x, "neuron": {"kind": "input"}, "microcomplexes": joints},
        "gc": {"size": n_gc, "neuron": GC, "microcomplexes": joints},
    }
    proj: dict[str, Any] = {
        "mf_gc": {"pre": "mf", "post": "gc", "receptor": "ampa", "synapses": n_gc * 4, "weight_nS": 0.18,
                  "rule": {"kind": "joint_combinations", "joints": joints, "signals": 4,
                           "fibers_per_signal": fibers}},
        "mf_dcn": {"pre": "mf", "post": "dcn", "rule": {"kind": "all_to_all"}, "receptor": "ampa",
                   "synapses": n_mf * n_x, "weight_nS": 0.1},
    }
    three = [(140.0, 0.0006, -0.00042, 120.0), (150.0, 0.00112, -0.0006, 125.0), (165.0, 0.001, -0.00039, 130.0)]
    pcs = []
    for k in range(kernels):
        sfx = "" if kernels == 1 else str(k + 1)
        pc, cf_pc = f"pc{sfx}", f"cf_pc{sfx}"
        pcs.append(pc)
        pops[pc] = {"size": n_x, "neuron": PC, "microcomplexes": joints}
        peak, ltp, ltd, onset = (150.0, 0.002, -0.0008, 120.0) if kernels == 1 else three[k]
        proj[f"pf_{pc}"] = {
            "pre": "gc", "post": pc, "rule": {"kind": "all_to_all"}, "receptor": "ampa",
            "synapses": n_gc * n_x, "weight_nS": pf_weight, "weight_range_nS": [0.0, 5.0],
            "plasticity": {"kind": "kernel_stdp", "ltp_nS": ltp, "ltd_nS": ltd, "kernel_peak_ms": peak,
                           "kernel_onset_ms": onset, "teacher": cf_pc},
        }
        proj[f"{pc}_dcn"] = {"pre": pc, "post": "dcn", "rule": {"kind": "one_to_one"}, "receptor": "gaba",
                             "synapses": n_x, "weight_nS": round(1.0 / kernels, 6)}
        proj[cf_pc] = {"pre": "cf", "post": pc, "rule": {"kind": "one_to_one"}, "receptor": "ampa",
                       "synapses": n_x, "weight_nS": 0.0, "teaching": True}
    pops["dcn"] = {"size": n_x, "neuron": DCN, "microcomplexes": joints}
    proj["cf_dcn_ampa"] = {"pre": "cf", "post": "dcn", "rule": {"kind": "one_to_one"}, "receptor": "ampa",
                           "synapses": n_x, "weight_nS": 0.5}
    proj["cf_dcn_nmda"] = {"pre": "cf", "post": "dcn", "rule": {"kind": "one_to_one"}, "receptor": "nmda",
                           "synapses": n_x, "weight_nS": 0.25}
    name = "full" if kernels == 1 else "multikernel"
    return {"name": name, "dt_ms": 0.5, "populations": pops, "projections": proj,
            "io": {"mossy": "mf", "climbing": "cf", "output": "dcn", "purkinje": pcs, "granule": "gc"}}


def network(**kw: Any) -> NetworkConfig:
    """:func:`network_dict` validated."""
    return NetworkConfig.model_validate(network_dict(**kw))
