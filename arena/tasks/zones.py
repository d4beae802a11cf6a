"""Zones: labelled polygons of a world and the scenario that uses them (Arena specs §2.7).

Two files, both in Arena-Rosnav's layout of a world folder:

``map/zones.yaml``, a list of zones::

    - label: Lobby
      category: public                    # or a list: [public, staff]
      polygon: [[10.4, -2.2], [17.5, -2.2], [17.5, 5.8], [10.4, 5.8]]   # or a list of polygons

``zones/<name>.yaml``, the zone scenario::

    pedestrians:
      - name: visitor
        type: human/adult                 # adult, elder or child (``human/`` prefix optional)
        model: actor1                     # or a list; a label only
        waypoints in: [public]            # or "*": every category
        number of waypoints: [2, 3]       # n or [min, max]
        amount: 5                         # n or [min, max]
    robots:
      - name: cleaning robot
        waypoints in: [public, staff]

Keys with spaces (or dashes) are normalised to identifiers (``waypoints_in``); both files are
closed (an unknown key is an error), and errors name the file and the entry
(``pedestrians[2].amount``). Coordinates are metres in the map frame. Categories a scenario
names must exist in the zones file it is used with.

Used by ``obstacles.zones`` (pedestrians walking between zones) and ``robots.zones`` (robot
roles with start and goals in their zones).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    Strict,
    StrictStr,
    TypeAdapter,
    ValidationError,
    field_validator,
    model_validator,
)

from arena.core.errors import ConfigError, SamplingError, from_validation_error
from arena.core.geometry import points_in_polygon
from arena.maps.sources import resolve_world
from arena.tasks.datafiles import read_yaml_any
from arena.tasks.scenario import KIND_CODES
from arena.tasks.world import WorldSampler

FloatArray = NDArray[np.float64]

ALL = "*"
"""``waypoints in: "*"``: every category of the zones file."""

_CONFIG = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False)

Coord = Annotated[float, Strict()]
Point = tuple[Coord, Coord]
"""``[x, y]`` in metres."""
Polygon = Annotated[list[Point], Field(min_length=3)]
"""At least three ``[x, y]`` vertices (m), in order; the polygon closes itself."""


def _normalise_keys(data: Any) -> Any:
    """``{"waypoints in": ...}`` → ``{"waypoints_in": ...}`` (spaces and dashes → ``_``)."""
    if not isinstance(data, Mapping):
        return data
    out: dict[Any, Any] = {}
    for key, value in data.items():
        k = "_".join(key.strip().replace("-", " ").split()) if isinstance(key, str) else key
        if k in out:
            raise ValueError(f"key {key!r} given twice (as {k!r})")
        out[k] = value
    return out


def polygon_area(polygon: FloatArray) -> float:
    """Unsigned area (m²) of a simple polygon ``(k, 2)`` (shoelace formula)."""
    x, y = polygon[:, 0], polygon[:, 1]
    return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


class Zone(BaseModel):
    """One labelled zone: one or more polygons with one or more categories."""

    model_config = _CONFIG
    label: StrictStr
    category: list[StrictStr] = Field(min_length=1, description="categories (str or list)")
    polygon: list[Polygon] = Field(min_length=1, description="polygon(s) of [x, y] points (m)")

    @field_validator("category", mode="before")
    @classmethod
    def _one_category(cls, v: Any) -> Any:
        return [v] if isinstance(v, str) else v

    @field_validator("polygon", mode="before")
    @classmethod
    def _one_polygon(cls, v: Any) -> Any:
        # A single polygon is a list of points, i.e. its first item is a list of numbers.
        first = v[0] if isinstance(v, list) and v else None
        if isinstance(first, list | tuple) and first and isinstance(first[0], int | float):
            return [v]
        return v

    @field_validator("polygon")
    @classmethod
    def _has_area(cls, v: list[list[Point]]) -> list[list[Point]]:
        for k, poly in enumerate(v):
            if polygon_area(np.array(poly, dtype=np.float64)) <= 1e-9:
                raise ValueError(f"polygon {k} has no area (collinear or repeated points)")
        return v

    def polygons(self) -> list[FloatArray]:
        """The zone's polygons as ``(k, 2)`` arrays (m)."""
        return [np.array(p, dtype=np.float64) for p in self.polygon]


