import math

import numpy as np
import pytest

from arena.core.errors import ConfigError, UnknownNameError
from arena.core.types import Pose2D
from arena.robots.presets import load_robot
from arena.scene.episode import episode_digest
from arena.tasks.base import build_mode
from arena.tasks.config import TaskConfig
from arena.tasks.generator import TaskGenerator
from arena.tasks.goal import goal_reached, heading_error

BARN = {"type": "barn", "width": 12.0, "height": 10.0}


def gen(seed=0, map_spec=BARN, **task):
    task.setdefault("obstacles", {"type": "random", "static": 1, "dynamic": 2})
    return TaskGenerator(
        TaskConfig.model_validate(task), map_spec=map_spec, robots=[load_robot("burger")],
        seed=seed,
    )


def test_episode_is_a_pure_function_of_seed_and_index():
    a, b = gen(), gen()
    forward = [episode_digest(a.episode(i)) for i in range(5)]
    backward = [episode_digest(b.episode(i)) for i in reversed(range(5))][::-1]
    assert forward == backward  # order of drawing does not matter
    assert len(set(forward)) == 5


def test_one_map_per_run_unless_dynamic_map():
    g = gen()
    assert len({episode_digest_grid(g.episode(i)) for i in range(4)}) == 1
    g = gen(modules=[{"type": "dynamic_map", "episodes_per_map": 2}])
    grids = [episode_digest_grid(g.episode(i)) for i in range(6)]
    assert grids[0] == grids[1] and grids[2] == grids[3] and grids[4] == grids[5]
    assert len(set(grids)) == 3


def episode_digest_grid(ep):
    return ep.grid.data.tobytes()


def test_forbidden_zones_are_kept_clear_and_can_be_cleared():
    zone = {"polygon": [[0, 0], [12, 0], [12, 5], [0, 5]]}  # the lower half of the map
    g = gen(map_spec={"type": "empty", "width": 12.0, "height": 10.0}, forbidden_zones=[zone])
    for i in range(10):
        ep = g.episode(i)
        ys = [ep.robots[0].start.y, ep.robots[0].goal.y, *ep.agents.positions[:, 1]]
        assert min(ys) > 5.0
    g = gen(
        map_spec={"type": "empty", "width": 12.0, "height": 10.0},
        forbidden_zones=[zone],
        modules=["clear_forbidden_zones"],
    )
    ys = [g.episode(i).robots[0].start.y for i in range(20)]
    assert min(ys) < 5.0


def test_forbidden_zone_needs_one_shape():
    with pytest.raises(ValueError, match="either center and radius"):
        TaskConfig.model_validate({"forbidden_zones": [{"center": [1, 1]}]})


def test_goal_reached_distance_and_heading():
    goal = Pose2D(1.0, 1.0, math.pi - 0.1)
    assert goal_reached(Pose2D(1.2, 1.0, -math.pi + 0.1), goal, 0.3, math.radians(30))
    assert not goal_reached(Pose2D(1.2, 1.0, 0.0), goal, 0.3, math.radians(30))
    assert goal_reached(Pose2D(1.2, 1.0, 0.0), goal, 0.3, None)
    assert not goal_reached(Pose2D(1.31, 1.0, goal.theta), goal, 0.3, None)
    assert heading_error(3 * math.pi, -math.pi) == pytest.approx(0.0)
    assert heading_error(0.1, 2 * math.pi - 0.1) == pytest.approx(0.2)


def test_runtime_reports_arrival_with_heading():
    g = gen(goal_tolerance_angle=0.5)
    ep = g.episode(0)
    rt = g.runtime(ep)
    goal = ep.robots[0].goal
    wrong = np.array([[goal.x, goal.y, goal.theta + 1.0]])
    assert not rt.update(0.0, wrong).done
    right = np.array([[goal.x, goal.y, goal.theta + 0.2]])
    upd = rt.update(0.1, right)
    assert upd.done and upd.reached == [0] and rt.goals_reached == [1]


def test_mode_errors_name_role_and_place():
    with pytest.raises(UnknownNameError, match=r"task\.robots\.type.*did you mean 'random'"):
        build_mode("robots", {"type": "randon"}, path="task.robots")
    with pytest.raises(ConfigError, match=r"task\.obstacles\.static"):
        build_mode("obstacles", {"type": "random", "static": [3, 1]}, path="task.obstacles")
    with pytest.raises(ConfigError, match=r"task\.modules\[0\].*missing 'type'"):
        build_mode("modules", {"episodes_per_map": 3}, path="task.modules[0]")
