"""Arena scenario JSON files: read, validate, write, and turn into an :class:`Episode`.

The format is Arena-Rosnav's ``worlds/<map>/scenarios/*.json`` (task mode ``scenario``)::

    {"robots": [{"start": [x, y, θ], "goal": [x, y, θ]}],
     "obstacles": {"static": [...], "interactive": [...], "dynamic": [...]},
     "map": "arena_corridor", "resets": 50}

Files are read as Arena's loader reads them (it takes each block's keys with ``dict.get``):

* At the top level, in each robot, in the ``obstacles`` block and in each pedestrian
  (``dynamic``), a key Arena does not read is ignored: published files carry ``format``,
  ``yaml_file`` and ``number_of_peds``. The ignored keys are named in ONE :class:`UserWarning`
  per file and in :attr:`Scenario.warnings`. An unknown key close to a known one (``vamx``,
  ``robot``; see :data:`TYPO_CUTOFF`) stays an error: Arena would silently drop the value the
  author meant. A file with none of ``robots``/``obstacles`` but other keys (Arena's pre-2023
  format) is refused, as Arena would load it as an empty task. Typed models stay closed
  (``extra="forbid"``); only files go through this reading. ``map`` and ``resets`` appear in
  files but Arena's 2024 loader ignores them; they are kept (and written back) as information.
* Static and interactive obstacles are open: Arena keeps every key beyond ``name``, ``model``
  and ``pos`` as the obstacle's "extra" (pedsim reads ``type``, ``interaction_radius``,
  ``yaml_path``). The three known ones are fields; anything else lands in
  :attr:`ObstacleEntry.extra`, is written back unchanged and is listed in the warnings.
* A pedestrian without ``name`` is named ``dynamic_<i>`` (its index, made unique among the
  file's names; the name is then written on save), with a warning; a static or interactive
  obstacle without ``name`` likewise ``static_<i>`` / ``interactive_<i>`` (Arena: ``""``).
* An entity without ``pos`` stands at ``[0, 0, 0]``, the map origin, as in Arena
  (``obj.get("pos", (0, 0, 0))``), with a warning. Two pedestrians without ``pos`` are then on
  one spot, which is refused (below): arena-rosnav's ``old/Eval_13_02.json`` is such a file.
* A static or interactive obstacle without ``model`` is refused: Arena's loader reads
  ``obs["model"]`` and fails on it too. Files of the 2023 task generator name a flatland model
  file by ``yaml_path`` instead (``long_shelf.model.yaml``), which Arena no longer reads.

Missing keys default as in Arena: lists are empty, positions are ``[0, 0, 0]``, a pedestrian's
model is ``actor1``, its ``waypoint_mode`` 0 and its ``type`` adult. Positions and waypoints
may have two values (``[x, y]``, some published files do); the third (θ for poses, a radius
for waypoints) is then 0. Files are kept as written: a missing key stays missing on save.

Quirks of the published files that load with a recorded warning (:attr:`Scenario.warnings`)
instead of an error, so that every file Arena ships loads unchanged:

* ``waypoint_mode: 2`` (hospital scenarios) is not defined in pedsim (0 loop, 1 random); it is
  kept in the file and treated as 0 (loop) when the episode is built.
* A pedestrian with no waypoints stands at its start position.
* Legacy model names ending in ``.yaml`` (``shelf.yaml``) name the library model ``shelf``.
* An unknown pedestrian ``type`` is treated as adult (what Arena's crowd model does).

Refused although Arena would load them (each would fail late or make no sense): a key given
twice, a ``[hi, lo]`` range, a negative parameter, a probability above 1, a ``vmax`` outside
[0, 3] m/s, a robot goal within the goal radius of its start, two pedestrians on one spot (closer
than 1 cm: Arena's map7 ``default.json`` has such a pair). Pedestrians whose bodies merely
overlap (Arena's floor, hospital and map_empty_medium worlds place some 0.5 m apart) load with a
warning. Against the episode's map the task modes also refuse a
robot start or goal off the map or on an unknown (-1) cell, and a
robot whose real footprint overlaps a wall or an obstacle at its start or goal (``check_map:
false`` turns the map checks off). Both are in :mod:`arena.tasks.scenario_checks`.
"""

