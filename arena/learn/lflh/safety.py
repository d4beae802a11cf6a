"""The run-time safety check: roll a command out against the current scan.

LfLH's policy is a regression and can be wrong off its training distribution, so the planner
never executes its command blindly (as in LfH/LfLH, which fall back when the learned command
would collide). A command ``[v, ω]`` is *safe* when the robot's bounding disc, moved along the
command's arc for ``horizon`` s in ``step`` s steps, keeps ``margin`` m from every scan return.
Unsafe: the best of a small grid of sampled commands (the safe one whose arc ends nearest the
target, the faster on ties) replaces it; when no command that moves is safe, the robot turns on
the spot toward the target (a disc turning in place sweeps nothing new).

When the robot is already closer than ``margin`` to a return (squeezed through a gap), the
threshold shrinks to just below the current clearance, so moving away stays allowed.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field


class SafetyParams(BaseModel):
    """The safety check and its fallback."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    horizon: float = Field(1.0, gt=0, description="s, how long a command is rolled out")
    step: float = Field(0.1, gt=0, description="s, rollout step")
    margin: float = Field(0.05, ge=0, description="m, gap kept beyond the robot's disc")
    samples_v: int = Field(5, ge=1, description="fallback speeds, (0, v_max] evenly")
    samples_omega: int = Field(11, ge=1, description="fallback yaw rates, [-ω, ω] evenly")
    turn_rate: float = Field(1.5, gt=0, description="rad/s, on-the-spot turn when all else fails")


def arc_points(commands: NDArray[np.float64], horizon: float, step: float) -> NDArray[np.float64]:
    """``(K, S, 2)`` positions (m, robot frame) along each command ``(K, 2)``'s arc.

    Times ``step, 2 step, ..., horizon`` (s), from the origin heading +x.
    """
    t = np.arange(1, max(1, round(horizon / step)) + 1) * step
    v, w = commands[:, 0:1], commands[:, 1:2]
    th = w * t
    small = np.abs(w) < 1e-6
    ws = np.where(small, 1.0, w)
    x = np.where(small, v * t, v / ws * np.sin(th))
    y = np.where(small, 0.0, v / ws * (1.0 - np.cos(th)))
    return np.stack([x, y], axis=-1)


def unsafe(
    commands: NDArray[np.float64], points: NDArray[np.float64], radius: float,
    params: SafetyParams,
) -> NDArray[np.bool_]:
    """``(K,)`` whether each command ``(K, 2)`` brings the disc too near a return ``(M, 2)``."""
    if len(points) == 0:
        return np.zeros(len(commands), dtype=bool)
    now = float(np.min(np.linalg.norm(points, axis=1)))
    limit = min(radius + params.margin, now - 1e-3)
    xy = arc_points(commands, params.horizon, params.step)
    d2 = np.sum((xy[:, :, None, :] - points[None, None]) ** 2, axis=-1)
    return np.asarray(np.min(d2, axis=(1, 2)) < limit * limit)


def safe_command(
    command: NDArray[np.float64], target_xy: NDArray[np.float64], points: NDArray[np.float64],
    radius: float, v_max: float, omega_max: float, params: SafetyParams,
) -> tuple[NDArray[np.float64], str]:
    """The command to drive and why: ``"policy"``, ``"fallback"`` or ``"turn"``.

    Args:
        command: ``(2,)`` the policy's ``[v m/s, ω rad/s]``.
        target_xy: ``(2,)`` the target (m, robot frame).
        points: ``(M, 2)`` scan returns (m, robot frame).
        radius: the robot's bounding radius (m).
        v_max: fastest forward speed sampled by the fallback (m/s).
        omega_max: largest yaw rate sampled by the fallback (rad/s).
        params: the check's parameters.
    """
    reach = v_max * params.horizon + radius + params.margin
    near = points[np.sum(points**2, axis=1) < reach * reach] if len(points) else points
    cmd = np.asarray(command, dtype=np.float64).reshape(1, 2)
    if not unsafe(cmd, near, radius, params)[0]:
        return cmd[0], "policy"
    vs = np.linspace(v_max, 0.0, params.samples_v, endpoint=False)[::-1]
    ws = np.linspace(-omega_max, omega_max, params.samples_omega)
    grid = np.stack(np.meshgrid(vs, ws, indexing="ij"), axis=-1).reshape(-1, 2)
    ok = ~unsafe(grid, near, radius, params)
    if np.any(ok):
        cand = grid[ok]
        end = arc_points(cand, params.horizon, params.step)[:, -1]
        miss = np.linalg.norm(end - target_xy, axis=1)
        best = np.lexsort((-cand[:, 0], np.round(miss, 3)))[0]  # nearest end, then faster
        return cand[best], "fallback"
    side = math.copysign(1.0, float(target_xy[1])) if target_xy[1] != 0 else 1.0
    return np.array([0.0, side * min(params.turn_rate, omega_max)]), "turn"
