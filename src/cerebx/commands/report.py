"""``cerebx report``: run the studies a report needs (``--profile``), then build ``reports/``."""

from cerebx.report.build import main  # noqa: F401 - the command's entry
