"""The stage design: every registered controller and stage keeps the stage contract; a plant with a
non-torque command and a robot-side stage added by a plugin run without any change to the loop;
stages whose signals do not meet are refused with one line."""

from __future__ import annotations

from typing import Literal

import numpy as np
import pytest

from cerebx import registry
from cerebx.build import build_components
from cerebx.cli import main
from cerebx.errors import ConfigError
from cerebx.loop.runner import run_experiment
from cerebx.plants.planar2 import Planar2Arm
from cerebx.recording.reader import read_messages
from cerebx.schema.plant import Planar2Config
from cerebx.schema.stages import StageConfig
from cerebx.signals import Frame, Signal, StageIO
from cerebx.stages.base import Stage
from cerebx.stages.check import check_experiment

pytestmark = pytest.mark.integration

DEMO = ["+experiment=demo", "trials=1"]
UPPER_LIMB = ["+experiment=upper_limb_pd", "+task=vertical_circle_fast", "trials=1"]

# every controller and stage kind, each in an experiment where it belongs (planar arm unless it needs Baxter)
KINDS = {
    "controller": {
        "pd": [*DEMO],
        "position": ["+task=circle", "controller=position"],
        "snn": ["+task=circle", "+experiment=small_snn"],
        "ann": ["+task=circle", "controller=ann"],
        "crude_inverse_dynamics": ["+experiment=luque2011_eight", "~controller",
                                   "+controller={kind: crude_inverse_dynamics}"],
        "luque2011_cerebellum": ["+experiment=luque2011_eight"],
        "composite": [*DEMO, "controller=pd_planar2",
                      "~controller", "+controller={kind: composite, parts: [{kind: pd, kp: [60.0, 40.0], "
                      "kd: [4.0, 2.5], tau_max_Nm: [30.0, 20.0]}, {kind: pd, kp: [5.0, 5.0], kd: [0.0, 0.0], "
                      "tau_max_Nm: [1.0, 1.0]}]}"],
        # Capolei 2020 parts, each in the architecture preset that composes it
        "pid_velocity": ["+experiment=capolei2020_arch1", "trials=1"],
        "capolei_forward": ["+experiment=capolei2020_arch3", "trials=1"],
        "capolei_inverse": ["+experiment=capolei2020_arch2", "trials=1"],
        "muscle_rest": ["+experiment=fig4_6b", "trials=1"],
    },
    "stage": {
        "hold": [*DEMO, "robot=[{kind: hold}]"],
        "mean": [*DEMO, "robot=[{kind: mean, taps: 5}]"],
        "future_past": [*DEMO, "robot=[{kind: future_past}]"],
        "supervisor": [*DEMO, "robot=[{kind: hold}, {kind: supervisor, kp: [20.0, 20.0], kd: [5.0, 5.0], "
                       "bounds: plant}]"],
        "ekeberg": ["+task=eight", "+experiment=small_snn", "plant=baxter_muscles", "muscle=ekeberg",
                    "controller.output=agonist_antagonist", "controller.decoder.spikes_full_scale=10"],
        "spinal_cord": [*UPPER_LIMB, "spinal=cord"],
        "direct_muscles": [*UPPER_LIMB, "spinal=direct"],
        "split_pairs": [*UPPER_LIMB, "spinal=cord"],
    },
}


def test_every_registered_kind_has_a_contract_case():
    registry.load_plugins()
    for group in ("controller", "stage"):
        assert set(registry.GROUPS[group].kinds()) <= set(KINDS[group]), f"add the new {group} kinds to KINDS"


@pytest.mark.parametrize("group,kind", [(g, k) for g, ks in KINDS.items() for k in ks])
def test_stage_contract(load, group, kind):
    cfg = load(KINDS[group][kind])
    check_experiment(lambda: build_components(cfg))


# ---- a plugin: a plant commanded with muscle activations and a robot-side stage that makes them ----

class MuscleArmConfig(Planar2Config):
    """The planar arm driven through one agonist/antagonist muscle pair per joint (test plant)."""

    kind: Literal["muscle_arm_test"] = "muscle_arm_test"

    def command_signals(self) -> dict:
        return {"muscle.activation": Signal("muscle.activation", 4, "", 0.0, 1.0)}


class MuscleArm(Planar2Arm):
    """Joint torque = 20 N·m x (agonist - antagonist activation)."""

    def command_signals(self) -> dict:
        return {"muscle.activation": Signal("muscle.activation", 4, "", 0.0, 1.0)}

    def actuate(self, command: dict) -> np.ndarray:
        a = np.clip(command["muscle.activation"], 0.0, 1.0)
        self.apply(20.0 * (a[0::2] - a[1::2]))
        return a


