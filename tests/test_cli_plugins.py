"""``arena plugins`` (piped, --json, one plugin's parameters) and ``--plugin`` for run/bench."""

from __future__ import annotations

import csv
import json
import os
import sys
import textwrap

import pytest

from arena.core.registry import all_registries
from tests.cli_kit import run_cli

PLANNER = '''
"""A user's planner: drive straight at the goal at a fixed speed."""
import math

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from arena.nav import LOCAL_PLANNERS
from arena.nav.local_planners.base import limit_command


@LOCAL_PLANNERS.register("{name}")
class Beeline:
    """Turn to the goal, then drive straight at it."""

    supports = frozenset({{"diff_drive"}})

    class Params(BaseModel):
        model_config = ConfigDict(frozen=True, extra="forbid")
        speed: float = Field(0.5, gt=0, description="m/s, cruise speed")

    def __init__(self, params=None):
        self.params = params or self.Params()

    def reset(self):
        pass

    def compute(self, obs):
        x, y, th = obs.pose
        g = obs.goal_pose
        err = math.atan2(g.y - y, g.x - x) - th
        err = math.atan2(math.sin(err), math.cos(err))
        v = self.params.speed * max(math.cos(err), 0.0)
        return limit_command(np.array([v, 0.0, 2.0 * err]), obs.twist, obs.limits, obs.dt)
'''


@pytest.fixture
def user_planner(tmp_path, monkeypatch, request):
    """A plugin file registering a local planner; unregistered again after the test."""
    import arena.plugins as plugins
    from arena.nav import LOCAL_PLANNERS

    monkeypatch.delenv(plugins.PLUGINS_ENV, raising=False)
    name = f"beeline_{request.node.name.removeprefix('test_')[:20]}"
    path = tmp_path / "my_planner.py"
    path.write_text(PLANNER.format(name=name), encoding="utf-8")
    yield name, path
    LOCAL_PLANNERS._entries.pop(name, None)
    module = plugins._loaded.pop(str(path.resolve()), None)
    if module is not None:
        sys.modules.pop(module.__name__, None)


def test_plugins_piped_is_one_untruncated_line_per_plugin(monkeypatch, capsys):
    code, out, _ = run_cli(monkeypatch, capsys, "plugins")
    assert code == 0
    lines = out.splitlines()
    rows = [line.split("\t") for line in lines]
    assert all(len(r) == 4 for r in rows), lines[:3]
    expected = {(k.replace(" ", "_"), e.name) for k, reg in all_registries().items()
                for e in reg.entries()}
    # aliases (Arena's `rosnav`) are listed too, tagged and pointing at their plugin
    expected |= {(k.replace(" ", "_"), a) for k, reg in all_registries().items()
                 for a in reg.aliases()}
    assert {(r[0], r[1]) for r in rows} == expected
    assert ["local_planner", "rosnav", "alias", "alias of rosnav_rl"] in rows
    assert len(rows) == len(expected)
    # long names and descriptions come whole (a rich table at 80 columns cut them)
    zones = next(r for r in rows if r[1] == "modules.clear_forbidden_zones")
    assert zones[:3] == ["task_mode", "modules.clear_forbidden_zones", "modules"]
    dwa = next(r for r in rows if r[:2] == ["local_planner", "dwa"])
    assert dwa[3] == (
        "Dynamic Window Approach local planner (velocity sampling + forward simulation)."
    )


def test_plugins_json_and_one_kind(monkeypatch, capsys):
    code, out, _ = run_cli(monkeypatch, capsys, "plugins", "--json")
    assert code == 0
    rows = json.loads(out)
    assert {"kind": "crowd_model", "name": "waypoint_walker", "tags": ["baseline"],
            "description": "Pedestrians walk straight to their destinations at their preferred "
            "speed, no avoidance."} in rows
    for kind in ("local-planners", "local_planner", "local planner"):
        code, out, _ = run_cli(monkeypatch, capsys, "plugins", kind, "--json")
        assert code == 0
        rows = json.loads(out)
        plugins = [r["name"] for r in rows if "alias" not in r["tags"]]  # aliases follow targets
        assert plugins == sorted(plugins) and {"cohan", "crowdnav", "dwa"} <= set(plugins)
        assert {"rosnav"} <= {r["name"] for r in rows if "alias" in r["tags"]}
        assert {r["kind"] for r in json.loads(out)} == {"local_planner"}


