"""Benchmark suites: loading Arena's files, stage experiments, determinism, errors."""

from pathlib import Path

import pytest

import arena
from arena.config.schema import ExperimentConfig
from arena.core.errors import ConfigError
from arena.robots.presets import load_robot
from arena.scene.episode import episode_digest
from arena.tasks.config import TaskConfig
from arena.tasks.generator import TaskGenerator
from arena.tasks.suite import arena_stage_seed, load_benchmark, load_contest, load_suite

ARENA_BASIC = """\
stages:
  - name: scenario
    episodes: 1
    robot: jackal
    map: corridor
    tm_robots: scenario
    tm_obstacles: scenario
    config:
      SCENARIO:
        file: default.json
  - name: scenario_random
    episodes: 4
    robot: jackal
    map: empty_room
    tm_robots: scenario
    tm_obstacles: random
    config:
      SCENARIO:
        file: default.json
      RANDOM:
        static:
          min: 5
          max: 10
          models: [shelf]
        dynamic:
          min: 3
          max: 5
          models: [actor1]
"""


def _gen(suite, seed=0, scale=1.0):
    cfg = TaskConfig.model_validate(
        {"modules": [{"type": "benchmark", "suite": str(suite), "scale_episodes": scale}]}
    )
    return TaskGenerator(cfg, map_spec={"type": "world", "name": "small_office"},
                         robots=[load_robot("jackal")], seed=seed)


def _digests(gen):
    return [(ep.label, episode_digest(ep)) for ep in gen.episodes()]


def _write(tmp_path, text, name="suite.yaml"):
    f = tmp_path / name
    f.write_text(text)
    return f


def test_arena_files_load_unchanged(tmp_path):
    (tmp_path / "suites").mkdir()
    (tmp_path / "contests").mkdir()
    (tmp_path / "suites" / "basic.yaml").write_text(ARENA_BASIC)
    (tmp_path / "contests" / "basic.yaml").write_text(
        "contestants:\n  - name: teb-basic\n    local_planner: teb\n    inter_planner: bypass\n"
    )
    (tmp_path / "config.yaml").write_text(
        "suite:\n  config: basic.yaml\n  scale_episodes: 2\ncontest:\n  config: basic.yaml\n"
        "general:\n  simulator: flatland\n"
    )
    suite, contest = load_benchmark(tmp_path / "config.yaml")
    assert suite.episode_counts == [2, 8]
    assert contest is not None and contest[0].contestants[0].local_planner == "teb"
    exps = suite.stage_experiments(ExperimentConfig())
    _, cfg = exps[1]
    assert cfg.task.obstacles["static"] == {"min": 5, "max": 10, "models": ["shelf"]}
    assert cfg.task.obstacles["dynamic"]["min"] == 3 and cfg.task.obstacles["dynamic"]["max"] == 5
    assert cfg.task.robots["file"].endswith("empty_room/scenarios/default.json")
    gen = _gen(tmp_path / "suites" / "basic.yaml")
    assert gen.num_episodes == 5
    eps = list(gen.episodes())
    assert [e.label for e in eps] == ["scenario"] + ["scenario_random"] * 4


def test_default_seed_is_arenas_sha1():
    raw = {"name": "a", "episodes": 1}
    seed = arena_stage_seed(raw)
    assert 0 <= seed < 2**31
    assert seed == arena_stage_seed({"episodes": 1, "name": "a"})
    assert seed != arena_stage_seed({"name": "b", "episodes": 1})


def test_same_suite_twice_same_episodes():
    assert _digests(_gen("quick")) == _digests(_gen("quick"))
    assert _digests(_gen("quick")) != _digests(_gen("quick", seed=1))


def test_stage_episodes_independent_of_earlier_stages(tmp_path):
    def suite(n_first):
        return _write(tmp_path, f"""\
stages:
  - {{name: first, episodes: {n_first}, map: empty_room}}
  - {{name: second, episodes: 3, map: {{type: canteen}}, seed: 7,
     config: {{RANDOM: {{static: {{min: 0, max: 0}}, dynamic: {{min: 2, max: 2}}}}}}}}
""", f"s{n_first}.yaml")

    a = [d for label, d in _digests(_gen(suite(1))) if label == "second"]
    b = [d for label, d in _digests(_gen(suite(4))) if label == "second"]
    assert a == b and len(set(a)) == 3  # and a new canteen map per episode


def test_stage_experiment_equals_stage_inside_suite():
    gen = _gen("quick", seed=5)
    inside = [episode_digest(ep) for ep in gen.episodes() if ep.label == "canteen"]
    suite = load_suite("quick")
    stage, cfg = suite.stage_experiments(ExperimentConfig(seed=5))[1]
    alone = TaskGenerator.from_config(cfg)
    assert stage.name == "canteen"
    assert [episode_digest(e) for e in alone.episodes(cfg.episodes)] == inside


