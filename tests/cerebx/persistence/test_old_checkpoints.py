"""Checkpoints written before the joint-torque controllers became stages still resume, to the same trials.

The fixtures were written by the code of commit 354b163 (PD, and a composite of two PDs, on the planar arm
over a gamma link delay; checkpoint after 2 of 4 trials): its pickles hold the adapter
``cerebx.stages.controllers.TorqueControllerStage`` around each controller. The expected trial errors are
what that code computed when it resumed them.
"""

from __future__ import annotations

import tarfile
from pathlib import Path

import pytest

from cerebx.controllers.base import Controller
from cerebx.loop import resume
from cerebx.persistence.checkpoint import TorqueControllerStage
from cerebx.recording.recorder import Recorder
from cerebx.stages.controllers import Composite

pytestmark = pytest.mark.integration

FIXTURES = Path(__file__).parent / "fixtures" / "checkpoints_before_controllers_were_stages.tar.gz"
RUN = ["+experiment=demo", "delay=gamma25", "trials=4", "recording.progress=off"]
TWO_PDS = ["~controller", "+controller={kind: composite, parts: [{kind: pd, kp: [60.0, 40.0], kd: [4.0, 2.5], "
           "tau_max_Nm: [30.0, 20.0]}, {kind: pd, kp: [5.0, 5.0], kd: [0.5, 0.5], tau_max_Nm: [30.0, 20.0]}]}"]
CASES = {
    "pd": (RUN, [0.21197097604144693, 0.2523260674289302, 0.2412644305850446, 0.3612005761335439]),
    "composite": (RUN + TWO_PDS, [0.20771291438105755, 0.2924764318409315, 0.2621508384801112, 0.2667350092777504]),
}


def _controllers(stages):
    for st in stages:
        yield from _controllers(st.parts) if isinstance(st, Composite) else [st]


@pytest.mark.parametrize("name", sorted(CASES))
def test_a_checkpoint_from_before_controllers_were_stages_resumes_to_the_same_trials(load, tmp_path, name):
    overrides, mae = CASES[name]
    with tarfile.open(FIXTURES) as tar:
        tar.extractall(tmp_path, filter="data")
    run_dir = tmp_path / name
    rec = Recorder(run_dir / "run.1.mcap")
    loop, _ = resume.load(load(overrides), run_dir, rec)
    controllers = list(_controllers(loop.ctx.brain))
    assert len(controllers) == (2 if name == "composite" else 1)
    for c in controllers:
        assert isinstance(c, Controller) and not isinstance(c, TorqueControllerStage)
        assert c.name == "pd" and c.reads == ("ref.q", "ref.qd") and [s.name for s in c.writes] == ["joint.torque"]
    if name == "composite":
        assert controllers[1].adds == frozenset({"joint.torque"})  # its torque adds to the first part's
    for trial in range(loop.trials_done, 4):
        loop.run_trial(trial)
    loop.settle()
    rec.close()
    assert [m.mae for m in loop.metrics] == mae  # exactly what the code before computed from this checkpoint
