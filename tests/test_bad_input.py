"""Regression corpus of malformed input: every case is one clean line, never a traceback.

Each case runs the real ``arena`` entry point (``arena.cli.main``, in-process) from an empty
working folder and asserts: exit status 2, exactly one line on stderr starting with ``error:``,
the file (or override) and the field named, no traceback, and nothing written (no ``runs/``).
Cases that once ran on (the YAML alias bomb, 100,000 nested brackets) are refused by the
structure of the input, so this file needs no timeouts: a regression would hang it visibly.
"""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

import numpy as np
import pytest

from arena import cli

BOMB = "a: &a [x, x, x, x, x, x, x, x, x]\n" + "".join(
    f"{chr(98 + i)}: &{chr(98 + i)} [{', '.join(['*' + chr(97 + i)] * 9)}]\n" for i in range(9)
)
"""The "billion laughs" YAML: 10 lines that expand to 9**10 (3.5 billion) strings."""

BURGER = (Path(cli.__file__).parent / "robots" / "presets" / "burger.yaml").read_text()
# the burger with its laser written as named sensors, and a second lidar block to add to it
BURGER_SENSORS = re.sub(
    r"^laser:\n((?:  .*\n)+)",
    lambda m: "sensors:\n  laser:\n    type: lidar2d\n" + m.group(1).replace("  ", "    "),
    BURGER, count=1, flags=re.MULTILINE,
)


def with_rear(block: str) -> str:
    """The burger in the sensors layout with ``block`` added under ``sensors``."""
    return BURGER_SENSORS.replace("  laser:\n", block + "  laser:\n", 1)


REAR = "  rear: {type: lidar2d, angle_min: -0.5, angle_max: 0.5, num_beams: 9, range_max: 5}\n"

SCENARIO = {
    "robots": [{"start": [2.0, 2.0, 0.0], "goal": [8.0, 8.0, 0.0]}],
    "obstacles": {
        "static": [],
        "interactive": [],
        "dynamic": [{"name": "p0", "pos": [5.0, 2.0, 0.0], "waypoints": [[5.0, 8.0, 0.0]]}],
    },
}


def _scenario(**change) -> str:
    data = json.loads(json.dumps(SCENARIO))
    for key, value in change.items():
        if key == "ped":
            data["obstacles"]["dynamic"][0].update(value)
        elif key == "peds":
            data["obstacles"]["dynamic"] = value
        elif key == "static":
            data["obstacles"]["static"] = value
        else:
            data["robots"][0][key] = value
    return json.dumps(data)


MAP_YAML = "image: map.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n" \
    "occupied_thresh: 0.65\nfree_thresh: 0.196\n"

SUITE_OK = "stages:\n  - {name: s1, episodes: 1, map: {type: empty}}\n"

