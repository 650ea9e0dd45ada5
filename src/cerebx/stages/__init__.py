"""Stages: the parts of the closed loop between the task and the plant.

Brain side (before the link): the controller's parts, then any further brain stages. Robot side
(after the link): a receiver that turns the commands that arrived this tick into the command to
apply (hold, Eq. 2.18 mean, Eq. 3.6 future/past), then stages such as the safety supervisor,
muscles or a spinal cord. Each stage declares the signals it reads and writes; the chain is checked
when the run is built.
"""