from __future__ import annotations

import difflib
import json
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import (
    AfterValidator,
    BaseModel,
    ConfigDict,
    Field,
    PrivateAttr,
    Strict,
    StrictInt,
    StrictStr,
    ValidationError,
    model_validator,
)

from arena.core import files
from arena.core.errors import ConfigError, UnknownNameError, from_validation_error
from arena.maps.obstacles import obstacle_model
from arena.scene.episode import (
    MAX_COUNT,
    MAX_PERSON_SPEED,
    WAYPOINT_LOOP,
    speed_range_problem,
)
from arena.tasks.scenario_checks import DEFAULT_PED_RADIUS, check_layout, validate_against_map

DEFAULT_VMAX = 0.3
"""m/s, Arena's task-generator default ``VMAX`` for a pedestrian without a ``vmax`` (§5.3)."""
DEFAULT_PED_MODEL = "actor1"
"""Arena's default pedestrian model name."""

WAYPOINT_UNDEFINED = 2
"""``waypoint_mode`` 2: used by the hospital scenarios, undefined in pedsim; read as loop."""

KIND_CODES = {"adult": 0, "elder": 1, "child": 2}
"""Pedestrian ``type`` (with or without the ``human/`` prefix) → :attr:`AgentSpawn.kinds`."""

STARTUP_CODES = {"default": 0, "wait_timer": 1, "trigger_zone": 2}
"""Arena's ``start_up_mode`` → :attr:`AgentSpawn.startup_mode`."""

# Scalars are strict ("3" is not a number, true is not a count; an int is a fine float), while
# JSON arrays still fill tuples: the file is parsed with json and validated in lax mode.
Num = Annotated[float, Strict()]
Position = Annotated[tuple[Num, ...], Field(min_length=2, max_length=3)]
"""``[x, y]`` or ``[x, y, θ]`` (m, rad); a missing θ is 0."""
Waypoint = Annotated[tuple[Num, ...], Field(min_length=2, max_length=3)]
"""``[x, y]`` or ``[x, y, r]`` (m); Arena forwards ``r`` to pedsim as a radius."""


def _bounds(v: float | tuple[float, float]) -> tuple[float, float]:
    return v if isinstance(v, tuple) else (v, v)


def _check_param(v: float | tuple[float, float]) -> float | tuple[float, float]:
    # A reversed [hi, lo] would reach numpy as a negative spread ("scale < 0") only when the
    # episode is drawn; no pedsim parameter is negative.
    lo, hi = _bounds(v)
    if lo > hi:
        raise ValueError(f"a range must be [low, high], got {[lo, hi]}")
    if lo < 0:
        raise ValueError(f"must be >= 0, got {v!r}")
    return v


def _check_probability(v: float | tuple[float, float]) -> float | tuple[float, float]:
    if _bounds(v)[1] > 1:
        raise ValueError(f"a probability must lie in [0, 1], got {v!r}")
    return v


def _check_speed(v: float | tuple[float, float]) -> float | tuple[float, float]:
    if speed_range_problem(*_bounds(v)):  # a vmax of 1e6 m/s is a typo, not a person
        raise ValueError(
            f"must lie in [0, {MAX_PERSON_SPEED:g}] m/s (a person's walking speed), got {v!r}"
        )
    return v


Param = Annotated[
    Num | Annotated[tuple[Num, Num], Field(description="[lo, hi], sampled")],
    AfterValidator(_check_param),
]
"""A pedsim parameter: a number >= 0, or ``[lo, hi]`` (lo <= hi) sampled from
N((lo+hi)/2, (hi−lo)/6) clipped."""
Probability = Annotated[Param, AfterValidator(_check_probability)]
"""A :data:`Param` in [0, 1]."""
Speed = Annotated[Param, AfterValidator(_check_speed)]
"""A :data:`Param` in m/s within [0, :data:`~arena.scene.episode.MAX_PERSON_SPEED`]."""


# NaN or infinity is never a valid coordinate or parameter (Python's json accepts them).
_CONFIG = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False)


