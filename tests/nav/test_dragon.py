"""Dragon: lidar gaps (swept and radial), admissible gaps, the subgoal toward the goal, episodes."""

from __future__ import annotations

import math

import numpy as np
import pytest

from arena.nav.local_planners import LOCAL_PLANNERS
from arena.nav.local_planners.dragon import DragonPlanner, segment_clearance
from arena.nav.local_planners.gaps import find_gaps
from tests.nav.planner_kit import DIFF, obs

BEAMS = np.linspace(-math.pi, math.pi, 720, endpoint=False)
STEP = 2 * math.pi / 720


def room_scan(radius: float, openings: list[tuple[float, float]]) -> np.ndarray:
    """A round room of ``radius`` m around the sensor, open at (bearing, half angle) rad."""
    ranges = np.full(BEAMS.shape, radius)
    for bearing, half in openings:
        off = np.abs(np.angle(np.exp(1j * (BEAMS - bearing))))
        ranges[off < half] = np.inf
    return ranges


def wall_scan(distance: float, opening: float, back: float | None = None) -> np.ndarray:
    """A straight wall ``distance`` m ahead (x), open over ``|y| < opening / 2``.

    Behind the opening a second wall at ``x = back`` when given; beams beyond 8 m see nothing.
    """
    c = np.cos(BEAMS)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(c > 0, distance / c, np.inf)
        through = np.abs(t * np.sin(BEAMS)) < opening / 2
        tb = np.where(c > 0, (back or np.inf) / c, np.inf)
    t = np.where(through, tb, t)
    return np.where(t < 8.0, t, np.inf)


def test_a_room_with_one_opening_has_one_swept_gap_there():
    half = 0.4
    gaps = find_gaps(room_scan(2.0, [(0.7, half)]), BEAMS, max_range=3.0, jump=0.5)
    assert len(gaps) == 1 and bool(gaps.swept[0])
    assert gaps.bearing[0] == pytest.approx(0.7, abs=STEP)
    # the sides are the last returns on either side: the chord across the opening
    assert gaps.width[0] == pytest.approx(2 * 2.0 * math.sin(half), abs=2 * 2.0 * STEP)


def test_an_opening_across_the_scan_seam_is_one_gap():
    gaps = find_gaps(room_scan(2.0, [(math.pi, 0.3)]), BEAMS, max_range=3.0, jump=0.5)
    assert len(gaps) == 1
    assert abs(np.angle(np.exp(1j * (gaps.bearing[0] - math.pi)))) < STEP
    assert gaps.left_angle[0] > gaps.right_angle[0]


def test_an_opening_with_a_wall_behind_is_one_radial_gap_of_its_width():
    # the back wall lies within the horizon: both edges of the opening are range jumps, which
    # describe the same passage (kept once)
    gaps = find_gaps(wall_scan(1.5, 1.0, back=3.5), BEAMS, max_range=6.0, jump=0.5)
    radial = ~gaps.swept
    assert radial.sum() == 1
    assert gaps.width[radial][0] == pytest.approx(1.0, abs=0.03)
    assert gaps.bearing[radial][0] == pytest.approx(0.0, abs=2 * STEP)


def test_an_empty_scan_has_no_gaps_and_bad_input_is_refused():
    assert len(find_gaps(np.full(90, np.inf), BEAMS[::8], max_range=3.0, jump=0.5)) == 0
    with pytest.raises(ValueError, match="differ in shape"):
        find_gaps(np.ones(3), np.ones(4), max_range=3.0, jump=0.5)


def _blocked_obs(ranges: np.ndarray, goal_bearing: float):
    goal = 5.0 * np.array([math.cos(goal_bearing), math.sin(goal_bearing)])
    path = np.linspace([0.0, 0.0], goal, 20)
    return obs((0.0, 0.0, 0.0), path, limits=DIFF, ranges=ranges, angles=BEAMS)


def test_the_subgoal_is_in_the_gap_toward_the_goal():
    # two openings of a 1.5 m room; the straight path to the goal (bearing -0.6) hits the wall
    ranges = room_scan(1.5, [(1.0, 0.4), (-1.0, 0.4)])
    planner = DragonPlanner()
    choice = planner.choose(_blocked_obs(ranges, -0.6))
    assert not choice.direct and len(choice.gaps) == 2
    assert choice.admissible.all()
    assert choice.chosen is not None
    assert choice.gaps.bearing[choice.chosen] == pytest.approx(-1.0, abs=0.02)
    sub = choice.subgoal
    assert sub is not None
    # inside the opening's angular interval, just past the wall, reachable from the robot
    assert -1.4 < math.atan2(sub[1], sub[0]) < -0.6
    assert np.hypot(*sub) > 1.5
    assert segment_clearance(sub, _blocked_obs(ranges, -0.6).scan_points())[0] >= 0.3
    # and the command turns the robot toward it
    cmd = DragonPlanner().compute(_blocked_obs(ranges, -0.6))
    assert cmd[2] < 0


def test_a_gap_narrower_than_the_robot_is_not_admissible():
    # jackal-like radius 0.3 m + margin 0.1 m needs 0.7 m; a 0.5 m opening does not do
    ranges = wall_scan(1.5, 0.5)
    choice = DragonPlanner().choose(_blocked_obs(ranges, 0.0))
    assert not choice.direct
    narrow = np.abs(choice.gaps.bearing) < 0.05
    assert narrow.sum() == 1 and choice.gaps.width[narrow][0] < 0.6
    assert not choice.admissible[narrow].any()
    # a 1 m opening does; the goal beyond the wall is off to the left (the path hits the wall)
    wide = DragonPlanner().choose(_blocked_obs(wall_scan(1.5, 1.0), 0.5))
    front = np.abs(wide.gaps.bearing) < 0.05
    assert wide.admissible[front].all() and wide.chosen == int(np.flatnonzero(front)[0])


def test_a_visible_target_is_followed_directly():
    choice = DragonPlanner().choose(_blocked_obs(room_scan(3.0, []), 0.0))
    assert choice.direct and choice.chosen is None


def test_dragon_is_registered_with_dwa_params():
    planner = LOCAL_PLANNERS.build({"type": "dragon", "margin": 0.2, "dwa": {"max_speed": 0.5}})
    assert isinstance(planner, DragonPlanner)
    assert planner.params.dwa.max_speed == 0.5


def test_dragon_crosses_generated_barn_maps_without_collision():
    from arena.config.loader import load_config
    from arena.eval.runner import plan_jobs, run_job
    from arena.tasks.suite import ContestFile, load_suite

    contest = ContestFile.model_validate(
        {"contestants": [{"name": "dragon", "local_planner": "dragon"}]}
    )
    jobs = plan_jobs(load_suite("barn", scale_episodes=0.06), contest, load_config())
    assert len(jobs) == 3
    for job in jobs:
        row, _ = run_job(job)
        assert row["outcome"] == "success", (job.episode, row["outcome"], row["error"])
        assert row["collisions"] == 0
