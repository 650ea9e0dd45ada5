"""Where a failing shape check is explained: each plugin's explanations file (registered with
``registry.explanations``) links a figure's check, named by the start of its claim, to the docs page and anchor
that shows its cause with the runs behind it. The report copies the link into the check's ``explained_at``
(``figures.json``, ``shapes.csv``, index.html) when the check fails; a passing check keeps none.

    explanations:
      - figure: fig3_4
        claim: "ANN mean MAE over 0–50 ms"     # the start of the check's claim
        at: reproductions/thesis-ch3.md#why-the-ann-holds-to-40-ms   # docs-relative page and anchor
        profiles: [full]                        # where it applies (default: every profile)
"""

from __future__ import annotations

import dataclasses
import functools
from pathlib import Path

from cerebx.report.registry import EXPLANATION_FILES, Check, Figure, load_reports
from cerebx.report.schema import Explanation, ExplanationsFile
from cerebx.report.studies import read_yaml_model


def load_explanations(*paths: Path) -> list[Explanation]:
    """The explanations of ``paths`` (default: every plugin's registered file)."""
    if not paths:
        load_reports()
        paths = tuple(EXPLANATION_FILES)
    out: list[Explanation] = []
    for path in paths:
        out += _read(Path(path))
    return out


@functools.lru_cache(maxsize=16)
def _read(path: Path) -> tuple[Explanation, ...]:
    return tuple(read_yaml_model(path, ExplanationsFile).explanations)


def explain(name: str, fig: Figure, profile: str | None, known: list[Explanation]) -> None:
    """Set ``explained_at`` on each failing check of figure ``name`` that an explanation for ``profile`` names
    (an unknown profile: explanations of any profile apply)."""
    mine = [e for e in known if e.figure == name and (profile is None or profile in e.profiles)]
    fig.checks = [_with_link(c, mine) for c in fig.checks]


def _with_link(check: Check, mine: list[Explanation]) -> Check:
    if check.holds is not False:
        return dataclasses.replace(check, explained_at=None)
    hit = next((e for e in mine if check.claim.startswith(e.claim)), None)
    return dataclasses.replace(check, explained_at=None if hit is None else f"docs/{hit.at}")
