"""The one episode loop: hook order, tick-by-tick = run-to-end, failures end the episode."""

import math

import numpy as np
import pytest

import arena.plugins  # noqa: F401  (fills the registries)
from arena.config import load_config
from arena.core.errors import NoPathFound
from arena.core.types import Outcome
from arena.crowd.driver import build_driver
from arena.episode.navigation import NavigationController, build_stack
from arena.episode.runner import EpisodeHooks, EpisodeRunner
from arena.eval.record import EpisodeMeta
from arena.eval.recorder import Recorder
from arena.experiment import make_episode, run_episode
from arena.learn.env import SocialNavEnv
from arena.learn.planners.crowdnav import ValuePlannerParams
from arena.learn.value.train import RecordingPlanner, run_training_episode
from arena.maps.grid import OccupancyGrid
from arena.nav.local_planners.base import LOCAL_PLANNERS
from arena.robots.presets import load_robot
from arena.sim.native2d import Native2DBackend
from arena.tasks.generator import TaskGenerator, TaskRuntime
from tests.conftest import make_episode as hand_episode
from tests.conftest import standing_agents

SHORT = ["output.video=false", "task.obstacles.dynamic=4", "task.obstacles.static=2",
         "task.timeout=6", "task.robots.min_goal_distance=4", "episodes=1"]


class Log(EpisodeHooks):
    """Notes every call: ``(name, hook, state.step, state.time)``."""

    def __init__(self, name: str, calls: list) -> None:
        self.name, self.calls = name, calls

    def _note(self, what, runner):
        self.calls.append((what, self.name, runner.state.step, round(runner.state.time, 9)))

    def initialize_episode(self, runner):
        self._note("initialize_episode", runner)

    def before_step(self, runner):
        self._note("before_step", runner)

    def after_step(self, runner):
        self._note("after_step", runner)

    def episode_end(self, runner):
        self._note("episode_end", runner)


class Constant:
    """Drives forward at ``v`` m/s; ``fail_at``: raise that exception at that tick."""

    def __init__(self, v=0.5, fail_at=None, error=None):
        self.v, self.fail_at, self.error = v, fail_at, error

    def command(self, runner):
        if runner.ticks == self.fail_at:
            raise self.error
        return np.array([[self.v, 0.0, 0.0]])


def _episode(room, time_limit=0.35, agents=None):
    jackal = load_robot("jackal")
    return hand_episode(room, [(jackal, (2, 5, 0), (8, 5, 0))], time_limit=time_limit,
                        agents=agents)


def _crowd():
    return build_driver({"type": "pysocial"}, None)


def test_hooks_are_called_in_order_with_each_state(room):
    calls: list = []
    runner = EpisodeRunner(Native2DBackend(), 0.1, [Log("a", calls), Log("b", calls)],
                           Constant())
    runner.reset(_episode(room), _crowd(), seed=0)
    assert runner.run() is Outcome.TIMEOUT
    expected = [("initialize_episode", "a", 0, 0.0), ("initialize_episode", "b", 0, 0.0)]
    for k in range(4):  # 0.35 s at 0.1 s: four steps, the fifth tick meets the limit
        expected += [("before_step", h, k, round(0.1 * k, 9)) for h in "ab"]
        expected += [("after_step", h, k + 1, round(0.1 * (k + 1), 9)) for h in "ab"]
    expected += [("before_step", h, 4, 0.4) for h in "ab"]
    expected += [("episode_end", h, 4, 0.4) for h in "ab"]
    assert calls == expected
    assert runner.ticks == 4
    assert runner.events == [(pytest.approx(0.4), "outcome", "timeout")]
    assert not runner.tick()  # an ended episode does not step
    assert runner.state.step == 4


def test_a_hook_ends_the_episode_and_later_hooks_wait(room):
    calls: list = []

    class Stop(EpisodeHooks):
        def before_step(self, runner):
            if runner.ticks == 2:
                runner.end(Outcome.SUCCESS)

    runner = EpisodeRunner(Native2DBackend(), 0.1, [Stop(), Log("a", calls)], Constant())
    runner.reset(_episode(room, time_limit=5.0), _crowd(), seed=0)
    assert runner.run() is Outcome.SUCCESS
    assert [c[0] for c in calls[-2:]] == ["after_step", "episode_end"]
    assert runner.state.step == 2


@pytest.mark.parametrize(("error", "outcome", "text"), [
    (RuntimeError("boom\nsecond line"), Outcome.ERROR, "RuntimeError: boom (at test_runner.py:"),
    (NoPathFound("no way"), Outcome.PLANNER_FAILURE, "NoPathFound: no way"),
])
def test_an_exception_in_the_controller_ends_the_episode(room, error, outcome, text):
    calls: list = []
    recorder = Recorder()
    runner = EpisodeRunner(Native2DBackend(), 0.1, [recorder, Log("a", calls)],
                           Constant(fail_at=2, error=error))
    runner.reset(_episode(room, time_limit=5.0), _crowd(), seed=0)
    assert runner.run() is outcome
    assert runner.error.startswith(text)
    assert runner.exception is error
    assert len(recorder) == 3  # the reset and the two steps before the failure
    assert [c[0] for c in calls].count("episode_end") == 1
    assert runner.events[-1][1:] == ("outcome", outcome.value)


