"""What the navigation stack does when stuck: :class:`StuckRecovery`, mixed into the stack.

While the stack is active its :class:`~arena.nav.recovery.OscillationMonitor` watches
progress; a robot that has not moved ``oscillation_distance`` within ``oscillation_timeout``
runs the next of ``recovery_behaviors`` (see :mod:`arena.nav.recovery` for what each does);
the status is ``RECOVERING`` during a motion recovery. Once every behaviour has run without the
robot getting away, the status becomes ``STUCK`` (commands only brake; the episode ends
``stuck``). Getting ``oscillation_distance + back_up_distance`` away from where it got stuck
re-arms the list.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from arena.core.types import Pose2D
from arena.nav.config import NavStatus
from arena.nav.costmap import GlobalCostmap, LocalCostmap
from arena.nav.local_planners import LocalObservation, LocalPlanner, infer_kinematics, limit_command
from arena.nav.recovery import OscillationMonitor, RecoveryName, RecoveryRun, rear_is_free


class StuckRecovery:
    """Oscillation detection and recovery of :class:`~arena.nav.stack.NavigationStack`."""

    # the stack's state this part reads and writes (set by NavigationStack)
    local_planner: LocalPlanner
    kinematics: str | None
    robot_radius: float
    status: NavStatus
    oscillation: OscillationMonitor
    recovery_behaviors: tuple[RecoveryName, ...]
    recoveries: list[RecoveryName]
    back_up_distance: float
    back_up_speed: float
    rotate_speed: float
    _time: float
    _scan_world: NDArray[np.float64]
    _stuck_xy: NDArray[np.float64] | None
    _recovery_index: int
    _recovery: RecoveryRun | None

    global_costmap: GlobalCostmap | None
    local_costmap: LocalCostmap | None

    if TYPE_CHECKING:  # the stack's, for the type checker

        def replan(self, pose: Pose2D, *, mark_scan: bool | None = None) -> bool:
            """Plan anew from ``pose``."""
            ...

    def _stuck(self, q: NDArray[np.float64]) -> bool:
        """Feed the oscillation monitor; re-arm the recoveries once the robot got away."""
        if self._stuck_xy is not None and float(np.hypot(*(q[:2] - self._stuck_xy))) > (
            self.oscillation.distance + self.back_up_distance
        ):
            self._stuck_xy = None
            self._recovery_index = 0
        return self.oscillation.update(q[:2], self._time)

    def _start_recovery(
        self, obs: LocalObservation, q: NDArray[np.float64], v: NDArray[np.float64]
    ) -> NDArray[np.float64] | None:
        """Run the next applicable recovery; ``None`` lets the normal tick go on."""
        if self._stuck_xy is None:
            self._stuck_xy = q[:2].copy()
        lim = obs.limits
        drive = obs.kinematics or self.kinematics or infer_kinematics(lim)
        while self._recovery_index < len(self.recovery_behaviors):
            name = self.recovery_behaviors[self._recovery_index]
            self._recovery_index += 1
            if name == "clear_costmap":
                self.recoveries.append(name)
                self._clear_costmaps()
                self.local_planner.reset()
                self.oscillation.reset(q[:2], self._time)
                self.replan(Pose2D.from_array(q), mark_scan=False)
                return None
            if name == "rotate" and drive != "ackermann" and lim.omega_max > 0:
                omega = min(self.rotate_speed, float(lim.omega_max))
                deadline = self._time + 1.5 * 2 * math.pi / omega + 2.0
            elif name == "back_up" and lim.vx_min < 0 and rear_is_free(
                q, self._scan_world, self.robot_radius, self.back_up_distance
            ):
                speed = min(self.back_up_speed, -float(lim.vx_min))
                deadline = self._time + 2.0 * self.back_up_distance / speed + 2.0
            else:
                continue
            self.recoveries.append(name)
            self._recovery = RecoveryRun(name, q[:2].copy(), self._time, float(q[2]), 0.0, deadline)
            self.status = NavStatus.RECOVERING
            cmd = self._recover(obs, q, v)
            if cmd is not None:
                return cmd
        if self.status is NavStatus.ACTIVE:
            self.status = NavStatus.STUCK
            return limit_command(np.zeros(3), v, lim, obs.dt)
        return None

    def _recover(
        self, obs: LocalObservation, q: NDArray[np.float64], v: NDArray[np.float64]
    ) -> NDArray[np.float64] | None:
        """One tick of the running motion recovery; ``None`` once it has finished."""
        run = self._recovery
        lim = obs.limits
        if run is None:
            self.status = NavStatus.ACTIVE
            return None
        if run.name == "rotate":
            run.track(float(q[2]))
            done = run.turned >= 2 * math.pi - 0.05
            cmd = np.array([0.0, 0.0, min(self.rotate_speed, float(lim.omega_max))])
        else:
            travelled = float(np.hypot(*(q[:2] - run.start_xy)))
            left = self.back_up_distance - travelled
            done = left <= 1e-3 or not rear_is_free(
                q, self._scan_world, self.robot_radius, max(left, 0.0)
            )
            cmd = np.array([-min(self.back_up_speed, -float(lim.vx_min)), 0.0, 0.0])
        if done or self._time >= run.deadline:
            self._recovery = None
            self.status = NavStatus.ACTIVE
            self.local_planner.reset()
            self.oscillation.reset(q[:2], self._time)
            self.replan(Pose2D.from_array(q))
            return None
        return limit_command(cmd, v, lim, obs.dt)

    def _clear_costmaps(self) -> None:
        """Forget the obstacle layers (recovery ``clear_costmap``)."""
        if self.global_costmap is not None:
            self.global_costmap.obstacles.costs[:] = 0
            self.global_costmap.update()
        if self.local_costmap is not None:
            self.local_costmap.obstacles.costs[:] = 0
