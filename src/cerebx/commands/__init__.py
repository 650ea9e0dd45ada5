"""The ``cerebx`` subcommands, one module each with a ``main(args) -> exit code``, loaded by name when chosen
(:func:`run_command`), so a command imports only what it needs (``cerebx inspect`` no Hydra, MuJoCo or numba).
``cerebx.cli`` is the entry point that picks one."""

from __future__ import annotations

import importlib

from cerebx.commands.common import fail
from cerebx.errors import CerebxError

COMMANDS = {**{name: f"cerebx.commands.{name}" for name in
               ("run", "validate", "inspect", "plot", "bench", "report", "tune", "summarize", "export",
                "crosscheck")},
            "robot": "cerebx.loop.robot_side", "relay": "cerebx.link.relay", "delays": "cerebx.link.trace"}
"""Command name -> the module whose ``main(args)`` runs it."""


def run_command(name: str, args: list[str]) -> int:
    """Run command ``name``; a CerebxError it raises is its one-line message and exit code 2."""
    try:
        return importlib.import_module(COMMANDS[name]).main(args)
    except CerebxError as err:
        return fail([str(err)])
