"""The lflh planner's sober deployment: DWA drives in open space, the policy in clutter."""

from __future__ import annotations

import numpy as np

from arena.learn.planners.lflh import LflhPlanner
from arena.nav.local_planners.base import LocalObservation
from arena.nav.local_planners.dwa import DWAPlanner
from arena.robots.presets import load_robot


def _obs(wall_ahead: float | None) -> LocalObservation:
    """A jackal at the origin heading +x, goal 6 m ahead; a wall ``wall_ahead`` m ahead."""
    rb = load_robot("jackal")
    angles = rb.laser.angles()
    ranges = np.full(angles.size, 25.0)
    if wall_ahead is not None:
        with np.errstate(divide="ignore"):
            hit = wall_ahead / np.cos(angles)
        ranges = np.where((np.cos(angles) > 0) & (hit < 25.0), hit, ranges)
    return LocalObservation(
        pose=np.zeros(3), twist=np.zeros(3), goal=np.array([6.0, 0.0, 0.0]),
        path=np.array([[0.0, 0.0], [6.0, 0.0]]), limits=rb.limits(), robot_radius=rb.radius,
        dt=0.1, scan_ranges=ranges, scan_angles=angles,
    )


def test_open_space_is_driven_by_dwa_and_clutter_by_the_policy():
    planner = LflhPlanner()
    open_obs = _obs(None)
    assert planner.is_open(open_obs)
    cmd = planner.compute(open_obs)
    assert planner.last_source == "open"
    np.testing.assert_allclose(cmd, DWAPlanner().compute(open_obs))
    near = _obs(planner.params.open_clearance * 0.5 + 0.3)  # a wall within the clearance
    assert not planner.is_open(near)
    planner.compute(near)
    assert planner.last_source in ("policy", "fallback", "turn")


def test_open_space_policy_keeps_the_policy_everywhere():
    planner = LflhPlanner(LflhPlanner.Params(open_space="policy"))
    planner.compute(_obs(None))
    assert planner.last_source != "open"