def _model_name(model: str) -> str:
    """The library name of an Arena model: legacy ``shelf.yaml`` names the model ``shelf``."""
    return model.removesuffix(".yaml")


def _pose3(pos: Sequence[float]) -> list[float]:
    return [float(pos[0]), float(pos[1]), float(pos[2]) if len(pos) > 2 else 0.0]


class RobotEntry(BaseModel):
    """One robot of the scenario: start and goal ``[x, y, θ]``."""

    model_config = _CONFIG

    start: Position = (0.0, 0.0, 0.0)
    goal: Position = (0.0, 0.0, 0.0)


class ObstacleEntry(BaseModel):
    """A static or interactive obstacle.

    Arena keeps every key beyond ``name``/``model``/``pos`` as "extra" data for pedsim, so this
    entry is open: ``type``, ``interaction_radius`` and ``yaml_path`` (the keys pedsim reads) are
    fields, any other key is collected into :attr:`extra` and written back unchanged.
    """

    model_config = _CONFIG

    name: StrictStr
    model: StrictStr = Field(description="folder name under Arena's entities/obstacles/static/")
    pos: Position = (0.0, 0.0, 0.0)
    type: StrictStr | None = None
    interaction_radius: Num | None = None
    yaml_path: StrictStr | None = None
    extra: dict[str, Any] = Field(default_factory=dict, description="other keys, kept as is")

    @model_validator(mode="before")
    @classmethod
    def _collect_extra(cls, data: Any) -> Any:
        if not isinstance(data, dict):
            return data
        known = set(cls.model_fields) - {"extra"}
        out = {k: v for k, v in data.items() if k in known}
        out["extra"] = {k: v for k, v in data.items() if k not in known}
        return out


class Pedestrian(BaseModel):
    """A dynamic obstacle (pedsim pedestrian) with Arena's optional per-ped overrides.

    Unset overrides keep Arena's defaults (§5.3). Numbers may also be ``[lo, hi]`` ranges, the
    way Arena's ``pedsim.yaml`` writes them; they are sampled per episode.
    """

    model_config = _CONFIG

    name: StrictStr
    pos: Position = (0.0, 0.0, 0.0)
    model: StrictStr = DEFAULT_PED_MODEL
    type: StrictStr = "adult"
    waypoints: tuple[Waypoint, ...] = ()
    waypoint_mode: StrictInt = Field(
        WAYPOINT_LOOP, ge=0, le=2, description="0 loop, 1 random, 2 undefined (read as loop)"
    )
    id: StrictInt | None = Field(None, description="present in some files; not used")
    vmax: Speed | None = Field(None, description="m/s, 0 to 3")
    start_up_mode: Literal["default", "wait_timer", "trigger_zone"] | None = None
    wait_time: Num | None = Field(None, ge=0, description="s, for start_up_mode wait_timer")
    trigger_zone_radius: Num | None = Field(None, ge=0, description="m, for trigger_zone")
    chatting_probability: Probability | None = None
    tell_story_probability: Probability | None = None
    group_talking_probability: Probability | None = None
    talking_and_walking_probability: Probability | None = None
    requesting_service_probability: Probability | None = None
    requesting_guide_probability: Probability | None = None
    requesting_follower_probability: Probability | None = None
    max_talking_distance: Param | None = None
    max_servicing_radius: Param | None = None
    talking_base_time: Param | None = None
    tell_story_base_time: Param | None = None
    group_talking_base_time: Param | None = None
    talking_and_walking_base_time: Param | None = None
    receiving_service_base_time: Param | None = None
    requesting_service_base_time: Param | None = None
    force_factor_desired: Param | None = None
    force_factor_obstacle: Param | None = None
    force_factor_social: Param | None = None
    force_factor_robot: Param | None = None

    @property
    def kind(self) -> str:
        """``adult``/``elder``/``child`` from ``type`` (``human/`` prefix dropped)."""
        return self.type.removeprefix("human/")

    @property
    def effective_waypoint_mode(self) -> int:
        """The mode used in the simulation: the undefined mode 2 runs as loop (0)."""
        # Validation admits only 0, 1 and 2, so the result is WAYPOINT_LOOP or WAYPOINT_RANDOM.
        return WAYPOINT_LOOP if self.waypoint_mode == WAYPOINT_UNDEFINED else self.waypoint_mode


