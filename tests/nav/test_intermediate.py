"""Intermediate planners (arena_specs §7): behaviours near people, thresholds, stack integration."""

from __future__ import annotations

import math

import numpy as np
import pytest

from arena.core.errors import UnknownNameError
from arena.core.types import Pose2D
from arena.maps.grid import OccupancyGrid
from arena.nav import LocalObservation
from arena.nav.build import stack_from_config
from arena.nav.intermediate import (
    INTERMEDIATE_PLANNERS,
    AggressivePlanner,
    IntermediateInput,
    IntermediateOutput,
    MetaPlanner,
    Pedestrians,
    PolitePlanner,
    ShortsightedPlanner,
    SidewaysPlanner,
    danger_level,
)
from arena.robots.limits import VelocityLimits

PATH = np.array([[0.0, 0.0], [10.0, 0.0]])
DIFF = VelocityLimits(
    vx_min=0.0, vx_max=1.0, vy_min=0.0, vy_max=0.0, omega_max=1.5,
    acc_x=1.0, acc_y=0.0, acc_omega=3.0,
)


def _inp(
    peds=(), *, pose=(0.0, 0.0, 0.0), kinds=None, points=None, time=0.0, path=PATH, window=5.0
) -> IntermediateInput:
    pos = np.array(peds, dtype=float).reshape(-1, 2)
    return IntermediateInput(
        pose=np.array(pose, dtype=float), twist=np.zeros(3), path=path,
        goal=np.array([10.0, 0.0, 0.0]), max_speed=1.0, robot_radius=0.3,
        pedestrians=Pedestrians(
            positions=pos, velocities=np.zeros_like(pos),
            kinds=np.zeros(len(pos), dtype=np.int64) if kinds is None else np.array(kinds),
        ),
        obstacle_points=np.zeros((0, 2)) if points is None else np.array(points, dtype=float),
        window=window, time=time,
    )


# -- aggressive ---------------------------------------------------------------------------------
def test_aggressive_keeps_the_path_and_nearly_its_speed():
    p = AggressivePlanner()
    assert p.plan(_inp()).overrides == {}
    assert p.plan(_inp([(6.0, 0.0)])).overrides == {}  # beyond slowdown_distance 5 m
    out = p.plan(_inp([(2.0, 0.0)]))
    assert out.path is PATH
    assert out.overrides["max_speed"] == pytest.approx(1.0 - 1.0 / (1.0 + 4.0))  # 0.8 v_max
    assert p.plan(_inp([(0.0, 1.0)])).overrides["max_speed"] == pytest.approx(0.5)
    near = AggressivePlanner(AggressivePlanner.Params(slowdown_distance=1.0))
    assert near.plan(_inp([(2.0, 0.0)])).overrides == {}


def test_danger_signal():
    assert danger_level(np.zeros(0)) == 0.0
    assert danger_level(np.array([3.0])) == pytest.approx(math.exp(-1.0))
    assert danger_level(np.array([1.0])) > 0.6 > danger_level(np.array([5.0]))
    out = AggressivePlanner().plan(_inp([(1.0, 0.0)]))
    assert out.info["signal"] == 1.0


# -- polite -------------------------------------------------------------------------------------
def test_polite_slows_within_caution_range():
    p = PolitePlanner()
    assert p.plan(_inp([(5.0, 0.0)])).overrides == {}
    out = p.plan(_inp([(3.0, 0.0)]))
    assert out.overrides == {"max_speed": pytest.approx(0.5)}
    assert out.path is PATH  # 3 m > ped_minimum_distance: no retreat


def test_polite_backs_away_from_a_pedestrian_in_front_until_the_temp_goal():
    p = PolitePlanner()
    out = p.plan(_inp([(1.5, 2.0)], pose=(1.0, 1.0, math.pi / 2)))  # ped at bearing −27°: in fov
    np.testing.assert_allclose(out.path, [[1.0, 1.0], [1.0, -1.0]], atol=1e-12)  # 2 m behind
    # The person left: the robot still goes to its temporary goal ...
    out = p.plan(_inp(pose=(1.0, 0.0, math.pi / 2)))
    np.testing.assert_allclose(out.path[-1], [1.0, -1.0], atol=1e-12)
    assert out.overrides == {}
    # ... until within temp_goal_tolerance (0.25 m); then the global path again.
    assert p.plan(_inp(pose=(1.0, -0.8, math.pi / 2))).path is PATH


