"""The counterfactual crowd (replayed without the robot) and the cf_* metrics end to end."""

from __future__ import annotations

import math

import numpy as np
import pytest

from arena.config import load_config
from arena.eval.counterfactual import CrowdTrack, align
from arena.eval.io import load_record, save_record
from arena.eval.metrics import compute_metrics
from arena.experiment import make_episode, run_episode
from arena.robots.presets import load_robot
from arena.sim.native2d import Native2DBackend

CF = ("cf_displacement_mean", "cf_displacement_max", "cf_people_displaced")


def _run(overrides, index=0):
    cfg = load_config(None, ["output.video=false", "task.timeout=15", *overrides])
    episode = make_episode(cfg, index, load_robot(cfg.robot))
    return run_episode(cfg, episode, Native2DBackend(), None)


def test_align_matches_rows_by_step_and_id():
    track = CrowdTrack(
        row=np.array([0, 0, 1, 1, 2]), ids=np.array([7, 3, 3, 7, 3]),
        positions=np.array([[0.0, 7], [0, 3], [1, 3], [1, 7], [2, 3]]),
    )
    out = align(np.array([0, 0, 1, 2, 2]), np.array([3, 7, 7, 3, 7]), track)
    np.testing.assert_array_equal(out[:4], [[0, 3], [0, 7], [1, 7], [2, 3]])
    assert np.isnan(out[4]).all()  # id 7 is missing at step 2 in the replay


def test_crowd_that_ignores_robots_is_not_displaced():
    # buddy's lidar is noisy: the crowd still gets the same draws without the robot's scans.
    # The walker has no robot term; the statechart (off here) would react to the robot.
    res = _run(["robot=buddy", "crowd.type=waypoint_walker", "task.obstacles.dynamic=6",
                "task.obstacles.static=0", "pedestrians.social_states=false"])
    rec = res.record
    assert rec.ped_cf_position is not None and rec.ped_position.shape[0] > 0
    np.testing.assert_array_equal(rec.ped_cf_position, rec.ped_position)
    values = compute_metrics(rec, CF)
    assert values == {"cf_displacement_mean": 0.0, "cf_displacement_max": 0.0,
                      "cf_people_displaced": 0.0}


def test_reacting_crowd_is_displaced_deterministically():
    over = ["crowd.type=pedsim", "task.obstacles.dynamic=12", "task.obstacles.static=0",
            "map.type=empty"]
    rows = []
    for _ in range(2):
        rec = _run(over).record
        rows.append(compute_metrics(rec, CF))
    assert rows[0] == rows[1]  # one seed, one counterfactual
    v = rows[0]
    assert v["cf_displacement_max"] > 0.05
    assert 0 < v["cf_displacement_mean"] <= v["cf_displacement_max"]
    assert 0 < v["cf_people_displaced"] <= 1


def test_people_far_from_the_robot_are_not_displaced():
    # 30 m × 30 m: most people never come near the robot, nor near anyone it disturbed.
    rec = _run(["crowd.type=pedsim", "task.obstacles.dynamic=12", "task.obstacles.static=0",
                "map.type=empty", "map.width=30", "map.height=30"]).record
    d = np.hypot(*(rec.ped_position - rec.ped_cf_position).T)
    gap = np.hypot(*(rec.ped_position - rec.pose[rec.ped_row, :2]).T)
    ids = np.unique(rec.ped_id)
    closest = np.array([gap[rec.ped_id == i].min() for i in ids])
    moved = np.array([d[rec.ped_id == i].max() for i in ids])
    far = closest > 5.0
    assert far.sum() >= 6
    # Social forces have exponential tails: far people move by far less than a millimetre.
    assert moved[far].max() < 1e-3


def test_counterfactual_can_be_switched_off_and_survives_parquet(tmp_path):
    off = _run(["evaluation.counterfactual=false", "task.obstacles.dynamic=3"]).record
    assert off.ped_cf_position is None
    assert all(math.isnan(v) for v in compute_metrics(off, CF).values())
    on = _run(["task.obstacles.dynamic=3"]).record
    back = load_record(save_record(on, tmp_path / "e.parquet"))
    np.testing.assert_array_equal(back.ped_cf_position, on.ped_cf_position)
    assert load_record(save_record(off, tmp_path / "f.parquet")).ped_cf_position is None


@pytest.mark.parametrize("typo", ["evaluation.counterfactuals=false", "evaluation.cf=true"])
def test_misspelt_evaluation_keys_are_rejected(typo):
    from arena.core.errors import ConfigError

    with pytest.raises(ConfigError, match="evaluation"):
        load_config(None, [typo])
