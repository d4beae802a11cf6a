"""Runs are named after what they run; packaged resources are addressed by name from any folder."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from arena import cli
from arena.config import load_config
from arena.core.errors import ConfigError
from arena.experiment import default_output_dir, run_name
from arena.maps.sources import WORLDS_DIR, resolve_scenario
from tests.cli_kit import run_cli


@pytest.mark.parametrize(
    ("overrides", "expected"),
    [
        ([], "small_office_jackal_pure_pursuit"),
        (["map.name=corridor", "robot=burger"], "corridor_burger_pure_pursuit"),
        (["map.type=empty", "navigation.local_planner.type=dwa"], "empty_jackal_dwa"),
        (["map.type=file", f"map.path={WORLDS_DIR / 'campus' / 'map' / 'map.yaml'}"],
         "campus_jackal_pure_pursuit"),
        (["name=my_study", "map.type=empty"], "my_study"),
    ],
)
def test_run_name_says_what_runs(overrides, expected):
    cfg = load_config(None, overrides)
    assert run_name(cfg) == expected
    folder = default_output_dir(cfg)
    assert folder.parent == Path("runs")
    assert folder.name.startswith(expected + "_")
    assert folder.name[len(expected) + 1:].replace("-", "").isdigit()


def test_run_name_of_a_robot_file(tmp_path):
    robot = tmp_path / "my bot.yaml"
    robot.write_text("x: 1\n")
    cfg = load_config(None, ["map.type=barn"]).model_copy(update={"robot": str(robot)})
    assert run_name(cfg) == "barn_my-bot_pure_pursuit"


def test_resolve_scenario_by_name():
    packaged = WORLDS_DIR / "corridor" / "scenarios" / "default.json"
    assert resolve_scenario("corridor/default") == packaged
    assert resolve_scenario("default", "corridor") == packaged
    assert resolve_scenario("default.json", str(WORLDS_DIR / "corridor")) == packaged
    assert resolve_scenario(str(packaged), "small_office") == packaged  # a file wins
    with pytest.raises(ConfigError, match=r"no scenario 'defualt' in world 'corridor' .*did you "
                       r"mean 'default'\? scenarios: default"):
        resolve_scenario("defualt", "corridor")
    with pytest.raises(ConfigError, match="a scenario name needs a world"):
        resolve_scenario("default")
    with pytest.raises(ConfigError, match=r"no such scenario file 'a/b/c\.json'"):
        resolve_scenario("a/b/c.json", "corridor")


def test_run_from_another_folder_by_names(monkeypatch, capsys, tmp_path):
    """The README's `arena run --map corridor --scenario default` works outside the repo; the
    run folder is named after the map, robot and planner."""
    monkeypatch.chdir(tmp_path)
    code, out, err = run_cli(monkeypatch, capsys, "run", "--map", "corridor", "--scenario",
                             "default", "--no-video", "task.timeout=2")
    assert code == 0, err
    (run,) = (tmp_path / "runs").iterdir()
    assert run.name.startswith("corridor_jackal_pure_pursuit_")
    assert "arena run · corridor_jackal_pure_pursuit" in out
    cfg = yaml.safe_load((run / "config.yaml").read_text())
    packaged = str(WORLDS_DIR / "corridor" / "scenarios" / "default.json")
    assert cfg["task"]["robots"] == {"type": "scenario", "file": packaged}
    assert (run / "summary.csv").is_file()
    code, _, err = run_cli(monkeypatch, capsys, "run", "--map", "corridor", "--scenario", "nope")
    assert code == 2
    assert err.strip().startswith("error: --scenario: no scenario 'nope' in world 'corridor'")


def test_training_config_by_name_from_another_folder(monkeypatch, capsys, tmp_path):
    from arena.learn.train import load_training, resolve_training_config

    monkeypatch.chdir(tmp_path)
    path = resolve_training_config("rosnav_rl")
    assert path == Path(cli.__file__).parent / "learn" / "data" / "train" / "rosnav_rl.yaml"
    cfg, settings = load_training("rosnav_rl", ["learning.train.n_envs=2"])
    assert cfg.name == "rosnav_rl_train" and settings.train.n_envs == 2
    assert resolve_training_config("mine.yaml") == "mine.yaml"  # a path stays a path
    code, _, err = run_cli(monkeypatch, capsys, "train", "rosnav")
    assert code == 2
    assert err.strip() == ("error: no such file or packaged training config 'rosnav'; did you "
                           "mean 'rosnav_rl'? packaged: applr, rlca, rosnav_rl, trail, "
                           "trail_indoor, value_policy")