@pytest.mark.parametrize(("cooldown", "retreats_again"), [(4.0, False), (0.0, True)])
def test_polite_retreat_cooldown(cooldown, retreats_again):
    p = PolitePlanner(PolitePlanner.Params(retreat_cooldown=cooldown))
    ped = [(1.0, 1.0)]  # 1 m ahead of a robot facing +x
    assert p.plan(_inp(ped, time=0.0)).info["mode"] == "polite_retreat"
    # Arrived at the temporary goal 2 m behind at t = 3 s: the retreat ends.
    assert p.plan(_inp(pose=(-2.0, 0.0, 0.0), time=3.0)).path is PATH
    # The person still stands 1.5 m in front at t = 4 s.
    out = p.plan(_inp([(-0.5, 0.0)], pose=(-2.0, 0.0, 0.0), time=4.0))
    assert (out.info["mode"] == "polite_retreat") is retreats_again
    # After the cooldown the robot yields again.
    later = p.plan(_inp([(-0.5, 0.0)], pose=(-2.0, 0.0, 0.0), time=7.5))
    assert later.info["mode"] == "polite_retreat"


def test_polite_ignores_people_behind_and_respects_its_thresholds():
    assert PolitePlanner().plan(_inp([(-1.0, 0.0)])).path is PATH  # behind: outside the fov
    narrow = PolitePlanner(PolitePlanner.Params(fov=math.pi / 4))
    assert narrow.plan(_inp([(1.0, 1.0)])).path is PATH  # 45° off: outside a 45° cone
    shy = PolitePlanner(PolitePlanner.Params(ped_minimum_distance=1.0))
    assert shy.plan(_inp([(1.5, 0.0)])).path is PATH
    slow = PolitePlanner(PolitePlanner.Params(cautious_speed=0.2, caution_detection_range=2.0))
    assert slow.plan(_inp([(1.5, 0.0)])).overrides == {"max_speed": pytest.approx(0.2)}


def test_polite_does_not_back_into_a_wall():
    wall = [(-0.5, y) for y in np.linspace(-1, 1, 11)]  # 0.5 m behind < 2·0.3 + 0.075
    out = PolitePlanner().plan(_inp([(1.0, 0.0)], points=wall))
    assert out.path is PATH
    far = [(-1.5, y) for y in np.linspace(-1, 1, 11)]
    assert len(PolitePlanner().plan(_inp([(1.0, 0.0)], points=far)).path) == 2


# -- sideways -----------------------------------------------------------------------------------
def test_sideways_steps_back_to_the_right_then_waits():
    p = SidewaysPlanner()
    out = p.plan(_inp([(1.5, 0.0)]))  # heading +x: right is −y
    target = -3.0 * np.array([math.cos(math.pi / 4), math.sin(math.pi / 4)])
    np.testing.assert_allclose(out.path, [[0.0, 0.0], target], atol=1e-12)
    assert target[0] < 0 and target[1] < 0  # behind and to the right
    assert out.overrides == {"max_speed": pytest.approx(0.4)}  # cautious_speed within 5 m
    # Reaching the temporary goal: stop for wait_time (2.5 s), then resume the global path.
    out = p.plan(_inp([(1.5, 0.0)], pose=(*target, 0.0), time=3.0))
    assert out.overrides == {"max_speed": 0.0} and len(out.path) == 1
    out = p.plan(_inp(pose=(*target, 0.0), time=5.0))
    assert out.overrides == {"max_speed": 0.0}
    out = p.plan(_inp(pose=(*target, 0.0), time=5.5))
    assert out.path is PATH and out.overrides == {}


