"""Hydra search-path plugin: adds the presets of every loaded cerebx plugin (``registry.add_config_source``)
after cerebx's own ``conf/``, so ``+experiment=NAME`` finds a plugin's experiments like the platform's."""

from hydra.core.config_search_path import ConfigSearchPath
from hydra.plugins.search_path_plugin import SearchPathPlugin

from cerebx import registry


class CerebxPluginConfigs(SearchPathPlugin):
    def manipulate_search_path(self, search_path: ConfigSearchPath) -> None:
        registry.load_plugins()
        for source in registry.config_sources:
            search_path.append(provider=f"cerebx-{source.plugin}", path=f"pkg://{source.target}")
