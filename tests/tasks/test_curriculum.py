"""Curriculum files: Arena's format unchanged, our wrapper, algorithm mapping and errors."""

import pytest

from arena.core.errors import ConfigError
from arena.tasks.curriculum import load_curriculum

ARENA_DEFAULT = """\
- static: 0
  interactive: 0
  dynamic: 12
  goal_radius: 1.0
  map_generator:
    algorithm: barn
    algorithm_config:
      fill_pct: 0.075
      smooth_iter: 3
- static: 0
  interactive: 0
  dynamic: 15
  goal_radius: 0.75
  map_generator:
    algorithm: rosnav
    algorithm_config:
      map_type: indoor
      fill_pct: 0.1
      indoor: {corridor_radius: 5, iterations: 60}
      outdoor: {obstacle_num: 15, obstacle_extra_radius: 1}
"""


def test_packaged_default_is_arenas():
    c = load_curriculum("default")
    assert len(c) == 7
    assert [s.dynamic for s in c.stages] == [12, 15, 20, 25, 30, 35, 40]
    assert all(s.static == 0 for s in c.stages)
    assert [s.goal_radius for s in c.stages[:4]] == [1.0, 0.75, 0.5, 0.3]
    pairs = [(m["fill_pct"], m["smooth_iter"]) for m in c.map_specs]
    assert pairs == [(0.075, 3), (0.10, 8), (0.10, 2), (0.125, 5), (0.125, 2), (0.15, 2),
                     (0.15, 5)]
    assert all(m["type"] == "barn" for m in c.map_specs)
    assert (c.upper_threshold, c.lower_threshold) == (0.9, 0.65)


def test_packaged_semantic_uses_rosnav_indoor():
    c = load_curriculum("semantic")
    assert c.map_specs[0] == {"type": "rosnav_indoor", "corridor_radius": 5, "iterations": 60}
    assert c.stages[0].dynamic == 10 and c.stages[0].goal_radius == 0.5


def test_arena_list_format_loads_unchanged(tmp_path):
    f = tmp_path / "arena.yaml"
    f.write_text(ARENA_DEFAULT)
    c = load_curriculum(f)
    assert len(c) == 2
    assert c.map_specs[1] == {"type": "rosnav_indoor", "corridor_radius": 5, "iterations": 60}
    assert c.window == 20


def test_old_numbered_format(tmp_path):
    f = tmp_path / "old.yaml"
    f.write_text("1: {static: 0, dynamic: 0}\n2: {static: 3, dynamic: 2}\n")
    c = load_curriculum(f)
    assert [s.static for s in c.stages] == [0, 3]
    assert c.map_specs == [None, None]


def _bad(tmp_path, text):
    f = tmp_path / "bad.yaml"
    f.write_text(text)
    with pytest.raises(ConfigError) as e:
        load_curriculum(f)
    assert str(f) in str(e.value)
    return e.value


def test_unknown_algorithm_names_file_and_stage(tmp_path):
    stages = "".join("  - {dynamic: 1}\n" for _ in range(3))
    err = _bad(tmp_path, "stages:\n" + stages
               + "  - {dynamic: 1, map_generator: {algorithm: maze}}\n")
    assert err.path == "stages[3].map_generator.algorithm"
    assert "maze" in err.message


def test_unknown_param_and_map_type(tmp_path):
    err = _bad(tmp_path, "- map_generator: {algorithm: barn, algorithm_config: {fill: 0.1}}\n")
    assert err.path.startswith("stages[0].map_generator.algorithm_config")
    err = _bad(tmp_path, "- map_generator: {algorithm: rosnav, algorithm_config: "
               "{map_type: cave}}\n")
    assert err.path == "stages[0].map_generator.algorithm_config.map_type"


def test_unknown_stage_key_and_malformed_yaml(tmp_path):
    err = _bad(tmp_path, "- {static: 1, dynamc: 3}\n")
    assert err.path == "stages[0].dynamc"
    err = _bad(tmp_path, "- static: 1\n  dynamic: [3\n")
    assert "malformed YAML at line" in err.message


def test_thresholds_and_missing_file(tmp_path):
    err = _bad(tmp_path, "stages: [{dynamic: 1}]\nupper_threshold: 0.5\nlower_threshold: 0.6\n")
    assert "lower_threshold" in str(err)
    with pytest.raises(ConfigError, match="packaged"):
        load_curriculum("defualt")
