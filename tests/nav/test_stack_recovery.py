"""Navigation stack, move_base_flex features: costmaps, blocked-path replanning, recovery."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from arena.core.errors import ConfigError
from arena.core.types import Pose2D
from arena.maps.grid import OccupancyGrid
from arena.nav import (
    AStarPlanner,
    LocalObservation,
    NavigationStack,
    NavStatus,
    PurePursuitPlanner,
)
from arena.nav.build import stack_from_config
from arena.nav.config import GlobalCostmapConfig, LocalCostmapConfig, NavigationConfig
from arena.nav.costmap import LETHAL, Costmap
from arena.nav.recovery import OscillationMonitor, mark_points, rear_is_free, sample_path
from arena.robots.limits import VelocityLimits

RES = 0.05
RADIUS = 0.3
DT = 0.1
RANGE_MAX = 4.0
LIMITS = VelocityLimits(
    vx_min=-0.3, vx_max=1.0, vy_min=0.0, vy_max=0.0, omega_max=1.5,
    acc_x=1.0, acc_y=0.0, acc_omega=3.0,
)


def _lidar(grid: OccupancyGrid, pose: np.ndarray, n: int = 180) -> tuple[np.ndarray, np.ndarray]:
    """Ray-marching lidar against ``grid`` (robot-frame angles; RANGE_MAX when no hit)."""
    angles = np.linspace(-math.pi, math.pi, n, endpoint=False)
    steps = np.arange(0.0, RANGE_MAX, RES / 2)
    world = angles + pose[2]
    pts = pose[:2] + steps[None, :, None] * np.stack([np.cos(world), np.sin(world)], -1)[:, None]
    hit = grid.is_occupied(pts)
    first = np.where(hit.any(axis=1), hit.argmax(axis=1), len(steps))
    ranges = np.where(first < len(steps), steps[np.minimum(first, len(steps) - 1)], RANGE_MAX)
    return ranges, angles


def _box(grid: OccupancyGrid, x0: float, x1: float, y0: float, y1: float) -> OccupancyGrid:
    """``grid`` with the rectangle ``[x0, x1] × [y0, y1]`` (m) occupied."""
    xy = grid.cell_to_world(np.stack(np.indices(grid.data.shape), axis=-1))
    inside = (xy[..., 0] >= x0) & (xy[..., 0] <= x1) & (xy[..., 1] >= y0) & (xy[..., 1] <= y1)
    return grid.with_occupied(inside)


def _obs(pose: np.ndarray, twist: np.ndarray, t: float, world: OccupancyGrid) -> LocalObservation:
    ranges, angles = _lidar(world, pose)
    return LocalObservation(
        pose=pose, twist=twist, goal=Pose2D(), path=np.zeros((0, 2)), limits=LIMITS,
        robot_radius=RADIUS, dt=DT, scan_ranges=ranges, scan_angles=angles, time=t,
        kinematics="diff_drive",
    )


def _drive(pose: np.ndarray, cmd: np.ndarray, world: OccupancyGrid) -> tuple[np.ndarray, bool]:
    """Unicycle step; a step that would put the disc into ``world`` is refused (contact)."""
    x, y, th = pose
    new = np.array([x + cmd[0] * math.cos(th) * DT, y + cmd[0] * math.sin(th) * DT,
                    th + cmd[2] * DT])
    if float(world.distance_at(new[:2])) - RES / 2 < RADIUS:
        return np.array([x, y, new[2]]), True
    return new, False


def _stack(local: PurePursuitPlanner | None = None, **kw: object) -> NavigationStack:
    kw.setdefault("scan_range_max", RANGE_MAX)
    return NavigationStack(
        AStarPlanner(), local or PurePursuitPlanner(), robot_radius=RADIUS, **kw
    )


def _run(nav, static, world_at, start, goal, t_max):
    """Closed loop; ``world_at(nav, t)`` gives the true world. Returns (pose, t, contacts)."""
    nav.reset(static, start, goal)
    pose, twist, t, contacts = start.as_array(), np.zeros(3), 0.0, 0
    while t < t_max and nav.status in (NavStatus.ACTIVE, NavStatus.RECOVERING):
        world = world_at(nav, t)
        cmd = nav.step(_obs(pose, twist, t, world))
        assert cmd.shape == (3,) and np.all(np.isfinite(cmd))
        pose, blocked = _drive(pose, cmd, world)
        twist = np.zeros(3) if blocked else cmd
        contacts += blocked
        t += DT
    return pose, t, contacts


RECOVERY = dict(oscillation_timeout=2.0, oscillation_distance=0.2, back_up_distance=0.3)


def test_boxed_robot_runs_every_recovery_then_ends_stuck() -> None:
    static = OccupancyGrid.empty(10.0, 4.0, RES)
    wall = _box(static, 3.0, 3.4, 0.0, 4.0)  # a temporary wall across the whole corridor
    nav = _stack(**RECOVERY)
    seen: list[NavStatus] = []

    def world_at(n: NavigationStack, t: float) -> OccupancyGrid:
        seen.append(n.status)
        return wall

    _pose, t, contacts = _run(nav, static, world_at, Pose2D(1.0, 2.0), Pose2D(8.0, 2.0), 60.0)
    assert nav.status is NavStatus.STUCK
    assert nav.recoveries == ["clear_costmap", "rotate", "back_up"]
    assert NavStatus.RECOVERING in seen
    assert contacts >= 0 and t < 40.0  # pure pursuit stops short of the wall or touches it
    # Once stuck the stack only brakes.
    cmd = nav.step(_obs(np.array([2.6, 2.0, 0.0]), np.array([0.2, 0.0, 0.0]), t, wall))
    np.testing.assert_allclose(cmd, [0.1, 0.0, 0.0])


def test_recovery_then_success_when_the_obstacle_goes() -> None:
    static = OccupancyGrid.empty(10.0, 4.0, RES)
    wall = _box(static, 3.0, 3.4, 0.0, 4.0)

    def world_at(n: NavigationStack, t: float) -> OccupancyGrid:
        return static if n.recoveries else wall  # removed once the first recovery ran

    nav = _stack(**RECOVERY)
    pose, _t, _ = _run(nav, static, world_at, Pose2D(1.0, 2.0), Pose2D(8.0, 2.0), 60.0)
    assert nav.status is NavStatus.GOAL_REACHED, (pose, nav.recoveries)
    assert nav.recoveries[0] == "clear_costmap"


def test_rotate_recovery_turns_a_full_circle_and_back_up_needs_a_free_rear() -> None:
    static = OccupancyGrid.empty(10.0, 4.0, RES)
    # Boxed in front and behind: rotate runs, back_up is skipped (rear not free).
    boxed = _box(_box(static, 3.0, 3.4, 0.0, 4.0), 2.0, 2.2, 0.0, 4.0)
    # a local planner that only waits (pure pursuit's own detour would drive along the walls)
    waiting = PurePursuitPlanner(PurePursuitPlanner.Params(detour_after=None))
    nav = _stack(waiting, **RECOVERY, recovery_behaviors=("rotate", "back_up"))
    yaws: list[float] = []

    def world_at(n: NavigationStack, t: float) -> OccupancyGrid:
        return boxed

    nav.reset(static, Pose2D(2.6, 2.0), Pose2D(8.0, 2.0))
    pose, twist, t = np.array([2.6, 2.0, 0.0]), np.zeros(3), 0.0
    while t < 40.0 and nav.status in (NavStatus.ACTIVE, NavStatus.RECOVERING):
        cmd = nav.step(_obs(pose, twist, t, boxed))
        if nav.status is NavStatus.RECOVERING:
            yaws.append(float(pose[2]))
        pose, blocked = _drive(pose, cmd, boxed)
        twist = np.zeros(3) if blocked else cmd
        t += DT
    assert nav.recoveries == ["rotate"]
    assert nav.status is NavStatus.STUCK
    assert np.sum(np.abs(np.diff(np.unwrap(yaws)))) > 2 * math.pi - 0.3
    assert not rear_is_free(pose, np.array([[pose[0] - 0.5, pose[1]]]), RADIUS, 0.3)
    assert rear_is_free(pose, np.array([[pose[0] + 0.5, pose[1]]]), RADIUS, 0.3)


def test_car_like_robots_skip_rotate() -> None:
    nav = _stack(**RECOVERY, recovery_behaviors=("rotate",))
    static = OccupancyGrid.empty(10.0, 4.0, RES)
    nav.reset(static, Pose2D(1.0, 2.0), Pose2D(8.0, 2.0))
    car = VelocityLimits(
        vx_min=-0.5, vx_max=1.0, vy_min=0.0, vy_max=0.0, omega_max=1.0,
        acc_x=1.0, acc_y=0.0, acc_omega=3.0, min_turning_radius=1.0,
    )
    pose = np.array([1.0, 2.0, 0.0])
    for k in range(30):
        obs = LocalObservation(
            pose=pose, twist=np.zeros(3), goal=Pose2D(), path=np.zeros((0, 2)), limits=car,
            robot_radius=RADIUS, dt=DT, time=k * DT, kinematics="ackermann",
        )
        nav.step(obs)
    assert nav.status is NavStatus.STUCK
    assert nav.recoveries == []


def test_oscillation_monitor() -> None:
    mon = OscillationMonitor(timeout=1.0, distance=0.2)
    mon.reset([0.0, 0.0], 0.0)
    assert not mon.update([0.1, 0.0], 0.5)
    assert mon.update([0.1, 0.0], 1.0)
    assert not mon.update([0.35, 0.0], 1.1)  # progress restarts the watch
    assert not mon.update([0.35, 0.0], 2.0)
    assert mon.update([0.35, 0.0], 2.1)
    assert not OscillationMonitor(0.0, 0.2).update([0.0, 0.0], 100.0)


def test_blocked_path_triggers_immediate_replanning_around_the_obstacle() -> None:
    static = OccupancyGrid.empty(10.0, 6.0, RES)
    x0, x1, y0, y1 = 4.0, 4.8, 2.4, 3.6
    world = _box(static, x0, x1, y0, y1)  # unknown to the map the stack plans on
    nav = _stack(replan_on_blocked=True, replan_period=0.0)
    pose, _t, contacts = _run(
        nav, static, lambda n, t: world, Pose2D(1.0, 3.0), Pose2D(8.0, 3.0), 40.0
    )
    assert nav.status is NavStatus.GOAL_REACHED, pose
    assert contacts == 0
    assert nav.blocked_replans >= 1
    assert nav.replans >= nav.blocked_replans

    # The first blocked replan already avoids the box with the robot's clearance.
    nav = _stack(replan_on_blocked=True, replan_period=0.0)
    nav.reset(static, Pose2D(2.5, 3.0), Pose2D(8.0, 3.0))
    before = nav.path.copy()
    nav.step(_obs(np.array([2.5, 3.0, 0.0]), np.zeros(3), 0.0, world))
    assert nav.blocked_replans == 1 and nav.replans == 1
    assert len(before) == 2  # straight through the box
    pts, _ = sample_path(nav.path, 0.02)
    assert float(np.min(world.distance_at(pts))) > RADIUS
    # Without the option the stack keeps driving into it (today's behaviour).
    plain = _stack(replan_period=0.0)
    plain.reset(static, Pose2D(2.5, 3.0), Pose2D(8.0, 3.0))
    plain.step(_obs(np.array([2.5, 3.0, 0.0]), np.zeros(3), 0.0, world))
    assert plain.replans == 0 and plain.blocked_replans == 0


def test_blocked_replanning_with_the_local_costmap() -> None:
    static = OccupancyGrid.empty(10.0, 6.0, RES)
    world = _box(static, 4.0, 4.8, 2.4, 3.6)
    nav = _stack(replan_on_blocked=True, replan_period=0.0, local_costmap=LocalCostmapConfig())
    nav.reset(static, Pose2D(2.5, 3.0), Pose2D(8.0, 3.0))
    nav.step(_obs(np.array([2.5, 3.0, 0.0]), np.zeros(3), 0.0, world))
    assert nav.blocked_replans == 1
    assert nav.local_costmap is not None
    assert int(nav.local_costmap.master.cost_at(np.array([4.0, 3.0]), off_map=0)) == LETHAL


def _corner_map() -> OccupancyGrid:
    occ = np.zeros((200, 200), dtype=bool)
    occ[0:100, 80:120] = True  # a block x ∈ [4, 6], y ∈ [0, 5] between start and goal
    return OccupancyGrid.from_occupied(occ, RES)


def test_costmap_global_planning_keeps_clearance() -> None:
    grid = _corner_map()
    start, goal = Pose2D(2.0, 2.0), Pose2D(8.0, 2.0)
    nav = _stack(global_costmap=GlobalCostmapConfig(cost_weight=3.0))
    nav.reset(grid, start, goal)
    assert nav.global_costmap is not None
    pts, _ = sample_path(nav.path, 0.02)
    clearance = float(np.min(grid.distance_at(pts)))
    assert clearance > RADIUS + 0.05 + 0.1  # well outside the inscribed zone
    np.testing.assert_allclose(nav.path[0], start.xy)
    np.testing.assert_allclose(nav.path[-1], goal.xy)
    # cost_weight = 0: the configured planner on the costmap's lethal cells, which are exactly
    # the inflated map's occupied cells: the default plan.
    zero = _stack(global_costmap=GlobalCostmapConfig(cost_weight=0.0))
    zero.reset(grid, start, goal)
    default = _stack()
    default.reset(grid, start, goal)
    np.testing.assert_allclose(zero.path, default.path)
    assert default.global_costmap is None and default.local_costmap is None


def test_global_costmap_with_scan_remembers_and_clears_obstacles() -> None:
    static = OccupancyGrid.empty(10.0, 6.0, RES)
    world = _box(static, 4.0, 4.8, 2.4, 3.6)
    nav = _stack(global_costmap=GlobalCostmapConfig(use_scan=True), replan_period=0.5)
    nav.reset(static, Pose2D(2.5, 3.0), Pose2D(8.0, 3.0))
    assert len(nav.path) == 2
    for k in range(6):
        nav.step(_obs(np.array([2.5, 3.0, 0.0]), np.zeros(3), k * DT, world))
    assert nav.replans == 1
    pts, _ = sample_path(nav.path, 0.02)
    assert float(np.min(world.distance_at(pts))) > RADIUS
    gcm = nav.global_costmap
    assert gcm is not None and int(gcm.obstacles.cost_at(np.array([4.0, 3.0]))) == LETHAL
    nav._clear_costmaps()
    assert not np.any(gcm.obstacles.costs)


def test_local_costmap_reaches_the_local_planner() -> None:
    seen: list[Costmap | None] = []

    class Spy(PurePursuitPlanner):
        def compute(self, obs: LocalObservation) -> np.ndarray:
            seen.append(obs.costmap)
            return super().compute(obs)

    static = OccupancyGrid.empty(10.0, 6.0, RES)
    world = _box(static, 4.0, 4.8, 2.4, 3.6)
    nav = NavigationStack(
        AStarPlanner(), Spy(), robot_radius=RADIUS,
        local_costmap=LocalCostmapConfig(width=4.0, height=4.0), scan_range_max=RANGE_MAX,
    )
    nav.reset(static, Pose2D(2.5, 3.0), Pose2D(8.0, 3.0))
    nav.step(_obs(np.array([2.5, 3.0, 0.0]), np.zeros(3), 0.0, world))
    cm = seen[-1]
    assert isinstance(cm, Costmap)
    assert cm.shape == (80, 80)
    assert int(cm.cost_at(np.array([4.0, 3.0]))) == LETHAL
    assert int(cm.cost_at(np.array([2.5, 3.0]))) < LETHAL
    plain = _stack()
    assert plain.local_costmap is None


def test_mark_points_inflates_scan_returns() -> None:
    grid = OccupancyGrid.empty(4.0, 4.0, RES)
    marked = mark_points(grid, np.array([[2.0, 2.0]]), 0.35)
    assert marked.is_occupied(np.array([2.3, 2.0]))
    assert not marked.is_occupied(np.array([2.5, 2.0]))
    assert mark_points(grid, np.zeros((0, 2)), 0.35) is grid


def test_config_blocks_validate_and_build() -> None:
    cfg = {
        "global_costmap": {"use_scan": True, "cost_weight": 2.0},
        "local_costmap": {"width": 4.0, "height": 4.0},
        "replan_on_blocked": True,
        "oscillation_timeout": 5.0,
        "recovery_behaviors": ["rotate", "back_up"],
    }
    nav = stack_from_config(cfg, robot_radius=0.25)
    assert nav.global_costmap_config == GlobalCostmapConfig(use_scan=True, cost_weight=2.0)
    assert nav.recovery_behaviors == ("rotate", "back_up")
    assert nav.oscillation.timeout == 5.0 and nav.replan_on_blocked
    with pytest.raises(ConfigError, match=r"navigation\.global_costmap\.use_scn"):
        stack_from_config({"global_costmap": {"use_scn": True}}, 0.3)
    with pytest.raises(ConfigError, match=r"navigation\.recovery_behaviors"):
        stack_from_config({"recovery_behaviors": ["dance"]}, 0.3)
    defaults = NavigationConfig()
    assert defaults.global_costmap is None and defaults.local_costmap is None
    assert defaults.oscillation_timeout == 0.0 and not defaults.replan_on_blocked


def _arena(monkeypatch: pytest.MonkeyPatch, *args: str) -> int:
    from arena import cli

    monkeypatch.setattr(sys, "argv", ["arena", *args])
    try:
        cli.main()
    except SystemExit as e:
        return int(e.code or 0)
    return 0


def test_cli_run_with_scan_costmap_and_stuck_outcome(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    out = tmp_path / "scan"
    common = ["--robot", "burger", "output.video=false"]
    code = _arena(
        monkeypatch, "run", "navigation.global_costmap.use_scan=true",
        "navigation.local_costmap.width=4", "navigation.replan_on_blocked=true",
        "task.timeout=6", "--out", str(out), *common,
    )
    assert code == 0
    info = json.loads((out / "episode_000" / "episode.json").read_text())
    assert info["outcome"] in ("success", "timeout") and info["path_length"] > 0.3
    # A planner that barely moves: oscillation → clear, rotate, back up → "stuck".
    out = tmp_path / "stuck"
    code = _arena(
        monkeypatch, "run", "navigation.oscillation_timeout=2",
        "navigation.local_planner.max_speed=0.001", "task.timeout=40", "--out", str(out), *common,
    )
    assert code == 0
    info = json.loads((out / "episode_000" / "episode.json").read_text())
    assert info["outcome"] == "stuck"
    assert info["time"] < 40.0


_KIN_LIMITS = {
    "diff_drive": VelocityLimits(-0.3, 1.0, 0.0, 0.0, 1.5, 1.0, 0.0, 3.0),
    "legged": VelocityLimits(-0.3, 0.7, 0.0, 0.0, 1.0, 0.8, 0.0, 2.0),
    "omni": VelocityLimits(-0.8, 0.8, -0.6, 0.6, 1.2, 1.0, 1.0, 2.0),
    "ackermann": VelocityLimits(-0.5, 1.5, 0.0, 0.0, 1.5, 1.0, 0.0, 2.0, min_turning_radius=1.2),
}


def _planner_cases() -> list[tuple[str, str]]:
    from arena.nav import LOCAL_PLANNERS

    cases = []
    for name in LOCAL_PLANNERS.names():
        supports = LOCAL_PLANNERS.build({"type": name}).supports
        cases.append((name, "diff_drive" if "diff_drive" in supports else sorted(supports)[0]))
    return cases


# these observations carry no camera: iplanner plans on the image an empty floor gives
_CAMERA_LESS = {"iplanner": {"missing_frame": "floor"}}


@pytest.mark.parametrize(("name", "kin"), _planner_cases())
def test_every_local_planner_runs_through_the_full_stack(name: str, kin: str) -> None:
    """Costmaps, blocked replanning and recovery on: each planner still gets valid ticks."""
    cfg = {
        "local_planner": {"type": name, **_CAMERA_LESS.get(name, {})},
        "global_costmap": {"use_scan": True},
        "local_costmap": {"width": 4.0, "height": 4.0},
        "replan_on_blocked": True,
        "oscillation_timeout": 1.0,
    }
    nav = stack_from_config(cfg, robot_radius=RADIUS, kinematics=kin)
    nav.scan_range_max = RANGE_MAX
    from arena.nav import LOCAL_PLANNERS

    if "external" in LOCAL_PLANNERS.entry(name).tags:
        # a ROS planner: an in-memory node answers (over ROS: tests/ros)
        from arena.testing.ros import attach_loopback

        attach_loopback(nav.local_planner, reply=lambda sent: np.array([0.6, 0.0, 0.3]))
    static = OccupancyGrid.empty(10.0, 6.0, RES)
    world = _box(static, 4.0, 4.8, 2.4, 3.6)
    lim = _KIN_LIMITS[kin]
    nav.reset(static, Pose2D(1.0, 3.0), Pose2D(8.0, 3.0))
    pose, twist = np.array([1.0, 3.0, 0.0]), np.zeros(3)
    for k in range(15):
        ranges, angles = _lidar(world, pose, n=90)
        obs = LocalObservation(
            pose=pose, twist=twist, goal=Pose2D(), path=np.zeros((0, 2)), limits=lim,
            robot_radius=RADIUS, dt=DT, scan_ranges=ranges, scan_angles=angles, time=k * DT,
            kinematics=kin,
        )
        cmd = nav.step(obs)
        assert cmd.shape == (3,) and np.all(np.isfinite(cmd)), (name, cmd)
        assert np.all(cmd >= lim.lower - 1e-6) and np.all(cmd <= lim.upper + 1e-6)
        c, s = math.cos(pose[2]), math.sin(pose[2])
        pose = pose + DT * np.array([c * cmd[0] - s * cmd[1], s * cmd[0] + c * cmd[1], cmd[2]])
        twist = cmd
    assert nav.status in (NavStatus.ACTIVE, NavStatus.RECOVERING, NavStatus.GOAL_REACHED)
