"""The error of an invalid build configuration, apart so that :mod:`tablegen.tabulation.config` and the module it
calls for the ``[shapes.NAME]`` sections (:mod:`tablegen.tabulation.shape_config`) both raise it while the import
between them goes one way (config imports shape_config). :mod:`tablegen.tabulation.config` re-exports it."""


class ConfigError(ValueError):
    """An invalid build configuration; the message names the offending key."""
