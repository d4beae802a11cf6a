"""World ``w`` of an ``Engine(W)`` equals ``native2d`` on the same episode, bit for bit.

Every registered crowd model, every kinematics kind, W = 1, 3 and 8 with different episodes
per world and one world restarting mid-run, serial and parallel kernels, circle and legs
bodies, multi-robot worlds, ``collision_response`` stop and record.
"""

from __future__ import annotations

import pytest

import arena.plugins  # noqa: F401  (fills the registries)
from arena.crowd.base import CROWD_MODELS
from arena.sim.engine import EngineParams
from tests.sim.engine.helpers import episodes, lock_step


@pytest.mark.parametrize("model", CROWD_MODELS.names())
def test_every_crowd_model(model: str) -> None:
    peds = {"social_states": "true", "initial_levels": "random"} if model == "pysocial" else {
        "social_states": "false"}
    if model == "fast_social_force":  # it has no groups (and says so once if asked for them)
        peds["group_fraction"] = "0"
    eps = episodes(["jackal"], 4, "task.obstacles.dynamic=8")
    seen = lock_step(eps, {"type": model}, pedestrians=peds, steps=60)
    if model != "spinny":  # spinny turns people on the spot
        assert seen["people_moved"], model
    if model == "pysocial":
        assert seen["states_seen"] and seen["groups"]


@pytest.mark.parametrize("robot", ["jackal", "burger", "ridgeback", "f1tenth", "go1"])
def test_every_kinematics_kind(robot: str) -> None:
    eps = episodes([robot], 4)
    seen = lock_step(eps, {"type": "waypoint_walker"}, steps=80, speed=2.5)
    assert seen["people_moved"]


def test_collisions_happen_and_agree() -> None:
    eps = episodes(["jackal"], 9, "task.obstacles.static=6")
    seen = lock_step(eps, {"type": "waypoint_walker"}, steps=120, speed=3.0)
    assert seen["collided"]


@pytest.mark.parametrize("parallel_min_worlds", [1, 1000])
@pytest.mark.parametrize("body", ["circle", "legs"])
def test_many_worlds_serial_and_parallel_bodies(parallel_min_worlds: int, body: str) -> None:
    eps = episodes(["jackal"], 9)
    params = EngineParams(pedestrian_body=body, parallel_min_worlds=parallel_min_worlds)
    lock_step(eps, {"type": "pysocial"}, pedestrians={"social_states": "true"}, params=params,
              steps=50)


def test_one_world_with_reset() -> None:
    lock_step(episodes(["burger"], 2), None, steps=40, reset_at=20)


@pytest.mark.parametrize("response", ["stop", "record"])
def test_multi_robot_worlds(response: str) -> None:
    eps = episodes(["jackal", "burger", "ridgeback"], 4)
    params = EngineParams(collision_response=response, pedestrian_body="legs")
    seen = lock_step(eps, {"type": "waypoint_walker"}, params=params, steps=60, speed=2.0)
    assert seen["people_moved"]


def test_lidar_off_and_people_invisible() -> None:
    eps = episodes(["jackal"], 3)
    lock_step(eps, {"type": "waypoint_walker"}, params=EngineParams(lidar=False), steps=20)
    lock_step(eps, {"type": "waypoint_walker"},
              params=EngineParams(pedestrians_block_lidar=False), steps=20)
