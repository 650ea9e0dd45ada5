"""The supported names for a plugin's report module: registering figures and studies, reading runs, the
figure's parts (checks, intervals over seeds, convergence) and the plotting helpers. A plugin's report
imports only this module (and :mod:`cerebx.api`).

- :func:`figure` registers a figure function ``(runs: RunSet, stem: Path) -> Figure``; :func:`studies`
  registers the plugin's studies file; :func:`explanations` its explanations of failing checks.
- :class:`Figure` (images, caption, the paper-vs-cerebx table, notes, :class:`Check` s, convergence,
  :class:`Interval` s); :class:`MissingRuns` when a figure's runs are absent.
- :class:`Run` and :class:`RunSet`: run folders chosen by content (``RunSet.where``, ``best``, ``seeds``).
- :func:`interval`: a headline number's mean and 95 % interval over seeds; :func:`with_intervals` adds them
  to a figure's table.
- Convergence: :func:`learning_convergence`, :func:`plateau`, :func:`combined`, :func:`study_plateau`.
- Learning-curve metrics (Luque et al. 2011): :func:`accuracy_gain`, :func:`final_error`,
  :func:`final_error_stability`, :func:`convergence_speed`, :func:`improvement_pct`.
- Plotting: :func:`save` (PNG + SVG), :func:`panel_letter`, :func:`fmt`, :func:`mean_std`; delays:
  :func:`delays`, ``DELAY_TRIALS``.
"""

from cerebx.metrics import accuracy_gain, convergence_speed, final_error, final_error_stability, improvement_pct
from cerebx.report.convergence import Convergence, combined, learning_convergence, plateau
from cerebx.report.delays import DELAY_TRIALS, delays
from cerebx.report.plot import fmt, mean_std, panel_letter, save
from cerebx.report.registry import Check, Figure, MissingRuns, explanations, figure, studies
from cerebx.report.runs import Run, RunSet
from cerebx.report.stats import Interval, interval, with_intervals
from cerebx.report.studies import study_plateau

__all__ = [
    "DELAY_TRIALS",
    "Check",
    "Convergence",
    "Figure",
    "Interval",
    "MissingRuns",
    "Run",
    "RunSet",
    "accuracy_gain",
    "combined",
    "convergence_speed",
    "delays",
    "explanations",
    "figure",
    "final_error",
    "final_error_stability",
    "fmt",
    "improvement_pct",
    "interval",
    "learning_convergence",
    "mean_std",
    "panel_letter",
    "plateau",
    "save",
    "studies",
    "study_plateau",
    "with_intervals",
]
