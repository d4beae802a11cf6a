"""The scenario editor's live validation: the project's own scenario reading and map checks.

Nothing is checked here that ``arena run --scenario`` does not check: the scenario JSON goes
through :func:`arena.tasks.scenario.parse_scenario` (format, obstacle models, start == goal,
people on one spot), then :func:`~arena.tasks.scenario_checks.validate_against_map` (positions
off the map, in walls, robots in unknown space) and
:func:`~arena.tasks.scenario_checks.check_robot_bodies` (the robot's real footprint against
walls and the scenario's obstacles). Where those stop at the first error, the editor asks
again per entry, so that the page can list (and mark) every problem at once. Zones are checked
with :class:`arena.tasks.zones.Zone`, the model the ``zones`` task modes read.
"""

from __future__ import annotations

import json
import re
import warnings
from dataclasses import asdict, dataclass
from functools import lru_cache
from typing import Any

from pydantic import TypeAdapter, ValidationError

from arena.core.errors import ArenaError, ConfigError, from_validation_error
from arena.core.types import Pose2D
from arena.maps.grid import OccupancyGrid
from arena.robots.model import RobotModel
from arena.robots.presets import load_robot
from arena.scene.episode import RobotSpawn
from arena.tasks.scenario import Scenario, _pose3, parse_scenario
from arena.tasks.scenario_checks import check_robot_bodies, validate_against_map
from arena.tasks.scenario_convert import scenario_obstacles
from arena.tasks.zones import Zone

_ZONES = TypeAdapter(list[Zone])

# The key paths validate_against_map joins its findings with ("text; path: text; ...").
_JOINED = re.compile(
    r"; ((?:robots|obstacles\.(?:static|interactive|dynamic))\[\d+\][\w.\[\]]*): ")
# A warning line that starts with a key path ("obstacles.dynamic[0].waypoints: empty ...").
_LEADING_PATH = re.compile(r"^((?:robots|obstacles)[\w.\[\]]*): (.*)$")


@dataclass(frozen=True)
class Finding:
    """One problem or warning: the key path it concerns (``None`` for the whole), and what."""

    path: str | None
    message: str


@dataclass(frozen=True)
class Validation:
    """The outcome of :func:`validate`.

    Attributes:
        problems: what ``arena run`` would refuse; the scenario is saved only without them.
        warnings: what Arena accepts with a remark.
        scenario: the parsed scenario when it reads (``None`` when the format is wrong).
    """

    problems: list[Finding]
    warnings: list[Finding]
    scenario: Scenario | None

    @property
    def ok(self) -> bool:
        """No problems."""
        return not self.problems

    def as_json(self) -> dict[str, Any]:
        """``{"ok", "problems": [{path, message}], "warnings": [...]}``."""
        return {"ok": self.ok, "problems": [asdict(f) for f in self.problems],
                "warnings": [asdict(f) for f in self.warnings]}


@lru_cache(maxsize=1)
def default_robot() -> str:
    """The robot ``arena run`` drives without ``--robot`` (the default config's)."""
    from arena.config import load_config

    return str(load_config(None, []).robot)


@lru_cache(maxsize=16)
def robot_model(name: str) -> RobotModel:
    """A robot preset (cached; :class:`~arena.core.errors.ConfigError` for an unknown one)."""
    return load_robot(name)


def _finding(e: ConfigError) -> Finding:
    return Finding(e.path, e.message)


def _split_map_error(e: ConfigError) -> list[Finding]:
    """The findings validate_against_map joined into one error, one each."""
    parts = _JOINED.split(e.message)
    out = [Finding(e.path, parts[0])]
    out += [Finding(parts[i], parts[i + 1]) for i in range(1, len(parts) - 1, 2)]
    return out


def _warning(line: str) -> Finding:
    line = line.removeprefix("scenario: ")
    m = _LEADING_PATH.match(line)
    return Finding(m.group(1), m.group(2)) if m else Finding(None, line)


def validate(data: Any, grid: OccupancyGrid, robot: RobotModel,
             zones: Any = ()) -> Validation:
    """Check scenario JSON ``data`` (as the file would hold it) against ``grid``.

    Args:
        data: the scenario's JSON value (a dict; anything else is a problem).
        grid: the map it is drawn on.
        robot: the robot model whose footprint is checked at every start and goal.
        zones: the zones drawn with it (a list in ``zones.yaml``'s format).

    Returns:
        The problems and warnings; never raises for bad input.
    """
    problems: list[Finding] = []
    notes: list[Finding] = []
    try:
        _ZONES.validate_python(list(zones))
    except ValidationError as e:
        problems.append(_finding(from_validation_error(e, prefix="zones")))
    except TypeError:
        problems.append(Finding("zones", "expected a list of zones"))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            scenario = parse_scenario(json.dumps(data), source=None)
        except ConfigError as e:
            return Validation([*problems, _finding(e)], notes, None)
        except (TypeError, ValueError) as e:  # not JSON-serialisable: not from a page
            return Validation([*problems, Finding(None, f"not scenario JSON: {e}")], notes, None)
    seen: set[str] = set()
    for line in [*scenario.warnings, *(str(w.message) for w in caught)]:
        finding = _warning(line)
        if finding.message not in seen:
            seen.add(finding.message)
            notes.append(finding)
    if not scenario.robots:
        problems.append(Finding("robots", "no robot: arena run needs a start and a goal "
                                          "(place them with the start and goal tools)"))
    try:
        validate_against_map(scenario, grid)
    except ConfigError as e:
        problems += _split_map_error(e)
    # a start already off the map or in a wall needs no second word about its body
    placed = {f.path for f in problems}
    problems += [f for f in _body_problems(scenario, grid, robot) if f.path not in placed]
    return Validation(problems, notes, scenario)


def _body_problems(scenario: Scenario, grid: OccupancyGrid, robot: RobotModel) -> list[Finding]:
    """Each robot's footprint at start and goal against walls and the scenario's obstacles."""
    try:
        obstacles = scenario_obstacles(scenario)
    except ArenaError as e:  # parse_scenario checked the models; kept for safety of the page
        return [Finding(getattr(e, "path", None), str(e))]
    out = []
    for k, entry in enumerate(scenario.robots):
        # one pose per call (start == goal): check_robot_bodies stops at the first overlap,
        # the page shows every one
        for key, pose in (("start", entry.start), ("goal", entry.goal)):
            at = Pose2D.from_array(_pose3(pose))
            try:
                check_robot_bodies([RobotSpawn(robot.name, robot, at, at)], grid, obstacles)
            except ConfigError as e:
                out.append(Finding(f"robots[{k}].{key}", e.message))
    return out
