"""Holds the lab's plugin to cerebx's contracts: the pendulum to the plant contract, and the controller and every
stage of its demo experiment (the rate limiter among them) to the stage contract. Raises on the first breach."""

from cerebx import registry
from cerebx.build import build_components
from cerebx.config import load
from cerebx.plants.check import check_plant
from cerebx.stages.check import check_experiment

cfg, _ = load(["+experiment=pendulum_demo"])
check_plant(lambda: registry.plants.build(cfg.plant, None))
check_experiment(lambda: build_components(cfg))
print(f"{cfg.plant.kind}, {cfg.controller.kind} and {[s.kind for s in cfg.robot]} keep their contracts")