class SplitConfig(StageConfig):
    """Splits a joint torque into agonist/antagonist activations (test stage)."""

    kind: Literal["split_test"] = "split_test"
    gain_per_Nm: float = 0.05

    def io(self, n_joints: int) -> StageIO:
        return StageIO(("joint.torque",), (Signal("muscle.activation", 2 * n_joints, "", 0.0, 1.0),))


class Split(Stage):
    def __init__(self, cfg: SplitConfig, ctx):
        self.gain = cfg.gain_per_Nm
        io = cfg.io(ctx.plant.n_joints)
        self.reads, self.writes = io.reads, io.writes

    def step(self, frame: Frame) -> None:
        tau = frame.signals["joint.torque"]
        act = np.empty(2 * len(tau))
        act[0::2], act[1::2] = np.clip(self.gain * tau, 0, 1), np.clip(-self.gain * tau, 0, 1)
        self.emit(frame, "muscle.activation", act)


class ReflexConfig(StageConfig):
    """Reads muscle lengths (test stage): only fits a plant that senses them."""

    kind: Literal["reflex_test"] = "reflex_test"

    def io(self, n_joints: int) -> StageIO:
        return StageIO(("muscle.length", "joint.torque"), (Signal("joint.torque", n_joints, "N·m"),))


@pytest.fixture
def muscle_plugin(monkeypatch):
    """Registers the plugin's kinds as an entry point would, and removes them afterwards."""
    registry.load_plugins()
    from cerebx.schema.experiment import experiment_model

    registry.plants.register(MuscleArmConfig, MuscleArm)
    registry.stages.register(SplitConfig, Split)
    registry.stages.register(ReflexConfig, Split)
    experiment_model.cache_clear()
    yield
    registry.plants._entries.pop("muscle_arm_test")
    registry.stages._entries.pop("split_test")
    registry.stages._entries.pop("reflex_test")
    experiment_model.cache_clear()


def test_plugin_plant_and_stage_run_in_the_loop(muscle_plugin, load, tmp_path):
    cfg = load([*DEMO, "trials=2", "plant.kind=muscle_arm_test", "robot=[{kind: hold}, {kind: split_test}]"])
    s = run_experiment(cfg, tmp_path)
    assert s["status"] == "completed", s
    assert s["mae_per_trial"][1] < 0.2  # the PD still tracks through the muscles
    acts = [m["tau_controller"] for topic, _, m in read_messages(tmp_path) if topic == "/control"]
    assert len(acts) == 2000 and len(acts[0]) == 2  # the brain sends a joint torque; the robot makes muscles


def test_mismatched_stages_refused_with_one_line(muscle_plugin, load, capsys, tmp_path):
    # the plant wants muscle activations but nothing makes them
    with pytest.raises(ConfigError) as err:
        load([*DEMO, "plant.kind=muscle_arm_test"])
    assert err.value.problems == [
        "controller (pd): the brain side writes joint.torque, but neither the robot stages nor plant muscle_arm_test "
        "(muscle.activation[4]) use it"]
    # a stage that reads what its neighbour does not give: one line, exit 2, nothing run
    code = main(["validate", *DEMO, "robot=[{kind: hold}, {kind: reflex_test}]"])
    lines = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and lines == [
        "robot stage 1 (reflex_test): reads muscle.length, but the link (hold: joint.torque[2]) and plant planar2 "
        "provides only joint.torque[2], joint.q[2], joint.qd[2]"]
    code = main(["run", *DEMO, "robot=[{kind: hold}, {kind: reflex_test}]", "hydra.run.dir=" + str(tmp_path / "r")])
    assert code == 2 and not (tmp_path / "r").exists()


def test_body_slots_run_after_the_receiver_before_the_robot_list(muscle_plugin, load, tmp_path):
    from cerebx.wiring import wire

    cfg = load([*DEMO, "trials=1", "plant.kind=muscle_arm_test", "+muscle={kind: split_test}",
                "robot=[{kind: mean}]"])
    wiring = wire(cfg)
    assert wiring.receiver.kind == "mean" and [s.kind for s in wiring.robot] == ["split_test"]
    s = run_experiment(cfg, tmp_path)
    assert s["status"] == "completed", s
    # a stage in the muscle slot reads what the link gives; the slot cannot hold a receiver
    with pytest.raises(ConfigError) as err:
        load([*DEMO, "+muscle={kind: hold}"])
    assert err.value.problems == ["muscle: stage 'hold' cannot stand between the receiver and the plant"]
