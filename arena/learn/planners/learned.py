"""``rosnav_rl``: a PPO policy trained with ``arena train``, as a local planner.

Description:
    Each tick the planner rebuilds the observation :class:`~arena.learn.env.SocialNavEnv`
    gives its policy, from the :class:`LocalObservation`: ``lidar`` (the last
    ``laser_stack`` scans; no-return beams read as the laser's maximum range), ``goal``
    (``[ρ, θ]`` to a subgoal on the global path ``subgoal_horizon`` m ahead, Arena's
    "spacial horizon", or to the goal when it is closer) and ``last_action`` (the planner's own
    previous command). It runs the exported actor with numpy (:class:`NumpyPolicy`), decodes
    the deterministic action into ``[vx, vy, ω]`` as the env does, and passes it through
    :func:`~.path_tracking.finish_command` (acceleration window, velocity box).

    Any laser works: each scan is resampled onto the policy's own beams
    (:func:`resample_scan`, the layout recorded in the policy file's ``laser`` meta; files
    without it are taken to have evenly spread full-circle beams).

    ``rosnav_rl`` does not take policies whose observation has ``pedestrians`` or ``semantic``
    parts; ``trail`` rebuilds ``semantic`` from the observation's known people
    (:meth:`PolicyPlanner.semantic`; the local observation carries no pedestrian types or
    social states, so those channels read an adult with no state).

    The machinery (observation rebuilding, numpy inference, command limiting) lives in
    :class:`PolicyPlanner`, which other learned planners (``rlca``) subclass with their own
    weights and observation parts.

Arguments:
    See :class:`LearnedPlanner.Params`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, ClassVar, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

from arena.core.errors import ConfigError
from arena.learn.config import SemanticObsConfig
from arena.learn.paths import subgoal_on_path
from arena.learn.ped_maps import semantic_maps, to_robot_frame
from arena.learn.policy import NumpyPolicy
from arena.nav.local_planners.base import LOCAL_PLANNERS, LocalObservation
from arena.nav.local_planners.path_tracking import finish_command

DEFAULT_WEIGHTS = (
    Path(__file__).resolve().parents[1] / "data" / "policies" / "rosnav_rl.npz"
)
"""The packaged policy (``arena/learn/data/policies/rosnav_rl.npz``)."""
SUPPORTED_KEYS = frozenset({"lidar", "goal", "last_action"})


def _wrap(a: NDArray[np.float64]) -> NDArray[np.float64]:
    return (a + np.pi) % (2 * np.pi) - np.pi


def beam_bins(angles: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Half-widths ``(below, above)`` (rad) of each beam's angular bin.

    A bin reaches half way to each neighbour; a layout covering the full circle wraps around,
    otherwise the end beams mirror their inner half-width.
    """
    a = np.asarray(angles, dtype=np.float64).reshape(-1)
    n = a.size
    if n == 0:
        return np.zeros(0), np.zeros(0)
    if n == 1:
        return np.full(1, np.pi), np.full(1, np.pi)
    gaps = np.abs(_wrap(np.diff(a)))  # (n-1,) spacing to the next beam
    span = float(np.sum(gaps))
    full = span + float(np.median(gaps)) >= 2 * np.pi - 1e-3
    if full:
        last = float(np.abs(_wrap(np.array([a[0] - a[-1]])))[0])
        ring = np.append(gaps, last)
        below = np.roll(ring, 1) / 2
        above = ring / 2
    else:
        below = np.concatenate([[gaps[0]], gaps]) / 2
        above = np.concatenate([gaps, [gaps[-1]]]) / 2
    return below, above


def resample_scan(
    scan_angles: NDArray[np.float64],
    scan_ranges: NDArray[np.float64],
    beam_angles: NDArray[np.float64],
    range_max: float,
) -> NDArray[np.float64]:
    """A scan (any beam count, incl. 0) as seen by the beams ``beam_angles`` (robot frame).

    Per target beam: the minimum range of the scan beams inside its bin (:func:`beam_bins`),
    else the range of the nearest scan beam by angle when it lies within one target spacing,
    else ``range_max``; non-finite ranges read ``range_max``; clipped to ``[0, range_max]``.
    Identical layouts give the scan back unchanged.
    """
    tgt = np.asarray(beam_angles, dtype=np.float64).reshape(-1)
    sa = np.asarray(scan_angles, dtype=np.float64).reshape(-1)
    sr = np.asarray(scan_ranges, dtype=np.float64).reshape(-1)
    out = np.full(tgt.size, float(range_max))
    if sa.size == 0 or tgt.size == 0:
        return out
    sr = np.clip(np.where(np.isfinite(sr), sr, range_max), 0.0, range_max)
    if sa.shape == tgt.shape and np.array_equal(sa, tgt):
        # the policy's own laser: each bin holds exactly its beam (and the (P, S) comparison
        # below, 720 × 720 for a jackal, would be most of a control cycle)
        return sr
    below, above = beam_bins(tgt)
    d = _wrap(sa[None, :] - tgt[:, None])  # (P, S)
    inside = (d >= -below[:, None]) & (d < above[:, None])
    binned = np.where(inside, sr[None, :], np.inf).min(axis=1)
    has = inside.any(axis=1)
    ad = np.abs(d)
    nearest = np.argmin(ad, axis=1)
    close = ad[np.arange(tgt.size), nearest] <= below + above
    out = np.where(has, binned, np.where(close, sr[nearest], range_max))
    return np.clip(out, 0.0, range_max)


