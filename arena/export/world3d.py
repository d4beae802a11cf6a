"""``arena maps export``: a map (packaged world, map file, world folder or generator) as SDF/MJCF.

Needs no simulator: the SDF and MJCF text come from :mod:`.sdf` and :mod:`.mjcf`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import arena.plugins  # noqa: F401  (registers the map generators)
from arena.config.loader import parse_override
from arena.core.errors import ConfigError
from arena.core.files import make_dir, read_json
from arena.core.rng import derive_rng
from arena.maps.generators import MAP_GENERATORS
from arena.maps.io import load_map
from arena.maps.obstacles import make_obstacle
from arena.maps.sources import MapResult, packaged_worlds, resolve_scenario, world_folder
from arena.scene.episode import AgentSpawn
from arena.scene.state import Obstacle
from arena.sim.mujoco.mjcf import to_mjcf
from arena.sim.mujoco.scene import Scene3D, WorldParams
from arena.sim.mujoco.sdf import to_sdf
from arena.sim.mujoco.world import build_world
from arena.tasks.scenario import load_scenario
from arena.tasks.scenario_convert import scenario_agents, scenario_obstacles

Format = Literal["sdf", "mjcf"]
FILE_NAMES: dict[str, str] = {"sdf": "world.sdf", "mjcf": "world.xml"}
"""What each format writes into the output folder (fixed names: nothing user-given becomes a
path except the folder itself)."""


@dataclass(frozen=True)
class ExportSource:
    """What to export: the map with its obstacles, a scenario's people, and where it came from."""

    result: MapResult
    agents: AgentSpawn | None
    source: str


def _generated_obstacles(folder: Path) -> list[Obstacle]:
    """Obstacles of a world folder written by ``arena maps generate`` (``map/obstacles.json``)."""
    path = folder / "map" / "obstacles.json"
    if not path.is_file():
        return []
    data = read_json(path, what="obstacles file")
    try:
        entries = data["obstacles"]["static"]
        return [make_obstacle(e["name"], e["model"], e["pos"]) for e in entries]
    except (KeyError, TypeError) as e:
        raise ConfigError(
            f"obstacles.static: expected [{{name, model, pos: [x, y, yaw]}}, ...] ({e!r} missing "
            "or of the wrong type)", source=str(path)
        ) from None


def load_export_source(world: str, params: list[str], *, seed: int = 0,
                       scenario: str | None = None) -> ExportSource:
    """Resolve ``WORLD [key=value ...]`` as ``arena maps`` does.

    ``world`` is a packaged world name, a world folder, a ``map.yaml`` file, or a map generator
    type followed by its parameters (``canteen width=20``). ``scenario`` (a file or a name in the
    world) adds its obstacles and pedestrians (as walking people).

    Raises:
        ConfigError: an unknown world or generator, bad parameters, or a bad scenario.
    """
    path = Path(world).expanduser()
    is_world = world in packaged_worlds() or path.is_dir()
    if (is_world or path.suffix in (".yaml", ".yml")) and params:
        raise ConfigError(f"{world}: a map takes no parameters, got {' '.join(params)!r}",
                          source="command line")
    if is_world:
        folder = world_folder(world)
        result = MapResult(folder.name, load_map(folder / "map" / "map.yaml"
                                                 if (folder / "map").is_dir()
                                                 else folder / "map.yaml"),
                           tuple(_generated_obstacles(folder)))
    elif path.suffix in (".yaml", ".yml"):
        result = MapResult(path.parent.parent.name if path.parent.name == "map" else path.stem,
                           load_map(path))
    elif world not in MAP_GENERATORS.names() and not path.exists():
        raise ConfigError(
            f"WORLD {world!r}: not a packaged world, world folder, map.yaml or map generator; "
            f"packaged worlds: {', '.join(packaged_worlds())}; generators: "
            f"{', '.join(MAP_GENERATORS.names())}", source="command line"
        )
    else:
        spec: dict[str, object] = {"type": world}
        for text in params:
            key, value = parse_override(text)
            spec[key] = value
        result = MAP_GENERATORS.build(spec, source="command line").build(derive_rng(seed, "map"))
    agents = None
    if scenario is not None:
        scen_path = resolve_scenario(scenario, world if is_world else None)
        scen = load_scenario(scen_path)
        result = MapResult(result.name, result.grid,
                           (*result.obstacles, *scenario_obstacles(scen)))
        agents = scenario_agents(scen.obstacles.dynamic, derive_rng(seed, "agents"))
    return ExportSource(result, agents, world)


def export_scene(src: ExportSource, params: WorldParams | None = None) -> Scene3D:
    """The 3-D world of an export source."""
    r = src.result
    return build_world(r.grid, r.obstacles, agents=src.agents, params=params, name=r.name,
                       source=src.source)


def write_export(scene: Scene3D, fmt: Format, out: str | Path) -> Path:
    """Write ``scene`` as ``fmt`` into folder ``out``; returns the file written."""
    if fmt not in FILE_NAMES:
        raise ConfigError(f"format: expected sdf or mjcf, got {fmt!r}")
    folder = make_dir(out, what="export folder")
    path = folder / FILE_NAMES[fmt]
    path.write_text(to_sdf(scene) if fmt == "sdf" else to_mjcf(scene), encoding="utf-8")
    return path