def test_scale_episodes():
    assert load_suite("paper").total_episodes == 160
    assert load_suite("paper", scale_episodes=0.1).episode_counts == [10, 1, 1, 1, 1, 1, 1]
    assert _gen("quick", scale=2.0).num_episodes == 62


def test_quick_suite_and_first_episode_of_every_paper_stage():
    eps = list(_gen("quick").episodes())
    # enough per stage for intervals that mean something (the scenario is one fixed episode)
    assert [sum(e.label == s for e in eps) for s in ("random", "canteen", "office")] == [10] * 3
    assert len(eps) == 31
    assert {e.label for e in eps} == {"random", "canteen", "office", "corridor_scenario"}
    assert all(len(e.agents) >= 3 for e in eps if e.label != "corridor_scenario")
    gen = _gen("paper")
    suite = gen.modules[0].suite
    start = 0
    for stage, n in zip(suite.stages, suite.episode_counts, strict=True):
        ep = gen.episode(start)
        assert ep.label == stage.name
        assert ep.robots[0].model.name == "jackal"
        start += n


@pytest.mark.slow
def test_every_paper_episode_is_valid():
    eps = list(_gen("paper").episodes())
    assert len(eps) == 160
    assert max(len(e.agents) for e in eps[:100]) <= 30


def test_contest_packaged():
    contest, _ = load_contest("basic")
    assert contest.contestants[0].local_planner == "pure_pursuit"
    assert contest.contestants[0].inter_planner == "bypass"


# -- errors ------------------------------------------------------------------------------------
def _stage_error(tmp_path, stage_yaml, n_before=3):
    ok = "".join(f"  - {{name: s{i}, episodes: 1, map: empty_room}}\n" for i in range(n_before))
    f = _write(tmp_path, "stages:\n" + ok + stage_yaml)
    with pytest.raises(ConfigError) as e:
        load_suite(f).stage_experiments(ExperimentConfig())
    assert str(f) in str(e.value)
    return e.value


def test_missing_map_names_the_stage(tmp_path):
    err = _stage_error(tmp_path, "  - {name: x, episodes: 1, map: arena_hospital_small}\n")
    assert err.path == "stages[3].map" and "arena_hospital_small" in err.message


def test_missing_scenario_names_the_key(tmp_path):
    err = _stage_error(tmp_path, "  - {name: x, episodes: 1, map: corridor, tm_robots: scenario,"
                       " config: {SCENARIO: {file: 9.json}}}\n")
    assert err.path == "stages[3].config.SCENARIO.file"


def test_unknown_mode_and_model(tmp_path):
    err = _stage_error(tmp_path, "  - {name: x, episodes: 1, map: corridor, tm_robots: flying}\n")
    assert err.path == "stages[3].tm_robots"
    err = _stage_error(tmp_path, "  - {name: x, episodes: 1, map: corridor, config: "
                       "{RANDOM: {static: {min: 1, max: 2, models: [sofa]}}}}\n")
    assert err.path.startswith("stages[3]") and "sofa" in err.message


def test_unknown_key_and_malformed_yaml(tmp_path):
    f = _write(tmp_path, "stages:\n  - {name: x, episodes: 1, mapp: corridor}\n")
    with pytest.raises(ConfigError) as e:
        load_suite(f)
    assert e.value.path == "stages[0].mapp"
    f = _write(tmp_path, "stages:\n  - {name: x, episodes: 1, config: {RANDOM: {statc: 1}}}\n")
    with pytest.raises(ConfigError) as e:
        load_suite(f)
    assert e.value.path == "stages[0].config.RANDOM.statc"
    f = _write(tmp_path, "stages:\n  - name: x\n    episodes: [1\n")
    with pytest.raises(ConfigError, match=r"malformed YAML at line \d+"):
        load_suite(f)
    packaged = "packaged: barn, barn_rgbd, indoor_people, indoor_people_rgbd, paper, quick"
    with pytest.raises(ConfigError, match=packaged):
        load_suite("papr")


def test_contestant_planner_params(tmp_path):
    from arena.tasks.suite import contestant_config

    f = _write(tmp_path, "contestants:\n  - {name: slow, local_planner: dwa, "
               "params: {max_speed: 0.4}}\n", "contest.yaml")
    contest, _ = load_contest(f)
    cfg = contestant_config(ExperimentConfig(), contest.contestants[0], source=str(f))
    assert cfg.navigation.local_planner == {"type": "dwa", "max_speed": 0.4}
    bad = _write(tmp_path, "contestants:\n  - {name: x, local_planner: dwa, "
                 "params: {max_sped: 0.4}}\n", "bad.yaml")
    with pytest.raises(ConfigError, match=r"params\.max_sped: unknown key") as e:
        contestant_config(ExperimentConfig(), load_contest(bad)[0].contestants[0], source=str(bad))
    assert e.value.path == "contestants[0].params.max_sped"


