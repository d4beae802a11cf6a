"""Open-space motions: smooth ``(v, ω)`` command sequences rolled out with unicycle kinematics.

LfH collects motions where nothing can be hit; the obstacles come later
(:mod:`arena.learn.lflh.hallucinate`). Each command ramps linearly from its first to its last
value over the horizon, so the swept path bends more or less than a constant arc would.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field


class MotionParams(BaseModel):
    """How open-space motions are drawn."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    horizon: float = Field(1.5, gt=0, description="s, duration of one motion")
    dt: float = Field(0.05, gt=0, description="s, integration step of the rollout")
    v_min: float = Field(0.1, ge=0, description="m/s, slowest first speed")
    v_max: float = Field(1.5, gt=0, description="m/s, fastest first speed")
    omega_max: float = Field(2.0, gt=0, description="rad/s, largest first yaw rate")
    dv: float = Field(0.3, ge=0, description="m/s, largest speed change over the horizon")
    domega: float = Field(1.0, ge=0, description="rad/s, largest yaw-rate change over it")


@dataclass(frozen=True, eq=False)
class Motion:
    """One open-space motion from the origin, heading +x.

    Attributes:
        commands: ``(T, 2)`` ``[v m/s, ω rad/s]`` held for ``dt`` each.
        poses: ``(T + 1, 3)`` ``[x m, y m, θ rad]``, the first at the origin.
    """

    commands: NDArray[np.float64]
    poses: NDArray[np.float64]


def rollout(commands: NDArray[np.float64], dt: float) -> NDArray[np.float64]:
    """``(T + 1, 3)`` unicycle poses from the origin under ``commands`` ``(T, 2)`` (exact arcs)."""
    poses = np.zeros((len(commands) + 1, 3))
    for i, (v, w) in enumerate(commands):
        x, y, th = poses[i]
        if abs(w) < 1e-9:  # straight: the arc formula divides by ω
            poses[i + 1] = (x + v * dt * np.cos(th), y + v * dt * np.sin(th), th)
        else:
            th1 = th + w * dt
            r = v / w
            poses[i + 1] = (x + r * (np.sin(th1) - np.sin(th)), y - r * (np.cos(th1) - np.cos(th)),
                            th1)
    return poses


def sample_motion(params: MotionParams, rng: np.random.Generator) -> Motion:
    """Draw one motion: first command uniform in the box, last one a bounded step away."""
    p = params
    steps = max(1, round(p.horizon / p.dt))
    v0 = rng.uniform(p.v_min, p.v_max)
    w0 = rng.uniform(-p.omega_max, p.omega_max)
    v1 = float(np.clip(v0 + rng.uniform(-p.dv, p.dv), 0.0, p.v_max))
    w1 = float(np.clip(w0 + rng.uniform(-p.domega, p.domega), -p.omega_max, p.omega_max))
    s = np.arange(steps) / steps
    commands = np.stack([v0 + (v1 - v0) * s, w0 + (w1 - w0) * s], axis=-1)
    return Motion(commands, rollout(commands, p.dt))
