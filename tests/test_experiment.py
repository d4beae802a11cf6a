"""The experiment loop end to end: determinism, outcomes, files."""

import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from arena import cli
from arena.config import load_config
from arena.core.errors import ArenaError, ConfigError
from arena.core.types import Outcome, Pose2D
from arena.crowd.base import CROWD_MODELS
from arena.experiment import make_episode, run_episode, run_experiment
from arena.maps.grid import OccupancyGrid
from arena.nav.local_planners.base import LOCAL_PLANNERS
from arena.nav.local_planners.pure_pursuit import PurePursuitPlanner
from arena.robots.presets import load_robot
from arena.sim.native2d import Native2DBackend
from tests.conftest import make_episode as hand_episode

FAST = [
    "output.video=false",
    "task.obstacles.dynamic=6",
    "task.obstacles.static=2",
    "task.timeout=20",
    "task.robots.min_goal_distance=6",
    "episodes=2",
]


def test_same_seed_identical_files(tmp_path):
    cfg = load_config(None, FAST)
    out_a, res_a = run_experiment(cfg, tmp_path / "a")
    out_b, res_b = run_experiment(cfg, tmp_path / "b")
    for i in range(2):
        for name in ("trajectory.csv", "agents.csv"):
            a = (out_a / f"episode_{i:03d}" / name).read_bytes()
            b = (out_b / f"episode_{i:03d}" / name).read_bytes()
            assert a == b, f"episode {i} {name} differs between two runs with one seed"
    assert [r.outcome for r in res_a] == [r.outcome for r in res_b]
    other = run_experiment(load_config(None, [*FAST, "seed=1"]), tmp_path / "c")[0]
    assert (other / "episode_000" / "trajectory.csv").read_bytes() != (
        out_a / "episode_000" / "trajectory.csv"
    ).read_bytes()


def test_episodes_differ_within_a_run():
    cfg = load_config(None, FAST)
    e0, e1 = make_episode(cfg, 0), make_episode(cfg, 1)
    assert e0.robots[0].start != e1.robots[0].start


def test_success_is_reached_goal(tmp_path):
    cfg = load_config(
        None, [*FAST, "task.obstacles.dynamic=0", "task.obstacles.static=0", "task.timeout=60"]
    )
    _, results = run_experiment(cfg, tmp_path)
    for r in results:
        assert r.outcome == Outcome.SUCCESS
        assert r.final_goal_distance < 0.3
        info = json.loads((tmp_path / f"episode_{r.index:03d}" / "episode.json").read_text())
        assert info["outcome"] == "success"


