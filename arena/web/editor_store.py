"""The scenario editor's workspace inside a run store: saved scenarios and maps.

Two folders under the store's root, whose names start with ``_`` so that
:class:`~arena.web.store.RunStore` (which lists only names matching
:data:`~arena.web.store.RUN_NAME`) never shows them as runs:

* ``_scenarios/<name>.json``: Arena scenario JSON, the file ``arena run --scenario`` reads;
  ``_scenarios/<name>.zones.yaml`` beside it when the scenario was drawn with zones (a
  ``zones.yaml`` in Arena's format, for the ``zones`` task modes' ``zones`` parameter);
* ``_maps/<name>/map.yaml`` + ``map.png``: a generated or uploaded map, a world folder that
  ``arena run --map <root>/_maps/<name>`` reads.

A scenario names the map it was drawn on in its ``map`` key (informational for Arena): a
packaged world's name (``small_office``) or ``_maps/<name>`` for a map of the workspace.
Every name a request gives is checked to be one plain file name (no ``/``, no ``..``, no
absolute path), so nothing is read or written outside these two folders.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import yaml

from arena.core.errors import ConfigError
from arena.maps.grid import OccupancyGrid
from arena.maps.io import load_map, save_map
from arena.maps.sources import WORLDS_DIR, packaged_worlds
from arena.tasks.scenario import Scenario, parse_scenario
from arena.web.store import RUN_NAME, NotFound

SCENARIOS = "_scenarios"
"""Folder of saved scenarios under the store root."""
MAPS = "_maps"
"""Folder of saved maps under the store root."""
MAP_PREFIX = MAPS + "/"
"""How a scenario's ``map`` key names a workspace map (``_maps/<name>``)."""
ZONES_SUFFIX = ".zones.yaml"
"""Suffix of the zones file saved beside a scenario."""


def check_name(name: str, what: str) -> str:
    """``name`` if it is one plain file name (letters, digits, ``._-``; leading alphanumeric).

    Raises:
        ConfigError: a path (``../x``, ``/etc/x``, ``a/b``), an empty or over-long name.
    """
    if not isinstance(name, str) or not RUN_NAME.match(name) or name.endswith(".json"):
        raise ConfigError(
            f"{name!r} is not a plain {what} name: expected 1 to 128 letters, digits, '.', "
            "'_' or '-', starting with a letter or digit (no path, no '..', no .json suffix)",
            path="name")
    return name


@dataclass(frozen=True)
class MapRef:
    """The map a scenario is drawn on.

    Attributes:
        kind: ``"world"`` (a packaged world) or ``"saved"`` (a map of the workspace).
        name: the world's or the saved map's name.
    """

    kind: str
    name: str

    @property
    def label(self) -> str:
        """What the scenario's ``map`` key says: the world name or ``_maps/<name>``."""
        return self.name if self.kind == "world" else MAP_PREFIX + self.name

    @classmethod
    def from_label(cls, label: str) -> MapRef:
        """The reference a ``map`` key names (see :attr:`label`)."""
        if label.startswith(MAP_PREFIX):
            return cls("saved", label.removeprefix(MAP_PREFIX))
        return cls("world", label)


class EditorWorkspace:
    """Saved scenarios and maps under a store root (see the module doc)."""

    def __init__(self, root: str | Path) -> None:
        self.root = Path(root).resolve()

    @property
    def scenarios_dir(self) -> Path:
        """``<root>/_scenarios``."""
        return self.root / SCENARIOS

    @property
    def maps_dir(self) -> Path:
        """``<root>/_maps``."""
        return self.root / MAPS

    # -- maps -------------------------------------------------------------------------------------
    def map_yaml(self, ref: MapRef) -> Path:
        """The ``map.yaml`` of a packaged world or a saved map.

        Raises:
            NotFound: no such world or saved map.
        """
        if ref.kind == "world":
            if ref.name not in packaged_worlds():
                raise NotFound(f"no packaged world {ref.name!r}; worlds: "
                               f"{', '.join(packaged_worlds())}")
            return WORLDS_DIR / ref.name / "map" / "map.yaml"
        if ref.kind == "saved":
            if not RUN_NAME.match(ref.name):
                raise NotFound(f"no saved map {ref.name!r}")
            path = self.maps_dir / ref.name / "map.yaml"
            if not path.is_file():
                raise NotFound(f"no saved map {ref.name!r} in {self.maps_dir}")
            return path
        raise NotFound(f"no map of kind {ref.kind!r} (expected 'world' or 'saved')")

    def grid(self, ref: MapRef) -> OccupancyGrid:
        """The occupancy grid of ``ref`` (see :meth:`map_yaml` for the errors)."""
        return load_map(self.map_yaml(ref))

    def save_map(self, name: str, grid: OccupancyGrid) -> Path:
        """Write ``grid`` as ``_maps/<name>/map.yaml`` + ``map.png`` (overwriting); the folder."""
        folder = self.maps_dir / check_name(name, "map")
        save_map(grid, folder / "map.yaml", image_format="png")
        return folder

    def maps(self) -> list[str]:
        """Names of the saved maps, sorted."""
        if not self.maps_dir.is_dir():
            return []
        return sorted(p.name for p in self.maps_dir.iterdir()
                      if RUN_NAME.match(p.name) and (p / "map.yaml").is_file())

    # -- scenarios --------------------------------------------------------------------------------
    def scenario_path(self, name: str) -> Path:
        """``_scenarios/<name>.json`` (the name checked, the file need not exist)."""
        return self.scenarios_dir / f"{check_name(name, 'scenario')}.json"

    def scenarios(self) -> list[str]:
        """Names of the saved scenarios, sorted."""
        if not self.scenarios_dir.is_dir():
            return []
        return sorted(p.stem for p in self.scenarios_dir.glob("*.json")
                      if RUN_NAME.match(p.stem))

    def load(self, name: str) -> tuple[Scenario, list[dict[str, object]]]:
        """The saved scenario ``name`` and its zones (empty without a zones file).

        Raises:
            NotFound: a bad name or no such scenario.
            ConfigError: the file does not read as a scenario (naming the file).
        """
        try:
            path = self.scenario_path(name)
        except ConfigError:
            raise NotFound(f"no saved scenario {name!r}") from None
        if not path.is_file():
            raise NotFound(f"no saved scenario {name!r}")
        scenario = parse_scenario(path.read_text(encoding="utf-8"), source=path.name)
        zones_file = path.with_name(path.stem + ZONES_SUFFIX)
        zones: object = []
        if zones_file.is_file():
            try:
                zones = yaml.safe_load(zones_file.read_text(encoding="utf-8")) or []
            except yaml.YAMLError as e:
                raise ConfigError(f"not a YAML file ({str(e).splitlines()[0]})",
                                  source=zones_file.name) from None
        if not isinstance(zones, list):
            raise ConfigError("expected a list of zones", source=zones_file.name)
        return scenario, zones

    def save(self, name: str, scenario: Scenario, zones: list[dict[str, object]]) -> Path:
        """Write the scenario (and its zones, or remove a stale zones file); its path."""
        path = self.scenario_path(name)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(scenario.to_json_dict(), indent=2) + "\n", encoding="utf-8")
        zones_file = path.with_name(path.stem + ZONES_SUFFIX)
        if zones:
            zones_file.write_text(yaml.safe_dump(zones, sort_keys=False), encoding="utf-8")
        elif zones_file.is_file():
            zones_file.unlink()
        return path
