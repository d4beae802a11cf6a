"""Where an experiment's map comes from: the ``map:`` block of a config.

Every entry of :data:`MAP_SOURCES` turns its parameters (and a seeded generator, for procedural
maps) into a :class:`MapResult`. The worlds and generators issue registers the procedural map
generators here as well.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from arena.core.errors import ConfigError, MapError
from arena.core.files import make_dir
from arena.core.registry import Registry
from arena.maps.grid import OccupancyGrid, check_grid_size
from arena.maps.io import load_map, save_map
from arena.maps.raster import burn_obstacles as burn
from arena.scene.state import Obstacle

WORLDS_DIR = Path(__file__).resolve().parent.parent / "worlds"
"""Folder of the worlds shipped with Arena (``<name>/map/map.yaml``, ``<name>/scenarios/``)."""


@dataclass(frozen=True, eq=False)
class MapResult:
    """A map ready for an episode: its name, grid and any obstacles placed with it."""

    name: str
    grid: OccupancyGrid
    obstacles: tuple[Obstacle, ...] = ()


class MapSource(Protocol):
    """Builds the map for an episode."""

    def build(self, rng: np.random.Generator) -> MapResult:
        """Return the map; procedural sources draw only from ``rng``."""
        ...


MAP_SOURCES: Registry[MapSource] = Registry("map source", entry_points="arena.map_sources")


class GridSizeParams(BaseModel):
    """Base of the parameters of generated maps: ``width``, ``height``, ``resolution`` (m).

    The validator refuses sizes the grid cannot hold (infinite, under 3 cells a side, over
    :data:`~arena.maps.grid.MAX_CELLS` cells) when the config is loaded, so that the error names
    the key instead of failing while the map is built.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")
    width: float = Field(10.0, gt=0, description="m (the map: 3 to 50,000,000 cells)")
    height: float = Field(10.0, gt=0, description="m (the map: 3 to 50,000,000 cells)")
    resolution: float = Field(0.05, gt=0, description="m per cell")

    @model_validator(mode="after")
    def _grid_size(self) -> GridSizeParams:
        try:
            check_grid_size(self.width, self.height, self.resolution)
        except MapError as e:
            raise ValueError(str(e)) from None
        return self


def packaged_worlds() -> list[str]:
    """Names of the worlds shipped inside the package."""
    if not WORLDS_DIR.is_dir():
        return []
    return sorted(p.name for p in WORLDS_DIR.iterdir() if (p / "map" / "map.yaml").is_file())


def resolve_world(name_or_folder: str) -> Path:
    """The ``map.yaml`` of a packaged world name or of a world folder in Arena's layout.

    A folder may hold ``map/map.yaml`` (Arena-Rosnav's ``worlds/<name>/``) or ``map.yaml``.
    """
    folder = Path(name_or_folder).expanduser()
    for candidate in (folder / "map" / "map.yaml", folder / "map.yaml"):
        if candidate.is_file():
            return candidate
    packaged = WORLDS_DIR / name_or_folder / "map" / "map.yaml"
    if "/" not in name_or_folder and packaged.is_file():
        return packaged
    import difflib

    known = packaged_worlds()
    close = difflib.get_close_matches(name_or_folder, known, n=1, cutoff=0.5)
    hint = f"did you mean {close[0]!r}? " if close else ""
    raise ConfigError(
        f"no world {name_or_folder!r}: not a packaged world and not a folder with map/map.yaml; "
        f"{hint}packaged worlds: {', '.join(known) or '(none)'}"
    )


def check_worlds_folder(folder: str | Path, *, source: str | None = None,
                        path: str | None = None) -> Path:
    """A folder of worlds in Arena's layout (``<world>/map/map.yaml``), resolved.

    Raises:
        ConfigError: the folder does not exist or is a file (one line naming ``source``).
    """
    p = Path(folder).expanduser()
    what = ("expected a folder of worlds in Arena's layout, <world>/map/map.yaml "
            "(e.g. arena-simulation-setup/worlds)")
    if not p.exists():
        raise ConfigError(f"no folder {str(p)!r}; {what}", source=source, path=path)
    if not p.is_dir():
        raise ConfigError(f"{str(p)!r} is a file; {what}", source=source, path=path)
    return p.resolve()


def worlds_in(folder: Path) -> list[str]:
    """Names of the worlds in a folder: its sub-folders holding ``map/map.yaml`` or ``map.yaml``."""
    try:
        subs = sorted(folder.iterdir())
    except OSError:
        return []
    return [c.name for c in subs
            if (c / "map" / "map.yaml").is_file() or (c / "map.yaml").is_file()]


def world_folder(name_or_folder: str) -> Path:
    """The folder of a packaged world name or world folder (holding ``map/``, ``scenarios/``)."""
    map_yaml = resolve_world(name_or_folder)
    return map_yaml.parent.parent if map_yaml.parent.name == "map" else map_yaml.parent


