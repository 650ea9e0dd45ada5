"""Tiny runs of every report study: the quick plan with 1-3 trials and reduced networks."""

from __future__ import annotations

from pathlib import Path

from cerebx.report.studies import Job, execute, in_process_runner, plan

SMALL = ["controller.mf.fibers_per_signal=5", "controller.decoder.alpha_Nm_per_spike=[7.5,11.0,3.75,6.3,0.78,0.78]"]


def shrink(job: Job) -> Job:
    """A few trials; the spiking network reduced as in the small_snn preset."""
    from cerebx.config import load

    exp, _ = load([*job.args, *job.sweep_args])
    job.trials = exp.warmup_trials + (3 if "reaching" in job.study else 4 if job.study == "fig2_10_adaptation" else 2)
    net = getattr(exp.controller, "network", None)
    if net is not None and net.name != "upper_limb":  # the 2-joint network is small enough
        small = {"multikernel": "small_multikernel", "thesis_ch2": "small_ch2"}.get(net.name, "small")
        job.args = [*job.args, f"network={small}", *SMALL]
    return job


def make_fixture_runs(root: Path, log=lambda line: None) -> list[str]:
    # the Capolei studies repeat one preset over 20 seeds: two seeds are enough to draw the bands
    jobs = [shrink(j) for j in plan("quick", root)
            if not j.study.startswith("capolei2020") or j.label.endswith((",seed=0", ",seed=1"))]
    # the adaptation events happen within the shortened run
    for j in jobs:
        if j.study == "fig2_10_adaptation":
            j.args += ["events.0.at_trial=1", "events.1.at_trial=2", "events.2.at_trial=2", "events.3.at_trial=3"]
        if j.study.startswith("interaction_"):
            j.args += ["events.0.at_trial=2", "events.1.at_trial=3"]
    return execute(jobs, runner=in_process_runner, parallel=1, log=log)