def test_enclosed_goal_is_a_planner_failure():
    occ = np.zeros((200, 200), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    occ[140:180, 140] = occ[140:180, 180] = True  # a closed box around (8, 8)
    occ[140, 140:181] = occ[180, 140:181] = True
    grid = OccupancyGrid.from_occupied(occ, 0.05)
    ep = hand_episode(grid, [(load_robot("burger"), (2, 2, 0), (8, 8, 0))])
    cfg = load_config(None, ["output.video=false"])
    res = run_episode(cfg, ep, Native2DBackend(), None)
    assert res.outcome == Outcome.PLANNER_FAILURE
    assert "NoPathFound" in res.error or "GoalOccupied" in res.error


def test_timeout(tmp_path):
    cfg = load_config(None, [*FAST, "robot=burger", "task.timeout=2", "episodes=1"])
    _, (res,) = run_experiment(cfg, tmp_path)
    assert res.outcome == Outcome.TIMEOUT
    assert abs(res.time - 2.0) < 1e-6


@pytest.mark.parametrize("model", sorted(CROWD_MODELS.names()))
def test_every_crowd_model_runs_an_episode(model, tmp_path):
    cfg = load_config(
        None,
        [
            f"crowd.type={model}",
            "task.obstacles.dynamic=8",
            "task.obstacles.static=1",
            "task.timeout=6",
            "output.video=false",
            "pedestrians.initial_levels=random",
            # the fast crowd has no social states or groups (it would say so, once per process)
            *(["pedestrians.social_states=false", "pedestrians.group_fraction=0"]
              if model == "fast_social_force" else []),
        ],
    )
    _, (res,) = run_experiment(cfg, tmp_path)
    assert res.outcome in {o.value for o in Outcome}
    assert res.outcome != Outcome.ERROR, res.error
    agents = np.loadtxt(tmp_path / "episode_000" / "agents.csv", delimiter=",", skiprows=1)
    assert agents.shape[0] == 8 * (res.steps + 1)
    assert np.all(np.isfinite(agents))


def test_scenario_task_runs_a_packaged_world(tmp_path):
    from arena.maps.sources import WORLDS_DIR

    file = WORLDS_DIR / "corridor" / "scenarios" / "default.json"
    cfg = load_config(
        None,
        [
            "map.name=corridor",
            "task.robots.type=scenario",
            f"task.robots.file={file}",
            "task.obstacles.type=scenario",
            f"task.obstacles.file={file}",
            "episodes=2",
            "output.video=false",
            "task.timeout=60",
        ],
    )
    _, results = run_experiment(cfg, tmp_path)
    assert [r.outcome for r in results] == ["success", "success"]
    assert results[0].start == [-13.5, 0.0, 0.0]  # from the file
    # The same file every episode: the robot starts at the same pose.
    assert results[1].start == results[0].start


def test_scenario_task_rejects_positions_in_walls(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{"robots": [{"start": [-15.5, 0, 0], "goal": [13, 0, 0]}]}')
    cfg = load_config(
        None,
        [
            "map.name=corridor",
            "task.robots.type=scenario",
            f"task.robots.file={bad}",
            "output.video=false",
        ],
    )
    with pytest.raises(ConfigError, match=r"bad\.json: robots\[0\]\.start"):
        run_experiment(cfg, tmp_path / "out")
    assert not (tmp_path / "out").exists()  # failed before writing anything


@pytest.mark.parametrize("robot", ["jackal", "burger"])
def test_heading_tolerance_is_met_by_aligning_at_the_goal(robot):
    from dataclasses import replace

    grid = OccupancyGrid.empty(8.0, 6.0, 0.05)
    ep = hand_episode(grid, [(load_robot(robot), (1.5, 3.0, 0.0), (4.5, 3.0, 3.0))])
    ep = replace(ep, goal_tolerance_angle=0.5236, time_limit=60.0)
    cfg = load_config(None, ["output.video=false"])
    res = run_episode(cfg, ep, Native2DBackend(), None)
    assert res.outcome == Outcome.SUCCESS
    assert res.final_goal_distance < ep.goal_radius


def test_teleport_moves_the_robot_at_rest():
    from arena.testing.conformance import standard_episode

    backend = Native2DBackend()
    backend.reset(standard_episode(0), None, np.random.default_rng(0))
    s = backend.step(np.array([[1.0, 0.0, 0.5], [0.2, 0.0, 0.0]]), 0.1)
    t = backend.teleport(0, Pose2D(5.0, 5.0, 1.0))
    assert np.allclose(t.robots.poses[0], [5.0, 5.0, 1.0]) and np.allclose(t.robots.twists[0], 0)
    assert t.time == s.time and not t.collisions.any[0]


class _BoomPlanner(PurePursuitPlanner):
    """Raises a plain Python exception after half a simulated second."""

    def compute(self, obs):  # type: ignore[no-untyped-def]
        if obs.time > 0.5:
            raise RuntimeError("boom from the test planner")
        return super().compute(obs)


class _BadInitPlanner(PurePursuitPlanner):
    """Raises while it is built (before the episode's first step)."""

    def __init__(self, params=None):  # type: ignore[no-untyped-def]
        raise ValueError("cannot build the test planner")


@pytest.fixture
def raising_planners(monkeypatch):
    """Register the raising planners for one test only."""
    monkeypatch.setattr(LOCAL_PLANNERS, "_entries", dict(LOCAL_PLANNERS._entries))
    LOCAL_PLANNERS.add("test_experiment_boom", _BoomPlanner)
    LOCAL_PLANNERS.add("test_experiment_bad_init", _BadInitPlanner)


@pytest.mark.usefixtures("raising_planners")
@pytest.mark.parametrize(("planner", "error"), [
    ("test_experiment_boom", "RuntimeError: boom from the test planner (at test_experiment.py:"),
    ("test_experiment_bad_init", "ValueError: cannot build the test planner (at "),
])
def test_a_raising_planner_costs_its_episode_only(planner, error, tmp_path):
    cfg = load_config(None, [*FAST, "episodes=3", f"navigation.local_planner.type={planner}"])
    rows_seen = []

    def seen(res):  # summary.csv already holds every finished episode
        rows_seen.append((tmp_path / "summary.csv").read_text().count("\n") - 1)

    _, results = run_experiment(cfg, tmp_path, on_episode=seen)
    assert [r.outcome for r in results] == ["error"] * 3  # every episode ran
    assert all(r.error.startswith(error) for r in results)
    assert rows_seen == [1, 2, 3]
    lines = (tmp_path / "summary.csv").read_text().splitlines()
    assert len(lines) == 4 and all(",error," in line for line in lines[1:])
    if planner == "test_experiment_boom":  # the steps before the fault are recorded
        assert results[0].record is not None and results[0].time > 0.5
        assert (tmp_path / "episode_000" / "episode.parquet").is_file()
    else:
        assert results[0].record is None and math.isnan(results[0].time)


@pytest.mark.usefixtures("raising_planners")
def test_cli_run_logs_a_raising_planner_in_one_line(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(sys, "argv", ["arena", "run", *FAST, "-o", str(tmp_path),
                                      "navigation.local_planner.type=test_experiment_boom"])
    monkeypatch.setattr(cli.console, "width", 300)
    with pytest.raises(SystemExit) as ok:
        cli.main()
    out, err = capsys.readouterr()
    assert ok.value.code in (0, None), err
    lines = [line for line in out.splitlines() if "episode " in line and "error" in line]
    assert len(lines) == 2, out
    assert all("RuntimeError: boom from the test planner" in line for line in lines)
    assert "Traceback" not in out + err
    assert (tmp_path / "summary.csv").read_text().count("\n") == 3


@pytest.mark.parametrize("where", ["file", "dev_null", "long_name"])
def test_output_folder_that_cannot_be_made_is_a_one_line_error(where, tmp_path):
    target = {"file": tmp_path / "taken", "dev_null": "/dev/null",
              "long_name": tmp_path / ("x" * 300)}[where]
    if where == "file":
        target.write_text("mine")
    with pytest.raises(ArenaError, match=r"output folder \(output\.dir, -o\)"):
        run_experiment(load_config(None, FAST), Path(target))


def test_video_is_readable_and_its_legend_lists_what_it_shows(tmp_path, monkeypatch):
    import imageio.v3 as iio

    import arena.render as render
    from arena.render import style

    legends, plans = [], []

    class Recording(render.FrameRenderer):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            legends.append(self.legend)

        def render(self, state, overlay=None):
            plans.append((state.robots.poses[0, :2].copy(), overlay.paths[0]))
            return super().render(state, overlay)

    monkeypatch.setattr(render, "FrameRenderer", Recording)
    cfg = load_config(None, [*FAST, "output.video=true", "episodes=1", "task.timeout=4",
                             "output.frame_every=4"])
    _, (res,) = run_experiment(cfg, tmp_path)
    meta = iio.immeta(res.files["video"], extension=".mp4")
    width, height = meta["size"]
    assert width == 800 and height % 2 == 0  # the default output.width_px, even for H.264
    assert meta["codec"] == "h264"
    (legend,) = legends
    elements = [e for e in legend if e not in style.AGENT_STATE_NAMES]
    expected = ["robot", "collision", "trail", "plan", "goal", "lidar"]
    if res.collisions == 0:
        expected.remove("collision")
    assert elements == expected
    assert 1 <= len(legend) - len(elements) <= len(style.AGENT_STATE_NAMES)  # people's states
    # each frame shows the plan of its time: the first one starts where the robot starts
    (start, first), (end, final) = plans[0], plans[-1]
    assert np.hypot(*(first[0] - start)) < 0.3
    assert np.hypot(*(end - start)) > 1.0  # the robot drove off
    assert np.hypot(*(final[0] - start)) > 1.0  # and replanned: the last frame's plan is newer
