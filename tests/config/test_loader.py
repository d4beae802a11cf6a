from pathlib import Path

import pytest

from arena.config import DEFAULT_CONFIG, ExperimentConfig, load_config, parse_override
from arena.core.errors import ConfigError, UnknownNameError


def write(tmp_path: Path, text: str, name: str = "exp.yaml") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


def test_packaged_default_loads():
    cfg = load_config()
    assert isinstance(cfg, ExperimentConfig)
    assert cfg.robot == "jackal"
    assert cfg.map["type"] == "world"
    assert DEFAULT_CONFIG.is_file()


def test_overrides_are_typed_and_nested():
    cfg = load_config(
        None,
        ["robot=burger", "seed=3", "task.obstacles.dynamic=4", "output.video=false",
         "task.obstacles.agent_speed=[0.4, 0.9]"],
    )
    assert cfg.robot == "burger"
    assert cfg.seed == 3
    assert cfg.task.obstacles["dynamic"] == 4
    assert cfg.output.video is False
    assert cfg.task.obstacles["agent_speed"] == [0.4, 0.9]


def test_changing_a_plugin_type_replaces_the_block():
    cfg = load_config(None, ["map.type=empty", "map.width=6"])
    assert cfg.map == {"type": "empty", "width": 6}


def test_file_merges_over_defaults_and_relative_paths(tmp_path):
    from arena.maps.grid import OccupancyGrid
    from arena.maps.io import save_map

    save_map(OccupancyGrid.empty(8, 8, 0.1), tmp_path / "maps" / "m.yaml")
    p = write(tmp_path, "seed: 5\nmap: {type: file, path: maps/m.yaml}\nsim: {dt: 0.05}\n")
    cfg = load_config(p)
    assert cfg.seed == 5
    assert cfg.sim.dt == 0.05
    assert cfg.sim.backend == {"type": "native2d"}  # default kept
    assert Path(cfg.map["path"]).is_absolute()
    assert "name" not in cfg.map  # the default world's key did not leak into the file block


def test_misspelt_key_in_file_names_file_and_path(tmp_path):
    p = write(tmp_path, "seed: 1\ntask:\n  obstacles:\n    type: random\n    agnets: 3\n")
    with pytest.raises(ConfigError) as info:
        load_config(p)
    msg = str(info.value)
    assert str(p) in msg
    assert "task.obstacles.agnets" in msg
    assert "unknown key" in msg


def test_misspelt_top_level_key(tmp_path):
    p = write(tmp_path, "sed: 1\n")
    with pytest.raises(ConfigError, match=r"exp\.yaml: sed: unknown key"):
        load_config(p)


def test_wrong_type_names_expected(tmp_path):
    p = write(tmp_path, "episodes: many\n")
    with pytest.raises(ConfigError, match=r"episodes: .*integer"):
        load_config(p)


def test_override_errors_blame_the_override():
    with pytest.raises(ConfigError) as info:
        load_config(None, ["task.obstacles.agnets=3"])
    assert "override 'task.obstacles.agnets=3'" in str(info.value)
    with pytest.raises(ConfigError, match="override 'seed=-1'"):
        load_config(None, ["seed=-1"])
    with pytest.raises(ConfigError, match=r"key\.path=value"):
        parse_override("seed")
    with pytest.raises(ConfigError, match="dotted key path"):
        parse_override("a..b=1")
    with pytest.raises(ConfigError, match="is a value, not a block"):
        load_config(None, ["seed.x=1"])


def test_unknown_robot_and_plugin_suggest_names():
    with pytest.raises(UnknownNameError) as info:
        load_config(None, ["robot=burgr"])
    assert "did you mean 'burger'" in str(info.value)
    assert "robot" in str(info.value)
    with pytest.raises(UnknownNameError, match="did you mean 'astar'"):
        load_config(None, ["navigation.global_planner.type=astra"])
    with pytest.raises(UnknownNameError, match=r"crowd\.type"):
        load_config(None, ["crowd.type=nope"])


def test_plugin_param_errors_have_key_path(tmp_path):
    p = write(tmp_path, "navigation:\n  local_planner: {type: pure_pursuit, lookahed: 1.0}\n")
    with pytest.raises(ConfigError, match=r"navigation\.local_planner\.lookahed: unknown key"):
        load_config(p)


def test_malformed_yaml_and_missing_file(tmp_path):
    p = write(tmp_path, "seed: 1\ntask: [unclosed\n")
    with pytest.raises(ConfigError, match=r"malformed YAML at line \d+"):
        load_config(p)
    with pytest.raises(ConfigError, match="file not found"):
        load_config(tmp_path / "nope.yaml")
    q = write(tmp_path, "- a\n- b\n", "list.yaml")
    with pytest.raises(ConfigError, match="mapping"):
        load_config(q)