class Obstacles(BaseModel):
    """The ``obstacles`` block."""

    model_config = _CONFIG

    static: tuple[ObstacleEntry, ...] = Field((), max_length=MAX_COUNT)
    interactive: tuple[ObstacleEntry, ...] = Field((), max_length=MAX_COUNT)
    dynamic: tuple[Pedestrian, ...] = Field((), max_length=MAX_COUNT)


class Scenario(BaseModel):
    """A whole scenario file (see the module docstring for the format and its quirks)."""

    model_config = _CONFIG

    robots: tuple[RobotEntry, ...] = ()
    obstacles: Obstacles = Field(default_factory=Obstacles)
    map: StrictStr | None = Field(None, description="informational; the launch arg picks the map")
    resets: StrictInt | None = Field(None, ge=0, description="informational; not read by Arena")
    # Set by parse_scenario: what reading the file as Arena does changed (generated names,
    # ignored keys), one line each; not part of the value (equality, saving).
    _read_notes: tuple[str, ...] = PrivateAttr(default=())

    def __eq__(self, other: object) -> bool:
        # The fields only: how a file was read (the notes) does not change what it describes.
        return type(other) is type(self) and self.__dict__ == other.__dict__

    def __hash__(self) -> int:  # frozen: hashable, consistent with __eq__
        return hash(tuple(self.__dict__.values()))

    @property
    def warnings(self) -> tuple[str, ...]:
        """Quirks accepted on load, one readable line each (key path first)."""
        out: list[str] = list(self._read_notes)
        for i, r in enumerate(self.robots):
            for key in ("start", "goal"):
                if key not in r.model_fields_set:
                    out.append(f"robots[{i}].{key}: missing, Arena uses [0, 0, 0]")
        for group in ("static", "interactive", "dynamic"):
            for i, entity in enumerate(getattr(self.obstacles, group)):
                if "pos" not in entity.model_fields_set:
                    out.append(f"obstacles.{group}[{i}].pos: missing, Arena uses [0, 0, 0] "
                               "(the map origin)")
        for group in ("static", "interactive"):
            for i, o in enumerate(getattr(self.obstacles, group)):
                where = f"obstacles.{group}[{i}]"
                if o.model != _model_name(o.model):
                    out.append(
                        f"{where}.model: legacy name {o.model!r} read as {_model_name(o.model)!r}"
                    )
                if o.extra:
                    keys = ", ".join(sorted(o.extra))
                    out.append(f"{where}: extra keys kept but not used: {keys}")
        for i, p in enumerate(self.obstacles.dynamic):
            where = f"obstacles.dynamic[{i}]"
            if p.waypoint_mode == WAYPOINT_UNDEFINED:
                out.append(
                    f"{where}.waypoint_mode: 2 is undefined in pedsim (0 loop, 1 random); "
                    "treated as 0 (loop)"
                )
            if not p.waypoints:
                out.append(f"{where}.waypoints: empty; the pedestrian stands at its start")
            if p.kind not in KIND_CODES:
                out.append(f"{where}.type: unknown type {p.type!r}, treated as adult")
        return tuple(out)

    def to_json_dict(self) -> dict[str, Any]:
        """The file's JSON object: keys missing on load stay missing, extras are flattened."""
        data = self.model_dump(mode="json", exclude_unset=True)
        for group in ("static", "interactive"):
            for entry in data.get("obstacles", {}).get(group, []):
                entry.update(entry.pop("extra", {}))
        return data


# -- reading and writing ------------------------------------------------------------------------
TYPO_CUTOFF = 0.75
"""difflib similarity from which an unknown key counts as a misspelt known one (``vamx`` →
``vmax`` is 0.75, ``robot`` → ``robots`` 0.91; the extra keys of Arena's files stay below 0.6)."""

# The blocks Arena reads with ``dict.get``: an unknown key there is ignored by Arena.
_BLOCK_FIELDS: dict[str, frozenset[str]] = {
    "top": frozenset(Scenario.model_fields),
    "robot": frozenset(RobotEntry.model_fields),
    "obstacles": frozenset(Obstacles.model_fields),
    "dynamic": frozenset(Pedestrian.model_fields),
}


