"""CrowdNav's discrete action sets and the one-step lookahead of a value policy.

Action set (Chen et al. 2019): 5 speeds ``(e^(i/5) - 1) / (e - 1) · v_pref`` (``i = 1..5``)
times 16 directions, plus stop. Holonomic robots move in 16 directions spread over 2π (we
measure them in the robot's body frame; CrowdNav in the world frame, which spans the same set);
unicycle robots turn by one of 16 rotations in ``[-π/4, π/4]`` over the time step. Our addition
for unicycle robots: the 16 rotations at speed 0 as well (turning on the spot), which a robot
in an open CrowdNav square never needs but a differential drive facing a wall does.

A unicycle action ``(v, r)`` is held as the twist ``[v, 0, r / Δt]``, so its lookahead follows
the exact arc of that twist (CrowdNav turns first, then drives straight).

Lookahead (:func:`lookahead`): every action's next robot state after ``Δt``, the humans moved
at constant velocity, and the immediate reward of CrowdNav's policy: ``-0.25`` on a collision
(closest approach during the step, robot taken along the chord of its arc), ``+1`` when the
robot's centre ends within its radius of the goal, else ``(d - 0.2) · 0.5 · Δt`` when the
closest gap ``d`` to a human is under 0.2 m. SARL*'s handling of static obstacles, which
CrowdNav lacks: the laser returns are obstacles that actions may not come within
``robot radius + wall_margin`` of (pruned; unless the action increases a clearance that is
already smaller, so a robot grazing a wall can still leave it) and that cost
``(c - wall_soft) · wall_factor · Δt`` when the clearance ``c`` is under ``wall_soft``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from arena.learn.value.state import JointState

FloatArray = NDArray[np.float64]

ARC_SAMPLES = 4
"""Points along each action's step checked against the laser returns (the last is the end)."""


