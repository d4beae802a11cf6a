"""Scenario entries without ``pos``, ``name`` or ``model``: read as Arena's loader reads them.

Arena's ``Obstacle.parse`` / ``DynamicObstacle.parse`` take ``obj.get("name", "")`` and
``obj.get("pos", (0, 0, 0))``, its scenario task ``obs["model"]`` for static and interactive
obstacles (``obs.get("model", actor1)`` for pedestrians). The fixtures follow the published
files of arena-rosnav's side branches: ``old/Eval_13_02.json`` (pedestrians with waypoints only)
and ``new_scenario_2.json`` (an interactive obstacle given by ``pos`` and ``yaml_path``).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from arena.core.errors import ConfigError
from arena.maps.grid import OccupancyGrid
from arena.robots.presets import load_robot
from arena.tasks.scenario import load_scenario, parse_scenario
from arena.tasks.scenario_convert import scenario_episode

ROBOT = {"start": [1.0, 1.0, 0.0], "goal": [5.0, 5.0, 0.0]}


def _write(tmp_path: Path, obstacles: dict[str, Any]) -> Path:
    path = tmp_path / "s.json"
    path.write_text(json.dumps({"robots": [ROBOT], "obstacles": obstacles}))
    return path


def test_a_pedestrian_without_pos_starts_at_the_origin_with_a_warning(tmp_path: Path) -> None:
    path = _write(tmp_path, {"dynamic": [
        {"type": "pedestrian", "waypoints": [[3.0, 3.0, 0.0], [4.0, 1.0, 0.0]]}]})
    s = load_scenario(path)
    p = s.obstacles.dynamic[0]
    assert p.pos == (0.0, 0.0, 0.0) and p.name == "dynamic_0"
    assert "obstacles.dynamic[0].pos: missing, Arena uses [0, 0, 0] (the map origin)" \
        in s.warnings
    grid = OccupancyGrid.empty(10.0, 10.0, 0.1)
    ep = scenario_episode(s, grid, [load_robot("jackal")], time_limit=10.0)
    assert np.array_equal(ep.agents.positions, [[0.0, 0.0]])
    assert np.array_equal(ep.agents.waypoints[0], [[3.0, 3.0], [4.0, 1.0]])


def test_two_pedestrians_without_pos_are_one_spot_and_refused(tmp_path: Path) -> None:
    # Eval_13_02.json: Arena starts both at [0, 0, 0]
    path = _write(tmp_path, {"dynamic": [
        {"type": "pedestrian", "waypoints": [[-5.3, 0.2, 0], [1, -1.1, 0]]},
        {"type": "pedestrian", "waypoints": [[-4.6, -3.9, 0], [0.9, -4.1, 0]]}]})
    with pytest.raises(ConfigError) as e:
        load_scenario(path)
    assert e.value.path == "obstacles.dynamic[1].pos"
    assert "two people on one spot" in e.value.message
    assert e.value.message.endswith("obstacles.dynamic[0] and obstacles.dynamic[1] have no "
                                    "pos, so Arena starts them at [0, 0, 0]")
    # one of the two placed: only the other is named
    path = _write(tmp_path, {"dynamic": [{"name": "a", "pos": [0.0, 0.0]}, {"name": "b"}]})
    with pytest.raises(ConfigError, match=r"; obstacles\.dynamic\[1\] has no pos, so Arena"):
        load_scenario(path)


def test_static_and_interactive_without_name_or_pos(tmp_path: Path) -> None:
    s = load_scenario(_write(tmp_path, {
        "static": [{"model": "shelf", "pos": [2.0, 3.0, 0.0]}, {"name": "static_1",
                                                                "model": "table"}],
        "interactive": [{"model": "long_shelf", "pos": [8.0, 8.0]}]}))
    names = [o.name for o in (*s.obstacles.static, *s.obstacles.interactive)]
    assert names == ["static_0", "static_1", "interactive_0"]
    assert "obstacles.static[0].name: missing, named 'static_0' (Arena: '')" in s.warnings
    assert "obstacles.interactive[0].name: missing, named 'interactive_0' (Arena: '')" \
        in s.warnings
    assert not any("static[1].name" in w for w in s.warnings)
    assert "obstacles.static[1].pos: missing, Arena uses [0, 0, 0] (the map origin)" \
        in s.warnings
    # a generated name never takes an existing one
    s = parse_scenario(json.dumps({"obstacles": {"static": [
        {"model": "shelf", "pos": [1, 1]},
        {"name": "static_0", "model": "shelf", "pos": [3, 3]}]}}))
    assert [o.name for o in s.obstacles.static] == ["static_0_2", "static_0"]


def test_an_obstacle_without_model_is_refused_as_arena_fails_on_it(tmp_path: Path) -> None:
    # new_scenario_2.json: {"pos": [28.0, 22.0], "yaml_path": "long_shelf.model.yaml"}
    path = _write(tmp_path, {
        "static": [{"name": "ok", "model": "shelf", "pos": [2.0, 2.0]}],
        "interactive": [{"pos": [28.0, 22.0], "yaml_path": "long_shelf.model.yaml"},
                        {"pos": [3.0, 3.0]}]})
    with pytest.raises(ConfigError) as e:
        load_scenario(path)
    assert str(e.value).startswith(f"{path}: obstacles.interactive[0].model: required key is "
                                   "missing: Arena's loader reads obs['model'] and fails")
    assert "yaml_path 'long_shelf.model.yaml'" in e.value.message
    assert "(2 obstacle(s) of the file lack one)" in e.value.message
    assert "\n" not in str(e.value)
