"""The Hydra application behind ``cerebx run``: output folders, multirun, launchers, --cfg."""

from __future__ import annotations

import logging
import sys
from pathlib import Path

import hydra
from hydra.core.config_store import ConfigStore
from hydra.core.hydra_config import HydraConfig
from omegaconf import DictConfig

from cerebx.config import to_plain, user_choices
from cerebx.errors import ConfigError
from cerebx.schema.experiment import validate

log = logging.getLogger("cerebx")

SWEEP_SUMMARY = "sweep_summary"  # hydra/callbacks option that prints a sweep's table when it ends
# Registered here, in code: config files name no code. `cerebx run -m` selects it (cli.py).
ConfigStore.instance().store(group="hydra/callbacks", name=SWEEP_SUMMARY, package="hydra.callbacks",
                             node={SWEEP_SUMMARY: {"_target_": "cerebx.report.sweep.PrintSweepSummary"}})


@hydra.main(config_path="conf", config_name="config", version_base="1.3")
def run_app(cfg: DictConfig) -> float | None:
    from cerebx import jobenv

    jobenv.configure()  # before numba is imported: launchers' jobs do not inherit the Makefile's env
    log.info("job: %s", jobenv.describe())
    from cerebx.loop import resume
    from cerebx.loop.runner import run_experiment
    from cerebx.report.console import print_summary

    hc = HydraConfig.get()
    run_dir = Path(hc.runtime.output_dir)
    try:
        plain = to_plain(cfg)
        exp = validate(plain)
        exp, run_dir, reused = resume.continued(exp, plain, run_dir)
    except ConfigError as err:
        for line in err.problems:
            print(line, file=sys.stderr)
        raise SystemExit(2) from None
    if reused is not None:
        print(f"reused: {run_dir} already completed {reused.get('trials_completed')} trials")
        return reused.get("final_mae")
    choices = user_choices(hc.runtime.choices)
    summary = run_experiment(exp, run_dir, plain, overrides=list(hc.overrides.task), choices=choices)
    print_summary(summary, run_dir)
    if summary["status"] == "failed":
        raise SystemExit(1)
    if summary["status"] == "interrupted":
        raise SystemExit(130)
    return summary["final_mae"]