class Range(BaseModel):
    """A count drawn uniformly from ``{min..max}``: written ``n`` or ``[min, max]``."""

    model_config = _CONFIG
    min: int = Field(ge=0)
    max: int = Field(ge=0)

    @model_validator(mode="before")
    @classmethod
    def _shorthand(cls, v: Any) -> Any:
        if isinstance(v, int) and not isinstance(v, bool):
            return {"min": v, "max": v}
        if isinstance(v, list | tuple):
            if len(v) != 2:
                raise ValueError(f"expected n or [min, max], got {list(v)!r}")
            return {"min": v[0], "max": v[1]}
        return v

    @model_validator(mode="after")
    def _order(self) -> Range:
        if self.min > self.max:
            raise ValueError(f"min ({self.min}) must not exceed max ({self.max})")
        return self

    def draw(self, rng: np.random.Generator) -> int:
        """One value, uniform over ``{min..max}``."""
        return int(rng.integers(self.min, self.max + 1))


Categories = list[StrictStr] | Literal["*"]
"""``[category, ...]`` or ``"*"`` for every category."""


class PedestrianGroup(BaseModel):
    """One ``pedestrians`` entry: ``amount`` pedestrians of one type walking between zones."""

    model_config = _CONFIG
    name: StrictStr
    type: StrictStr = Field("human/adult", description="adult, elder or child (human/ optional)")
    model: list[StrictStr] = Field(
        default_factory=lambda: ["actor1"], description="Arena model name(s), labels only"
    )
    waypoints_in: Categories = Field(description="categories of the zones visited, or '*'")
    number_of_waypoints: Range = Field(description="waypoints per pedestrian beside its start")
    amount: Range = Field(description="pedestrians of this entry")

    @model_validator(mode="before")
    @classmethod
    def _keys(cls, v: Any) -> Any:
        return _normalise_keys(v)

    @field_validator("model", mode="before")
    @classmethod
    def _one_model(cls, v: Any) -> Any:
        return [v] if isinstance(v, str) else v

    @field_validator("type")
    @classmethod
    def _known_type(cls, v: str) -> str:
        if v.removeprefix("human/") not in KIND_CODES:
            raise ValueError(
                f"unknown pedestrian type {v!r}; known: {', '.join(KIND_CODES)} "
                "(optionally prefixed human/)"
            )
        return v

    @property
    def kind(self) -> int:
        """Type code of :attr:`~arena.scene.episode.AgentSpawn.kinds` (0 adult, 1 elder ...)."""
        return KIND_CODES[self.type.removeprefix("human/")]


class RobotRole(BaseModel):
    """One ``robots`` entry: a role and the zone categories its goals lie in."""

    model_config = _CONFIG
    name: StrictStr
    waypoints_in: Categories = Field(description="categories of the robot's zones, or '*'")

    @model_validator(mode="before")
    @classmethod
    def _keys(cls, v: Any) -> Any:
        return _normalise_keys(v)


class ZoneScenario(BaseModel):
    """A zone scenario file: pedestrian groups and robot roles."""

    model_config = _CONFIG
    pedestrians: list[PedestrianGroup] = Field(default_factory=list)
    robots: list[RobotRole] = Field(default_factory=list)

    @model_validator(mode="before")
    @classmethod
    def _keys(cls, v: Any) -> Any:
        return _normalise_keys(v)


_ZONES = TypeAdapter(list[Zone])