def test_plugin_parameters_with_defaults_units_and_bounds(monkeypatch, capsys):
    code, out, _ = run_cli(monkeypatch, capsys, "plugins", "local_planner", "pure_pursuit")
    assert code == 0
    lines = out.splitlines()
    assert lines[0].startswith("# local_planner pure_pursuit: Pure pursuit path follower")
    assert lines[1] == "name\ttype\tdefault\tunit\tconstraints\tdescription"
    assert "lookahead\tfloat\t0.6\tm\t> 0\tlookahead distance at standstill" in lines
    assert "max_speed\tfloat | None\tNone\tm/s\t> 0\tcruise speed; None uses the robot's vx_max" \
        in lines
    code, out, _ = run_cli(monkeypatch, capsys, "plugins", "local_planner", "dwa", "--json")
    info = json.loads(out)
    steps = next(p for p in info["parameters"] if p["name"] == "steps")
    assert steps == {"name": "steps", "type": "int", "default": "20", "unit": "",
                     "description": "time steps of each rollout",
                     "constraints": [">= 2", "<= 200"]}
    sim_time = next(p for p in info["parameters"] if p["name"] == "sim_time")
    assert (sim_time["unit"], sim_time["default"]) == ("s", "1.5")
    code, out, _ = run_cli(monkeypatch, capsys, "plugins", "metrics", "time_to_goal", "--json")
    assert json.loads(out)["unit"] == "s"


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        (["plugins", "local_planer"], "unknown plugin kind 'local_planer'; did you mean "
         "'local_planner'?"),
        (["plugins", "local_planner", "dwaa"], "unknown local planner 'dwaa'; did you mean 'dwa'?"),
        (["plugins", "--plugin", "no/such/file.py"], "no/such/file.py: no such plugin file"),
        (["plugins", "--plugin", "no_such_module_xyz"],
         "no_such_module_xyz: no such plugin module"),
        (["run", "--plugin", "a b"], "neither a .py file nor a dotted module name"),
    ],
)
def test_plugin_lookup_errors_are_one_line(monkeypatch, capsys, args, expected):
    monkeypatch.delenv("ARENA_PLUGINS", raising=False)
    code, _, err = run_cli(monkeypatch, capsys, *args)
    assert code == 2
    assert expected in err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err


def test_a_plugin_that_raises_on_import_is_named(monkeypatch, capsys, tmp_path):
    monkeypatch.delenv("ARENA_PLUGINS", raising=False)
    bad = tmp_path / "broken_planner.py"
    bad.write_text("import math\nraise RuntimeError('no licence server')\n")
    code, _, err = run_cli(monkeypatch, capsys, "run", "--plugin", str(bad))
    assert code == 2
    assert err.strip() == (f"error: {bad}: plugin failed on import: RuntimeError: no licence "
                           "server")
    dup = tmp_path / "dup.py"
    dup.write_text(textwrap.dedent('''
        from arena.nav import LOCAL_PLANNERS

        @LOCAL_PLANNERS.register("dwa")
        class Mine:
            """Not the real DWA."""
    '''))
    code, _, err = run_cli(monkeypatch, capsys, "plugins", "--plugin", str(dup))
    assert code == 2
    assert f"{dup}: plugin failed on import: ValueError: duplicate local planner name 'dwa'" in err


def test_run_with_a_plugin_planner(monkeypatch, capsys, tmp_path, user_planner):
    name, path = user_planner
    monkeypatch.chdir(tmp_path)
    code, _, err = run_cli(
        monkeypatch, capsys, "run", "--plugin", path.name, f"navigation.local_planner.type={name}",
        "navigation.local_planner.speed=0.7", "map.type=empty", "map.width=8", "map.height=6",
        "task.robots.min_goal_distance=3", "task.obstacles.static=0",
        "task.obstacles.dynamic=0", "task.timeout=20", "--no-video", "-o", "out",
    )
    assert code == 0, err
    cfg = (tmp_path / "out" / "config.yaml").read_text()
    assert f"type: {name}" in cfg and "speed: 0.7" in cfg
    rows = list(csv.DictReader((tmp_path / "out" / "summary.csv").open()))
    assert rows[0]["outcome"] == "success", rows[0]
    # it really drove: at most 0.7 m/s, so at least (distance / 0.7) s
    start, goal = (json.loads((tmp_path / "out" / "episode_000" / "episode.json").read_text())[k]
                   for k in ("start", "goal"))
    dist = ((goal[0] - start[0]) ** 2 + (goal[1] - start[1]) ** 2) ** 0.5
    assert float(rows[0]["time"]) >= (dist - 0.5) / 0.7


