"""The Hydra application behind ``cerebx run``: output folders, multirun, launchers, --cfg.

Importing this module first sets the job's numba settings (``jobenv.configure``): a launcher's job process
(joblib, SLURM) imports it to find ``run_app``, before anything has imported numba."""

from cerebx import jobenv

jobenv.configure()

import logging
import sys
from pathlib import Path

import hydra
from hydra.core.hydra_config import HydraConfig
from hydra.types import RunMode
from omegaconf import DictConfig

from cerebx import runfiles
from cerebx.config import to_plain, user_choices
from cerebx.errors import CerebxError, ConfigError
from cerebx.link.pairing import NotPaired
from cerebx.loop import resume
from cerebx.loop.brain_side import leave_nothing
from cerebx.loop.runner import run_experiment
from cerebx.recording.console import print_summary
from cerebx.schema.experiment import validate

log = logging.getLogger("cerebx")


@hydra.main(config_path="conf", config_name="config", version_base="1.3")
def run_app(cfg: DictConfig) -> float | None:
    jobenv.configure_job()
    log.info("job: %s", jobenv.describe())
    hc = HydraConfig.get()
    run_dir = Path(hc.runtime.output_dir)
    in_sweep = hc.mode == RunMode.MULTIRUN  # a sweep's job fails alone: the next job still runs
    try:
        plain = to_plain(cfg)
        exp = validate(plain)
        exp, run_dir, reused = resume.continued(exp, plain, run_dir)
    except ConfigError as err:
        for line in err.problems:
            print(line, file=sys.stderr)
        if in_sweep:
            (run_dir / runfiles.ERROR).write_text("; ".join(err.problems) + "\n")
            return None
        raise SystemExit(2) from None
    # a refusal an earlier attempt of this job left (error.txt) no longer stands: this attempt's summary tells
    (Path(hc.runtime.output_dir) / runfiles.ERROR).unlink(missing_ok=True)
    if reused is not None:
        print(f"reused: {run_dir} already completed {reused.get('trials_completed')} trials")
        return reused.get("final_mae")
    choices = user_choices(hc.runtime.choices)
    try:
        summary = run_experiment(exp, run_dir, plain, overrides=list(hc.overrides.task), choices=choices)
    except NotPaired as err:  # a wall-clock run whose sides did not pair: one line, nothing left behind
        print(err, file=sys.stderr)
        leave_nothing(run_dir)
        raise SystemExit(2) from None
    except CerebxError as err:
        print(err, file=sys.stderr)
        raise SystemExit(1) from None
    print_summary(summary, run_dir)
    if summary["status"] == "interrupted":
        raise SystemExit(130)
    if summary["status"] == "failed" and not in_sweep:
        raise SystemExit(1)
    return summary["final_mae"]
