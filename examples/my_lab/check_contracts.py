"""Holds the lab's plugin to cerebx's contracts: the pendulum to the plant contract, and the controller and every
stage of its demo experiment (the rate limiter among them) to the stage contract. Raises on the first breach."""

from cerebx.api import build_components, check_experiment, check_plant, load
from cerebx.api.schema import plants

cfg, _ = load(["+experiment=pendulum_demo"])
check_plant(lambda: plants.build(cfg.plant, None))
check_experiment(lambda: build_components(cfg))
print(f"{cfg.plant.kind}, {cfg.controller.kind} and {[s.kind for s in cfg.robot]} keep their contracts")
