"""Robot 0 driven by the navigation stack through the task's runtime: the benchmark controller.

:func:`build_stack` makes the stack of an episode (tolerances, laser range and, for training,
another local planner set at construction); :class:`NavigationController` is the hook and
controller of :class:`~arena.episode.runner.EpisodeRunner` that ``arena run``, ``arena bench``
and the value-policy trainer share.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from arena.core.errors import ArenaError
from arena.core.types import Outcome, Pose2D
from arena.episode.runner import EpisodeHooks, EpisodeRunner
from arena.maps.raster import planning_grid
from arena.nav.build import stack_from_config
from arena.nav.config import NavStatus
from arena.nav.local_planners.base import LocalObservation
from arena.nav.stack import NavigationStack
from arena.perception.stage import GroundTruthPeople, PeoplePerception, Perceived, Senses
from arena.sensors.spec import LidarReading, LidarSpec, lidar_geometry

if TYPE_CHECKING:
    from arena.nav.config import NavigationConfig
    from arena.nav.local_planners.base import LocalPlanner
    from arena.robots.model import RobotModel
    from arena.scene.episode import Episode
    from arena.tasks.generator import TaskRuntime

FloatArray = NDArray[np.float64]


def build_stack(
    cfg: NavigationConfig,
    robot: RobotModel,
    episode: Episode,
    *,
    local_planner: LocalPlanner | None = None,
) -> NavigationStack:
    """The navigation stack of ``robot`` in ``episode``.

    The goal tolerances follow the episode: position within ``0.9 · goal_radius`` (or the
    navigation config's, if smaller) and, when the task checks the heading
    (``goal_tolerance_angle``), the heading too. The stack reads the lidar
    ``cfg.scan_sensor``; its ranges at the sensor's ``range_max`` count as free space.
    ``local_planner`` replaces the configured one (a trainer's planner).
    """
    yaw = cfg.goal_tolerance_yaw
    if episode.goal_tolerance_angle is not None:
        yaw = float(episode.goal_tolerance_angle)
    return stack_from_config(
        cfg, robot_radius=robot.radius,
        footprint_radius=robot.inscribed_radius or None,  # narrow passages: the body fits
        local_planner=local_planner,
        scan_range_max=float(
            robot.lidar(cfg.scan_sensor, path="navigation.scan_sensor").range_max
        ),
        goal_tolerance=(min(cfg.goal_tolerance_xy, 0.9 * episode.goal_radius), yaw),
    )


def _fmt_pose(p: Pose2D) -> str:
    return f"[{p.x:.3f}, {p.y:.3f}, {p.theta:.3f}]"


class NavigationController(EpisodeHooks):
    """Robot 0 follows the task (goals, teleports, resets) with the navigation stack.

    Each tick, before the time limit is checked, the task's runtime says what happens:
    ``goal_reached`` is noted; a forced reset ends the episode as ``aborted``; the task done
    ends it as ``success``; teleports move the robots (the stack plans afresh for robot 0) and
    a new goal makes it replan. Then the stack computes the command; when it reports ``STUCK``
    (every recovery behaviour tried) the episode ends as ``stuck``. A local planner that is
    itself an :class:`~arena.episode.runner.EpisodeHooks` (the ROS planners, which send the
    episode's frames) gets every hook call after the controller's own.

    Args:
        stack: robot 0's navigation stack (:func:`build_stack`).
        runtime: the task's runtime (when goals are reached and what comes next).
        robot: robot 0's model.
        scan_sensor: the lidar whose scan is the observation's ``scan_*`` fields
            (``navigation.scan_sensor``); every sensor is in its ``sensors`` by name.
        perception: where the stack's people come from (``navigation.perception``,
            :data:`~arena.perception.stage.PERCEPTION`; default: the ground truth).

    Attributes:
        goal: robot 0's current goal.
        control_s: wall time (s) of each stack call (global + intermediate + local).
        teleported: robot 0's recorded rows reached by a teleport (not driven).
        perceived: ``(time s, Perceived)`` of each tick of a detecting perception plugin
            (empty for the ground truth).
    """

    def __init__(
        self, stack: NavigationStack, runtime: TaskRuntime, robot: RobotModel,
        scan_sensor: str = "laser", perception: PeoplePerception | None = None,
    ) -> None:
        self.stack = stack
        self.perception = perception if perception is not None else GroundTruthPeople()
        self._range_max = float(robot.lidar(scan_sensor, path="navigation.scan_sensor").range_max)
        self.runtime = runtime
        self.robot = robot
        self.limits = robot.limits()
        robot.lidar(scan_sensor, path="navigation.scan_sensor")  # a clear error, not a KeyError
        self.scan_sensor = scan_sensor
        # beam geometry per lidar, computed once (the readings change, the mounts do not)
        self._geometry = {
            name: lidar_geometry(spec) for name, spec in robot.sensors.items()
            if isinstance(spec, LidarSpec)
        }
        self.goal: Pose2D | None = None
        self.control_s: list[float] = []
        self.perceived: list[tuple[float, Perceived]] = []
        # a local planner that follows the episode itself (the ROS planners send its frames)
        planner = getattr(stack, "local_planner", None)
        self._planner_hooks = [planner] if isinstance(planner, EpisodeHooks) else []

    def initialize_episode(self, runner: EpisodeRunner) -> None:
        """Plan from robot 0's start to its goal."""
        assert runner.episode is not None
        spawn = runner.episode.robots[0]
        self.goal = spawn.goal
        self.control_s = []
        self.perceived = []
        self.perception.reset()
        self.stack.reset(planning_grid(runner.episode), spawn.start, self.goal)
        for hook in self._planner_hooks:
            hook.initialize_episode(runner)

    def after_step(self, runner: EpisodeRunner) -> None:
        """Forward to a local planner that follows the episode."""
        for hook in self._planner_hooks:
            hook.after_step(runner)

    def episode_end(self, runner: EpisodeRunner) -> None:
        """Forward to a local planner that follows the episode."""
        for hook in self._planner_hooks:
            hook.episode_end(runner)

    def before_step(self, runner: EpisodeRunner) -> None:
        """Apply the task's update (see the class doc)."""
        state, episode = runner.state, runner.episode
        assert state is not None
        assert episode is not None
        update = self.runtime.update(state.time, state.robots.poses, state.agents.positions)
        if 0 in update.reached:
            runner.event("goal_reached", "robot 0")
        if update.reset:
            runner.event("reset", "forced reset")
            runner.end(Outcome.ABORTED)
            return
        if update.done:
            runner.end(Outcome.SUCCESS)
            return
        for i, target in sorted(update.teleports.items()):
            state = runner.teleport(i, target)
            if i == 0:
                runner.event("teleport", f"robot 0 to {_fmt_pose(target)}")
        if 0 in update.goals:
            self.goal = update.goals[0]
            runner.event("new_goal", f"robot 0 to {_fmt_pose(self.goal)}")
        if 0 in update.goals or 0 in update.teleports:
            assert self.goal is not None
            self.stack.reset(
                planning_grid(episode), Pose2D.from_array(state.robots.poses[0]), self.goal,
                time=state.time,
            )
        for hook in self._planner_hooks:
            hook.before_step(runner)

    def command(self, runner: EpisodeRunner) -> FloatArray:
        """The stack's ``(1, 3)`` command for robot 0 (the episode ends on ``STUCK``)."""
        state = runner.state
        assert state is not None
        assert self.goal is not None
        robot = self.robot
        sensors: dict[str, LidarReading | FloatArray] = {}
        for name, reading in state.robots.sensors[0].items():
            geometry = self._geometry.get(name)
            sensors[name] = (
                LidarReading(reading, *geometry) if geometry is not None else reading
            )
        scan = sensors[self.scan_sensor]
        assert isinstance(scan, LidarReading)
        obs = LocalObservation(
            pose=state.robots.poses[0],
            twist=state.robots.twists[0],
            goal=self.goal,
            path=self.stack.path,
            limits=self.limits,
            robot_radius=robot.radius,
            dt=runner.dt,
            scan_ranges=scan.ranges,
            scan_angles=scan.angles,
            scan_origin=scan.origin,
            sensors=sensors,
            time=state.time,
            kinematics=robot.kinematics_type,
        )
        peds = self.perception.people(Senses(state.time, state.robots.poses[0], scan,
                                             self._range_max, sensors, state.agents))
        if self.perception.last is not None:
            self.perceived.append((state.time, self.perception.last))
        t_ctl = time.perf_counter()
        cmd = np.asarray(self.stack.step(obs, peds), dtype=np.float64)
        self.control_s.append(time.perf_counter() - t_ctl)
        if self.stack.status is NavStatus.STUCK:  # every recovery behaviour failed
            runner.end(Outcome.STUCK)
        elif cmd.shape != (3,) or not np.all(np.isfinite(cmd)):
            raise ArenaError(f"the navigation stack returned an invalid command {cmd!r}")
        return cmd[None, :]
