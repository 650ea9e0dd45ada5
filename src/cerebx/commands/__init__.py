"""The ``cerebx`` subcommands, one module each with a ``main(args) -> exit code``; ``cerebx.cli`` loads
the chosen one by name, so a command imports only what it needs (``cerebx inspect`` no Hydra, MuJoCo or
numba)."""
