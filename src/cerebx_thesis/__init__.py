"""The thesis (Abadía 2022), chapters 2-4, as a cerebx plugin: the rate-based (ANN) cerebellum baseline, the
presets of every experiment, the studies behind the report and the figures and tables beside the thesis's.

Registered through the ``cerebx.plugins`` entry point ``thesis`` (see pyproject.toml), as a third party's
package would be.
"""

from cerebx.api.schema import add_bench_run, add_config_source, add_report, controllers
from cerebx_thesis.ann.schema import ANNController


def register() -> None:
    controllers.register(ANNController, "cerebx_thesis.ann.controller:ANN")
    add_config_source("cerebx_thesis.conf")
    add_report("cerebx_thesis.report")
    # learning runs as users make them, timed by `cerebx bench`: what `make run` runs, and chapter 3's
    add_bench_run("make_run", ["+experiment=default"])
    add_bench_run("learn_circle_ch3", ["+experiment=learn_circle_ch3"])
    add_bench_run("learn_circle_golgi", ["+experiment=learn_circle_golgi"])
