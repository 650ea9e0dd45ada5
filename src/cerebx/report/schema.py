"""The schemas of the report's own files: each plugin's studies file (``studies.yaml``: the experiment presets a
report runs, per profile) and explanations file (``explanations.yaml``: where a failing check is explained).
Their readers are :mod:`cerebx.report.studies` and :mod:`cerebx.report.explain`; like every schema module this
one imports no runtime module.
"""

from __future__ import annotations

from pydantic import Field

from cerebx.schema.base import Strict

PROFILES = ("quick", "full")
WINDOW_FRACTION = 0.1
"""The plateau test's window, a fraction of the full profile's trials (``report.convergence``)."""
MIN_WINDOW = 5
"""The plateau test's window is at least this many trials."""
TOLERANCE = 0.10
"""The largest relative fall from the window before to the last of a curve that has levelled off."""


class ProfileSpec(Strict):
    """How a study runs in one profile."""

    trials: int = Field(ge=1, description="trials of every job")
    args: list[str] = Field(default_factory=list, description="extra overrides in this profile")
    init_from: str | None = Field("inherit", description="start from this study's run instead (null: scratch)")
    seeds: int = Field(1, ge=1, le=20, description="independently learned seeds (seed 0 .. seeds-1; each more "
                       "seed k runs as the study <name>~seed<k>)")
    from_full: bool = Field(False, description="quick only: the learning behind this study cannot reach its plateau "
                            "in the quick profile's budget, so the quick profile does not run it (nor the studies "
                            "that start from it); their figures are drawn from the full profile's runs when they "
                            "exist (cerebx report --profile quick --dry-run lists them)")


class PlateauSpec(Strict):
    """The plateau test of a learning study's curves (``report.convergence``): the window is a fraction of the
    full profile's trials (where the paper's shape appears); the last window may fall this much below the one
    before."""

    window_fraction: float = Field(WINDOW_FRACTION, gt=0, le=0.5, description="window, a fraction of the full "
                                   "profile's trials")
    min_window: int = Field(MIN_WINDOW, ge=1, description="window at least this many trials")
    tolerance: float = Field(TOLERANCE, ge=0, description="largest relative fall from the window before to the last")


class StudySpec(Strict):
    """One experiment preset run once or as a sweep."""

    args: list[str] = Field(min_length=1, description="overrides of every job, the experiment preset first (its "
                            "hydra.sweeper.params make the study a sweep; an arg setting a swept key fixes it, "
                            "or with a sweep value (seed=0,1,2) sweeps those values instead)")
    init_from: str | None = Field(
        None, description="study whose learned state starts each job: a single-run study, or one with the same "
        "sweep (each job then starts from the job of the same sweep values)")
    quick: ProfileSpec = Field(description="the quick profile (< 30 min on 2 cores in all)")
    full: ProfileSpec = Field(description="the full profile (the paper's trial counts)")
    plateau: PlateauSpec = Field(default_factory=PlateauSpec, description="when a run of this study that learns "
                                 "has levelled off (the report's convergence badge)")


class StudiesFile(Strict):
    studies: dict[str, StudySpec] = Field(description="study name -> study")



class Explanation(Strict):
    """One check's explanation."""

    figure: str = Field(min_length=1, description="the figure's registered name")
    claim: str = Field(min_length=1, description="the start of the check's claim")
    at: str = Field(pattern=r"^[\w./-]+\.md#[\w-]+$", description="docs-relative page and anchor (page.md#anchor)")
    profiles: list[str] = Field(default_factory=lambda: list(PROFILES), description="the profiles it applies to")


class ExplanationsFile(Strict):
    explanations: list[Explanation] = Field(default_factory=list)
