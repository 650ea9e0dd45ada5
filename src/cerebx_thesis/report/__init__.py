"""The thesis's figures and tables, each beside the thesis's numbers, drawn from the runs of its studies
(``studies.yaml``). Importing this package registers them with the report engine."""

from pathlib import Path

from cerebx.report.registry import studies
from cerebx_thesis.report import ch2, ch3, ch4, ch4_muscles  # noqa: F401 - their import registers the figures

studies(Path(__file__).with_name("studies.yaml"))
