"""modules.interactive: commands, validation, the runtime hook, episodes and the CLI."""

import json
import subprocess
import sys
import threading

import numpy as np
import pytest

from arena.config import load_config
from arena.core.errors import ConfigError
from arena.core.types import Pose2D
from arena.eval.metrics import get_metric
from arena.experiment import run_experiment
from arena.robots.presets import load_robot
from arena.tasks.config import TaskConfig
from arena.tasks.generator import TaskGenerator
from arena.tasks.modules.interactive import CommandError, parse_command

QUIET = {"type": "random", "static": 0, "dynamic": 0}


def _gen(robots=None, modules=()) -> TaskGenerator:
    cfg = TaskConfig.model_validate({
        "robots": robots or {"type": "random", "min_goal_distance": 3.0},
        "obstacles": QUIET, "modules": list(modules),
    })
    return TaskGenerator(cfg, map_spec={"type": "empty", "width": 10.0, "height": 8.0},
                         robots=[load_robot("jackal")], seed=1)


def test_parse_command():
    assert parse_command("goal 1 2").pose == Pose2D(1.0, 2.0, 0.0)
    cmd = parse_command("teleport 1 2 0.5 robot=1")
    assert (cmd.kind, cmd.robot, cmd.pose.theta) == ("teleport", 1, 0.5)
    assert parse_command("reset").kind == "reset"
    assert parse_command("quit") is None
    for bad in ("fly 1 2", "goal 1", "goal a b", "reset now"):
        with pytest.raises(CommandError):
            parse_command(bad)


def test_validation_and_thread_safe_queue():
    gen = _gen(modules=[{"type": "interactive"}])
    ui = gen.modules[0]
    gen.episode(0)
    with pytest.raises(CommandError, match="outside the map"):
        ui.set_goal(0, Pose2D(50.0, 1.0))
    with pytest.raises(CommandError, match="from a wall"):
        ui.teleport(0, Pose2D(0.1, 4.0))
    with pytest.raises(CommandError, match="no robot 3"):
        ui.set_goal(3, Pose2D(5.0, 4.0))
    threads = [threading.Thread(target=ui.set_goal, args=(0, Pose2D(5.0, 4.0))) for _ in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(ui.poll(0.0)) == 8 and ui.poll(0.0) == []


def test_script_errors_name_the_entry():
    gen = _gen(modules=[{"type": "interactive", "script": [{"t": 1, "goal": [99, 1]}]}])
    with pytest.raises(ConfigError, match=r"script\[0\].*outside the map"):
        gen.episode(0)
    with pytest.raises(ConfigError):
        _gen(modules=[{"type": "interactive", "script": [{"t": 1}]}])


def test_runtime_applies_commands():
    gen = _gen(modules=[{"type": "interactive"}])
    ep = gen.episode(0)
    rt = gen.runtime(ep)
    ui = gen.modules[0]
    start = ep.robots[0].start.as_array()[None]
    ui.set_goal(0, Pose2D(5.0, 4.0, 1.0))
    ui.teleport(0, Pose2D(2.0, 2.0, 0.0))
    upd = rt.update(1.0, start)
    assert upd.goals[0] == Pose2D(5.0, 4.0, 1.0) and upd.teleports[0] == Pose2D(2.0, 2.0, 0.0)
    ui.reset()
    assert rt.update(2.0, start).reset


def test_guided_goal_appends_and_teleport_clears():
    gen = _gen({"type": "guided", "start": [2.0, 2.0, 0.0]}, [{"type": "interactive"}])
    ep = gen.episode(0)
    rt = gen.runtime(ep)
    ui = gen.modules[0]
    here = np.array([[2.0, 2.0, 0.0]])
    ui.set_goal(0, Pose2D(8.0, 2.0))
    ui.set_goal(0, Pose2D(8.0, 6.0))
    upd = rt.update(1.0, here)
    assert upd.goals[0] == Pose2D(8.0, 2.0) and len(gen.robot_mode.waypoints) == 2
    ui.teleport(0, Pose2D(5.0, 4.0))
    upd = rt.update(2.0, here)
    assert gen.robot_mode.waypoints == [] and rt.idle[0]


def _cfg(script, robots=None, timeout=30.0):
    return load_config(None, [
        "output.video=false", "robot=jackal", "map.type=empty", "map.width=10",
        "map.height=8", f"task.obstacles={json.dumps(QUIET)}", f"task.timeout={timeout}",
        f"task.robots={json.dumps(robots or {'type': 'guided', 'start': [2.0, 4.0, 0.0]})}",
        f"task.modules={json.dumps([{'type': 'interactive', 'script': script}])}",
    ])


def test_scripted_episode_goal_teleport_reset(tmp_path):
    script = [{"t": 1.0, "goal": [7.0, 4.0, 0.0]}, {"t": 12.0, "teleport": [2.0, 2.0, 0.0]},
              {"t": 14.0, "reset": True}]
    _, (res,) = run_experiment(_cfg(script), tmp_path)
    assert res.outcome == "aborted" and res.teleports == 1
    assert res.goals_reached >= 1  # the scripted goal was reached before the teleport
    traj = np.genfromtxt(tmp_path / "episode_000" / "trajectory.csv", delimiter=",", names=True)
    after = traj[traj["time"] > 12.05][0]
    assert abs(after["x"] - 2.0) < 0.1 and abs(after["y"] - 2.0) < 0.1
    assert res.path_length < 12.0  # the teleport jump is not driven distance
    # The record's metric finds the jump by its teleport event: the same driven length.
    assert get_metric("path_length")(res.record) == pytest.approx(res.path_length, rel=1e-12)
    jumped = np.sum(np.hypot(*np.diff(res.record.pose[:, :2], axis=0).T))
    assert jumped > res.path_length + 1.5  # the jump from about (7, 4) to (2, 2)


def test_cli_scenario_and_interactive(tmp_path):
    from arena.cli import app  # noqa: F401  (import check)

    scen = "arena/worlds/corridor/scenarios/default.json"
    base = [sys.executable, "-m", "arena.cli", "run", "--no-video", "task.timeout=5"]
    r = subprocess.run([*base, "--map", "corridor", "--scenario", scen, "-o", str(tmp_path / "s")],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    cfg = (tmp_path / "s" / "config.yaml").read_text()
    assert "type: scenario" in cfg
    r = subprocess.run([*base, "--interactive", "-o", str(tmp_path / "i"),
                        f"task.obstacles={json.dumps(QUIET)}"],
                       input="bogus\ngoal 999 999\nreset\n", capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 0, r.stderr
    assert "unknown command 'bogus'" in r.stderr and "outside the map" in r.stderr
    assert "aborted" in (tmp_path / "i" / "summary.csv").read_text()
