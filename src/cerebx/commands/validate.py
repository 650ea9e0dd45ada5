"""``cerebx validate``: compose and validate a config without running it; print it resolved. With ``-m``
every job of the sweep is validated (one line each); ``--config-dir`` adds a folder of presets as for
``cerebx run``."""

from __future__ import annotations

from typing import Any

import yaml

from cerebx.commands.common import Parser, fail
from cerebx.config import check, check_output_dir


def parser() -> Parser:
    """The command's arguments: the overrides of ``cerebx run``, ``-m`` and ``--config-dir``."""
    ap = Parser("cerebx validate", "check a config (or every job of a sweep with -m) without running it; "
                "print the composed config")
    ap.add_argument("-m", "--multirun", action="store_true", help="validate every job of a sweep (a=1,2 b=x,y)")
    ap.add_argument("-cd", "--config-dir", help="a folder of presets searched before cerebx's own (as in run)")
    ap.add_argument("overrides", nargs="*", help="+task=NAME [group=option ...] [key=value ...]")
    return ap


def main(args: list[str]) -> int:
    ns = parser().parse_intermixed_args(args)
    valid: list[tuple[list[str], Any, dict]] = []
    problems = check(ns.overrides, multirun=ns.multirun, config_dir=ns.config_dir, valid=valid)
    problems += check_output_dir(ns.overrides, ns.multirun, probe=False)
    if problems:
        return fail(problems)
    if ns.multirun:
        for job, exp, _ in valid:
            print(f"# [{' '.join(job)}] {_valid_line(exp)}")
        return 0
    _, exp, plain = valid[0]
    print(yaml.safe_dump(plain, sort_keys=False, default_flow_style=None, width=120), end="")
    print(f"# {_valid_line(exp)}")
    return 0


def _valid_line(exp: Any) -> str:
    net = getattr(exp.controller, "network", None)
    about = "" if net is None else (f" network={net.name} ({net.n_neurons:,} neurons, {net.n_synapses:,} synapses, "
                                    f"{net.n_plastic:,} plastic)")
    return (f"valid: task={exp.task.kind} controller={exp.controller.kind} plant={exp.plant.kind} "
            f"delay={exp.delay.kind}{about}")
