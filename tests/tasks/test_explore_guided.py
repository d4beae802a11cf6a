"""robots.explore and robots.guided: goal logic in the runtime and in simulated episodes."""

import json

import numpy as np

from arena.config import load_config
from arena.core.types import Pose2D
from arena.experiment import run_experiment
from arena.robots.presets import load_robot
from arena.tasks.config import TaskConfig
from arena.tasks.generator import TaskGenerator

ROOM = {"type": "empty", "width": 10.0, "height": 8.0}
QUIET = {"type": "random", "static": 0, "dynamic": 0}


def _gen(robots: dict, n_robots: int = 1) -> TaskGenerator:
    cfg = TaskConfig.model_validate({"robots": robots, "obstacles": QUIET, "timeout": 100.0})
    return TaskGenerator(cfg, map_spec=ROOM, robots=[load_robot("jackal")] * n_robots, seed=3)


def test_explore_new_goal_on_arrival_never_done():
    gen = _gen({"type": "explore", "min_goal_distance": 3.0})
    ep = gen.episode(0)
    rt = gen.runtime(ep)
    goal = ep.robots[0].goal
    upd = rt.update(5.0, goal.as_array()[None])
    assert upd.reached == [0] and not upd.done
    new = upd.goals[0]
    assert new.distance_to(goal) >= 3.0
    upd = rt.update(9.0, new.as_array()[None])
    assert upd.goals[0] != new and rt.goals_reached == [2] and not upd.done


def test_explore_goal_timeout_teleports():
    gen = _gen({"type": "explore", "goal_timeout": 10.0})
    ep = gen.episode(0)
    rt = gen.runtime(ep)
    start = ep.robots[0].start.as_array()[None]
    assert not rt.update(9.0, start).teleports
    upd = rt.update(10.0, start)
    pose = upd.teleports[0]
    assert 0 in upd.goals and upd.goals[0].distance_to(pose) > 0.5
    assert 0.3 < pose.x < 9.7 and 0.3 < pose.y < 7.7
    # The timer restarts with the new goal.
    assert not rt.update(15.0, pose.as_array()[None]).teleports


def test_guided_idle_without_waypoints_and_cycles():
    gen = _gen({"type": "guided", "start": [2.0, 2.0, 0.0]})
    ep = gen.episode(0)
    assert ep.robots[0].goal == ep.robots[0].start == Pose2D(2.0, 2.0, 0.0)
    rt = gen.runtime(ep)
    here = np.array([[2.0, 2.0, 0.0]])
    upd = rt.update(1.0, here)
    assert not upd.reached and not upd.done and rt.goals_reached == [0]
    mode = gen.robot_mode
    assert mode.add_goal(rt.ctx, 0, Pose2D(8.0, 2.0, 0.0)) == Pose2D(8.0, 2.0, 0.0)
    mode.add_goal(rt.ctx, 0, Pose2D(8.0, 6.0, 0.0))
    assert mode.next_goal(rt.ctx, 0, Pose2D(8.0, 2.0, 0.0), rt.rng) == Pose2D(8.0, 6.0, 0.0)
    assert mode.next_goal(rt.ctx, 0, Pose2D(8.0, 6.0, 0.0), rt.rng) == Pose2D(8.0, 2.0, 0.0)
    # A teleport clears the shared list: the robot idles where it lands.
    assert mode.on_teleport(rt.ctx, 0, Pose2D(5.0, 5.0, 0.0)) == Pose2D(5.0, 5.0, 0.0)
    assert mode.waypoints == []


def test_guided_scripted_waypoints_in_runtime():
    wps = [[8.0, 2.0, 0.0], [8.0, 6.0, 0.0], [2.0, 6.0, 0.0]]
    gen = _gen({"type": "guided", "start": [2.0, 2.0, 0.0], "waypoints": wps})
    ep = gen.episode(0)
    rt = gen.runtime(ep)
    assert ep.robots[0].goal == Pose2D(*wps[0])
    seen = []
    for k in range(4):
        upd = rt.update(float(k), np.array([wps[k % 3]]))
        seen.append(upd.goals[0])
        assert not upd.done
    assert seen == [Pose2D(*wps[1]), Pose2D(*wps[2]), Pose2D(*wps[0]), Pose2D(*wps[1])]


def _cfg(robots: dict, timeout: float) -> object:
    return load_config(None, [
        "output.video=false", "robot=jackal", "map.type=empty", "map.width=10",
        "map.height=8", f"task.robots={json.dumps(robots)}", f"task.obstacles={json.dumps(QUIET)}",
        f"task.timeout={timeout}", "episodes=1",
    ])


def test_explore_episode_reaches_several_goals(tmp_path):
    cfg = _cfg({"type": "explore", "min_goal_distance": 2.0}, 40.0)
    _, (res,) = run_experiment(cfg, tmp_path)
    assert res.outcome == "timeout"  # explore never ends by success
    assert res.goals_reached >= 2
    assert "goals_reached" in (tmp_path / "summary.csv").read_text().splitlines()[0]


def test_guided_episode_cycles_scripted_waypoints(tmp_path):
    wps = [[7.5, 2.0, 0.0], [7.5, 6.0, 0.0]]
    cfg = _cfg({"type": "guided", "start": [2.0, 4.0, 0.0], "waypoints": wps}, 40.0)
    _, (res,) = run_experiment(cfg, tmp_path)
    assert res.goals_reached >= 3  # 0 → 1 → 0 at least