def test_sideways_thresholds_are_parameters():
    p = SidewaysPlanner(SidewaysPlanner.Params(temp_goal_distance=1.0, wait_time=0.0))
    out = p.plan(_inp([(1.5, 0.0)], pose=(0.0, 0.0, math.pi / 2)))  # heading +y: right is +x
    np.testing.assert_allclose(
        out.path[-1], -1.5 * np.array([math.cos(3 * math.pi / 4), math.sin(3 * math.pi / 4)])
    )
    assert out.path[-1][0] > 0 and out.path[-1][1] < 0
    assert SidewaysPlanner().plan(_inp([(6.0, 0.0)])).overrides == {}


# -- meta ---------------------------------------------------------------------------------------
def test_meta_switches_by_its_rule():
    m = MetaPlanner()
    out = m.plan(_inp([(3.0, 0.0)]))
    assert m.mode == "aggressive" and out.overrides["max_speed"] == pytest.approx(0.9)
    # An elder within polite_range (5 m) makes it polite, and it stays polite.
    out = m.plan(_inp([(2.0, 3.0)], kinds=[1]))  # 3.6 m: also within caution range
    assert m.mode == "polite" and out.overrides["max_speed"] == pytest.approx(0.5)
    m.plan(_inp([(30.0, 0.0)], kinds=[1]))
    assert m.mode == "polite"
    # A laser return not explained by a pedestrian within sideways_range + padding → sideways.
    m.plan(_inp([(30.0, 0.0)], points=[(0.0, 3.05)]))
    assert m.mode == "sideways"  # 3.05 ≤ 3.0 + 0.075 (polite padding)
    m.reset()
    assert m.mode == "aggressive"
    m.plan(_inp(points=[(0.0, 3.1)]))
    assert m.mode == "sideways"  # 3.1 ≤ 3.0 + 0.135
    m.reset()
    m.plan(_inp(points=[(0.0, 3.2)]))
    assert m.mode == "aggressive"
    # A return at a pedestrian's distance is that pedestrian, not a wall.
    m.plan(_inp([(2.0, 0.0)], points=[(2.0, 0.1)]))
    assert m.mode == "aggressive"


def test_meta_in_polite_mode_backs_away():
    m = MetaPlanner()
    out = m.plan(_inp([(1.5, 0.0)], kinds=[1]))
    assert m.mode == "polite"
    np.testing.assert_allclose(out.path, [[0.0, 0.0], [-2.0, 0.0]], atol=1e-12)


# -- shortsighted -------------------------------------------------------------------------------
def test_shortsighted_keeps_points_within_the_window():
    path = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 8.0]])
    p = ShortsightedPlanner()
    out = p.plan(_inp(pose=(1.2, 0.3, 0.0), path=path, window=3.0))
    pts = out.path
    np.testing.assert_allclose(pts[0], [1.2, 0.0])  # the robot's projection onto the path
    assert np.all(np.hypot(*(pts - [1.2, 0.3]).T) <= 3.0)
    steps = np.hypot(*np.diff(pts, axis=0).T)
    assert np.all(steps <= 0.5 + 1e-9) and len(pts) >= 5
    wide = ShortsightedPlanner(ShortsightedPlanner.Params(spacing=1.0, window=100.0))
    out = wide.plan(_inp(path=path))
    np.testing.assert_allclose(out.path[-1], [4.0, 8.0])  # the whole path, end included
    assert len(out.path) == 13


# -- stack --------------------------------------------------------------------------------------
def _obs(pose, t=0.0):
    return LocalObservation(
        pose=np.array(pose, dtype=float), twist=np.zeros(3), goal=Pose2D(), path=np.zeros((0, 2)),
        limits=DIFF, robot_radius=0.3, dt=0.1, time=t,
    )


def _stack(inter: str, **kw):
    return stack_from_config(
        {"intermediate_planner": inter, **kw}, robot_radius=0.3, kinematics="diff_drive"
    )


