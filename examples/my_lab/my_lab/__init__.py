"""A lab's additions to cerebx as one plugin: a pendulum plant, a robot-side torque rate limiter, a swing task,
their presets, a report module with one figure and the study it needs, and a connector and a learning rule for
spiking networks."""

from cerebx.api.schema import add_config_source, add_report, connectors, plants, plasticity_rules, stages, tasks
from my_lab.network import ExpTeacher, RingConnector
from my_lab.schema import PendulumConfig, RateLimitConfig, SwingTask


def register() -> None:
    # builders are named as "module:attr": their code (MuJoCo, numpy) is imported only when a run uses them
    plants.register(PendulumConfig, "my_lab.pendulum:Pendulum")
    stages.register(RateLimitConfig, "my_lab.rate_limit:RateLimiter")
    tasks.register(SwingTask, "my_lab.swing:Swing")
    connectors.register(RingConnector, "my_lab.network:ring")
    plasticity_rules.register(ExpTeacher, "my_lab.network:exp_teacher")
    add_config_source("my_lab.conf")  # conf/plant, conf/task, conf/controller, conf/experiment
    add_report("my_lab.report")  # its figure and the study the figure needs
