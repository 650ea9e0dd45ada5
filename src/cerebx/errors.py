"""Error types that the command line turns into one readable line each and exit code 2."""

from __future__ import annotations


class CerebxError(Exception):
    """A problem the user can fix (bad input, missing file); reported without a traceback."""


class ConfigError(CerebxError):
    """One or more configuration problems, each already formatted as ``path: message``."""

    def __init__(self, problems: list[str] | str):
        self.problems = [problems] if isinstance(problems, str) else list(problems)
        super().__init__("\n".join(self.problems))


class StateMismatchError(CerebxError):
    """A saved controller state does not fit the network or controller it is loaded into."""


class Diverged(CerebxError):
    """The simulation left its physical envelope (NaN, joints far outside limits)."""
