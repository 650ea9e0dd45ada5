"""A cerebellar adaptive filter as a cerebx plugin: one function registers the model's kind and its presets."""

from cerebx.api.schema import add_config_source, controllers
from my_cerebellum.schema import AdaptiveFilterConfig


def register() -> None:
    # the builder is named as "module:attr" so its code is imported only when a run uses it
    controllers.register(AdaptiveFilterConfig, "my_cerebellum.controller:AdaptiveFilter")
    add_config_source("my_cerebellum.conf")  # conf/controller/*.yaml, conf/experiment/*.yaml