def test_bench_with_a_plugin_planner_on_two_workers(monkeypatch, capsys, tmp_path, user_planner):
    """Spawned workers import the plugin file too: no episode fails with an unknown name."""
    name, path = user_planner
    suite = tmp_path / "suite.yaml"
    suite.write_text(textwrap.dedent("""
        stages:
          - name: room
            episodes: 2
            robot: burger
            map: {type: empty, width: 8, height: 6}
            timeout: 60
            config:
              RANDOM:
                static: {min: 0, max: 0}
                dynamic: {min: 1, max: 1}
    """))
    contest = tmp_path / "contest.yaml"
    contest.write_text(f"contestants:\n  - {{name: mine, local_planner: {name}}}\n")
    run = tmp_path / "bench"
    code, _, err = run_cli(
        monkeypatch, capsys, "bench", str(suite), "--contest", str(contest), "-j", "2",
        "--plugin", str(path), "--no-progress", "-o", str(run),
    )
    assert code == 0, err
    from arena.eval.store import load_results

    rows = load_results(run).to_pylist()
    assert [r["local_planner"] for r in rows] == [name, name]
    assert [r["outcome"] for r in rows] == ["success", "success"], [r["error"] for r in rows]


def test_train_names_a_bad_plugin(monkeypatch, capsys, tmp_path):
    monkeypatch.delenv("ARENA_PLUGINS", raising=False)
    code, _, err = run_cli(monkeypatch, capsys, "train", "--plugin", str(tmp_path / "gone.py"),
                           "-o", str(tmp_path / "t"))
    assert code == 2
    assert err.strip() == f"error: {tmp_path / 'gone.py'}: no such plugin file"
    assert not (tmp_path / "t").exists()


CROWD = '''
"""A user's crowd model: walk straight at the destination."""
import numpy as np

from arena.crowd.base import CROWD_MODELS, ModelOutput


@CROWD_MODELS.register("{name}")
class Straight:
    """Walk straight at the destination at full speed."""

    output = "acceleration"

    def neighbor_cutoff(self):
        return 0.0

    def reset(self, state, world, rng):
        pass

    def compute(self, frame):
        s = frame.state
        d = frame.destinations - s.positions
        v = d / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-9) * s.vmax[:, None]
        acc = np.where(frame.active[:, None], (v - s.velocities) / 0.5, 0.0)
        return ModelOutput(accelerations=acc)
'''


@pytest.mark.slow
def test_train_with_a_plugin_crowd_in_subprocess_envs(monkeypatch, capsys, tmp_path):
    """``arena train``'s subprocess environments import the plugin file too."""
    import arena.plugins as plugins
    from arena.crowd.base import CROWD_MODELS

    monkeypatch.delenv(plugins.PLUGINS_ENV, raising=False)
    path = tmp_path / "my_crowd.py"
    path.write_text(CROWD.format(name="straight_e_train"))
    try:
        code, out, err = run_cli(
            monkeypatch, capsys, "train", "--plugin", str(path), "crowd.type=straight_e_train",
            "--steps", "64", "--envs", "2", "--no-progress", "-o", str(tmp_path / "run"),
            "learning.train.vec_env=subproc", "learning.ppo.batch_size=64",
            "learning.ppo.minibatch_size=32", "learning.ppo.n_epochs=1",
            "learning.train.tensorboard=false",
        )
    finally:
        CROWD_MODELS._entries.pop("straight_e_train", None)
    assert code == 0, err
    assert "64 steps" in out and (tmp_path / "run" / "policy.npz").is_file()


def test_plugin_by_module_name_from_the_working_folder(monkeypatch, capsys, tmp_path):
    import arena.plugins as plugins
    from arena.eval.metrics import METRICS

    monkeypatch.delenv(plugins.PLUGINS_ENV, raising=False)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "path", list(sys.path))  # the working folder is added for names
    (tmp_path / "lab_metrics_e.py").write_text(textwrap.dedent('''
        from arena.eval.metrics import metric

        @metric("wheel_time_e", unit="s", description="time with any wheel command")
        def wheel_time(record, params):
            """s, number of rows times dt."""
            return float(len(record.time) * record.meta.dt)
    '''))
    try:
        code, out, err = run_cli(monkeypatch, capsys, "plugins", "metric", "wheel_time_e",
                                 "--plugin", "lab_metrics_e", "--json")
        assert code == 0, err
        info = json.loads(out)
        assert (info["unit"], info["summary"]) == ("s", "time with any wheel command")
        assert info["source"] == "lab_metrics_e.wheel_time"
        # exported for worker processes
        assert os.environ[plugins.PLUGINS_ENV].split(os.pathsep) == ["lab_metrics_e"]
    finally:
        METRICS._entries.pop("wheel_time_e", None)
        plugins._loaded.pop("lab_metrics_e", None)
        sys.modules.pop("lab_metrics_e", None)