class PolicyParams(BaseModel):
    """Parameters shared by the planners that run an exported policy (``rosnav_rl``, ``rlca``)."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    weights: str | None = Field(
        None, description="exported policy (.npz, RUN/policy.npz); None: the packaged one"
    )
    subgoal_horizon: float | Literal["policy"] | None = Field(
        "policy",
        description="m along the path to the subgoal (Arena: 5.0); None: the goal itself; "
        "policy: the horizon the policy was trained with (observation.subgoal), else 5.0",
    )


class PolicyPlanner:
    """Base of the planners that run an exported PPO actor (numpy inference).

    Subclasses set :attr:`planner_name` (in messages), :attr:`default_weights` (the packaged
    file) and :attr:`supported_keys` (observation parts :meth:`observation` may rebuild), and
    define a ``Params`` model deriving from :class:`PolicyParams`. Observation parts: ``lidar``
    (the last ``stack`` scans, resampled onto the policy's beams), ``goal`` (``[ρ m, θ rad]``
    to the subgoal on the global path), ``last_action`` (the planner's previous command) and
    ``velocity`` (the measured body twist ``[vx, vy, ω]`` of the observation).
    """

    supports: ClassVar[frozenset[str]] = frozenset({"diff_drive", "omni", "legged"})
    planner_name: ClassVar[str] = "rosnav_rl"
    default_weights: ClassVar[Path] = DEFAULT_WEIGHTS
    supported_keys: ClassVar[frozenset[str]] = SUPPORTED_KEYS
    params: Any

    def __init__(self, params: Any = None) -> None:
        self.params = p = params if params is not None else self._default_params()
        path = Path(p.weights) if p.weights is not None else self.default_weights
        if not path.is_file():
            raise ConfigError(
                f"no policy file {str(path)!r}: train one with `arena train CONFIG -o RUN` and "
                "pass weights: RUN/policy.npz",
                path="navigation.local_planner.weights",
            )
        self.policy = NumpyPolicy.load(path)
        if not self.policy.is_dict:
            raise ConfigError(
                f"{path}: {self.planner_name} needs a Dict-observation policy "
                "(observation.flatten: false)",
                path="navigation.local_planner.weights",
            )
        extra = set(self.policy.keys) - self.supported_keys
        if extra:
            raise ConfigError(
                f"{path}: observation parts {sorted(extra)} are not supported by "
                f"{self.planner_name} (supported: {sorted(self.supported_keys)})",
                path="navigation.local_planner.weights",
            )
        if self.policy.meta.get("command") is None:
            raise ConfigError(f"{path}: the policy file records no action decoding",
                              path="navigation.local_planner.weights")
        self.beam_angles = np.zeros(0)
        self.range_max = 0.0
        if "lidar" in self.policy.keys:
            beams = int(self.policy.shapes["lidar"][-1])
            laser = self.policy.meta.get("laser") or {}
            self.range_max = float(
                laser.get("range_max", np.max(self.policy.arrays["high/lidar"]))
            )
            angles = laser.get("angles")
            if angles is None:  # older files: evenly spread full-circle beams
                angles = -np.pi + 2 * np.pi / beams * np.arange(beams)
            self.beam_angles = np.asarray(angles, dtype=np.float64).reshape(-1)
            if self.beam_angles.size != beams:
                raise ConfigError(
                    f"{path}: the laser meta has {self.beam_angles.size} angles for "
                    f"{beams} lidar beams",
                    path="navigation.local_planner.weights",
                )
        self.horizon: float | None
        if p.subgoal_horizon == "policy":
            sub = (self.policy.meta.get("observation") or {}).get("subgoal") or {}
            self.horizon = float(sub["horizon"]) if sub.get("enabled") else 5.0
        else:
            self.horizon = p.subgoal_horizon
        self.reset()

    def _default_params(self) -> Any:
        return type(self).Params()  # type: ignore[attr-defined]

    def reset(self) -> None:
        """Forget the scan history and the last command."""
        self._scans: NDArray[np.float64] | None = None
        self._last = np.zeros(3)

    def observation(self, obs: LocalObservation) -> dict[str, NDArray[np.float32]]:
        """The policy's observation for ``obs`` (updates the scan history)."""
        pol = self.policy
        out: dict[str, NDArray[np.float32]] = {}
        if "lidar" in pol.keys:
            shape = pol.shapes["lidar"]  # (beams,), or (stack, beams) for stacked scans
            stack = shape[0] if len(shape) == 2 else 1
            r = resample_scan(obs.scan_angles, obs.scan_ranges, self.beam_angles, self.range_max)
            if self._scans is None:
                self._scans = np.repeat(r[None], stack, axis=0)
            else:
                self._scans = np.concatenate([self._scans[1:], r[None]], axis=0)
            out["lidar"] = self._scans.reshape(shape).astype(np.float32)
        pose = np.asarray(obs.pose, dtype=np.float64).reshape(3)
        if "goal" in pol.keys:
            goal = np.array([obs.goal_pose.x, obs.goal_pose.y])
            target = goal
            path = np.asarray(obs.path, dtype=np.float64).reshape(-1, 2)
            if self.horizon is not None and len(path):
                target = subgoal_on_path(path, pose[:2], self.horizon)
            d = target - pose[:2]
            theta = (np.arctan2(d[1], d[0]) - pose[2] + np.pi) % (2 * np.pi) - np.pi
            rho = min(float(np.hypot(d[0], d[1])), float(pol.arrays["high/goal"][0]))
            out["goal"] = np.array([rho, theta], np.float32)
        if "last_action" in pol.keys:
            out["last_action"] = np.clip(
                self._last, pol.arrays["low/last_action"], pol.arrays["high/last_action"]
            ).astype(np.float32)
        if "semantic" in pol.keys:
            out["semantic"] = self.semantic(obs)
        if "velocity" in pol.keys:
            twist = np.asarray(obs.twist, dtype=np.float64).reshape(3)
            out["velocity"] = np.clip(
                twist, pol.arrays["low/velocity"], pol.arrays["high/velocity"]
            ).astype(np.float32)
        return out

    def semantic(self, obs: LocalObservation) -> NDArray[np.float32]:
        """The ``semantic`` part ``(channels, size, size)`` from ``obs.pedestrians``.

        The maps the policy was trained with (its recorded ``observation.semantic``), drawn
        by the environments' own :func:`~arena.learn.ped_maps.semantic_maps`.
        """
        sem = (self.policy.meta.get("observation") or {}).get("semantic")
        if sem is None:
            raise ConfigError(f"{self.policy.source}: the policy records no observation.semantic",
                              path="navigation.local_planner.weights")
        sc = SemanticObsConfig(**sem)
        pose = np.asarray(obs.pose, dtype=np.float64).reshape(3)
        peds = np.asarray(obs.pedestrians, dtype=np.float64).reshape(-1, 4)
        heading = pose[2:3]
        rel = to_robot_frame((peds[:, :2] - pose[:2])[None], heading)
        vel = to_robot_frame(peds[None, :, 2:4], heading)
        m = peds.shape[0]
        grid = semantic_maps(sc, rel, vel, np.zeros((1, m), np.int64),
                             np.zeros((1, m), np.int64), np.ones((1, m), bool))
        return grid[0]

    def compute(self, obs: LocalObservation) -> NDArray[np.float64]:
        """The policy's command, limited by :func:`finish_command`."""
        action = self.policy.act(self.observation(obs))
        cmd = self.policy.command(action)
        lim = obs.limits
        car = obs.drive == "ackermann" or lim.min_turning_radius > 0
        twist = np.asarray(obs.twist, dtype=np.float64).reshape(3)
        out = finish_command(cmd, twist, lim, float(obs.dt), car)
        self._last = out.copy()
        return out


@LOCAL_PLANNERS.register("rosnav_rl", tags=("learned",))
class LearnedPlanner(PolicyPlanner):
    """A trained PPO actor (numpy inference) driving the robot."""

    class Params(PolicyParams):
        """Parameters of ``rosnav_rl``."""

    def __init__(self, params: Params | None = None) -> None:
        super().__init__(params)
