"""The thesis's figures and tables, each beside the thesis's numbers, drawn from the runs of its studies
(``studies.yaml``). One module per figure family; ``common`` and ``stages`` hold what they share.
Importing this package registers the figures with the report engine."""

from pathlib import Path

from cerebx.report.api import explanations, studies
from cerebx_thesis.report import (  # noqa: F401 - their import registers the figures
    adaptation,
    baxter_muscles,
    constant_delays,
    kernels,
    learning,
    plant_realism,
    random_delays,
    reaching,
    upper_limb,
)

studies(Path(__file__).with_name("studies.yaml"))
explanations(Path(__file__).with_name("explanations.yaml"))