@dataclass(frozen=True, eq=False)
class ZoneMap:
    """The zones of a world, looked up by category.

    Attributes:
        zones: the zones in file order.
        source: the file they come from (for messages).
    """

    zones: tuple[Zone, ...]
    source: str = ""

    @property
    def categories(self) -> list[str]:
        """Every category, in order of first appearance."""
        return list(dict.fromkeys(c for z in self.zones for c in z.category))

    def expand(self, categories: Categories) -> list[str]:
        """The categories a ``waypoints in`` value names (``"*"`` → all)."""
        return self.categories if categories == ALL else list(categories)

    def of(self, category: str) -> list[Zone]:
        """Zones of one category (empty if none)."""
        return [z for z in self.zones if category in z.category]

    def contains(self, points: FloatArray, categories: Categories) -> NDArray[np.bool_]:
        """Which of the ``(n, 2)`` points (m) lie inside a zone of one of ``categories``."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        inside = np.zeros(len(p), dtype=bool)
        for cat in self.expand(categories):
            for zone in self.of(cat):
                for poly in zone.polygons():
                    inside |= points_in_polygon(p, poly)
        return inside


@dataclass(frozen=True, eq=False)
class ZoneSetup:
    """A zones file with a scenario whose categories it defines."""

    zones: ZoneMap
    scenario: ZoneScenario
    zones_file: Path
    scenario_file: Path


def load_zones(path: str | Path) -> ZoneMap:
    """Read and validate a ``zones.yaml`` (errors name the file and ``[2].polygon``)."""
    p = Path(path).expanduser()
    if not p.is_file():
        raise ConfigError(f"zones file not found (looked for {p})", source=str(p))
    data = read_yaml_any(p)
    try:
        zones = _ZONES.validate_python(data if data is not None else [])
    except ValidationError as e:
        raise from_validation_error(e, source=str(p)) from None
    if not zones:
        raise ConfigError("the zones file defines no zones", source=str(p))
    return ZoneMap(tuple(zones), str(p))


def load_zone_scenario(path: str | Path) -> ZoneScenario:
    """Read and validate a zone scenario (errors name the file and ``pedestrians[2].amount``)."""
    p = Path(path).expanduser()
    if not p.is_file():
        raise ConfigError(f"zone scenario file not found (looked for {p})", source=str(p))
    data = read_yaml_any(p)
    try:
        return ZoneScenario.model_validate(data if data is not None else {})
    except ValidationError as e:
        raise from_validation_error(e, source=str(p)) from None


def load_zone_setup(zones_file: str | Path, scenario_file: str | Path) -> ZoneSetup:
    """Both files, with every category the scenario names checked against the zones."""
    zones = load_zones(zones_file)
    scenario = load_zone_scenario(scenario_file)
    known = set(zones.categories)
    entries: list[tuple[str, Categories]] = [
        (f"pedestrians[{i}].waypoints_in", g.waypoints_in)
        for i, g in enumerate(scenario.pedestrians)
    ] + [(f"robots[{i}].waypoints_in", r.waypoints_in) for i, r in enumerate(scenario.robots)]
    for where, cats in entries:
        if cats != ALL and not cats:
            raise ConfigError("no category given", source=str(scenario_file), path=where)
        for cat in [] if cats == ALL else cats:
            if cat not in known:
                raise ConfigError(
                    f"unknown zone category {cat!r}; {zones.source} defines: "
                    f"{', '.join(zones.categories)}",
                    source=str(scenario_file),
                    path=where,
                )
    return ZoneSetup(zones, scenario, Path(zones_file), Path(scenario_file))


def default_zone_files(map_spec: Mapping[str, Any]) -> tuple[Path, Path] | None:
    """The world's ``map/zones.yaml`` and ``zones/default.yaml`` for a ``map`` block.

    Works for ``{type: world, name: <packaged name or folder>}`` and ``{type: file, path:
    <map.yaml>}`` (the zones file lies next to ``map.yaml``); ``None`` for other maps.
    """
    kind = map_spec.get("type")
    if kind == "world" and "name" in map_spec:
        map_yaml = resolve_world(str(map_spec["name"]))
    elif kind == "file" and "path" in map_spec:
        map_yaml = Path(str(map_spec["path"])).expanduser()
    else:
        return None
    folder = map_yaml.parent.parent if map_yaml.parent.name == "map" else map_yaml.parent
    return map_yaml.parent / "zones.yaml", folder / "zones" / "default.yaml"


class ZoneFileParams(BaseModel):
    """The two file parameters every zones mode takes."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    zones: str | None = Field(None, description="zones.yaml; default: the world's map/zones.yaml")
    scenario: str | None = Field(
        None, description="zone scenario YAML; default: the world's zones/default.yaml"
    )


