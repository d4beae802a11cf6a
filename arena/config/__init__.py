"""Experiment configuration: the pydantic schema, YAML loading and dotted overrides."""

from arena.config.loader import DEFAULT_CONFIG, load_config, parse_override, read_yaml
from arena.config.schema import ExperimentConfig, OutputConfig, SimConfig

__all__ = [
    "DEFAULT_CONFIG",
    "ExperimentConfig",
    "OutputConfig",
    "SimConfig",
    "load_config",
    "parse_override",
    "read_yaml",
]