# name -> text or bytes; the corpus folder holds them all.
FILES: dict[str, str | bytes] = {
    # experiment configs
    "dup.yaml": "seed: 1\nrobot: burger\nseed: 2\n",
    "bomb.yaml": BOMB,
    # the shape that ran on: the bomb where a string is expected, so that the error message
    # would print the expanded value
    "bomb_name.yaml": "name: [" + ", ".join(
        ["&a0 [x, x, x, x, x, x, x, x, x]"]
        + [f"&a{i} [{', '.join([f'*a{i - 1}'] * 9)}]" for i in range(1, 9)]) + "]\n",
    "deep.yaml": "name: " + "[" * 200 + "]" * 200 + "\n",
    "open_brackets.yaml": "[" * 100_000,
    "binary.yaml": bytes(range(256)) * 4,
    "utf16.yaml": "seed: 1\n".encode("utf-16"),
    "nul.yaml": b"seed: 1\x00\n",
    "list.yaml": "- 1\n- 2\n",
    "cycle.yaml": "task: &a {modules: [*a]}\n",
    "unhashable.yaml": "? [1, 2]\n: 3\n",
    "seed_true.yaml": "seed: true\n",
    "seed_str.yaml": "seed: '3'\n",
    "unknown.yaml": "robt: burger\n",
    "malformed.yaml": "seed: 1\n  robot: x\n",
    "name_dotdot.yaml": "name: ../../escape\n",
    "nested_dup.yaml": "task:\n  timeout: 5\n  timeout: 6\n",
    "goal_inf.yaml": "task: {goal_radius: .inf}\n",
    # scenario files
    "vmax_reversed.json": _scenario(ped={"vmax": [2.0, 1.0]}),
    "vmax_negative.json": _scenario(ped={"vmax": -1}),
    "vmax_huge.json": _scenario(ped={"vmax": 1e6}),
    "vmax_range_huge.json": _scenario(ped={"vmax": [0.5, 1e6]}),
    "probability.json": _scenario(ped={"chatting_probability": 2}),
    "wait_negative.json": _scenario(ped={"wait_time": -1}),
    "force_negative.json": _scenario(ped={"force_factor_social": [-1, 2]}),
    "same_spot.json": _scenario(peds=[
        {"name": "a", "pos": [5.0, 2.0, 0.0]}, {"name": "b", "pos": [5.0, 2.0, 0.0]}]),
    "start_goal.json": _scenario(goal=[2.0, 2.0, 0.0]),
    "wall.json": _scenario(start=[0.2, 5.0, 0.0]),
    "shelf.json": _scenario(start=[5.35, 5.0, 0.0],
                            static=[{"name": "s", "model": "shelf", "pos": [5.0, 5.0, 0.0]}]),
    "shelf_goal.json": _scenario(goal=[5.0, 5.3, 0.0],
                                 static=[{"name": "s", "model": "shelf", "pos": [5.0, 5.0, 0.0]}]),
    "nan.json": _scenario(start=[float("nan"), 2.0, 0.0]),
    "crowd.json": _scenario(peds=[{"name": f"p{i}", "pos": [i % 100, i // 100, 0]}
                                  for i in range(10_001)]),
    "pos4.json": _scenario(start=[1.0, 2.0, 0.0, 4.0]),
    "waypoint_mode.json": _scenario(ped={"waypoint_mode": 3}),
    "dup_keys.json": '{"robots": [], "robots": []}',
    "deep.json": '{"map": ' + "[" * 5000 + "]" * 5000 + "}",
    "deep_short.json": '{"map": ' + "[" * 80 + "]" * 80 + "}",
    "binary.json": bytes(range(256)) * 4,
    "utf16.json": json.dumps(SCENARIO).encode("utf-16"),
    "malformed.json": '{"robots": [}',
    "toplevel.json": "[1, 2]",
    "unknown.json": '{"robot": []}',
    # Arena ignores unknown keys (we warn), but one this close to a known key is a typo.
    "typo.json": _scenario(ped={"vamx": 1.0}),
    "legacy.json": '{"pedsim_agents": [], "robot_position": [1, 2], "format": "x"}',
    "bad_model.json": _scenario(static=[{"name": "s", "model": "shelv", "pos": [1, 1, 0]}]),
    # robot files
    "robot_dup.yaml": BURGER + "radius: 0.2\n",
    "robot_binary.yaml": b"\x89PNG\r\n\x1a\n" + bytes(100),
    "robot_utf16.yaml": BURGER.encode("utf-16"),
    "robot_bomb.yaml": BURGER + BOMB.replace("a:", "zz_a:", 1),
    "robot_radius.yaml": BURGER.replace("radius: 0.113", "radius: -0.1"),
    "robot_unknown.yaml": BURGER + "wheels: 4\n",
    "robot_beams.yaml": BURGER.replace("num_beams: 360", "num_beams: 1000000000"),
    "robot_range.yaml": BURGER.replace("range_max: 3.5", "range_max: .inf"),
    "robot_sensor_type.yaml": BURGER_SENSORS.replace("type: lidar2d", "type: lidar4d"),
    "robot_sensor_field.yaml": with_rear(REAR.replace("num_beams", "num_beam")),
    "robot_sensor_both.yaml": BURGER + "sensors: {}\n",
    "robot_sensor_name.yaml": with_rear(REAR.replace("  rear:", "  rear-left:")),
    # maps (map.pgm is written by the fixture)
    "map_origin.yaml": MAP_YAML.replace("[0.0, 0.0, 0.0]", "[1.0e20, 0.0, 0.0]"),
    "map_dup.yaml": MAP_YAML + "resolution: 0.1\n",
    "map_utf16.yaml": MAP_YAML.encode("utf-16"),
    "map_binary.yaml": bytes(range(256)),
    "map_resolution.yaml": MAP_YAML.replace("resolution: 0.05", "resolution: 0"),
    "map_origin2.yaml": MAP_YAML.replace("[0.0, 0.0, 0.0]", "[0.0, 0.0]"),
    "map_noimage.yaml": MAP_YAML.replace("map.pgm", "gone.pgm"),
    "map_huge.yaml": MAP_YAML.replace("map.pgm", "huge.pgm"),
    "map_bomb.yaml": MAP_YAML + BOMB.replace("a:", "type:", 1),
    # suites and contests
    "suite_ok.yaml": SUITE_OK,
    "suite_dup.yaml": SUITE_OK + "  - {name: s1, episodes: 2, map: {type: empty}}\n",
    "suite_name.yaml": "stages:\n  - {name: ../../x, episodes: 1}\n",
    "suite_slash.yaml": "stages:\n  - {name: a/b, episodes: 1}\n",
    "suite_long.yaml": "stages:\n  - {name: " + "s" * 300 + ", episodes: 1}\n",
    "suite_seed.yaml": "stages:\n  - {name: s1, episodes: 1, seed: true}\n",
    "suite_episodes.yaml": "stages:\n  - {name: s1, episodes: -1}\n",
    "suite_empty.yaml": "stages: []\n",
    "suite_many.yaml": "stages:\n  - {name: s1, episodes: 10000000}\n",
    "suite_inf.yaml": "stages:\n  - {name: s1, episodes: 1, task: {timeout: .inf}}\n",
    "suite_bomb.yaml": SUITE_OK + BOMB,
    "suite_binary.yaml": bytes(range(256)),
    "suite_dupkey.yaml": "stages: []\nstages:\n  - {name: s1, episodes: 1}\n",
    "contest_dup.yaml": "contestants:\n  - {name: x, local_planner: dwa}\n"
                        "  - {name: x, local_planner: teb}\n",
    "contest_name.yaml": "contestants:\n  - {name: ../../../../X, local_planner: dwa}\n",
    "contest_dot.yaml": "contestants:\n  - {name: .., local_planner: dwa}\n",
    "contest_empty.yaml": "contestants: []\n",
    "contest_planner.yaml": "contestants:\n  - {name: x, local_planner: dwaa}\n",
    # a text file where weights are expected
    "weights.txt": "not weights\n",
}


@pytest.fixture(scope="module")
def corpus(tmp_path_factory) -> Path:
    """A folder with every malformed file of :data:`FILES` (plus images and weight files)."""
    d = tmp_path_factory.mktemp("corpus")
    for name, content in FILES.items():
        (d / name).write_bytes(content if isinstance(content, bytes) else content.encode())
    (d / "map.pgm").write_bytes(b"P5 20 20 255\n" + bytes([254]) * 400)
    (d / "huge.pgm").write_bytes(b"P5 8000 8000 255\n")  # header only: never decoded
    (d / "folder.yaml").mkdir()
    np.savez(d / "pickled.npz", w1=np.array([object()], dtype=object), b1=np.zeros(1),
             w2=np.zeros(1), b2=np.zeros(1))
    np.savez(d / "other.npz", a=np.zeros(3))
    np.save(d / "single.npy", np.zeros(3))
    np.savez(d / "shapes.npz", w1=np.zeros(3), b1=np.zeros(2), w2=np.zeros(2), b2=np.zeros(1))
    run = d / "tampered_run"  # a run folder whose row names a contestant ../../../../X
    (run / "episodes" / "X" / "s1").mkdir(parents=True)
    (run / "run.json").write_text(json.dumps({"suite": "quick", "contest": "basic", "seed": 0}))
    row = {**ROW, "contestant": "../../../../X", "record": ""}
    (run / "episodes" / "X" / "s1" / "0000.json").write_text(json.dumps(row))
    run2 = d / "tampered_record"
    (run2 / "episodes" / "X" / "s1").mkdir(parents=True)
    (run2 / "run.json").write_text("{}")
    row = {**ROW, "record": "../../../etc/passwd"}
    (run2 / "episodes" / "X" / "s1" / "0000.json").write_text(json.dumps(row))
    run3 = d / "corrupt_record"  # a row whose parquet record is garbage
    (run3 / "episodes" / "X" / "s1").mkdir(parents=True)
    (run3 / "run.json").write_text("{}")
    row = {**ROW, "record": "episodes/X/s1/0000.parquet"}
    (run3 / "episodes" / "X" / "s1" / "0000.json").write_text(json.dumps(row))
    (run3 / "episodes" / "X" / "s1" / "0000.parquet").write_text("garbage")
    return d


# A well-formed stored episode row (as commit_episode writes it) of contestant X, stage s1.
ROW = {"contestant": "X", "local_planner": "dwa", "inter_planner": "", "stage": "s1",
       "episode": 0, "seed": 0, "map": "m", "robot": "jackal", "outcome": "success", "time": 1.0,
       "path_length": 1.0, "collisions": 0, "wall_time": 1.0, "error": "", "record": ""}
LONG = "x" * 300
EMPTY_MAP = ["map.type=empty", "map.width=10", "map.height=10"]
Q = "task.obstacles.dynamic=0"  # fewer people: the cases that reach the first draw stay quick

# (id, arguments ({d} is the corpus folder), fragments the error line must contain)
CASES: list[tuple[str, list[str], list[str]]] = [
    # -- overrides: seeds, counts, names
    ("seed_true", ["run", "seed=true"], ["override 'seed=true'", "seed", "valid integer"]),
    # -- ROS bridges: refused before any ROS traffic
    ("ros2_mode", ["ros2", "run", "--mode", "fast"], ["--mode", "realtime or lockstep"]),
    ("ros1_mode", ["ros1", "run", "--mode", "fast"], ["--mode", "realtime or lockstep"]),
    ("ros2_namespace", ["ros2", "run", "--namespace", "robot 1"],
     ["--namespace", "'robot 1'", "not a ROS namespace"]),
    ("ros2_remap_form", ["ros2", "run", "--remap", "/scan"], ["--remap", "FROM:=TO"]),
    ("ros2_remap_name", ["ros2", "run", "--remap", "/scan:=front scan"],
     ["--remap", "'front scan'", "not an absolute ROS name"]),
    ("ros2_planner_key", ["run", 'navigation.local_planner={"type": "ros2", "tmeout": 3}'],
     ["navigation.local_planner.tmeout", "unknown key"]),
    ("ros2_planner_remap", ["run", 'navigation.local_planner={"type": "ros2", '
                                   '"remap": {"/scan": "x y"}}'],
     ["navigation.local_planner.remap", "'x y'", "not an absolute ROS name"]),
    ("seed_negative", ["run", "seed=-1"],
     ["override 'seed=-1'", "seed", "greater than or equal to 0"]),
    ("seed_float", ["run", "seed=1.5"], ["override 'seed=1.5'", "seed"]),
    ("seed_huge", ["run", "seed=99999999999999999999999"], ["seed", "9223372036854775807"]),
    ("seed_string", ["run", "seed='3'"], ["seed", "valid integer"]),
    ("seed_list", ["run", "seed=[1]"], ["seed", "valid integer"]),
    ("episodes_true", ["run", "episodes=true"], ["override 'episodes=true'", "episodes"]),
    ("episodes_zero", ["run", "episodes=0"], ["episodes", "greater than or equal to 1"]),
    ("episodes_word", ["run", "episodes=many"], ["episodes", "valid integer"]),
    ("name_dotdot", ["run", "name=../../x"], ["override 'name=../../x'", "name:", "'..'"]),
    ("name_long", ["run", f"name={LONG}"], ["name:", "longer than 100 characters"]),
    ("name_hidden", ["run", "name=.hidden"], ["name:", "cannot be a file name"]),
    ("name_space", ["run", "name=a b"], ["name:", "cannot be a file name"]),
    ("name_empty", ["run", "name="], ["name:", "is empty"]),
    ("name_list", ["run", "name=[1]"], ["name:", "valid string"]),
    ("name_backslash", ["run", "name=a\\b"], ["name:", "cannot be a file name"]),
    ("name_in_file", ["run", "{d}/name_dotdot.yaml"], ["name_dotdot.yaml", "name:", "'..'"]),
    # -- overrides: maps
    ("map_width_inf", ["run", "map.type=empty", "map.width=.inf"],
     ["override 'map.width=.inf'", "map", "finite"]),
    ("map_width_nan", ["run", "map.type=empty", "map.width=.nan"], ["map.width"]),
    ("map_width_huge", ["run", "map.type=empty", "map.width=1e9"],
     ["override 'map.width=1e9'", "map", "50,000,000 cells", "GiB"]),
    ("map_resolution_100", ["run", "map.type=empty", "map.resolution=100"],
     ["override 'map.resolution=100'", "map", "at least 3"]),
    ("map_resolution_zero", ["run", "map.type=empty", "map.resolution=0"],
     ["map.resolution", "greater than 0"]),
    ("map_width_negative", ["run", "map.type=empty", "map.width=-1"], ["map.width"]),
    ("barn_huge", ["run", "map.type=barn", "map.width=1e6", "map.height=1e6"],
     ["map", "cells"]),
    ("canteen_inf", ["run", "map.type=canteen", "map.width=.inf"], ["map", "finite"]),
    ("map_type", ["run", "map.type=emtpy"], ["map.type", "did you mean 'empty'"]),
    ("world_missing", ["run", "map.name=nowhere"],
     ["override 'map.name=nowhere'", "map.name", "no world 'nowhere'"]),
    # -- overrides: people and task
    ("agent_speed_fast", ["run", "task.obstacles.agent_speed=[1000,2000]"],
     ["override 'task.obstacles.agent_speed=[1000,2000]'", "agent_speed", "<= 3"]),
    ("agent_speed_reversed", ["run", "task.obstacles.agent_speed=[2,1]"],
     ["agent_speed", "min <= max"]),
    ("agent_speed_negative", ["run", "task.obstacles.agent_speed=[-1,1]"], ["agent_speed"]),
    ("agent_speed_one", ["run", "task.obstacles.agent_speed=[1]"],
     ["override 'task.obstacles.agent_speed=[1]'", "agent_speed[1]"]),
    ("timeout_zero", ["run", "task.timeout=0"], ["task.timeout", "greater than 0"]),
    ("timeout_inf", ["run", "task.timeout=.inf"],
     ["override 'task.timeout=.inf'", "task.timeout", "must be a finite number"]),
    ("planner_speed_inf", ["run", "navigation.local_planner.max_speed=.inf"],
     ["navigation.local_planner.max_speed", "finite"]),
    ("config_goal_radius_inf", ["run", "{d}/goal_inf.yaml"],
     ["goal_inf.yaml", "task.goal_radius", "finite"]),
    ("suite_timeout_inf", ["tasks", "preview", "{d}/suite_inf.yaml"],
     ["suite_inf.yaml", "stages[0]", "task.timeout", "finite"]),
    ("people_100000", ["run", "task.obstacles.dynamic=100000"],
     ["task.obstacles.dynamic.min", "less than or equal to 10000"]),
    ("people_1e12", ["run", "task.obstacles.dynamic=[0, 1000000000000]"],
     ["task.obstacles.dynamic.max", "less than or equal to 10000"]),
    ("goal_radius", ["run", "task.goal_radius=-1"], ["task.goal_radius"]),
    ("dt_zero", ["run", "sim.dt=0"], ["sim.dt"]),
    ("dt_large", ["run", "sim.dt=5"], ["sim.dt"]),
    ("count_reversed", ["run", "task.obstacles.static={min: 5, max: 1}"],
     ["task.obstacles", "must not exceed"]),
    ("robot_typo", ["run", "robot=burgr"], ["robot", "did you mean 'burger'"]),
    ("robot_missing", ["run", "robot=/nonexistent/r.yaml"], ["r.yaml", "not found"]),
    ("crowd_type", ["run", "crowd.type=nope"], ["crowd.type"]),
    ("width_px", ["run", "output.width_px=10"], ["output.width_px"]),
    ("video_format", ["run", "output.video_format=avi"], ["output.video_format"]),
    ("forbidden_zone", ["run", "task.forbidden_zones=[{center: [0, 0]}]"],
     ["override 'task.forbidden_zones=", "task.forbidden_zones[0]"]),
    # -- overrides: syntax and structure
    ("override_no_key", ["run", "=3"], ["command line", "not a dotted key path"]),
    ("override_bad_key", ["run", "a..b=3"], ["command line", "not a dotted key path"]),
    ("override_unknown", ["run", "foo=1"], ["override 'foo=1'", "unknown key"]),
    ("override_value_not_block", ["run", "seed.x=1"], ["seed.x", "is a value, not a block"]),
    ("override_dup_key", ["run", "task={timeout: 1, timeout: 2}"],
     ["command line", "duplicate key 'timeout'"]),
    ("override_deep", ["run", "name=" + "[" * 100 + "]" * 100],
     ["command line", "nested deeper than 64"]),
    ("override_cycle", ["run", "task=&a {modules: [*a]}"], ["command line", "cycle"]),
    # -- command-line options (click would draw a multi-line box)
    ("option_type", ["run", "-n", "abc"], ["'--episodes' / '-n'", "valid integer",
                                           "(see arena run --help)"]),
    ("option_unknown", ["run", "--bogus"], ["No such option: --bogus"]),
    ("command_unknown", ["bogus"], ["No such command 'bogus'"]),
    ("argument_missing", ["report"], ["Missing argument 'run'"]),
    ("preview_seed", ["tasks", "preview", "quick", "--seed", "-1"],
     ["seed", "greater than or equal to 0"]),
    ("preview_seed_huge", ["tasks", "preview", "quick", "--seed", "99999999999999999999"],
     ["seed"]),
    # -- experiment config files
    ("config_dup_key", ["run", "{d}/dup.yaml"], ["dup.yaml", "line 3", "duplicate key 'seed'"]),
    ("config_nested_dup", ["run", "{d}/nested_dup.yaml"],
     ["nested_dup.yaml", "duplicate key 'timeout'"]),
    ("config_bomb", ["run", "{d}/bomb.yaml"], ["bomb.yaml", "more than 1,000,000 values"]),
    ("config_bomb_name", ["run", "{d}/bomb_name.yaml"],
     ["bomb_name.yaml", "more than 1,000,000 values"]),
    ("config_deep", ["run", "{d}/deep.yaml"], ["deep.yaml", "nested deeper than 64"]),
    ("config_open_brackets", ["run", "{d}/open_brackets.yaml"],
     ["open_brackets.yaml", "nested deeper than 64"]),
    ("config_binary", ["run", "{d}/binary.yaml"], ["binary.yaml", "not UTF-8 text"]),
    ("config_utf16", ["run", "{d}/utf16.yaml"], ["utf16.yaml", "UTF-16", "save it as UTF-8"]),
    ("config_nul", ["run", "{d}/nul.yaml"], ["nul.yaml", "NUL byte"]),
    ("config_list", ["run", "{d}/list.yaml"], ["list.yaml", "expected a mapping"]),
    ("config_cycle", ["run", "{d}/cycle.yaml"], ["cycle.yaml", "cycle"]),
    ("config_unhashable", ["run", "{d}/unhashable.yaml"], ["unhashable.yaml", "unhashable key"]),
    ("config_seed_true", ["run", "{d}/seed_true.yaml"], ["seed_true.yaml", "seed"]),
    ("config_seed_str", ["run", "{d}/seed_str.yaml"], ["seed_str.yaml", "seed"]),
    ("config_unknown", ["run", "{d}/unknown.yaml"], ["unknown.yaml", "robt", "unknown key"]),
    ("config_malformed", ["run", "{d}/malformed.yaml"], ["malformed.yaml", "line 2"]),
    ("config_folder", ["run", "{d}/folder.yaml"], ["folder.yaml", "found a folder"]),
    ("config_device", ["run", "/dev/null"], ["/dev/null", "device or pipe"]),
    ("config_missing", ["run", "{d}/nope.yaml"], ["nope.yaml", "not found"]),
    # -- scenario files, run
    *[(f"scenario_{name}", ["run", "--scenario", f"{{d}}/{name}.json", *EMPTY_MAP],
       [f"{name}.json", *want]) for name, want in [
        ("vmax_reversed", ["obstacles.dynamic[0].vmax", "[low, high]"]),
        ("vmax_negative", ["obstacles.dynamic[0].vmax", "must be >= 0, got -1"]),
        ("vmax_huge", ["obstacles.dynamic[0].vmax", "[0, 3] m/s", "got 1000000"]),
        ("vmax_range_huge", ["obstacles.dynamic[0].vmax", "[0, 3] m/s", "(0.5, 1000000.0)"]),
        ("probability", ["chatting_probability", "[0, 1]"]),
        ("wait_negative", ["obstacles.dynamic[0].wait_time"]),
        ("force_negative", ["force_factor_social", ">= 0"]),
        ("same_spot", ["obstacles.dynamic[1].pos", "two people on one spot"]),
        ("start_goal", ["robots[0].goal", "start == goal"]),
        ("wall", ["robots[0].start", "overlaps a wall"]),
        ("shelf", ["robots[0].start", "overlaps obstacle 's' (shelf)"]),
        ("shelf_goal", ["robots[0].goal", "overlaps obstacle 's' (shelf)"]),
        ("nan", ["robots[0].start"]),
        ("crowd", ["obstacles.dynamic", "at most 10000 items"]),
        ("pos4", ["robots[0].start"]),
        ("waypoint_mode", ["obstacles.dynamic[0].waypoint_mode"]),
        ("dup_keys", ["duplicate key 'robots'"]),
        ("deep", ["nested deeper than 64"]),
        ("deep_short", ["nested deeper than 64"]),
        ("binary", ["not UTF-8 text"]),
        ("utf16", ["UTF-16"]),
        ("malformed", ["malformed JSON at line 1"]),
        ("toplevel", ["valid dictionary"]),
        ("unknown", ["robot", "unknown key", "did you mean 'robots'"]),
        ("typo", ["obstacles.dynamic[0].vamx", "did you mean 'vmax'"]),
        ("legacy", ["none of the keys Arena reads (robots, obstacles)"]),
        ("bad_model", ["obstacles.static[0].model", "shelf"]),
    ]],
    ("scenario_missing", ["run", "--scenario", "{d}/nope.json"], ["--scenario", "nope.json"]),
    # -- scenario files, validate (it used to call vmax [2, 1] valid)
    *[(f"validate_{name}", ["scenario", "validate", f"{{d}}/{name}.json"],
       [f"{name}.json", want]) for name, want in [
        ("vmax_reversed", "obstacles.dynamic[0].vmax"),
        ("vmax_huge", "obstacles.dynamic[0].vmax"),
        ("same_spot", "two people on one spot"),
        ("start_goal", "start == goal"),
        ("utf16", "UTF-16"),
        ("deep", "nested deeper than 64"),
        ("dup_keys", "duplicate key"),
    ]],
    # -- robot files
    ("robot_dup", ["run", "robot={d}/robot_dup.yaml"],
     ["robot_dup.yaml", "duplicate key 'radius'"]),
    ("robot_binary", ["run", "robot={d}/robot_binary.yaml"], ["robot_binary.yaml", "UTF-8"]),
    ("robot_utf16", ["run", "robot={d}/robot_utf16.yaml"], ["robot_utf16.yaml", "UTF-16"]),
    ("robot_bomb", ["run", "robot={d}/robot_bomb.yaml"], ["robot_bomb.yaml", "1,000,000"]),
    ("robot_radius", ["run", "robot={d}/robot_radius.yaml"], ["robot_radius.yaml", "radius"]),
    ("robot_unknown", ["run", "robot={d}/robot_unknown.yaml"], ["robot_unknown.yaml", "wheels"]),
    ("robot_beams", ["run", "robot={d}/robot_beams.yaml"],
     ["robot_beams.yaml", "laser.num_beams", "10000"]),
    ("robot_range", ["run", "robot={d}/robot_range.yaml"],
     ["robot_range.yaml", "laser.range_max", "1000"]),
    ("robot_sensor_type", ["run", "robot={d}/robot_sensor_type.yaml"],
     ["robot_sensor_type.yaml", "sensors.laser.type", "lidar4d", "lidar2d"]),
    ("robot_sensor_both", ["run", "robot={d}/robot_sensor_both.yaml"],
     ["robot_sensor_both.yaml", "laser", "not both"]),
    ("robot_sensor_misspelt", ["run", "robot={d}/robot_sensor_field.yaml"],
     ["robot_sensor_field.yaml", "sensors.rear.num_beam"]),
    ("robot_sensor_name", ["run", "robot={d}/robot_sensor_name.yaml"],
     ["robot_sensor_name.yaml", "sensors.rear-left", "identifier"]),
    ("scan_sensor_unknown", ["run", "navigation.scan_sensor=rear", Q],
     ["navigation.scan_sensor", "no lidar2d sensor 'rear'", "laser"]),
    # -- maps
    ("map_origin", ["run", "--map", "{d}/map_origin.yaml"], ["map_origin.yaml", "origin", "1e+06"]),
    ("map_dup", ["run", "--map", "{d}/map_dup.yaml"], ["map_dup.yaml", "duplicate key"]),
    ("map_utf16", ["run", "--map", "{d}/map_utf16.yaml"], ["map_utf16.yaml", "UTF-16"]),
    ("map_binary", ["run", "--map", "{d}/map_binary.yaml"], ["map_binary.yaml", "UTF-8"]),
    ("map_resolution", ["run", "--map", "{d}/map_resolution.yaml"],
     ["map_resolution.yaml", "resolution"]),
    ("map_origin2", ["run", "--map", "{d}/map_origin2.yaml"], ["map_origin2.yaml", "origin"]),
    ("map_noimage", ["run", "--map", "{d}/map_noimage.yaml"], ["map_noimage.yaml", "gone.pgm"]),
    ("map_huge_image", ["run", "--map", "{d}/map_huge.yaml"],
     ["map_huge.yaml", "image", "8000 × 8000 pixels"]),
    ("map_bomb", ["run", "--map", "{d}/map_bomb.yaml"], ["map_bomb.yaml", "1,000,000"]),
    ("map_missing", ["run", "--map", "{d}/nope.yaml"], ["nope.yaml", "not found"]),
    # -- suites and contests
    ("suite_dup", ["tasks", "preview", "{d}/suite_dup.yaml"],
     ["suite_dup.yaml", "stages", "both named 's1'"]),
    ("suite_name", ["tasks", "preview", "{d}/suite_name.yaml"],
     ["suite_name.yaml", "stages[0].name", "cannot be a file name"]),
    ("suite_slash", ["tasks", "preview", "{d}/suite_slash.yaml"],
     ["suite_slash.yaml", "stages[0].name"]),
    ("suite_long", ["tasks", "preview", "{d}/suite_long.yaml"],
     ["suite_long.yaml", "stages[0].name", "longer than 100"]),
    ("suite_seed", ["tasks", "preview", "{d}/suite_seed.yaml"], ["suite_seed.yaml", "seed"]),
    ("suite_episodes", ["tasks", "preview", "{d}/suite_episodes.yaml"],
     ["suite_episodes.yaml", "stages[0].episodes"]),
    ("suite_empty", ["tasks", "preview", "{d}/suite_empty.yaml"], ["suite_empty.yaml", "stages"]),
    ("suite_bomb", ["tasks", "preview", "{d}/suite_bomb.yaml"], ["suite_bomb.yaml", "1,000,000"]),
    ("suite_binary", ["tasks", "preview", "{d}/suite_binary.yaml"], ["suite_binary.yaml", "UTF-8"]),
    ("suite_dupkey", ["tasks", "preview", "{d}/suite_dupkey.yaml"],
     ["suite_dupkey.yaml", "duplicate key 'stages'"]),
    ("contest_dup", ["tasks", "preview", "{d}/suite_ok.yaml", "--contest", "{d}/contest_dup.yaml"],
     ["contest_dup.yaml", "contestants", "both named 'x'"]),
    ("contest_name", ["tasks", "preview", "{d}/suite_ok.yaml", "--contest",
                      "{d}/contest_name.yaml"],
     ["contest_name.yaml", "contestants[0].name", "'../../../../X'"]),
    ("contest_dot", ["tasks", "preview", "{d}/suite_ok.yaml", "--contest", "{d}/contest_dot.yaml"],
     ["contest_dot.yaml", "contestants[0].name"]),
    ("contest_empty", ["tasks", "preview", "{d}/suite_ok.yaml", "--contest",
                       "{d}/contest_empty.yaml"], ["contest_empty.yaml", "contestants"]),
    ("contest_planner", ["tasks", "preview", "{d}/suite_ok.yaml", "--contest",
                         "{d}/contest_planner.yaml"],
     ["contest_planner.yaml", "contestants[0].local_planner"]),
    ("suite_missing", ["tasks", "preview", "nope_suite"], ["no suite 'nope_suite'"]),
    ("preview_scale_inf", ["tasks", "preview", "{d}/suite_ok.yaml", "--scale", "inf"],
     ["suite_ok.yaml", "scale_episodes must be a finite number > 0, got inf"]),
    ("preview_scale_huge", ["tasks", "preview", "{d}/suite_ok.yaml", "--scale", "1e300"],
     ["suite_ok.yaml", "a suite has at most 1,000,000"]),
    ("suite_episodes_huge", ["tasks", "preview", "{d}/suite_many.yaml"],
     ["suite_many.yaml", "stages[0].episodes", "less than or equal to 1000000"]),
    # -- run folders read by arena report
    ("report_contestant", ["report", "{d}/tampered_run", "--videos", "0"],
     ["0000.json", "contestant", "'../../../../X'"]),
    ("report_record", ["report", "{d}/tampered_record", "--videos", "0"],
     ["0000.json", "record", "not this episode's record"]),
    ("report_corrupt_record", ["report", "{d}/corrupt_record", "--videos", "1", "-o", "rep"],
     ["0000.parquet", "not a readable episode record"]),
    ("report_not_run", ["report", "{d}", "--videos", "0"], ["not a benchmark run folder"]),
    # -- crowd weights
    *[(f"weights_{name}", ["run", "crowd.type=deep_social_force", f"crowd.weights={{d}}/{name}"],
       [f"override 'crowd.weights={{d}}/{name}'", "crowd.weights", want])
      for name, want in [
        ("pickled.npz", "pickled Python objects"),
        ("other.npz", "lacks the arrays ['w1', 'b1', 'w2', 'b2']"),
        ("single.npy", "a single .npy array"),
        ("shapes.npz", "1-D of one length"),
        ("weights.txt", "not a zip archive"),
        ("nope.npz", "not found"),
    ]],
    # -- output folders
    ("output_dev_null", ["run", "output.dir=/dev/null", "output.video=false", Q],
     ["/dev/null", "output folder", "not a folder"]),
    ("output_file", ["run", "output.dir={d}/dup.yaml", "output.video=false", Q],
     ["dup.yaml", "not a folder"]),
    ("maps_generate_huge", ["maps", "generate", "barn", "width=1e9", "-o", "gen"],
     ["command line", "cells"]),
    ("maps_generate_dev_null", ["maps", "generate", "barn", "-o", "/dev/null"],
     ["/dev/null", "not a folder"]),
]


def run_cli(monkeypatch, capsys, *args: str) -> tuple[int, str, str]:
    """``arena ARGS`` in-process; returns (exit status, stdout, stderr)."""
    monkeypatch.setattr(sys, "argv", ["arena", *args])
    monkeypatch.delenv("ARENA_DEBUG", raising=False)
    code = 0
    try:
        cli.main()
    except SystemExit as e:
        code = int(e.code or 0)
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_the_corpus_is_large_and_names_are_unique():
    ids = [c[0] for c in CASES]
    assert len(ids) == len(set(ids))
    assert len(ids) >= 100


@pytest.mark.parametrize(("args", "fragments"), [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_malformed_input_gives_one_line_error(
    monkeypatch, capsys, tmp_path, corpus, args, fragments
):
    monkeypatch.chdir(tmp_path)  # default outputs (runs/ ...) would land here
    args = [a.replace("{d}", str(corpus)) for a in args]
    code, out, err = run_cli(monkeypatch, capsys, *args)
    lines = err.strip().splitlines()
    assert code == 2, (out, err)
    assert "Traceback" not in out + err
    assert len(lines) == 1, err
    assert lines[0].startswith("error: ")
    for frag in fragments:
        assert frag.replace("{d}", str(corpus)) in lines[0], lines[0]
    written = {p.name for p in tmp_path.iterdir()} - {"rep"}  # tables precede the videos
    assert not written, "a refused input wrote files"



# -- documented legal inputs next to the limits ------------------------------------------------
def test_limits_themselves_are_legal(tmp_path):
    from arena.config import load_config
    from arena.core.rng import MAX_SEED
    from arena.tasks.scenario import parse_scenario

    cfg = load_config(None, [f"seed={MAX_SEED}", "name=suite/stage-1.v2",
                             "task.obstacles.agent_speed=[0, 3]", "map.type=empty",
                             "map.width=350", "map.height=350", "map.resolution=0.05"])
    assert (cfg.seed, cfg.name) == (MAX_SEED, "suite/stage-1.v2")
    apart = _scenario(peds=[{"name": "a", "pos": [5.0, 2.0, 0.0], "vmax": [0.0, 3.0]},
                            {"name": "b", "pos": [5.6, 2.0, 0.0], "vmax": 3}])
    sc = parse_scenario(apart, source="ok.json")  # bodies touching, not overlapping
    assert [p.vmax for p in sc.obstacles.dynamic] == [(0.0, 3.0), 3.0]


def test_robot_body_clear_of_a_shelf_is_accepted(tmp_path):
    # jackal's footprint reaches 0.21 m ahead; the shelf's face is at x = 5.2
    scenario = tmp_path / "clear.json"
    scenario.write_text(_scenario(start=[5.45, 5.0, 0.0],
                                  static=[{"name": "s", "model": "shelf", "pos": [5.0, 5.0, 0.0]}]))
    from arena.config import load_config
    from arena.robots.presets import load_robot
    from arena.tasks.generator import TaskGenerator

    block = json.dumps({"type": "scenario", "file": str(scenario)})
    cfg = load_config(None, [*EMPTY_MAP, f"task.robots={block}", f"task.obstacles={block}"])
    ep = TaskGenerator.from_config(cfg, [load_robot(cfg.robot)]).episode(0)
    assert ep.robots[0].start.x == 5.45
