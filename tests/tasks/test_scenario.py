"""Arena scenario JSON: loading, checks, round trip and conversion to an episode.

The fixtures are written here from the format (Arena's ``worlds/<map>/scenarios/*.json``), in
the styles the published files use: map_empty's default (3 shelves, 3 peds), the hospital's
``waypoint_mode: 2`` with many waypoints, the corridor's ``map``/``resets`` keys, and a
pedestrian with per-ped overrides.
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
from arena.scene.episode import WAYPOINT_LOOP, WAYPOINT_RANDOM
from arena.tasks.scenario import (
    DEFAULT_PED_RADIUS,
    DEFAULT_VMAX,
    Scenario,
    load_scenario,
    parse_scenario,
    save_scenario,
    validate_file,
)
from arena.tasks.scenario_checks import validate_against_map
from arena.tasks.scenario_convert import scenario_episode


def ped(name: str, pos: list[float], waypoints: list[list[float]], **kw: Any) -> dict[str, Any]:
    return {
        "name": name,
        "pos": pos,
        "type": "adult",
        "model": "actor1",
        "waypoints": waypoints,
        **kw,
    }


# map_empty/scenarios/default.json, values as published.
DEFAULT_JSON: dict[str, Any] = {
    "robots": [{"start": [24.0, 20.0, 0.7], "goal": [2.0, 2.0, 0.0]}],
    "obstacles": {
        "static": [
            {"name": "shelf1", "model": "shelf", "pos": [13.0, 11.0, -0.5]},
            {"name": "shelf2", "model": "shelf", "pos": [12.0, 12.0, -0.5]},
            {"name": "shelf3", "model": "shelf", "pos": [14.0, 10.0, -0.5]},
        ],
        "dynamic": [
            ped("1", [14.0, 2.0, 0.0], [[2.0, 14.0, 0.0], [14.0, 2.0, 0.0]], waypoint_mode=1),
            ped("2", [2.0, 8.0, 0.0], [[8.0, 2.0, 0.0], [8.0, 2.0, 0.0]], waypoint_mode=1),
            ped("3", [8.0, 2.0, 0.0], [[2.0, 8.0, 0.0], [8.0, 2.0, 0.0]], waypoint_mode=1),
        ],
        "interactive": [],
    },
}

HOSPITAL_JSON: dict[str, Any] = {
    "robots": [{"start": [2.0, 2.0, 0.0], "goal": [20.0, 15.0, 1.57]}],
    "obstacles": {
        "static": [],
        "interactive": [],
        "dynamic": [
            ped(
                "nurse",
                [5.0, 5.0, 0.0],
                [
                    [6.0, 5.0, 0.0],
                    [10.0, 5.0, 0.0],
                    [10.0, 10.0, 0.0],
                    [6.0, 10.0, 0.0],
                    [6.0, 6.0, 0.0],
                ],
                waypoint_mode=2,
            ),
            {
                "name": "visitor",
                "pos": [8.0, 8.0, 0.0],
                "type": "human/elder",
                "waypoints": [[9.0, 9.0, 0.5], [12.0, 9.0, 0.5]],
                "waypoint_mode": 0,
            },
        ],
    },
    "map": "arena_hospital_small",
    "resets": 50,
}

CORRIDOR_JSON: dict[str, Any] = {
    "robots": [{"start": [11.0, 5.0, 1.0], "goal": [2.0, 5.0, 1.0]}],
    "obstacles": {
        "static": [],
        "dynamic": [
            ped(
                "Visitor_1",
                [4.0, 4.0, 0.0],
                [[6.0, 4.0, 0.0], [4.0, 4.0, 0.0]],
                waypoint_mode=1,
                vmax=0.8,
                start_up_mode="wait_timer",
                wait_time=2.5,
                chatting_probability=0.2,
                force_factor_social=[5.0, 8.0],
                id=3,
            ),
            ped(
                "Visitor_2",
                [5.0, 6.0, 0.0],
                [[9.0, 6.0, 0.0], [5.0, 6.0, 0.0]],
                waypoint_mode=1,
                vmax=[0.4, 0.6],
                start_up_mode="trigger_zone",
                trigger_zone_radius=3.0,
                type="child",
            ),
            ped("Visitor_3", [7.0, 5.0, 0.0], [[7.0, 3.0, 0.0], [7.0, 7.0, 0.0]], waypoint_mode=1),
        ],
        "interactive": [],
    },
    "resets": 50,
    "map": "arena_corridor",
}


def write(tmp_path: Path, data: Any, name: str = "scenario.json") -> Path:
    path = tmp_path / name
    path.write_text(data if isinstance(data, str) else json.dumps(data, indent=2))
    return path


@pytest.fixture
def grid() -> OccupancyGrid:
    """30 m × 25 m free map with a one-cell wall border and a wall block at x 20-22, y 0-5."""
    g = OccupancyGrid.empty(30.0, 25.0, 0.1)
    occ = g.occupied.copy()
    occ[0:50, 200:220] = True
    return OccupancyGrid.from_occupied(occ, 0.1)


# -- loading ------------------------------------------------------------------------------------
@pytest.mark.parametrize("data", [DEFAULT_JSON, HOSPITAL_JSON, CORRIDOR_JSON])
def test_round_trip_load_save_load_is_equal(tmp_path: Path, data: dict[str, Any]) -> None:
    first = load_scenario(write(tmp_path, data))
    save_scenario(first, tmp_path / "out.json")
    again = load_scenario(tmp_path / "out.json")
    assert again == first
    # Same format: the written object is the input object (keys missing stay missing).
    assert json.loads((tmp_path / "out.json").read_text()) == data


def test_default_json_values(tmp_path: Path) -> None:
    s = load_scenario(write(tmp_path, DEFAULT_JSON))
    assert s.robots[0].start == (24.0, 20.0, 0.7)
    assert [o.model for o in s.obstacles.static] == ["shelf"] * 3
    assert [p.name for p in s.obstacles.dynamic] == ["1", "2", "3"]
    assert s.obstacles.dynamic[0].waypoint_mode == WAYPOINT_RANDOM
    assert s.map is None and s.resets is None
    assert s.warnings == ()


def test_corridor_keeps_map_and_resets(tmp_path: Path) -> None:
    s = load_scenario(write(tmp_path, CORRIDOR_JSON))
    assert (s.map, s.resets) == ("arena_corridor", 50)
    v1 = s.obstacles.dynamic[0]
    assert (v1.vmax, v1.start_up_mode, v1.wait_time, v1.id) == (0.8, "wait_timer", 2.5, 3)
    assert v1.force_factor_social == (5.0, 8.0)


def test_waypoint_mode_2_is_loop_with_a_warning(tmp_path: Path) -> None:
    s = load_scenario(write(tmp_path, HOSPITAL_JSON))
    nurse = s.obstacles.dynamic[0]
    assert nurse.waypoint_mode == 2  # kept as written, so saving writes it back
    assert nurse.effective_waypoint_mode == WAYPOINT_LOOP
    assert len(s.warnings) == 1
    assert s.warnings[0].startswith("obstacles.dynamic[0].waypoint_mode")
    assert "treated as 0 (loop)" in s.warnings[0]


def test_missing_keys_default_like_arena() -> None:
    s = parse_scenario(
        json.dumps(
            {
                "robots": [{"start": [1, 2], "goal": [3, 4, 0]}],
                "obstacles": {"dynamic": [{"name": "a", "type": "adult", "pos": [1.0, 1.0]}]},
            }
        )
    )
    assert s.obstacles.static == () and s.obstacles.interactive == ()
    p = s.obstacles.dynamic[0]
    assert (p.model, p.waypoint_mode, p.waypoints) == ("actor1", 0, ())
    assert any("stands at its start" in w for w in s.warnings)
    assert parse_scenario("{}") == Scenario()


def test_static_extras_and_legacy_model_names_pass_through(tmp_path: Path) -> None:
    data = {
        "robots": [],
        "obstacles": {
            "static": [
                {
                    "name": "s",
                    "model": "shelf.yaml",
                    "pos": [1.0, 1.0, 0.0],
                    "type": "shelf",
                    "interaction_radius": 2.0,
                    "yaml_path": "x.yaml",
                    "colour": "red",
                }
            ]
        },
    }
    s = load_scenario(write(tmp_path, data))
    o = s.obstacles.static[0]
    assert (o.type, o.interaction_radius, o.extra) == ("shelf", 2.0, {"colour": "red"})
    assert any("legacy name 'shelf.yaml' read as 'shelf'" in w for w in s.warnings)
    assert any("extra keys kept but not used: colour" in w for w in s.warnings)
    save_scenario(s, tmp_path / "out.json")
    assert json.loads((tmp_path / "out.json").read_text()) == data


def test_pedestrian_without_name_gets_a_generated_unique_one(tmp_path: Path) -> None:
    # As in an Arena 2023 file (old/Eval_13_02.json): dynamic obstacles with no name.
    data = {
        "robots": [{"start": [1.0, 1.0, 0.0], "goal": [5.0, 5.0, 0.0]}],
        "obstacles": {
            "dynamic": [
                {"type": "pedestrian", "pos": [2.0, 2.0, 0.0], "waypoints": [[3.0, 3.0, 0.0]]},
                {"name": "dynamic_2", "pos": [4.0, 4.0, 0.0]},
                {"pos": [6.0, 6.0, 0.0]},
            ]
        },
    }
    s = load_scenario(write(tmp_path, data))
    assert [p.name for p in s.obstacles.dynamic] == ["dynamic_0", "dynamic_2", "dynamic_2_2"]
    assert s.obstacles.dynamic[0].waypoints == ((3.0, 3.0, 0.0),)
    assert "obstacles.dynamic[0].name: missing, named 'dynamic_0' (as Arena does)" in s.warnings
    assert not any("dynamic[1].name" in w for w in s.warnings)


@pytest.mark.parametrize(
    ("patch", "keys", "first"),
    [
        (lambda d: d.update(format="arena-rosnav"), "format", "format"),
        (
            lambda d: d["obstacles"]["dynamic"][1].update(yaml_file="/home/x/person.model.yaml"),
            "yaml_file",
            "obstacles.dynamic[1].yaml_file",
        ),
        (
            lambda d: [p.update(number_of_peds=1) for p in d["obstacles"]["dynamic"]],
            "number_of_peds",
            "obstacles.dynamic[0].number_of_peds",
        ),
        (  # all three, as in arena-rosnav@working_dir's scenario1.json: still ONE warning
            lambda d: (
                d.update(format="x"),
                [p.update(yaml_file="p.yaml", number_of_peds=1) for p in d["obstacles"]["dynamic"]],
            ),
            "format, number_of_peds, yaml_file",
            "format",
        ),
    ],
)
def test_keys_arena_ignores_are_ignored_with_one_warning(
    tmp_path: Path, patch: Any, keys: str, first: str
) -> None:
    data = json.loads(json.dumps(DEFAULT_JSON))
    patch(data)
    path = write(tmp_path, data, "extra.json")
    with pytest.warns(UserWarning, match="keys Arena does not read") as record:
        s = load_scenario(path)
    assert len(record) == 1
    text = str(record[0].message)
    assert text.startswith(f"{path}: keys Arena does not read, ignored: {keys} (")
    assert f"first {first})" in text
    assert s.warnings[0] == text.removeprefix(f"{path}: ")
    # Everything Arena reads is read as without the extra keys.
    assert s == parse_scenario(json.dumps(DEFAULT_JSON))


def test_a_file_with_no_key_arena_reads_is_refused(tmp_path: Path) -> None:
    # Arena's pre-2023 format (evaluation_floor/scenarios/obs10.json): Arena 3 reads nothing.
    legacy = {"pedsim_agents": [], "robot_position": [1, 2], "robot_goal": [3, 4], "format": "x"}
    with pytest.raises(ConfigError, match=r"legacy\.json: none of the keys Arena reads "
                       r"\(robots, obstacles\) is present, only format, pedsim_agents"):
        load_scenario(write(tmp_path, legacy, "legacy.json"))


# -- errors -------------------------------------------------------------------------------------
def test_malformed_json_names_file_line_and_column(tmp_path: Path) -> None:
    path = write(tmp_path, '{\n  "robots": [\n    {"start": [1, 2, 3],,}\n  ]\n}', "bad.json")
    with pytest.raises(ConfigError) as e:
        load_scenario(path)
    msg = str(e.value)
    assert msg.startswith(f"{path}: malformed JSON at line 3, column")


def test_wrong_type_names_file_and_entry(tmp_path: Path) -> None:
    data = json.loads(json.dumps(DEFAULT_JSON))
    data["obstacles"]["dynamic"][2]["waypoints"] = "not a list"
    path = write(tmp_path, data)
    with pytest.raises(ConfigError, match=r"scenario\.json: obstacles\.dynamic\[2\]\.waypoints: "):
        load_scenario(path)


@pytest.mark.parametrize(
    ("patch", "where"),
    [
        (lambda d: d["robots"][0].update(start=["1", 2, 0]), r"robots\[0\]\.start\[0\]"),
        (lambda d: d["obstacles"]["dynamic"][0].update(vmax="fast"), r"dynamic\[0\]\.vmax"),
        (
            lambda d: d["obstacles"]["dynamic"][1].update(waypoint_mode=3),
            r"dynamic\[1\]\.waypoint_mode",
        ),
        (lambda d: d["obstacles"]["dynamic"][1].update(vamx=1.0), r"dynamic\[1\]\.vamx: unknown"),
        (
            lambda d: d["obstacles"]["dynamic"][0]["waypoints"].append([1.0]),
            r"dynamic\[0\]\.waypoints\[2\]",
        ),
        (lambda d: d.update(resets=True), r"resets"),
        (lambda d: d.update(robot=[]), r"robot: unknown key"),
        (lambda d: d["obstacles"]["static"][0].pop("model"), r"static\[0\]\.model: required"),
    ],
)
def test_bad_values_name_the_entry(tmp_path: Path, patch: Any, where: str) -> None:
    data = json.loads(json.dumps(DEFAULT_JSON))
    patch(data)
    with pytest.raises(ConfigError, match=rf"scenario\.json: (obstacles\.)?{where}"):
        load_scenario(write(tmp_path, data))


def test_unknown_static_model_suggests_a_name(tmp_path: Path) -> None:
    data = json.loads(json.dumps(DEFAULT_JSON))
    data["obstacles"]["static"][2]["model"] = "shelff"
    with pytest.raises(ConfigError) as e:
        load_scenario(write(tmp_path, data))
    msg = str(e.value)
    assert "scenario.json: obstacles.static[2].model: unknown obstacle model 'shelff'" in msg
    assert "did you mean 'shelf'" in msg


def test_waypoint_outside_the_map(tmp_path: Path, grid: OccupancyGrid) -> None:
    data = json.loads(json.dumps(DEFAULT_JSON))
    data["obstacles"]["dynamic"][1]["waypoints"][1] = [40.0, 2.0, 0.0]
    s = load_scenario(write(tmp_path, data))
    with pytest.raises(ConfigError) as e:
        validate_against_map(s, grid, source="scenario.json")
    assert str(e.value).startswith(
        "scenario.json: obstacles.dynamic[1].waypoints[1]: (40, 2) lies outside the map"
    )


def test_robot_start_inside_a_wall(grid: OccupancyGrid) -> None:
    data = json.loads(json.dumps(DEFAULT_JSON))
    data["robots"][0]["start"] = [21.0, 2.0, 0.0]
    s = parse_scenario(json.dumps(data))
    with pytest.raises(ConfigError, match=r"^s\.json: robots\[0\]\.start: .* inside a wall"):
        validate_against_map(s, grid, source="s.json")


@pytest.mark.parametrize("key", ["start", "goal"])
def test_robot_in_unknown_space_is_refused(grid: OccupancyGrid, key: str) -> None:
    # Like ignc's default.json: a start outside the building, where the map is unknown (-1).
    data = grid.data.copy()
    data[100:150, 0:50] = -1  # x 0-5 m, y 10-15 m unknown
    g = OccupancyGrid(data, grid.resolution, grid.origin)
    sc = json.loads(json.dumps(DEFAULT_JSON))
    sc["robots"][0][key] = [2.5, 12.5, 0.0]
    sc["obstacles"]["dynamic"][0]["waypoints"][0] = [2.0, 12.0, 0.0]  # people may walk there
    with pytest.raises(ConfigError) as e:
        validate_against_map(parse_scenario(json.dumps(sc)), g, source="s.json")
    msg = str(e.value)
    assert msg == (
        f"s.json: robots[0].{key}: (2.5, 12.5) lies in unknown space of the map (cell -1, "
        "outside the mapped area); a robot needs a known free start and goal"
    )
    assert validate_against_map(parse_scenario(json.dumps(DEFAULT_JSON)), g) == []


def test_valid_scenario_passes_the_map_check(grid: OccupancyGrid) -> None:
    for data in (DEFAULT_JSON, CORRIDOR_JSON, HOSPITAL_JSON):
        assert validate_against_map(parse_scenario(json.dumps(data)), grid) == []


def test_validate_file_returns_findings(tmp_path: Path) -> None:
    assert validate_file(write(tmp_path, DEFAULT_JSON, "a.json"), None) == []
    findings = validate_file(write(tmp_path, HOSPITAL_JSON, "h.json"), None)
    assert len(findings) == 1 and findings[0].startswith(f"{tmp_path / 'h.json'}: obstacles.")


def test_validate_file_with_a_map_yaml(tmp_path: Path) -> None:
    # A 10 m × 10 m free map (0.5 m cells) in ROS map_server format, written as a PGM.
    (tmp_path / "map.pgm").write_bytes(b"P5\n20 20\n255\n" + bytes([254]) * 400)
    (tmp_path / "map.yaml").write_text(
        "image: map.pgm\nresolution: 0.5\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    path = write(tmp_path, DEFAULT_JSON)
    with pytest.raises(ConfigError, match=r"robots\[0\]\.start: \(24, 20\) lies outside the map"):
        validate_file(path, str(tmp_path / "map.yaml"))


def test_validate_file_refuses_a_start_in_unknown_space_of_a_map_yaml(tmp_path: Path) -> None:
    # 10 m × 10 m at 0.5 m: the left half unknown (PGM 205, ROS map_server's "unknown" grey).
    row = bytes([205]) * 10 + bytes([254]) * 10
    (tmp_path / "map.pgm").write_bytes(b"P5\n20 20\n255\n" + row * 20)
    (tmp_path / "map.yaml").write_text(
        "image: map.pgm\nresolution: 0.5\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    inside = {"robots": [{"start": [6.0, 5.0, 0.0], "goal": [9.0, 5.0, 0.0]}]}
    assert validate_file(write(tmp_path, inside, "in.json"), str(tmp_path / "map.yaml")) == []
    outside = {"robots": [{"start": [2.0, 5.0, 0.0], "goal": [9.0, 5.0, 0.0]}]}
    with pytest.raises(ConfigError, match=r"out\.json: robots\[0\]\.start: \(2, 5\) lies in "
                       r"unknown space"):
        validate_file(write(tmp_path, outside, "out.json"), str(tmp_path / "map.yaml"))


# -- episode ------------------------------------------------------------------------------------
def test_default_episode_values(grid: OccupancyGrid) -> None:
    jackal = load_robot("jackal")
    s = parse_scenario(json.dumps(DEFAULT_JSON))
    ep = scenario_episode(s, grid, [jackal], index=4, seed=9, time_limit=120.0, goal_radius=0.5)
    assert (ep.index, ep.seed, ep.time_limit, ep.goal_radius) == (4, 9, 120.0, 0.5)
    assert ep.map_name == "scenario"
    (r,) = ep.robots
    assert r.model is jackal and r.name == "jackal"
    assert (r.start.x, r.start.y, r.start.theta) == (24.0, 20.0, 0.7)
    assert (r.goal.x, r.goal.y, r.goal.theta) == (2.0, 2.0, 0.0)
    assert [o.name for o in ep.obstacles] == ["shelf1", "shelf2", "shelf3"]
    assert [o.model for o in ep.obstacles] == ["shelf"] * 3
    np.testing.assert_array_equal(ep.obstacles[0].pose, [13.0, 11.0, -0.5])
    a = ep.agents
    assert len(a) == 3
    np.testing.assert_array_equal(a.positions, [[14, 2], [2, 8], [8, 2]])
    np.testing.assert_array_equal(a.waypoints[0], [[2, 14], [14, 2]])
    np.testing.assert_array_equal(a.num_waypoints, [2, 2, 2])
    np.testing.assert_array_equal(a.waypoint_mode, [WAYPOINT_RANDOM] * 3)
    np.testing.assert_array_equal(a.radii, [DEFAULT_PED_RADIUS] * 3)
    np.testing.assert_array_equal(a.vmax, [DEFAULT_VMAX] * 3)
    np.testing.assert_array_equal(a.kinds, [0, 0, 0])
    assert a.startup_mode is None and a.wait_time is None and a.trigger_radius is None


def test_hospital_episode_pads_waypoints_and_maps_mode_2(grid: OccupancyGrid) -> None:
    s = parse_scenario(json.dumps(HOSPITAL_JSON))
    ep = scenario_episode(s, grid, [load_robot("jackal")], time_limit=60.0)
    a = ep.agents
    assert ep.map_name == "arena_hospital_small"
    assert a.waypoints.shape == (2, 5, 2)
    np.testing.assert_array_equal(a.num_waypoints, [5, 2])
    assert np.isnan(a.waypoints[1, 2:]).all() and not np.isnan(a.waypoints[1, :2]).any()
    np.testing.assert_array_equal(a.waypoint_mode, [WAYPOINT_LOOP, WAYPOINT_LOOP])
    np.testing.assert_array_equal(a.kinds, [0, 1])  # "human/elder" → elder


def test_corridor_episode_overrides(grid: OccupancyGrid) -> None:
    s = parse_scenario(json.dumps(CORRIDOR_JSON))
    robot = load_robot("jackal")
    ep = scenario_episode(s, grid, [robot], seed=3, time_limit=60.0)
    a = ep.agents
    assert a.vmax[0] == 0.8 and a.vmax[2] == DEFAULT_VMAX
    assert 0.4 <= a.vmax[1] <= 0.6  # [lo, hi] drawn from the episode seed
    again = scenario_episode(s, grid, [robot], seed=3, time_limit=60.0)
    assert again.agents.vmax[1] == a.vmax[1]
    np.testing.assert_array_equal(a.kinds, [0, 2, 0])
    assert a.startup_mode is not None and a.wait_time is not None and a.trigger_radius is not None
    np.testing.assert_array_equal(a.startup_mode, [1, 2, 0])
    np.testing.assert_array_equal(a.wait_time, [2.5, 0.0, 0.0])
    np.testing.assert_array_equal(a.trigger_radius, [0.0, 3.0, 0.0])


def test_pedestrian_without_waypoints_stays_at_start(grid: OccupancyGrid) -> None:
    s = parse_scenario(
        json.dumps(
            {
                "robots": [{"start": [1, 1, 0], "goal": [2, 2, 0]}],
                "obstacles": {
                    "dynamic": [{"name": "p", "pos": [3.0, 4.0], "type": "adult", "waypoints": []}]
                },
            }
        )
    )
    a = scenario_episode(s, grid, [load_robot("jackal")], time_limit=10.0).agents
    np.testing.assert_array_equal(a.waypoints[0], [[3.0, 4.0]])
    assert a.num_waypoints.tolist() == [1]


def test_robot_count(grid: OccupancyGrid) -> None:
    jackal = load_robot("jackal")
    two = dict(
        DEFAULT_JSON,
        robots=[*DEFAULT_JSON["robots"], {"start": [5.0, 5.0, 0.0], "goal": [6.0, 6.0, 0.0]}],
    )
    s = parse_scenario(json.dumps(two))
    assert len(scenario_episode(s, grid, [jackal], time_limit=1.0).robots) == 1  # extra dropped
    eps = scenario_episode(s, grid, [jackal, jackal], time_limit=1.0)
    assert [r.name for r in eps.robots] == ["robot0", "robot1"]
    one = parse_scenario(json.dumps(DEFAULT_JSON))
    with pytest.raises(ConfigError, match=r"robots: the scenario has 1 robot\(s\) but 2"):
        scenario_episode(one, grid, [jackal, jackal], time_limit=1.0)


def test_duplicate_obstacle_names_are_made_unique(grid: OccupancyGrid) -> None:
    data = json.loads(json.dumps(DEFAULT_JSON))
    for o in data["obstacles"]["static"]:
        o["name"] = "3"
    ep = scenario_episode(
        parse_scenario(json.dumps(data)), grid, [load_robot("jackal")], time_limit=1.0
    )
    assert [o.name for o in ep.obstacles] == ["3", "3_2", "3_3"]


def test_model_not_in_library_at_conversion_lists_known_models(grid: OccupancyGrid) -> None:
    # Built in code (not loaded), so the load-time check did not run.
    s = Scenario.model_validate(
        {"obstacles": {"interactive": [{"name": "x", "model": "forklift", "pos": [1, 1, 0]}]}}
    )
    with pytest.raises(ConfigError) as e:
        scenario_episode(s, grid, [], time_limit=1.0)
    msg = str(e.value)
    assert msg.startswith("obstacles.interactive[0].model: unknown obstacle model 'forklift'")
    assert "known: " in msg and "shelf" in msg


def test_people_with_overlapping_bodies_load_with_a_warning_one_spot_is_refused():
    """Arena's worlds place people 0.5 m apart (bodies of 0.3 m overlap): they load, with a
    warning; two people within 1 cm of each other are one spot and refused."""
    def scenario(second_x: float) -> str:
        return json.dumps({
            "robots": [{"start": [1.0, 1.0, 0.0], "goal": [8.0, 1.0, 0.0]}],
            "obstacles": {"static": [], "interactive": [], "dynamic": [
                {"name": "a", "pos": [5.0, 5.0, 0.0], "waypoints": [[6.0, 5.0, 0.0]]},
                {"name": "b", "pos": [second_x, 5.0, 0.0], "waypoints": [[6.0, 6.0, 0.0]]},
            ]},
        })

    with pytest.warns(UserWarning, match=r"close\.json: obstacles\.dynamic\[1\] starts 0\.5 m "
                                          r"from obstacles\.dynamic\[0\]: 1 pair"):
        sc = parse_scenario(scenario(5.5), source="close.json")
    assert [p.pos[0] for p in sc.obstacles.dynamic] == [5.0, 5.5]
    with pytest.raises(ConfigError, match=r"dynamic\[1\]\.pos.*two people on one spot"):
        parse_scenario(scenario(5.005), source="same.json")
