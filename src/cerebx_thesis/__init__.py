"""The thesis (Abadía 2022), chapters 2-4, as a cerebx plugin: the rate-based (ANN) cerebellum baseline, the
presets of every experiment, the studies behind the report and the figures and tables beside the thesis's.

Registered through the ``cerebx.plugins`` entry point ``thesis`` (see pyproject.toml), as a third party's
package would be.
"""

from cerebx import registry
from cerebx_thesis.ann.schema import ANNController


def register() -> None:
    registry.controllers.register(ANNController, "cerebx_thesis.ann.controller:ANN")
    registry.add_config_source("cerebx_thesis.conf")
    registry.add_report("cerebx_thesis.report")
    # learning runs as users make them, timed by `cerebx bench`: what `make run` runs, and chapter 3's
    registry.add_bench_run("make_run", ["+experiment=default"])
    registry.add_bench_run("learn_circle_ch3", ["+experiment=learn_circle_ch3"])