def test_a_failing_first_plan_still_records_the_first_state():
    occ = np.zeros((200, 200), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    occ[140:180, 140] = occ[140:180, 180] = True  # a closed box around (8, 8)
    occ[140, 140:181] = occ[180, 140:181] = True
    grid = OccupancyGrid.from_occupied(occ, 0.05)
    episode = hand_episode(grid, [(load_robot("burger"), (2, 2, 0), (8, 8, 0))])
    cfg = load_config(None, ["output.video=false"])
    robot = episode.robots[0].model
    nav = NavigationController(build_stack(cfg.navigation, robot, episode),
                               TaskRuntime.single_goal(episode), robot)
    recorder = Recorder()
    runner = EpisodeRunner(Native2DBackend(), 0.1, [recorder, nav], nav)
    runner.reset(episode, _crowd(), seed=0)
    assert runner.outcome is Outcome.PLANNER_FAILURE  # ended by initialize_episode
    assert runner.run() is Outcome.PLANNER_FAILURE
    assert len(recorder) == 1
    assert runner.ticks == 0


def _benchmark_runner(cfg, episode):
    robot = episode.robots[0].model
    nav = NavigationController(build_stack(cfg.navigation, robot, episode),
                               TaskRuntime.single_goal(episode), robot)
    recorder = Recorder()
    return EpisodeRunner(Native2DBackend(), cfg.sim.dt, [recorder, nav], nav), recorder


def test_ticking_from_outside_equals_running_to_the_end_and_run_episode():
    cfg = load_config(None, SHORT)
    episode = make_episode(cfg, 0, load_robot(cfg.robot))
    assert len(episode.agents)  # people moving
    res = run_episode(cfg, episode, Native2DBackend(), None)
    runner, recorder = _benchmark_runner(cfg, episode)
    runner.reset(episode, build_driver(cfg.crowd, cfg.pedestrians), cfg.seed)
    ticks = 0
    while runner.tick():
        ticks += 1
    assert runner.outcome.value == res.outcome
    meta = EpisodeMeta(0, 0, "", "", "", 0.1, np.zeros(3), np.zeros(3), 0.1, None, 1.0, 0.1, "")
    rec = recorder.finish(meta)
    np.testing.assert_array_equal(rec.pose, res.record.pose)
    np.testing.assert_array_equal(rec.ped_position, res.record.ped_position)
    assert rec.steps == res.steps + 1 > 10

    # the same commands through advance() (how an env steps the runner) give the same run
    plain = EpisodeRunner(Native2DBackend(), cfg.sim.dt)
    plain.reset(episode, build_driver(cfg.crowd, cfg.pedestrians), cfg.seed)
    poses = [plain.state.robots.poses[0].copy()]
    for cmd in res.record.command[1:]:
        poses.append(plain.advance(cmd[None, :]).robots.poses[0].copy())
    np.testing.assert_array_equal(np.array(poses), res.record.pose)
    assert plain.ticks == res.steps


def test_the_value_trainer_drives_the_benchmark_loop():
    # a training episode with ORCA as local planner is the benchmark episode with ORCA
    cfg = load_config(None, [*SHORT, "navigation.local_planner.type=orca", "crowd.type=orca"])
    robot = load_robot(cfg.robot)
    generator = TaskGenerator.from_config(cfg, [robot])
    planner = RecordingPlanner(LOCAL_PLANNERS.build({"type": "orca"}), ValuePlannerParams(),
                               (3.0,))
    (log,) = run_training_episode(cfg, generator, Native2DBackend(), 0, planner)
    res = run_episode(cfg, generator.episode(0), Native2DBackend(), None)
    rows = np.rint(np.asarray(log.times) / cfg.sim.dt).astype(int)
    assert len(rows) > 10
    np.testing.assert_array_equal(np.asarray(log.robots)[:, :2], res.record.pose[rows, :2])
    assert not res.record.collision.any()  # so the trainer ran the whole episode too
    assert log.outcome == res.outcome == "timeout"
    assert log.sim_time == pytest.approx(res.time)


def test_the_learning_env_steps_the_runner():
    env = SocialNavEnv(overrides=SHORT)
    env.reset(seed=4)
    driver = env.driver
    for k in range(5):
        env.step(env.action_space.sample())
        assert driver.runner.ticks == k + 1
        assert driver.state is driver.runner.state
        assert driver.state.step == k + 1
    assert driver.runner.episode is driver.episode
    assert math.isfinite(driver.state.time)


def test_the_hook_order_does_not_depend_on_standing_people(room):
    # people standing in the way: the same hooks, the same recorded crowd on two runs
    agents = standing_agents([[4.0, 5.0], [6.0, 5.5]])
    recs = []
    for _ in range(2):
        recorder = Recorder()
        runner = EpisodeRunner(Native2DBackend(), 0.1, [recorder], Constant(v=1.0))
        runner.reset(_episode(room, time_limit=3.0, agents=agents), _crowd(), seed=1)
        runner.run()
        recs.append(recorder.finish(EpisodeMeta(0, 0, "", "", "", 0.1, np.zeros(3),
                                                np.zeros(3), 0.1, None, 1.0, 0.1, "")))
    np.testing.assert_array_equal(recs[0].pose, recs[1].pose)
    np.testing.assert_array_equal(recs[0].collision, recs[1].collision)
    assert recs[0].collision.any()  # driving into the people
