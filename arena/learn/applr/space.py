"""What APPLR tunes, within which ranges, and what its policy sees (numpy only).

Parameters (APPLR's DWA parameters, in the terms of our :class:`~arena.nav.local_planners.dwa.
DWAPlanner`; ranges after the paper's, narrowed where ours would cost more than a control cycle
allows):

=================== ===== ======= ===== ==========================================================
name                low   default high  meaning
=================== ===== ======= ===== ==========================================================
``speed_fraction``  0.2   1.0     1.0   cap on ``vx``, share of ``vx_max`` (``max_vel_x``)
``turn_fraction``   0.2   1.0     1.0   cap on ``|ω|``, share of ``omega_max`` (``max_vel_theta``)
``vx_samples``      3     11      15    DWA samples of ``vx`` (``vx_samples``)
``omega_samples``   7     21      31    samples of ``ω`` (``vtheta_samples``)
``path_weight``     0.1   1.0     3.0   1/m, path distance (``path_distance_bias``)
``goal_weight``     0.1   1.2     3.0   1/m, goal distance (``goal_distance_bias``)
``obstacle_weight`` 0.0   0.6     3.0   obstacle cost (``occdist_scale``)
``obstacle_scale``  0.05  0.25    0.6   m, decay of the obstacle cost with clearance (inflation)
``min_clearance``   0.0   0.05    0.2   m, clearance a moving rollout must keep
=================== ===== ======= ===== ==========================================================

Action: ``a ∈ [-1, 1]^9``, mapped piecewise linearly per parameter: ``a = -1`` → low, ``a = 0``
→ DWA's default, ``a = 1`` → high (integers rounded). So ``a = 0`` is our DWA exactly (the
paper's fallback), and every action, even a diverging one, gives parameters inside the ranges
(:func:`parameter_values` clips first).

Observation (``(B + 2 + 9,)`` float32, :func:`observation`): the scan resampled onto ``B``
beams (min over each beam's bin) and clipped at 2 m, divided by 2 m (APPLR clips its laser at
2 m: farther obstacles do not change what DWA should do now); ``[ρ / horizon, θ / π]`` of the
local goal ``goal_horizon`` m along the global path in the robot frame (on a cluttered map the
final goal usually lies behind obstacles, so its direction says little about the way there);
the action now in force.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from arena.learn.paths import subgoal_on_path
from arena.learn.planners.learned import resample_scan
from arena.nav.local_planners.base import LocalObservation

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class TunedParam:
    """One tuned parameter: its range, DWA's default and the action mapping.

    Attributes:
        name: a :class:`DWAPlanner.Params` field, or ``speed_fraction`` / ``turn_fraction``
            (caps on the velocity box, applied by :class:`~.tuned_dwa.TunedDWA`).
        low: value at ``a = -1``.
        default: value at ``a = 0`` (DWA's default).
        high: value at ``a = 1``.
        integer: rounded to the nearest integer.
    """

    name: str
    low: float
    default: float
    high: float
    integer: bool = False

    def value(self, a: float) -> float:
        """The parameter for action component ``a`` (clipped to ``[-1, 1]`` first)."""
        a = min(max(float(a), -1.0), 1.0) if math.isfinite(a) else 0.0
        t, end = abs(a), (self.high if a > 0 else self.low)
        v = (1.0 - t) * self.default + t * end  # a = ±1 gives the ends exactly, not an ulp off
        v = min(max(v, self.low), self.high)
        return float(round(v)) if self.integer else v

    def action(self, value: float) -> float:
        """The action component giving ``value`` (inverse of :meth:`value`, clipped)."""
        if value >= self.default:
            span = self.high - self.default
            a = (value - self.default) / span if span > 0 else 0.0
        else:
            span = self.default - self.low
            a = (value - self.default) / span if span > 0 else 0.0
        return min(max(a, -1.0), 1.0)


PARAMETERS: tuple[TunedParam, ...] = (
    TunedParam("speed_fraction", 0.2, 1.0, 1.0),
    TunedParam("turn_fraction", 0.2, 1.0, 1.0),
    TunedParam("vx_samples", 3, 11, 15, integer=True),
    TunedParam("omega_samples", 7, 21, 31, integer=True),
    TunedParam("path_weight", 0.1, 1.0, 3.0),
    TunedParam("goal_weight", 0.1, 1.2, 3.0),
    TunedParam("obstacle_weight", 0.0, 0.6, 3.0),
    TunedParam("obstacle_scale", 0.05, 0.25, 0.6),
    TunedParam("min_clearance", 0.0, 0.05, 0.2),
)
"""The tuned parameters in action order (see the module docstring)."""
CAPS = ("speed_fraction", "turn_fraction")
"""Parameters that cap the velocity box instead of setting a DWA field."""


def parameter_values(
    action: NDArray[Any], params: tuple[TunedParam, ...] = PARAMETERS
) -> dict[str, float]:
    """``{name: value}`` for an action ``(k,)`` (any real values; non-finite ones read 0)."""
    a = np.asarray(action, dtype=np.float64).reshape(-1)
    if a.shape != (len(params),):
        raise ValueError(f"an APPLR action has {len(params)} components, got shape {a.shape}")
    return {p.name: p.value(float(x)) for p, x in zip(params, a, strict=True)}


def parameter_ranges(params: tuple[TunedParam, ...] = PARAMETERS) -> list[dict[str, Any]]:
    """The ranges as JSON rows (recorded in policy files)."""
    return [{"name": p.name, "low": p.low, "default": p.default, "high": p.high,
             "integer": p.integer} for p in params]


def parameters_from_rows(rows: list[dict[str, Any]]) -> tuple[TunedParam, ...]:
    """Inverse of :func:`parameter_ranges`."""
    return tuple(TunedParam(str(r["name"]), float(r["low"]), float(r["default"]),
                            float(r["high"]), bool(r["integer"])) for r in rows)


@dataclass(frozen=True, eq=False)
class FeatureSpec:
    """How :func:`observation` builds the policy's input.

    Attributes:
        beam_angles: ``(B,)`` rad, robot frame: the policy's beams (any scan is resampled).
        clip_range: m, ranges beyond this read as this (APPLR: 2 m).
        goal_horizon: m along the global path to the local goal.
    """

    beam_angles: FloatArray
    clip_range: float = 2.0
    goal_horizon: float = 2.0

    def size(self, n_params: int) -> int:
        """Length of the observation with ``n_params`` tuned parameters."""
        return int(self.beam_angles.size) + 2 + n_params

    def to_json(self) -> dict[str, Any]:
        """The spec as JSON (recorded in policy files)."""
        return {"beam_angles": [float(a) for a in self.beam_angles],
                "clip_range": self.clip_range, "goal_horizon": self.goal_horizon}

    @classmethod
    def from_json(cls, d: dict[str, Any]) -> FeatureSpec:
        """Inverse of :meth:`to_json`."""
        return cls(np.asarray(d["beam_angles"], dtype=np.float64), float(d["clip_range"]),
                   float(d["goal_horizon"]))


def spread_beams(angle_min: float, angle_max: float, beams: int) -> FloatArray:
    """``(beams,)`` angles (rad) evenly spread from ``angle_min`` to ``angle_max``."""
    return np.linspace(float(angle_min), float(angle_max), int(beams))


def observation(obs: LocalObservation, action: NDArray[Any], spec: FeatureSpec) -> (
    NDArray[np.float32]
):
    """The policy's input for ``obs`` with ``action`` ``(k,)`` in force (module docstring).

    Returns:
        ``(B + 2 + k,)`` float32: ranges / clip ``[0, 1]``, ``ρ / horizon ∈ [0, 1]``,
        ``θ / π ∈ [-1, 1]``, the action.
    """
    ranges = resample_scan(obs.scan_angles, obs.scan_ranges, spec.beam_angles, spec.clip_range)
    pose = np.asarray(obs.pose, dtype=np.float64).reshape(3)
    path = np.asarray(obs.path, dtype=np.float64).reshape(-1, 2)
    goal = obs.goal_pose
    target = (subgoal_on_path(path, pose[:2], spec.goal_horizon) if len(path)
              else np.array([goal.x, goal.y]))
    d = target - pose[:2]
    rho = min(float(np.hypot(d[0], d[1])), spec.goal_horizon) / spec.goal_horizon
    theta = (math.atan2(d[1], d[0]) - pose[2] + math.pi) % (2 * math.pi) - math.pi
    a = np.clip(np.asarray(action, dtype=np.float64).reshape(-1), -1.0, 1.0)
    return np.concatenate(
        [ranges / spec.clip_range, [rho, theta / math.pi], a]
    ).astype(np.float32)
