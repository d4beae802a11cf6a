"""The ``mujoco`` simulator backend: MuJoCo contacts as the truth, the engine's contract."""

from __future__ import annotations

import json
import subprocess
import sys
from typing import Literal

import numpy as np
import pytest
from pydantic import BaseModel, ConfigDict

from arena import cli
from arena.config import load_config
from arena.core.errors import ConfigError
from arena.core.rng import derive_rng
from arena.core.types import Pose2D
from arena.crowd.models.walker import WaypointWalker
from arena.crowd.simulator import CrowdSimulator, PedestrianConfig
from arena.eval.store import load_results, read_manifest
from arena.experiment import run_experiment
from arena.learn.env import SocialNavEnv
from arena.robots.model import RobotModel
from arena.robots.presets import load_robot
from arena.scene.state import AgentStates
from arena.sensors.base import SENSORS
from arena.sim.backend import BACKENDS
from arena.sim.mujoco.backend import MujocoBackend
from arena.sim.mujoco.mjcf import to_mjcf
from arena.sim.mujoco.params import MujocoParams
from arena.sim.native2d import Native2DBackend
from tests.eval._suites import stage
from tests.mujoco_kit import require_mujoco
from tests.sim.engine.helpers import assert_same_state
from tests.sim.mujoco.scenes import episode, people

require_mujoco()

HALF = np.pi / 2


def teleported(backend, ep, pose, *, robot: int = 0):
    backend.reset(ep, None, derive_rng(0, "contacts"))
    return backend.teleport(robot, Pose2D(*pose)).collisions


