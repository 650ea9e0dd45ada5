"""Error types that the command line turns into one readable line each and exit code 2."""

from __future__ import annotations

import traceback


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


class LinkLost(CerebxError):
    """Nothing came from the other side of a real link for too long: the run ends, status interrupted."""


class PeerEnded(CerebxError):
    """The other side of a real link said it stopped (its BYE): ``status`` is its status, the message its
    reason."""

    def __init__(self, status: str, reason: str):
        self.status = status
        super().__init__(reason)


def outcome(err: BaseException) -> dict[str, str]:
    """What a run's ``summary.json`` says of the exception that ended it: its ``status`` (interrupted,
    diverged or failed), its one-line ``error`` and, for a crash that is not a :class:`CerebxError`, the
    ``traceback``. One mapping for ``cerebx run`` and both sides of a real link."""
    if isinstance(err, KeyboardInterrupt):
        return {"status": "interrupted", "error": "interrupted by signal"}
    if isinstance(err, (LinkLost, PeerEnded)):
        return {"status": "interrupted", "error": str(err)}
    if isinstance(err, Diverged):
        return {"status": "diverged", "error": str(err)}
    if isinstance(err, CerebxError):
        return {"status": "failed", "error": str(err)}
    return {"status": "failed", "error": f"{type(err).__name__}: {err}",
            "traceback": "".join(traceback.format_exception(err))}