@dataclass(frozen=True, eq=False)
class ActionSet:
    """A discrete action set.

    Attributes:
        speeds: ``(A,)`` m/s.
        angles: ``(A,)`` rad: holonomic: direction of motion in the body frame; unicycle: the
            rotation over one time step.
        holonomic: which of the two meanings ``angles`` has.
        time_step: s, the lookahead step ``Δt``.
    """

    speeds: FloatArray
    angles: FloatArray
    holonomic: bool
    time_step: float

    def __len__(self) -> int:
        return int(self.speeds.size)

    def twists(self) -> FloatArray:
        """``(A, 3)`` body twists ``[vx m/s, vy m/s, omega rad/s]`` that execute the actions."""
        out = np.zeros((len(self), 3))
        if self.holonomic:
            out[:, 0] = self.speeds * np.cos(self.angles)
            out[:, 1] = self.speeds * np.sin(self.angles)
        else:
            out[:, 0] = self.speeds
            out[:, 2] = self.angles / self.time_step
        return out

    def propagate(self, pose: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Poses along each action's step and the velocity at its end.

        Args:
            pose: ``(3,)`` ``[x, y, theta]`` (m, rad, world).

        Returns:
            ``(A, ARC_SAMPLES, 3)`` poses at ``Δt · k / ARC_SAMPLES`` (``k = 1..``) and
            ``(A, 2)`` world velocities (m/s) at the end of the step.
        """
        q = np.asarray(pose, dtype=np.float64).reshape(3)
        tau = self.time_step * np.arange(1, ARC_SAMPLES + 1) / ARC_SAMPLES  # (k,)
        s = self.speeds[:, None]
        if self.holonomic:
            c, si = math.cos(q[2]), math.sin(q[2])
            vb = np.stack([self.speeds * np.cos(self.angles),
                           self.speeds * np.sin(self.angles)], axis=-1)
            vw = np.stack([c * vb[:, 0] - si * vb[:, 1], si * vb[:, 0] + c * vb[:, 1]], axis=-1)
            xy = q[:2] + vw[:, None, :] * tau[None, :, None]
            th = np.full(xy.shape[:2], q[2])
            return np.concatenate([xy, th[..., None]], axis=-1), vw
        w = (self.angles / self.time_step)[:, None]
        th = q[2] + w * tau[None, :]  # (A, k)
        straight = np.abs(w) < 1e-9
        safe_w = np.where(straight, 1.0, w)
        x = np.where(straight, s * tau * math.cos(q[2]),
                     s / safe_w * (np.sin(th) - math.sin(q[2])))
        y = np.where(straight, s * tau * math.sin(q[2]),
                     -s / safe_w * (np.cos(th) - math.cos(q[2])))
        poses = np.stack([q[0] + x, q[1] + y, th], axis=-1)
        vw = np.stack([self.speeds * np.cos(th[:, -1]), self.speeds * np.sin(th[:, -1])], axis=-1)
        return poses, vw

    def meta(self) -> dict[str, object]:
        """The set as plain data (for a policy file's meta)."""
        return {"holonomic": self.holonomic, "time_step": self.time_step,
                "speeds": self.speeds.tolist(), "angles": self.angles.tolist()}


def build_action_set(
    v_pref: float,
    holonomic: bool,
    time_step: float,
    speed_samples: int = 5,
    rotation_samples: int = 16,
    max_rotation: float = math.pi / 4,
    turn_in_place: bool = True,
) -> ActionSet:
    """CrowdNav's action set: stop first, then every speed × direction (see the module doc).

    Args:
        v_pref: m/s, the fastest speed.
        holonomic: directions over 2π (True) or rotations in ``±max_rotation`` (False).
        time_step: s, lookahead step.
        speed_samples: speeds, exponentially spaced up to ``v_pref``.
        rotation_samples: directions or rotations.
        max_rotation: rad, largest rotation per step of a unicycle robot.
        turn_in_place: unicycle only: add the rotations at speed 0.
    """
    i = np.arange(1, speed_samples + 1)
    speeds = (np.exp(i / speed_samples) - 1) / (math.e - 1) * v_pref
    if holonomic:
        angles = np.linspace(0, 2 * np.pi, rotation_samples, endpoint=False)
    else:
        angles = np.linspace(-max_rotation, max_rotation, rotation_samples)
    s, a = np.meshgrid(speeds, angles, indexing="ij")
    sp, an = [np.zeros(1)], [np.zeros(1)]
    if turn_in_place and not holonomic:
        turn = angles[np.abs(angles) > 1e-9]
        sp.append(np.zeros(turn.size))
        an.append(turn)
    sp.append(s.reshape(-1))
    an.append(a.reshape(-1))
    return ActionSet(np.concatenate(sp), np.concatenate(an), holonomic, float(time_step))


@dataclass(frozen=True, eq=False)
class Lookahead:
    """Every action's outcome after one time step.

    Attributes:
        next_robot: ``(A, 9)`` robot full states (same goal, ``v_pref`` and radius).
        next_humans: ``(n, 5)`` humans moved at constant velocity.
        rewards: ``(A,)`` immediate rewards (humans, goal and the soft wall cost).
        clearance: ``(A,)`` m, smallest distance between the robot's disc and a laser return
            along the step (``inf`` without returns).
        pruned: ``(A,)`` actions ruled out by the laser returns (never the stop action 0).
    """

    next_robot: FloatArray
    next_humans: FloatArray
    rewards: FloatArray
    clearance: FloatArray
    pruned: NDArray[np.bool_]


def _clearance(points: FloatArray, xy: FloatArray, radius: float) -> FloatArray:
    """``(...)`` m, gap between discs of ``radius`` at ``xy`` ``(..., 2)`` and ``points``."""
    if len(points) == 0:
        return np.full(xy.shape[:-1], np.inf)
    d = xy[..., None, :] - points  # (..., m, 2)
    d2: FloatArray = np.einsum("...ij,...ij->...i", d, d)
    out: FloatArray = np.sqrt(np.min(d2, axis=-1)) - radius
    return out


def lookahead(
    state: JointState,
    actions: ActionSet,
    obstacles: FloatArray,
    *,
    wall_margin: float = 0.05,
    wall_soft: float = 0.3,
    wall_factor: float = 0.5,
    collision_penalty: float = -0.25,
    goal_reward: float = 1.0,
    discomfort_dist: float = 0.2,
    discomfort_factor: float = 0.5,
) -> Lookahead:
    """One step of every action from ``state`` (see the module docstring).

    Args:
        state: the joint state (its robot ``theta`` is the current heading).
        actions: the action set.
        obstacles: ``(m, 2)`` laser returns (m, world frame).
        wall_margin: m, clearance below which an action is pruned.
        wall_soft: m, clearance below which an action pays the wall cost.
        wall_factor: 1/s, wall cost per m of missing clearance, times ``Δt``.
        collision_penalty: reward of a collision with a human.
        goal_reward: reward of reaching the goal.
        discomfort_dist: m, gap to a human under which discomfort is paid.
        discomfort_factor: 1/s, discomfort per m, times ``Δt``.
    """
    dt = actions.time_step
    r = state.robot
    poses, vel = actions.propagate(np.array([r[0], r[1], r[8]]))
    end = poses[:, -1, :]
    n_act = len(actions)
    next_robot = np.repeat(r[None, :], n_act, axis=0)
    next_robot[:, 0:2] = end[:, :2]
    next_robot[:, 2:4] = vel
    next_robot[:, 8] = end[:, 2]
    h = state.humans
    next_humans = h.copy()
    next_humans[:, 0:2] += h[:, 2:4] * dt
    # Closest approach during the step, both moving straight (the robot along its chord).
    p0 = h[None, :, 0:2] - r[None, None, 0:2]  # (1, n, 2)
    p1 = next_humans[None, :, 0:2] - end[:, None, 0:2]  # (A, n, 2)
    dp = p1 - p0
    den = np.einsum("anj,anj->an", dp, dp)
    t = np.clip(-np.einsum("anj,anj->an", np.broadcast_to(p0, dp.shape), dp)
                / np.where(den > 1e-12, den, 1.0), 0.0, 1.0)
    closest = np.hypot(*(p0 + t[..., None] * dp).transpose(2, 0, 1))
    gap = np.min(closest - (r[4] + h[None, :, 4]), axis=1)  # (A,)
    reached = np.hypot(end[:, 0] - r[5], end[:, 1] - r[6]) < r[4]
    rewards = np.where(
        gap < 0, collision_penalty,
        np.where(reached, goal_reward,
                 np.where(gap < discomfort_dist,
                          (gap - discomfort_dist) * discomfort_factor * dt, 0.0)))
    pts = np.asarray(obstacles, dtype=np.float64).reshape(-1, 2)
    reach = r[4] + max(wall_soft, wall_margin) + float(np.max(actions.speeds, initial=0.0)) * dt
    if len(pts):
        pts = pts[np.hypot(pts[:, 0] - r[0], pts[:, 1] - r[1]) <= reach + 1e-9]
    now = float(_clearance(pts, r[None, 0:2], r[4])[0])
    clearance = np.min(_clearance(pts, poses[..., :2], r[4]), axis=1)  # (A,)
    pruned = (clearance < wall_margin) & (clearance < now - 1e-3)
    pruned[0] = False
    rewards = rewards + np.where(clearance < wall_soft,
                                 (clearance - wall_soft) * wall_factor * dt, 0.0)
    return Lookahead(next_robot, next_humans, rewards, clearance, pruned)
