"""Arena's ROS 2 port stores suites, contests, benchmark configs and curricula as ROS 2
parameter files (``/**: ros__parameters: <the same document>``): they load as the ROS 1 files."""

from __future__ import annotations

from pathlib import Path

import pytest

from arena.core.errors import ConfigError
from arena.tasks.curriculum import load_curriculum
from arena.tasks.datafiles import read_arena_yaml
from arena.tasks.suite import load_benchmark, load_contest, load_suite

SUITE = """\
stages:
  - {name: a, episodes: 2, robot: jackal, map: empty_room, tm_robots: random,
     tm_obstacles: random, config: {RANDOM: {dynamic: {min: 1, max: 2}}}}
  - {name: b, episodes: 1, map: corridor, tm_robots: scenario, tm_obstacles: scenario}
"""
CONTEST = "contestants:\n  - {name: pp, local_planner: pure_pursuit, inter_planner: bypass}\n"
CURRICULUM = "- {static: 0, dynamic: 2}\n- {static: 3, dynamic: 4, goal_radius: 0.5}\n"


def _wrap(text: str, node: str = "/**") -> str:
    body = "".join(f"    {line}\n" for line in text.splitlines())
    return f"{node}:\n  ros__parameters:\n{body}"


def _pair(tmp_path: Path, name: str, text: str, node: str = "/**") -> tuple[Path, Path]:
    (tmp_path / "ros1").mkdir(exist_ok=True)
    (tmp_path / "ros2").mkdir(exist_ok=True)
    plain, wrapped = tmp_path / "ros1" / name, tmp_path / "ros2" / name
    plain.write_text(text)
    wrapped.write_text(_wrap(text, node))
    return plain, wrapped


@pytest.mark.parametrize("node", ["/**", "task_generator_node"])
def test_suite_contest_and_curriculum_load_as_the_ros1_files(tmp_path: Path, node: str) -> None:
    plain, wrapped = _pair(tmp_path, "s.yaml", SUITE, node)
    a, b = load_suite(plain), load_suite(wrapped)
    assert a.stages == b.stages and a.seeds == b.seeds  # seeds: Arena's SHA-1 of each stage
    assert [st.name for st in b.stages] == ["a", "b"] and b.total_episodes == 3
    plain, wrapped = _pair(tmp_path, "c.yaml", CONTEST, node)
    assert load_contest(plain)[0] == load_contest(wrapped)[0]
    plain, wrapped = _pair(tmp_path, "cur.yaml", CURRICULUM, node)
    assert load_curriculum(plain).stages == load_curriculum(wrapped).stages
    assert len(load_curriculum(wrapped)) == 2


def test_benchmark_config(tmp_path: Path) -> None:
    for folder, text in (("suites", SUITE), ("contests", CONTEST)):
        (tmp_path / folder).mkdir()
        (tmp_path / folder / "x.yaml").write_text(_wrap(text))
    (tmp_path / "config.yaml").write_text(_wrap(
        "suite: {config: x.yaml, scale_episodes: 2}\ncontest: {config: x.yaml}\n"
        "general: {simulator: flatland}\n"))
    suite, contest = load_benchmark(tmp_path / "config.yaml")
    assert suite.total_episodes == 6 and contest[0].contestants[0].name == "pp"


def test_only_the_exact_wrapper_is_unwrapped(tmp_path: Path) -> None:
    f = tmp_path / "f.yaml"
    for text, expected in (
        ("/**:\n  ros__parameters: {a: 1}\n", {"a": 1}),
        ("/**:\n  ros__parameters: {a: 1}\n  other: 2\n",  # another key: not a wrapper
         {"/**": {"ros__parameters": {"a": 1}, "other": 2}}),
        ("x: {ros__parameters: 1}\ny: 2\n", {"x": {"ros__parameters": 1}, "y": 2}),
        ("- 1\n- 2\n", [1, 2]),
    ):
        f.write_text(text)
        assert read_arena_yaml(f) == expected
    # a wrapped file with a mistake is reported at its key inside the wrapper's document
    f.write_text(_wrap("stages:\n  - {name: x, episodes: 1, mapp: corridor}\n"))
    with pytest.raises(ConfigError) as e:
        load_suite(f)
    assert e.value.path == "stages[0].mapp"