def _drop_unknown(
    block: dict[str, Any], kind: str, path: str, ignored: list[str], source: str | None
) -> dict[str, Any]:
    """``block`` without the keys Arena does not read, their paths appended to ``ignored``.

    Raises:
        ConfigError: an unknown key one edit or so from a known one (a spelling mistake that
            would silently drop a value the author meant).
    """
    known = _BLOCK_FIELDS[kind]
    out: dict[str, Any] = {}
    for key, value in block.items():
        if key in known:
            out[key] = value
            continue
        where = f"{path}.{key}" if path else key
        close = difflib.get_close_matches(key, sorted(known), n=1, cutoff=TYPO_CUTOFF)
        if close:
            raise ConfigError(
                f"unknown key; did you mean {close[0]!r}? (Arena would ignore it silently)",
                source=source, path=where,
            )
        ignored.append(where)
    return out


def _read_as_arena(data: Any, source: str | None) -> tuple[Any, list[str]]:
    """The file's JSON as Arena's loader sees it, and a note for each thing it changed.

    Arena reads every block with ``dict.get``: keys it does not know are ignored (the notes and
    one :class:`UserWarning` per file name them), and a pedestrian without ``name`` gets one
    (``dynamic_<i>``, made unique among the file's names). Anything of the wrong type is left
    for validation to report.
    """
    if not isinstance(data, dict):
        return data, []
    ignored: list[str] = []
    notes: list[str] = []
    out = _drop_unknown(data, "top", "", ignored, source)
    robots = out.get("robots")
    if isinstance(robots, list):
        out["robots"] = [
            _drop_unknown(r, "robot", f"robots[{i}]", ignored, source) if isinstance(r, dict) else r
            for i, r in enumerate(robots)
        ]
    obstacles = out.get("obstacles")
    if isinstance(obstacles, dict):
        obstacles = _drop_unknown(obstacles, "obstacles", "obstacles", ignored, source)
        _name_obstacles(obstacles, notes, source)
        peds = obstacles.get("dynamic")
        if isinstance(peds, list):
            taken = {p["name"] for p in peds
                     if isinstance(p, dict) and isinstance(p.get("name"), str)}
            fixed: list[Any] = []
            for i, p in enumerate(peds):
                if isinstance(p, dict):
                    where = f"obstacles.dynamic[{i}]"
                    p = _drop_unknown(p, "dynamic", where, ignored, source)
                    if "name" not in p:
                        p["name"] = _unique(f"dynamic_{i}", taken)
                        notes.append(f"{where}.name: missing, named {p['name']!r} (as Arena does)")
                fixed.append(p)
            obstacles["dynamic"] = fixed
        out["obstacles"] = obstacles
    if ignored and not {"robots", "obstacles"} & out.keys():
        # Nothing Arena reads: a legacy format (pedsim_agents, robot_position ...), which Arena's
        # loader would turn into an empty task; say so instead of loading nothing.
        raise ConfigError(
            f"none of the keys Arena reads (robots, obstacles) is present, only "
            f"{', '.join(sorted(ignored))}: not a scenario file of Arena's format (an older "
            "format Arena no longer reads?)",
            source=source,
        )
    if ignored:
        keys = ", ".join(sorted({w.rsplit(".", 1)[-1] for w in ignored}))
        line = (
            f"keys Arena does not read, ignored: {keys} ({len(ignored)} place(s), first "
            f"{ignored[0]})"
        )
        notes.insert(0, line)
        warnings.warn(f"{source or 'scenario'}: {line}", UserWarning, stacklevel=3)
    return out, notes