def test_contestant_global_planner(tmp_path):
    from arena.tasks.suite import contestant_config

    f = _write(tmp_path, "contestants:\n  - {name: a, local_planner: dwa, global_planner: "
               "theta_star}\n  - {name: b, local_planner: dwa, global_planner: {type: dijkstra}}"
               "\n  - {name: c, local_planner: dwa}\n", "contest.yaml")
    contest, _ = load_contest(f)
    got = [contestant_config(ExperimentConfig(), c, source=str(f), index=i).navigation
           for i, c in enumerate(contest.contestants)]
    assert got[0].global_planner["type"] == "theta_star"
    assert got[1].global_planner["type"] == "dijkstra"
    assert got[2].global_planner == ExperimentConfig().navigation.global_planner
    bad = _write(tmp_path, "contestants:\n  - {name: x, local_planner: dwa, global_planner: "
                 "astr}\n", "bad.yaml")
    with pytest.raises(ConfigError, match="did you mean 'astar'") as e:
        contestant_config(ExperimentConfig(), load_contest(bad)[0].contestants[0], source=str(bad))
    assert e.value.path == "contestants[0].global_planner.type"


def test_contestant_navigation_overlay(tmp_path):
    from arena.tasks.suite import contestant_config

    f = _write(tmp_path, "contestants:\n  - {name: a, local_planner: dwa, navigation: "
               "{oscillation_timeout: 5.0, back_up_distance: 0.4}}\n", "contest.yaml")
    nav = contestant_config(ExperimentConfig(), load_contest(f)[0].contestants[0]).navigation
    assert nav.oscillation_timeout == 5.0 and nav.back_up_distance == 0.4
    assert nav.local_planner["type"] == "dwa"
    for text, path in (
        ("{oscilation_timeout: 5.0}", "contestants[0].navigation.oscilation_timeout"),
        ("{local_planner: {type: teb}}", "contestants[0].navigation.local_planner"),
    ):
        bad = _write(tmp_path, "contestants:\n  - {name: x, local_planner: dwa, navigation: "
                     f"{text}}}\n", "bad.yaml")
        with pytest.raises(ConfigError) as e:
            contestant_config(ExperimentConfig(), load_contest(bad)[0].contestants[0],
                              source=str(bad))
        assert e.value.path == path and "\n" not in str(e.value)


@pytest.mark.parametrize(
    "name",
    sorted(p.stem for p in (Path(arena.__file__).parent / "tasks" / "data" / "contests").glob(
        "*.yaml")),
)
def test_every_packaged_contest_builds_its_planners(name):
    """Each packaged contest names registered planners whose (packaged) weights load."""
    from arena.nav.local_planners.base import LOCAL_PLANNERS
    from arena.tasks.suite import contestant_config

    contest, source = load_contest(name)
    for i, c in enumerate(contest.contestants):
        cfg = contestant_config(ExperimentConfig(), c, source=source, index=i)
        planner = LOCAL_PLANNERS.build(cfg.navigation.local_planner)
        assert hasattr(planner, "compute")
    if name == "learned":
        assert {c.local_planner for c in contest.contestants} >= {
            "dwa", "rosnav_rl", "rlca", "crowdnav", "sarl"}


def test_a_stage_robot_yaml_is_read_relative_to_the_suite_file(tmp_path):
    (tmp_path / "robots").mkdir()
    robot = (Path(arena.__file__).parent / "tasks/data/robots/jackal_rgbd.yaml").read_text()
    (tmp_path / "robots" / "cam.yaml").write_text(robot)
    f = _write(tmp_path, "stages:\n  - name: a\n    episodes: 1\n    robot: robots/cam.yaml\n"
               "  - name: b\n    episodes: 1\n    robot: jackal\n")
    suite = load_suite(f)
    assert suite.stage_robot(0) == str((tmp_path / "robots" / "cam.yaml").resolve())
    assert suite.stage_robot(1) == "jackal"
    cfg = suite.stage_experiment(0, ExperimentConfig())
    assert "camera" in load_robot(cfg.robot).sensors
    # the packaged barn_rgbd suite: the barn suite's stage with the camera jackal
    rgbd, barn = load_suite("barn_rgbd"), load_suite("barn")
    assert rgbd.seeds == barn.seeds
    assert load_robot(rgbd.stage_experiment(0, ExperimentConfig()).robot).name == "jackal_rgbd"