class ZoneFiles:
    """Finds and caches the zone files a zones task mode uses.

    Args:
        zones: path of ``zones.yaml``; ``None``: the world's ``map/zones.yaml``.
        scenario: path of the zone scenario; ``None``: the world's ``zones/default.yaml``.
        role: the mode (``obstacles.zones``) for messages.
    """

    def __init__(self, zones: str | None, scenario: str | None, role: str) -> None:
        self.zones = zones
        self.scenario = scenario
        self.role = role
        self._cache: dict[tuple[Path, Path], ZoneSetup] = {}
        if zones is not None and scenario is not None:
            self.get({})  # both given: check them now, not at the first reset

    def get(self, map_spec: Mapping[str, Any]) -> ZoneSetup:
        """The (cached) setup for an episode's ``map`` block."""
        defaults = default_zone_files(map_spec)
        if defaults is None and (self.zones is None or self.scenario is None):
            missing = "zones" if self.zones is None else "scenario"
            raise ConfigError(
                f"{self.role} needs a {missing} file: give task.{self.role.split('.')[0]}."
                f"{missing}, or use a world map (map: {{type: world, name: ...}}) with "
                "map/zones.yaml and zones/default.yaml",
                path=f"task.{self.role.split('.')[0]}.{missing}",
            )
        zones = Path(self.zones).expanduser() if self.zones else defaults[0]  # type: ignore[index]
        scenario = (
            Path(self.scenario).expanduser() if self.scenario else defaults[1]  # type: ignore[index]
        )
        key = (zones, scenario)
        if key not in self._cache:
            self._cache[key] = load_zone_setup(zones, scenario)
        return self._cache[key]


def sample_in_zones(
    world: WorldSampler,
    zones: ZoneMap,
    categories: Categories,
    clearance: float,
    rng: np.random.Generator,
    *,
    what: str,
    forbid: bool,
    within: NDArray[np.bool_] | None = None,
    attempts: int = 20,
) -> FloatArray:
    """One position (m) inside a random zone of a random category of ``categories``.

    Draws a category uniformly, then a zone of that category uniformly, then one of the zone's
    polygons with probability proportional to its area, and samples a position keeping
    ``clearance`` (m) inside it (:meth:`WorldSampler.sample` with ``polygon``). A full zone is
    redrawn, up to ``attempts`` times.

    Raises:
        SamplingError: no drawn zone had room.
    """
    cats = zones.expand(categories)
    tried: list[str] = []
    for _ in range(attempts):
        cat = cats[int(rng.integers(len(cats)))]
        candidates = zones.of(cat)
        zone = candidates[int(rng.integers(len(candidates)))]
        polys = zone.polygons()
        areas = np.array([polygon_area(p) for p in polys])
        poly = polys[int(rng.choice(len(polys), p=areas / areas.sum()))]
        try:
            xy = world.sample(
                1, clearance, rng, what=what, polygon=poly, within=within, forbid=forbid
            )
            return np.asarray(xy[0], dtype=np.float64)
        except SamplingError:
            tried.append(zone.label)
    raise SamplingError(
        f"cannot place {what} in a zone of {', '.join(cats)}: no room keeping {clearance:g} m "
        f"from walls, obstacles and forbidden zones in {', '.join(sorted(set(tried)))} "
        f"({attempts} draws); enlarge the zones or lower the counts"
    )


__all__ = [
    "ALL",
    "PedestrianGroup",
    "Range",
    "RobotRole",
    "Zone",
    "ZoneFiles",
    "ZoneMap",
    "ZoneScenario",
    "ZoneSetup",
    "default_zone_files",
    "load_zone_scenario",
    "load_zone_setup",
    "load_zones",
    "polygon_area",
    "sample_in_zones",
]