def _name_obstacles(obstacles: dict[str, Any], notes: list[str], source: str | None) -> None:
    """Name static/interactive obstacles without ``name``; refuse one without ``model``.

    Arena reads ``obj.get("name", "")`` but ``obs["model"]``: a missing name is Arena's empty
    name (here ``<group>_<i>``, unique among the file's obstacle names, with a note), a missing
    model fails Arena's loader as it fails here.
    """
    groups = [(g, obstacles[g]) for g in ("static", "interactive")
              if isinstance(obstacles.get(g), list)]
    taken = {o["name"] for _, group in groups for o in group
             if isinstance(o, dict) and isinstance(o.get("name"), str)}
    for g, group in groups:
        for i, o in enumerate(group):
            if not isinstance(o, dict):
                continue
            where = f"obstacles.{g}[{i}]"
            if "model" not in o:
                missing = sum(1 for _, grp in groups for e in grp
                              if isinstance(e, dict) and "model" not in e)
                named = (f"; it names a flatland model file by yaml_path {o['yaml_path']!r} "
                         "(the 2023 task generator's format)" if "yaml_path" in o else "")
                raise ConfigError(
                    f"required key is missing: Arena's loader reads obs['model'] and fails "
                    f"without it too{named}; give a model of the obstacle library "
                    f"({missing} obstacle(s) of the file lack one)",
                    source=source, path=f"{where}.model")
            if "name" not in o:
                group[i] = o = {**o, "name": _unique(f"{g}_{i}", taken)}
                notes.append(f"{where}.name: missing, named {o['name']!r} (Arena: '')")


def parse_scenario(text: str, *, source: str | None = None) -> Scenario:
    """Parse and validate scenario JSON text.

    Args:
        text: the file's content.
        source: the file name used in error messages.

    Raises:
        ConfigError: malformed JSON (with line and column; duplicate keys and deep nesting
            included, see :func:`arena.core.files.parse_json`), a wrong type or unknown key
            (with the key path, e.g. ``obstacles.dynamic[3].waypoints``), an obstacle model
            that is not in the library (with the closest name), a robot whose start is its goal
            or two pedestrians on one spot (see
            :func:`~arena.tasks.scenario_checks.check_layout`).
    """
    data, notes = _read_as_arena(files.parse_json(text, source=source), source)
    try:
        scenario = Scenario.model_validate(data)
    except ValidationError as e:
        raise from_validation_error(e, source=source) from None
    scenario._read_notes = tuple(notes)
    for group in ("static", "interactive"):
        for i, o in enumerate(getattr(scenario.obstacles, group)):
            try:
                obstacle_model(_model_name(o.model))
            except UnknownNameError as e:
                raise e.located(source=source, prefix=f"obstacles.{group}[{i}].model") from None
    check_layout(scenario, source=source)
    return scenario


def load_scenario(path: str | Path) -> Scenario:
    """Read an Arena scenario JSON file (see :func:`parse_scenario` for the errors)."""
    p = Path(path)
    return parse_scenario(files.read_text(p, what="scenario file"), source=str(p))


def save_scenario(scenario: Scenario, path: str | Path) -> None:
    """Write ``scenario`` in Arena's format (indented JSON); loading it gives an equal value."""
    text = json.dumps(scenario.to_json_dict(), indent=2)
    Path(path).write_text(text + "\n", encoding="utf-8")


def validate_file(path: str | Path, map_yaml: str | Path | None = None) -> list[str]:
    """CLI hook: load a scenario (and check it against a ROS ``map.yaml`` if given).

    Returns:
        Human-readable findings (warnings), each starting with the file and key path.

    Raises:
        ConfigError: the first error, naming the file and the entry.
    """
    from arena.maps.io import load_map  # map images are only needed when a map is given

    scenario = load_scenario(path)
    findings = list(scenario.warnings)
    if map_yaml is not None:
        findings += validate_against_map(scenario, load_map(map_yaml), source=str(path))
    return [f"{path}: {w}" for w in findings]


# -- conversion to an episode -------------------------------------------------------------------


def _unique(name: str, taken: set[str]) -> str:
    out, k = name, 2
    while out in taken:
        out, k = f"{name}_{k}", k + 1
    taken.add(out)
    return out


__all__ = [
    "DEFAULT_PED_RADIUS",
    "DEFAULT_VMAX",
    "ObstacleEntry",
    "Obstacles",
    "Pedestrian",
    "RobotEntry",
    "Scenario",
    "load_scenario",
    "parse_scenario",
    "save_scenario",
    "validate_file",
]
