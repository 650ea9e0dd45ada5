"""``cerebx validate``: compose and validate a config without running it; print it resolved."""

from __future__ import annotations

import yaml

from cerebx.commands.common import fail
from cerebx.config import load
from cerebx.errors import ConfigError


def main(args: list[str]) -> int:
    try:
        exp, plain = load(args)
    except ConfigError as err:
        return fail(err.problems)
    print(yaml.safe_dump(plain, sort_keys=False, default_flow_style=None, width=120), end="")
    net = getattr(exp.controller, "network", None)
    about = "" if net is None else (f" network={net.name} ({net.n_neurons:,} neurons, {net.n_synapses:,} synapses, "
                                    f"{net.n_plastic:,} plastic)")
    print(f"# valid: task={exp.task.kind} controller={exp.controller.kind} plant={exp.plant.kind} "
          f"delay={exp.delay.kind}{about}")
    return 0
