"""Training curricula for ``modules.staged`` (Arena specs §2.8).

Arena's format (``arena_bringup/configs/training/training_curriculums/*.yaml``) loads unchanged:
a YAML list of stages (older files: a mapping ``{1: stage, 2: stage, ...}``)::

    - static: 0            # static obstacles in this stage
      interactive: 0
      dynamic: 12          # pedestrians
      goal_radius: 1.0     # m, optional: absent keeps the run's goal radius
      map_generator:       # optional: absent keeps the run's map
        algorithm: barn
        algorithm_config: {fill_pct: 0.075, smooth_iter: 3}

Our optional wrapper adds the promotion rule of Arena's training callback::

    stages: [...]
    upper_threshold: 0.9   # promote when the evaluation success rate is >= this
    lower_threshold: 0.65  # demote when it is <= this
    window: 20             # episodes the success rate is taken over (auto mode)

Arena's algorithm names map onto our generators: ``barn`` → ``barn``; ``rosnav`` with
``map_type`` ``indoor``/``outdoor`` → ``rosnav_indoor``/``rosnav_outdoor``; ``rosmap`` with
``map_type`` ``canteen|outdoor|warehouse|office`` → the generator of that name. Arena's
``algorithm_config`` holds the keys of every algorithm (its ``map_generator.yaml``); keys that
belong to another Arena algorithm are ignored as Arena ignores them, a per-type block
(``indoor: {corridor_radius: 5}``) is merged over the flat keys, and any other key must be a
parameter of the chosen generator. Our own generator names (``canteen``, ``rosnav_indoor`` ...)
are accepted too, with their parameters as ``algorithm_config``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

import arena.maps.generators  # noqa: F401  (registers the generators)
from arena.core.errors import ConfigError, from_validation_error
from arena.maps.generators import MAP_GENERATORS
from arena.maps.sources import MAP_SOURCES
from arena.tasks.datafiles import find_data_file, read_arena_yaml

ARENA_MAP_TYPES: dict[str, dict[str, str]] = {
    "rosnav": {"indoor": "rosnav_indoor", "outdoor": "rosnav_outdoor"},
    "rosmap": {
        "canteen": "canteen",
        "outdoor": "outdoor",
        "warehouse": "warehouse",
        "office": "office",
    },
}
"""Arena algorithm → ``map_type`` → our generator."""

ARENA_DEFAULT_MAP_TYPE = {"rosnav": "indoor", "rosmap": "canteen"}
"""``map_type`` when an Arena ``algorithm_config`` gives none (Arena 2024 / PR #118 defaults)."""

ARENA_CONFIG_KEYS = frozenset(
    {
        "fill_pct", "smooth_iter", "map_type", "seed", "obstacle_num", "obstacle_extra_radius",
        "corridor_radius", "iterations", "indoor", "outdoor", "canteen", "warehouse", "office",
        "chair_chance", "pallet_jacks", "row_chance",
        "hor_dist_shelfs_min", "hor_dist_shelfs_max", "vert_dist_shelfs_min",
        "vert_dist_shelfs_max", "hor_dist_table_min", "hor_dist_table_max",
        "vert_dist_table_min", "vert_dist_table_max",
    }
)
"""Keys of Arena's ``algorithm_config`` for all algorithms; ignored where they do not apply."""


class MapGeneratorSpec(BaseModel):
    """A stage's ``map_generator`` block (Arena's ``/map_generator`` parameters)."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    algorithm: str = Field(description="Arena algorithm (barn, rosnav, rosmap) or our generator")
    algorithm_config: dict[str, Any] = Field(
        default_factory=dict, description="the algorithm's parameters"
    )


class CurriculumStage(BaseModel):
    """One stage: obstacle counts, goal radius and map generator."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    static: int = Field(0, ge=0, description="static obstacles (RANDOM static min = max)")
    interactive: int = Field(0, ge=0, description="interactive obstacles")
    dynamic: int = Field(0, ge=0, description="pedestrians")
    goal_radius: float | None = Field(None, gt=0, description="m; None keeps the run's")
    map_generator: MapGeneratorSpec | None = Field(
        None, description="the stage's map generator; None keeps the run's map"
    )


class CurriculumFile(BaseModel):
    """Our wrapper around Arena's list of stages, with the promotion thresholds."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    stages: list[CurriculumStage] = Field(min_length=1, description="stages, easiest first")
    upper_threshold: float = Field(
        0.9, ge=0, le=1, description="success rate promoting to the next stage (Arena: 0.90)"
    )
    lower_threshold: float = Field(
        0.65, ge=0, le=1, description="success rate demoting to the previous stage (Arena: 0.65)"
    )
    window: int = Field(20, ge=1, description="episodes the auto mode's success rate spans")

    @model_validator(mode="after")
    def _order(self) -> CurriculumFile:
        if self.lower_threshold > self.upper_threshold:
            raise ValueError(
                f"lower_threshold ({self.lower_threshold}) must not exceed upper_threshold "
                f"({self.upper_threshold})"
            )
        return self


class Curriculum:
    """A loaded curriculum: stages, thresholds and each stage's map block.

    Attributes:
        stages: the stages, easiest first.
        upper_threshold, lower_threshold: success rates (0-1) of promotion and demotion.
        window: episodes the auto mode's success rate spans.
        map_specs: per stage, our ``map`` block (``{type: barn, fill_pct: ...}``) or ``None``.
        source: the file it came from.
    """

    def __init__(self, file: CurriculumFile, source: str) -> None:
        self.stages = list(file.stages)
        self.upper_threshold = file.upper_threshold
        self.lower_threshold = file.lower_threshold
        self.window = file.window
        self.source = source
        self.map_specs = [
            None if s.map_generator is None else map_spec(s.map_generator, source=source,
                                                          path=f"stages[{i}].map_generator")
            for i, s in enumerate(self.stages)
        ]

    def __len__(self) -> int:
        return len(self.stages)


def map_spec(gen: MapGeneratorSpec, *, source: str | None, path: str) -> dict[str, Any]:
    """Our ``map`` block for an Arena ``map_generator`` block (validated).

    Raises:
        ConfigError: an unknown algorithm or map type, or a parameter the generator does not
            have, naming ``source`` and ``<path>.algorithm`` / ``<path>.algorithm_config``.
    """
    algo = gen.algorithm
    cfg = dict(gen.algorithm_config)
    if algo == "barn":
        name = "barn"
    elif algo in ARENA_MAP_TYPES:
        map_type = cfg.get("map_type", ARENA_DEFAULT_MAP_TYPE[algo])
        if map_type not in ARENA_MAP_TYPES[algo]:
            raise ConfigError(
                f"unknown {algo} map_type {map_type!r}; known: "
                f"{', '.join(ARENA_MAP_TYPES[algo])}",
                source=source,
                path=f"{path}.algorithm_config.map_type",
            )
        name = ARENA_MAP_TYPES[algo][map_type]
        nested = cfg.get(map_type)
        if isinstance(nested, dict):
            cfg = {**cfg, **nested}
    elif algo in MAP_GENERATORS:
        return _validated({"type": algo, **cfg}, source=source, path=f"{path}.algorithm_config")
    else:
        known = ["barn", *ARENA_MAP_TYPES, *MAP_GENERATORS.names()]
        raise ConfigError(
            f"unknown map generator algorithm {algo!r}; known: {', '.join(dict.fromkeys(known))}",
            source=source,
            path=f"{path}.algorithm",
        )
    model = MAP_GENERATORS.entry(name).params_model
    fields = set(model.model_fields) if model is not None else set()
    params = {
        k: v for k, v in cfg.items() if k in fields or k not in ARENA_CONFIG_KEYS
    }
    return _validated({"type": name, **params}, source=source, path=f"{path}.algorithm_config")


def _validated(spec: dict[str, Any], *, source: str | None, path: str) -> dict[str, Any]:
    try:
        MAP_SOURCES.validate(spec, source=source, path=path)
    except ConfigError as e:
        # The registry names "<path>.type" for the type; ours is derived, so blame the params.
        raise ConfigError(e.message, source=source, path=e.path or path) from None
    return spec


def parse_curriculum(data: Any, *, source: str) -> Curriculum:
    """A curriculum from parsed YAML: Arena's list, Arena's old ``{1: ...}`` form or ours."""
    if isinstance(data, list):
        data = {"stages": data}
    elif isinstance(data, dict) and data and all(isinstance(k, int) for k in data):
        data = {"stages": [data[k] for k in sorted(data)]}
    elif not isinstance(data, dict):
        raise ConfigError(
            "expected a list of stages or a mapping {stages: [...], upper_threshold, "
            f"lower_threshold, window}}, got {type(data).__name__}",
            source=source,
        )
    try:
        file = CurriculumFile.model_validate(data)
    except ValidationError as e:
        raise from_validation_error(e, source=source) from None
    return Curriculum(file, source)


def load_curriculum(name_or_path: str | Path) -> Curriculum:
    """Load a packaged curriculum (``"default"``, ``"semantic"``) or a curriculum file."""
    path = find_data_file("curricula", name_or_path)
    return parse_curriculum(read_arena_yaml(path), source=str(path))