def resolve_scenario(name_or_file: str, world: str | None = None) -> Path:
    """An Arena scenario file: a path, ``WORLD/NAME`` or a ``NAME`` in ``world``.

    ``corridor/default`` is the packaged world ``corridor``'s ``scenarios/default.json``;
    ``default`` with ``world="corridor"`` (a packaged world name or a world folder) the same.
    Names let commands work from any folder; an existing file always wins.

    Raises:
        ConfigError: a missing file, an unknown world or scenario (with the world's scenarios).
    """
    path = Path(name_or_file).expanduser()
    if path.is_file():
        return path.resolve()
    text = str(name_or_file).removesuffix(".json")
    parts = text.split("/")
    if len(parts) == 2 and all(parts) and (WORLDS_DIR / parts[0]).is_dir():
        world, name = parts
    elif len(parts) == 1 and text and world is not None:
        name = text
    elif len(parts) == 1 and text:
        raise ConfigError(
            f"no scenario file {name_or_file!r}; a scenario name needs a world: WORLD/{text} or "
            "--map WORLD"
        )
    else:
        raise ConfigError(f"no such scenario file {name_or_file!r}")
    folder = world_folder(world) / "scenarios"
    candidate = folder / f"{name}.json"
    if candidate.is_file():
        return candidate
    import difflib

    known = sorted(p.stem for p in folder.glob("*.json")) if folder.is_dir() else []
    close = difflib.get_close_matches(name, known, n=1, cutoff=0.5)
    hint = f"did you mean {close[0]!r}? " if close else ""
    raise ConfigError(
        f"no scenario {name!r} in world {world!r} ({folder}); {hint}"
        f"scenarios: {', '.join(known) or '(none)'}"
    )


@MAP_SOURCES.register("world", tags=("file",))
class WorldMap:
    """A packaged world by name, or any folder in Arena's layout (``<folder>/map/map.yaml``)."""

    class Params(BaseModel):
        """Parameters of :class:`WorldMap`."""

        model_config = ConfigDict(frozen=True, extra="forbid")
        name: str = Field(description="packaged world name or path to a world folder")

        @field_validator("name")
        @classmethod
        def _exists(cls, v: str) -> str:
            try:  # when the config is loaded, so that the error names map.name
                resolve_world(v)
            except ConfigError as e:
                raise ValueError(e.message) from None
            return v

    def __init__(self, params: Params) -> None:
        self.params = params
        self._result: MapResult | None = None

    def build(self, rng: np.random.Generator) -> MapResult:
        """Load the world's map (read once per instance)."""
        if self._result is None:
            path = resolve_world(self.params.name)
            self._result = MapResult(name=Path(self.params.name).name, grid=load_map(path))
        return self._result


@MAP_SOURCES.register("file", tags=("file",))
class FileMap:
    """A ROS map_server ``map.yaml`` file (with its PGM/PNG image)."""

    class Params(BaseModel):
        """Parameters of :class:`FileMap`."""

        model_config = ConfigDict(frozen=True, extra="forbid")
        path: str = Field(description="path to a map_server map.yaml")

    def __init__(self, params: Params) -> None:
        self.params = params
        self._result: MapResult | None = None

    def build(self, rng: np.random.Generator) -> MapResult:
        """Load the map file (read once per instance)."""
        if self._result is None:
            path = Path(self.params.path).expanduser()
            name = path.parent.parent.name if path.parent.name == "map" else path.stem
            self._result = MapResult(name=name, grid=load_map(path))
        return self._result


@MAP_SOURCES.register("empty", tags=("generator",))
class EmptyMap:
    """An empty rectangular room with walls around it."""

    class Params(GridSizeParams):
        """Parameters of :class:`EmptyMap` (sizes checked by :class:`GridSizeParams`)."""

    def __init__(self, params: Params) -> None:
        self.params = params

    def build(self, rng: np.random.Generator) -> MapResult:
        """Build the room."""
        p = self.params
        return MapResult("empty", OccupancyGrid.empty(p.width, p.height, p.resolution))


def write_world(
    result: MapResult, folder: str | Path, *, burn_obstacles: bool = False
) -> dict[str, Path]:
    """Save a map as an Arena-style world folder.

    Writes ``<folder>/map/map.yaml`` + ``map.png`` (ROS map_server) and
    ``<folder>/map/obstacles.json``: the placed obstacles in Arena's scenario format
    (``{"obstacles": {"static": [{"name", "model", "pos": [x, y, yaw]}]}}``). With
    ``burn_obstacles`` the cells the obstacles overlap are occupied in ``map.png`` too, so that
    tools that read only the map (ROS ``map_server``, RViz, ``arena run --map FOLDER``) see them.
    """
    folder = make_dir(folder, what="world folder")
    grid = burn(result.grid, result.obstacles) if burn_obstacles else result.grid
    yaml_path = save_map(grid, folder / "map" / "map.yaml", image_format="png")
    static = [
        {"name": o.name, "model": o.model, "pos": [round(float(v), 6) for v in o.pose]}
        for o in result.obstacles
    ]
    obstacles = folder / "map" / "obstacles.json"
    obstacles.write_text(json.dumps({"obstacles": {"static": static}}, indent=2))
    return {"map": yaml_path, "obstacles": obstacles}