# -- registry and configuration -------------------------------------------------------------------
def test_a_config_naming_mujoco_validates_without_importing_it():
    code = (
        "import sys\n"
        "from arena.config import load_config\n"
        "from arena.sim.backend import BACKENDS\n"
        "cfg = load_config(None, ['sim.backend.type=mujoco', 'sim.backend.max_substep=0.02',"
        " 'sim.backend.world.wall_height=3'])\n"
        "_, p = BACKENDS.validate(cfg.sim.backend, path='sim.backend')\n"
        "assert p.world.wall_height == 3.0 and p.max_substep == 0.02, p\n"
        "assert 'mujoco' not in sys.modules, 'mujoco imported'\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


def test_bad_backend_fields_are_one_line_errors():
    with pytest.raises(ConfigError, match=r"sim\.backend\.lidar_hieght: unknown key") as err:
        load_config(None, ["sim.backend.type=mujoco", "sim.backend.lidar_hieght=0.3"])
    assert "\n" not in str(err.value)
    with pytest.raises(ConfigError, match="max_substep"):
        BACKENDS.validate({"type": "mujoco", "max_substep": 0}, path="sim.backend")
    backend = BACKENDS.build({"type": "mujoco", "collision_response": "record"},
                             path="sim.backend")
    assert isinstance(backend, MujocoBackend)
    assert backend.params.collision_response == "record"


def test_robot_bodies_have_a_free_joint_in_the_written_mjcf():
    b = MujocoBackend()
    b.reset(episode(), None, derive_rng(0, "x"))
    xml = to_mjcf(b.world3d.scene)
    assert '<freejoint name="robot/robot/free"' in xml
    assert 'mocap="true"' not in xml.split('name="robot/robot"')[1].split(">")[0]


# -- contacts -------------------------------------------------------------------------------------
def test_wall_obstacle_and_robot_contacts_name_what_was_touched():
    b = MujocoBackend()
    assert teleported(b, episode(), (3.9, 1.0, 0.0)).wall.tolist() == [True]  # the wall stub
    c = teleported(b, episode(), (5.4, 4.5, 0.0))  # its nose in box_a (index 0)
    assert c.obstacle.tolist() == [0] and not c.wall[0]
    c = teleported(b, episode(), (1.67, 3.75, HALF))  # box_b's (index 1) lowest corner
    assert c.obstacle.tolist() == [1]
    free = teleported(b, episode(), (3.0, 2.0, 0.7))
    assert not free.any[0]
    assert teleported(b, episode(), (0.15, 3.0, 0.0)).wall.tolist() == [True]  # the border
    two = episode([("a", "jackal", (1.0, 1.0, 0.0)), ("b", "jackal", (3.0, 1.0, 0.0))])
    c = teleported(b, two, (1.4, 1.0, 0.0), robot=1)  # b's back (1.19 m) behind a's nose
    assert c.robot.tolist() == [1, 0]


def test_people_are_touched_at_their_figure_not_their_2d_circle():
    # jackal nose at x 1.21 m; person 1's leg capsules (radius 0.065 m) at x = px
    b, flat = MujocoBackend(), Native2DBackend()
    touching = episode(agents=people([(6.0, 1.0), (1.25, 1.0)]))
    assert teleported(b, touching, (1.0, 1.0, 0.0)).agent.tolist() == [1]
    assert teleported(flat, touching, (1.0, 1.0, 0.0)).agent.tolist() == [1]
    near = episode(agents=people([(6.0, 1.0), (1.4, 1.0)]))  # inside the 0.3 m circle only
    assert teleported(b, near, (1.0, 1.0, 0.0)).agent.tolist() == [-1]
    assert teleported(flat, near, (1.0, 1.0, 0.0)).agent.tolist() == [1]


@pytest.mark.parametrize("response", ["stop", "record"])
def test_driving_into_a_wall(response):
    b = MujocoBackend(MujocoParams(collision_response=response))
    b.reset(episode([("robot", "jackal", (3.7, 1.0, 0.0))]), None, derive_rng(0, "w"))
    st = b.step(np.array([[1.0, 0.0, 0.0]]), 0.1)  # the nose reaches 4.0 m: the wall
    assert st.collisions.wall.tolist() == [True]
    if response == "stop":
        assert st.robots.poses[0].tolist() == [3.7, 1.0, 0.0]
        assert st.robots.twists[0].tolist() == [0.0, 0.0, 0.0]
    else:
        assert st.robots.poses[0, 0] > 3.75


def test_substeps_stop_a_fast_robot_tunnelling_through_a_wall():
    ep = episode([("robot", "jackal", (3.5, 1.0, 0.0))])
    cmd = np.array([[2.0, 0.0, 0.0]])
    coarse = MujocoBackend(MujocoParams(max_substep=1.0))  # one test at the end of the move
    coarse.reset(ep, None, derive_rng(0, "t"))
    st = coarse.step(cmd, 0.5)
    assert st.robots.poses[0, 0] - 0.21 > 4.1  # all of it beyond the 0.1 m wall, unseen
    assert not st.collisions.any[0]
    fine = MujocoBackend()  # max_substep 0.05 m
    fine.reset(ep, None, derive_rng(0, "t"))
    st = fine.step(cmd, 0.5)
    assert st.collisions.wall.tolist() == [True]
    assert st.robots.poses[0].tolist() == [3.5, 1.0, 0.0]


# -- the contract ---------------------------------------------------------------------------------
def walkers() -> CrowdSimulator:
    return CrowdSimulator(WaypointWalker(), PedestrianConfig(social_states=False))


def test_same_seed_same_trajectories_and_teleport():
    ep = episode(agents=people([(5.0, 1.0), (6.0, 3.0), (2.0, 2.5)], vmax=1.0, goal=(1.5, 1.5)))
    cmd = np.array([[0.5, 0.0, 0.2]])
    runs = []
    for _ in range(2):
        b = MujocoBackend()
        states = [b.reset(ep, walkers(), derive_rng(7, "det"))]
        states += [b.step(cmd, 0.1) for _ in range(30)]
        runs.append((b, states))
    for k, (s1, s2) in enumerate(zip(runs[0][1], runs[1][1], strict=True)):
        assert_same_state(s1, s2, f"step {k}")
    first = runs[0][1]
    assert not np.array_equal(first[0].agents.positions, first[-1].agents.positions)
    assert not np.array_equal(first[1].robots.scans[0], first[-1].robots.scans[0])
    b, states = runs[0]
    before = states[-1]
    st = b.teleport(0, Pose2D(5.5, 1.2, 2.0))
    assert (st.time, st.step) == (before.time, before.step)
    assert st.robots.poses[0].tolist() == [5.5, 1.2, 2.0]
    assert st.robots.twists[0].tolist() == [0.0, 0.0, 0.0]
    assert not np.array_equal(st.robots.scans[0], before.robots.scans[0])
    assert b.teleport(0, Pose2D(3.9, 1.0, 0.0)).collisions.wall.tolist() == [True]


class _GrowingCrowd:
    """People standing still; a second one appears next to the robot at the third step."""

    def reset(self, spawn, world, rng) -> AgentStates:
        self.n, self.steps = 1, 0
        return self._agents()

    def _agents(self) -> AgentStates:
        xy = np.array([[6.0, 3.0], [1.25, 1.0]])[: self.n]
        n = self.n
        zi = np.zeros(n, dtype=np.int64)
        return AgentStates(np.arange(n), xy, np.zeros((n, 2)), np.zeros(n), np.full(n, 0.3),
                           zi, zi.copy())

    def step(self, robots, dt) -> AgentStates:
        self.steps += 1
        self.n = 2 if self.steps >= 3 else 1
        return self._agents()


def test_a_crowd_that_grows_mid_episode_rebuilds_the_world():
    b = MujocoBackend()
    b.reset(episode(), _GrowingCrowd(), derive_rng(0, "g"))
    assert b.world3d.num_people == 1
    stop = np.zeros((1, 3))
    assert b.step(stop, 0.1).collisions.agent.tolist() == [-1]
    b.step(stop, 0.1)
    st = b.step(stop, 0.1)
    assert b.world3d.num_people == 2
    assert st.collisions.agent.tolist() == [1]  # the newcomer's legs touch the jackal's nose


# -- bad input -------------------------------------------------------------------------------------
class _ProbeSpec(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid")
    type: Literal["mj_backend_probe"] = "mj_backend_probe"
    update_rate: float = 10.0


class _ProbeBank:
    """A sensor type only the 2-D engine could serve (the MuJoCo backend has no bank for it)."""

    Params = _ProbeSpec


def test_unserved_sensor_type_and_missing_height_are_one_line_errors(monkeypatch):
    # registered for this test only (the sensor conformance test builds every registered bank)
    monkeypatch.setattr(SENSORS, "_entries", dict(SENSORS._entries))
    SENSORS.add("mj_backend_probe", _ProbeBank)
    data = load_robot("jackal").model_dump()
    data["sensors"]["probe"] = {"type": "mj_backend_probe"}
    probed = RobotModel.model_validate(data)
    b = MujocoBackend()
    with pytest.raises(ConfigError) as err:
        b.reset(episode([("r1", probed, (1.0, 1.0, 0.0))]), None, derive_rng(0, "e"))
    msg = str(err.value)
    assert "\n" not in msg
    assert "robot 'r1'" in msg and "sensor 'probe'" in msg and "'mj_backend_probe'" in msg
    assert "serves lidar2d" in msg
    tall = load_robot("dingo")
    assert tall.height is None
    with pytest.raises(ConfigError, match="'dingo': field 'height' is not set"):
        b.reset(episode([("r1", tall, (1.0, 1.0, 0.0))]), None, derive_rng(0, "e"))


# -- a whole run ----------------------------------------------------------------------------------
RUN = ["map.type=empty", "map.width=8", "map.height=6", "task.robots.min_goal_distance=3",
       "task.obstacles.static=2", "task.obstacles.dynamic=3", "task.timeout=30", "episodes=1",
       "output.video=false"]


def test_an_episode_with_people_ends_as_on_native2d(tmp_path):
    outcomes = {}
    for kind in ("native2d", "mujoco"):
        cfg = load_config(None, [*RUN, f"sim.backend.type={kind}"])
        _, (res,) = run_experiment(cfg, tmp_path / kind)
        assert res.error in ("", None), res.error
        outcomes[kind] = res.outcome
    assert outcomes["mujoco"] == outcomes["native2d"] == "success"


def test_the_gym_env_runs_on_mujoco():
    room = ["map.type=empty", "map.width=8", "map.height=8", "task.obstacles.static=0",
            "task.robots.min_goal_distance=3"]
    still = [*room, "task.obstacles.dynamic=0"]
    deep = SocialNavEnv(None, ["sim.backend.type=mujoco", *still], robot="jackal")
    flat = SocialNavEnv(None, still, robot="jackal")
    assert isinstance(deep.driver.backend, MujocoBackend)
    od, _ = deep.reset(seed=1)
    of, _ = flat.reset(seed=1)
    for key in ("goal", "last_action", "lidar"):  # an empty room: the same observation
        assert np.allclose(od[key], of[key], atol=1e-5), key
    runs = []
    for _ in range(2):  # with people: the same seed, the same episode
        env = SocialNavEnv(None, ["sim.backend.type=mujoco", *room,
                                  "task.obstacles.dynamic=3"], robot="jackal")
        env.action_space.seed(5)
        obs, _ = env.reset(seed=2)
        seen = [obs["lidar"]]
        for _ in range(20):
            obs, *_ = env.step(env.action_space.sample())
            seen.append(obs["lidar"])
        runs.append(np.array(seen))
    assert np.array_equal(runs[0], runs[1])
    assert not np.array_equal(runs[0][0], runs[0][-1])


def test_arena_bench_runs_on_mujoco_and_resumes_only_on_it(tmp_path, monkeypatch, capsys):
    suite, contest = tmp_path / "suite.yaml", tmp_path / "contest.yaml"
    suite.write_text("stages:\n" + stage("open", 1, "jackal", dynamic=(2, 2)))
    contest.write_text("contestants:\n  - {name: pp, local_planner: pure_pursuit}\n")
    run = tmp_path / "run"

    def call(*args: str) -> tuple[int, str]:
        monkeypatch.setattr(sys, "argv", ["arena", "bench", str(suite), *args])
        try:
            cli.main()
            code = 0
        except SystemExit as e:
            code = int(e.code or 0)
        return code, capsys.readouterr().err

    code, err = call("--contest", str(contest), "--simulator", "mujoco", "--workers", "0",
                     "-o", str(run), "--no-progress")
    assert code == 0, err
    assert read_manifest(run)["simulator"] == "mujoco"
    (row,) = load_results(run).to_pylist()
    assert row["outcome"] != "error", row["error"]
    code, err = call("--resume", str(run), "--workers", "0", "--no-progress")  # the run's own
    assert code == 0, err
    code, err = call("--resume", str(run), "--simulator", "native2d", "--no-progress")
    assert code == 2 and "cannot resume: field 'simulator'" in " ".join(err.split())
    # a run written before the key existed ran native2d
    manifest = json.loads((run / "run.json").read_text())
    del manifest["simulator"]
    (run / "run.json").write_text(json.dumps(manifest))
    code, err = call("--resume", str(run), "--simulator", "mujoco", "--no-progress")
    assert code == 2 and "of the run is 'native2d'" in " ".join(err.split())