def test_stack_applies_and_restores_speed_overrides():
    grid = OccupancyGrid.empty(10, 4, 0.05)
    stack = _stack("polite")
    base = stack.local_planner.params
    stack.reset(grid, Pose2D(1.0, 2.0, 0.0), Pose2D(9.0, 2.0, 0.0))
    ped = Pedestrians(positions=np.array([[4.0, 2.0]]), velocities=np.zeros((1, 2)))
    stack.step(_obs((1.0, 2.0, 0.0)), ped)
    assert stack.local_planner.params.max_speed == pytest.approx(0.5)
    assert stack.overrides == {"max_speed": pytest.approx(0.5)}
    stack.step(_obs((1.0, 2.0, 0.0), 0.1))
    assert stack.local_planner.params is base and stack.overrides == {}
    # A pedestrian right in front: the robot follows the retreat path instead.
    near = Pedestrians(positions=np.array([[2.0, 2.0]]), velocities=np.zeros((1, 2)))
    stack.step(_obs((1.0, 2.0, 0.0), 0.2), near)
    np.testing.assert_allclose(stack.intermediate_path, [[1.0, 2.0], [-1.0, 2.0]])
    stack.reset(grid, Pose2D(1.0, 2.0, 0.0), Pose2D(9.0, 2.0, 0.0))
    assert stack.local_planner.params is base


def test_stack_bypass_changes_nothing():
    grid = OccupancyGrid.empty(10, 4, 0.05)
    a, b = _stack("bypass"), stack_from_config(None, robot_radius=0.3)
    for s in (a, b):
        s.reset(grid, Pose2D(1.0, 2.0, 0.0), Pose2D(9.0, 2.0, 0.0))
    ped = Pedestrians(positions=np.array([[2.0, 2.0]]), velocities=np.zeros((1, 2)))
    for k in range(5):
        np.testing.assert_array_equal(a.step(_obs((1.0, 2.0, 0.0), 0.1 * k), ped),
                                      b.step(_obs((1.0, 2.0, 0.0), 0.1 * k)))
    assert a.intermediate_path is a.path


def test_stack_calls_the_intermediate_planner_at_its_period():
    calls = []

    class Counting:
        def reset(self) -> None:
            pass

        def plan(self, inp: IntermediateInput) -> IntermediateOutput:
            calls.append(inp.time)
            return IntermediateOutput(path=inp.path)

    stack = _stack("bypass", intermediate_period=0.5)
    stack.intermediate_planner = Counting()
    stack.reset(OccupancyGrid.empty(10, 4, 0.05), Pose2D(1.0, 2.0, 0.0), Pose2D(9.0, 2.0, 0.0))
    for k in range(11):
        stack.step(_obs((1.0, 2.0, 0.0), 0.1 * k))
    assert calls == pytest.approx([0.0, 0.5, 1.0])


def test_unknown_intermediate_planner_names_the_key():
    with pytest.raises(UnknownNameError) as e:
        _stack("politely")
    assert e.value.path == "navigation.intermediate_planner.type"
    assert "polite" in str(e.value)
    assert set(INTERMEDIATE_PLANNERS.names()) >= {
        "bypass", "shortsighted", "aggressive", "polite", "sideways", "meta"
    }


@pytest.mark.parametrize("with_costmaps", [False, True])
def test_stack_hands_its_costmaps_to_the_intermediate_planner(with_costmaps):
    seen = []

    class Recording:
        def reset(self) -> None:
            pass

        def plan(self, inp: IntermediateInput) -> IntermediateOutput:
            seen.append((inp.global_costmap, inp.local_costmap))
            return IntermediateOutput(path=inp.path)

    kw = {"global_costmap": {}, "local_costmap": {}} if with_costmaps else {}
    stack = _stack("bypass", **kw)
    stack.intermediate_planner = Recording()
    stack.reset(OccupancyGrid.empty(10, 4, 0.05), Pose2D(1.0, 2.0, 0.0), Pose2D(9.0, 2.0, 0.0))
    stack.step(_obs((1.0, 2.0, 0.0)))
    glob, local = seen[-1]
    if with_costmaps:
        assert glob is not None and local is not None
        assert glob.costs.shape == (80, 200)  # the whole 10 x 4 m map at 0.05 m
        assert local.costs.shape[0] < glob.costs.shape[0] or local.costs.shape[1] < 200
    else:
        assert glob is None and local is None
