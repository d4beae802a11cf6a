"""Built-in intermediate planners: bypass, shortsighted, aggressive, polite, sideways, meta.

Behaviours and thresholds follow Arena-Rosnav's move_base_flex inter plugins (arena_specs §7).
Where Arena's code has a bug we implement the intended behaviour and say so:

- **aggressive**: Arena's speed helper is declared ``bool``, so the value it sends is 0 or 1;
  we send the formula ``v_max · d² / (1 + d²)``.
- **polite / sideways**: the pedestrian bearing is computed with ``atan2(dx, dy)`` (axes
  swapped); we use ``atan2(dy, dx)`` relative to the robot heading (:func:`in_fov`).
- **polite / sideways**: the "wall behind" check compares laser angles (robot frame) with the
  robot's yaw (world frame); we check the returns in the half-plane toward the temporary goal,
  i.e. in the direction the robot is about to drive.
- Distances: Arena's ``sqrt(dx² + dy²) + dz²`` is Euclidean in the plane.

Speeds are overrides of the local planner's ``max_speed`` (m/s), relative to the nominal cruise
speed ``IntermediateInput.max_speed`` (Arena's ``max_vel_x``). No override means "configured".
"""

from __future__ import annotations

import math

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from arena.nav.intermediate.base import (
    ELDER,
    INTERMEDIATE_PLANNERS,
    FloatArray,
    IntermediateInput,
    IntermediateOutput,
    danger_level,
    detour_path,
    in_fov,
    pedestrian_distances,
)

_FROZEN = ConfigDict(frozen=True, extra="forbid")


def _xy(inp: IntermediateInput) -> FloatArray:
    return np.asarray(inp.pose, dtype=np.float64).reshape(3)[:2].copy()


def _global_path(inp: IntermediateInput) -> FloatArray:
    path = np.asarray(inp.path, dtype=np.float64).reshape(-1, 2)
    if len(path) == 0:
        return np.asarray(inp.goal, dtype=np.float64).reshape(-1)[:2][None, :].copy()
    return path


def _info(distances: FloatArray, threshold: float, mode: str) -> dict[str, float | str]:
    danger = danger_level(distances)
    # Arena publishes a "SIGNAL" string on ~Danger above the threshold; we report it as a flag.
    return {"danger": danger, "signal": float(danger > threshold), "mode": mode}


@INTERMEDIATE_PLANNERS.register("bypass", tags=("default",))
class BypassPlanner:
    """Passes the global path through unchanged, with no overrides."""

    def __init__(self) -> None:
        pass

    def reset(self) -> None:
        """Nothing to forget."""

    def plan(self, inp: IntermediateInput) -> IntermediateOutput:
        """The global path itself (the same array) and no overrides."""
        return IntermediateOutput(path=inp.path)


@INTERMEDIATE_PLANNERS.register("shortsighted")
class ShortsightedPlanner:
    """Subsamples the global path inside the local window: a point every ``spacing`` m.

    From the robot's projection onto the path, points are taken every ``spacing`` m along it
    (plus the path's end) while they lie within the window radius of the robot; at least two
    points are returned when the path has two.
    """

    class Params(BaseModel):
        """Parameters of :class:`ShortsightedPlanner`."""

        model_config = _FROZEN

        spacing: float = Field(0.5, gt=0, description="m between subsampled points along the path")
        window: float | None = Field(
            None, gt=0, description="m, window radius; None uses the stack's local window"
        )

    def __init__(self, params: Params | None = None) -> None:
        self.params = params if params is not None else self.Params()

    def reset(self) -> None:
        """Stateless."""

    def plan(self, inp: IntermediateInput) -> IntermediateOutput:
        """The subsampled piece of the global path inside the window."""
        path = _global_path(inp)
        if len(path) < 2:
            return IntermediateOutput(path=path.copy(), info={"mode": "shortsighted"})
        window = self.params.window if self.params.window is not None else float(inp.window)
        xy = _xy(inp)
        a, b = path[:-1], path[1:]
        ab = b - a
        seg_len = np.hypot(ab[:, 0], ab[:, 1])
        t = np.clip(
            np.einsum("ij,ij->i", xy - a, ab) / np.maximum(seg_len**2, 1e-18), 0.0, 1.0
        )
        proj = a + t[:, None] * ab
        i = int(np.argmin(np.hypot(*(proj - xy).T)))
        cum = np.concatenate([[0.0], np.cumsum(seg_len)])
        s0, total = float(cum[i] + t[i] * seg_len[i]), float(cum[-1])
        s = np.append(np.arange(s0, total, self.params.spacing), total)
        idx = np.clip(np.searchsorted(cum, s, side="right") - 1, 0, len(seg_len) - 1)
        frac = (s - cum[idx]) / np.maximum(seg_len[idx], 1e-18)
        pts = path[idx] + np.clip(frac, 0.0, 1.0)[:, None] * ab[idx]
        outside = np.hypot(*(pts - xy).T) > window
        n = int(np.argmax(outside)) if outside.any() else len(pts)
        return IntermediateOutput(path=pts[: max(n, 2)].copy(), info={"mode": "shortsighted"})


@INTERMEDIATE_PLANNERS.register("aggressive", tags=("social",))
class AggressivePlanner:
    """Keeps the global path; slows down only a little near people: ``v = v_max·d²/(1+d²)``.

    With the nearest pedestrian at ``d ≤ slowdown_distance`` m the speed is
    ``v_max − v_max / (1 + d²)`` (80 % at 2 m, 50 % at 1 m), else full speed.
    """

    class Params(BaseModel):
        """Parameters of :class:`AggressivePlanner` (Arena's ``aggressive_inter.cfg``)."""

        model_config = _FROZEN

        slowdown_distance: float = Field(
            5.0, ge=0, le=20, description="m, pedestrians closer than this slow the robot"
        )
        danger_threshold: float = Field(
            0.6, ge=0, le=1, description="danger level above which the danger signal is raised"
        )

    def __init__(self, params: Params | None = None) -> None:
        self.params = params if params is not None else self.Params()

    def reset(self) -> None:
        """Stateless."""

    def plan(self, inp: IntermediateInput) -> IntermediateOutput:
        """The global path, and ``max_speed`` from the nearest pedestrian's distance."""
        d = pedestrian_distances(inp)
        info = _info(d, self.params.danger_threshold, "aggressive")
        overrides: dict[str, float] = {}
        if d.size and float(d.min()) <= self.params.slowdown_distance:
            dmin = float(d.min())
            overrides["max_speed"] = inp.max_speed - inp.max_speed / (1.0 + dmin**2)
        return IntermediateOutput(path=inp.path, overrides=overrides, info=info)


class _RetreatParams(BaseModel):
    """Parameters shared by the polite and sideways planners."""

    model_config = _FROZEN

    caution_detection_range: float = Field(
        4.0, gt=0, description="m, a pedestrian closer than this slows the robot to cautious_speed"
    )
    cautious_speed: float = Field(
        0.5, ge=0, le=1, description="speed multiplier (of max_speed) near pedestrians"
    )
    ped_minimum_distance: float = Field(
        2.0, gt=0, description="m, a pedestrian this close inside the fov makes the robot retreat"
    )
    temp_goal_distance: float = Field(
        2.0, gt=0, description="m, how far the temporary goal lies behind the robot"
    )
    temp_goal_tolerance: float = Field(
        0.25, gt=0, description="m, distance at which the temporary goal counts as reached"
    )
    fov: float = Field(
        math.pi, gt=0, le=2 * math.pi, description="rad, full width of the frontal cone"
    )
    danger_threshold: float = Field(
        0.6, ge=0, le=1, description="danger level above which the danger signal is raised"
    )
    retreat_cooldown: float = Field(
        4.0, ge=0,
        description="s after a retreat ends during which no new retreat starts (ours; Arena: 0, "
        "which lets a robot facing a standing group retreat over and over and never arrive)",
    )


class _Retreat:
    """Temporary-goal logic shared by polite and sideways."""

    params: _RetreatParams
    _padding: float
    _temp: FloatArray | None
    _retreat_end: float = -math.inf

    def _end_retreat(self, inp: IntermediateInput) -> None:
        self._temp = None
        self._retreat_end = float(inp.time)

    def _speed(self, inp: IntermediateInput, d: FloatArray) -> dict[str, float]:
        if d.size and float(d.min()) <= self.params.caution_detection_range:
            return {"max_speed": self.params.cautious_speed * inp.max_speed}
        return {}

    def _triggered(self, inp: IntermediateInput, d: FloatArray) -> bool:
        if float(inp.time) < self._retreat_end + self.params.retreat_cooldown - 1e-9:
            return False
        near = d <= self.params.ped_minimum_distance
        if not near.any():
            return False
        peds = np.asarray(inp.pedestrians.positions, dtype=np.float64).reshape(-1, 2)
        return bool(np.any(near & in_fov(inp, peds, self.params.fov)))

    def _blocked(self, inp: IntermediateInput, target: FloatArray) -> bool:
        """A laser return toward ``target`` (within ±90°) closer than the clearance."""
        pts = np.asarray(inp.obstacle_points, dtype=np.float64).reshape(-1, 2)
        if len(pts) == 0:
            return False
        xy = _xy(inp)
        heading = target - xy
        norm = float(np.hypot(*heading))
        if norm < 1e-9:
            return False
        rel = pts - xy
        ahead = rel @ (heading / norm) >= 0.0
        clearance = min(self.params.temp_goal_distance, 2 * inp.robot_radius + self._padding)
        return bool(np.any(ahead & (np.hypot(rel[:, 0], rel[:, 1]) < clearance)))


@INTERMEDIATE_PLANNERS.register("polite", tags=("social",))
class PolitePlanner(_Retreat):
    """Slows down near people and backs away from a pedestrian right in front of it.

    - A pedestrian within ``caution_detection_range`` → ``max_speed = cautious_speed · v_max``.
    - A pedestrian within ``ped_minimum_distance`` inside the frontal ``fov`` → a temporary goal
      ``temp_goal_distance`` m straight behind the robot replaces the path until the robot is
      within ``temp_goal_tolerance`` of it; it is abandoned (normal path again) when a laser
      return toward it is closer than ``min(temp_goal_distance, 2·robot_radius + 0.075)``.
    - No new retreat for ``retreat_cooldown`` s after one ended (our addition; Arena has none).
    """

    class Params(_RetreatParams):
        """Parameters of :class:`PolitePlanner` (Arena's ``polite_inter.cfg``)."""

    _PADDING = 0.075

    def __init__(self, params: Params | None = None) -> None:
        self.params = params if params is not None else self.Params()
        self._padding = self._PADDING
        self.reset()

    def reset(self) -> None:
        """Drop the temporary goal and the cooldown."""
        self._temp = None
        self._retreat_end = -math.inf

    def plan(self, inp: IntermediateInput) -> IntermediateOutput:
        """The global path or the retreat to the temporary goal, and the speed override."""
        d = pedestrian_distances(inp)
        info = _info(d, self.params.danger_threshold, "polite")
        overrides = self._speed(inp, d)
        xy = _xy(inp)
        if self._temp is None and self._triggered(inp, d):
            th = float(np.asarray(inp.pose).reshape(3)[2])
            dist = self.params.temp_goal_distance
            self._temp = xy - dist * np.array([math.cos(th), math.sin(th)])
        if self._temp is not None and (
            float(np.hypot(*(self._temp - xy))) <= self.params.temp_goal_tolerance
            or self._blocked(inp, self._temp)
        ):
            self._end_retreat(inp)
        if self._temp is None:
            return IntermediateOutput(path=inp.path, overrides=overrides, info=info)
        info["mode"] = "polite_retreat"
        return IntermediateOutput(
            path=detour_path(inp, self._temp), overrides=overrides, info=info
        )


@INTERMEDIATE_PLANNERS.register("sideways", tags=("social",))
class SidewaysPlanner(_Retreat):
    """Slows down near people and steps back and to the right of a pedestrian in front of it.

    - A pedestrian within ``caution_detection_range`` → ``max_speed = cautious_speed · v_max``.
    - A pedestrian within ``ped_minimum_distance`` inside the frontal ``fov`` → the temporary
      goal ``p − 1.5·temp_goal_distance·(cos(θ+π/4), sin(θ+π/4))``, i.e. behind the robot and
      to its **right** (135° clockwise from the heading), replaces the path. On reaching it
      (within ``temp_goal_tolerance``), or when a laser return toward it is closer than
      ``min(temp_goal_distance, 2·robot_radius + padding)``, the robot stops
      (``max_speed = 0``) for ``wait_time`` s; then the path and speed are restored.
    """

    class Params(_RetreatParams):
        """Parameters of :class:`SidewaysPlanner` (Arena's ``sideways_inter.cfg``)."""

        caution_detection_range: float = Field(
            5.0, gt=0,
            description="m, a pedestrian closer than this slows the robot to cautious_speed",
        )
        cautious_speed: float = Field(
            0.4, ge=0, le=1, description="speed multiplier (of max_speed) near pedestrians"
        )
        padding: float = Field(
            0.135, ge=0, description="m added to the robot diameter for the wall check"
        )
        wait_time: float = Field(
            2.5, ge=0, description="s the robot stands still after stepping aside"
        )

    def __init__(self, params: Params | None = None) -> None:
        self.params: SidewaysPlanner.Params = params if params is not None else self.Params()
        self._padding = self.params.padding
        self.reset()

    def reset(self) -> None:
        """Drop the temporary goal, the wait timer and the cooldown."""
        self._temp = None
        self._wait_until: float | None = None
        self._retreat_end = -math.inf

    def plan(self, inp: IntermediateInput) -> IntermediateOutput:
        """The global path, the step aside, or standing still; and the speed override."""
        d = pedestrian_distances(inp)
        info = _info(d, self.params.danger_threshold, "sideways")
        xy = _xy(inp)
        if self._wait_until is not None:
            if inp.time < self._wait_until - 1e-9:
                info["mode"] = "sideways_wait"
                return IntermediateOutput(path=xy[None, :], overrides={"max_speed": 0.0}, info=info)
            self._wait_until = None
        overrides = self._speed(inp, d)
        if self._temp is None and self._triggered(inp, d):
            th = float(np.asarray(inp.pose).reshape(3)[2]) + math.pi / 4
            dist = 1.5 * self.params.temp_goal_distance
            self._temp = xy - dist * np.array([math.cos(th), math.sin(th)])
        if self._temp is not None and (
            float(np.hypot(*(self._temp - xy))) <= self.params.temp_goal_tolerance
            or self._blocked(inp, self._temp)
        ):
            self._wait_until = float(inp.time) + self.params.wait_time
            self._temp = None
            # The cooldown starts when the robot moves on again, after the wait.
            self._retreat_end = self._wait_until
            info["mode"] = "sideways_wait"
            return IntermediateOutput(path=xy[None, :], overrides={"max_speed": 0.0}, info=info)
        if self._temp is None:
            return IntermediateOutput(path=inp.path, overrides=overrides, info=info)
        info["mode"] = "sideways_step"
        return IntermediateOutput(
            path=detour_path(inp, self._temp), overrides=overrides, info=info
        )


@INTERMEDIATE_PLANNERS.register("meta", tags=("social",))
class MetaPlanner:
    """Switches among aggressive, polite and sideways every call.

    - **polite** once an elder (type code 1) comes within ``polite_range`` m; sticky: it stays
      the base behaviour until :meth:`reset`.
    - **sideways** while a laser return not explained by a pedestrian (its range differs from
      every pedestrian's distance by more than ``explained_tolerance`` m) lies within
      ``sideways_range + padding`` m, ``padding`` being ``polite_padding`` when the current
      mode is polite, else ``sideways_padding``.
    - **aggressive** otherwise.

    The chosen planner's logic then runs with the shared parameters below; a planner is reset
    when the mode switches to it.
    """

    class Params(_RetreatParams):
        """Parameters of :class:`MetaPlanner` (Arena's ``meta_inter.cfg``)."""

        polite_range: float = Field(
            5.0, gt=0, description="m, an elder closer than this switches to polite (sticky)"
        )
        sideways_range: float = Field(
            3.0, gt=0, description="m, unexplained laser returns closer switch to sideways"
        )
        polite_padding: float = Field(
            0.075, ge=0, description="m added to sideways_range while polite"
        )
        sideways_padding: float = Field(
            0.135, ge=0, description="m added to sideways_range otherwise"
        )
        explained_tolerance: float = Field(
            1.0, ge=0, description="m, a return within this of a pedestrian's distance is that one"
        )
        slowdown_distance: float = Field(
            5.0, ge=0, le=20, description="m, aggressive mode's slowdown distance"
        )
        wait_time: float = Field(2.5, ge=0, description="s, sideways mode's wait after a step")

    def __init__(self, params: Params | None = None) -> None:
        self.params = params if params is not None else self.Params()
        p = self.params
        shared = {k: getattr(p, k) for k in _RetreatParams.model_fields}
        self._planners: dict[str, AggressivePlanner | PolitePlanner | SidewaysPlanner] = {
            "aggressive": AggressivePlanner(
                AggressivePlanner.Params(
                    slowdown_distance=p.slowdown_distance, danger_threshold=p.danger_threshold
                )
            ),
            "polite": PolitePlanner(PolitePlanner.Params(**shared)),
            "sideways": SidewaysPlanner(
                SidewaysPlanner.Params(
                    **shared, padding=p.sideways_padding, wait_time=p.wait_time
                )
            ),
        }
        self.reset()

    def reset(self) -> None:
        """Back to aggressive; forget the sticky polite mode and the planners' state."""
        self.mode = "aggressive"
        self._polite = False
        for planner in self._planners.values():
            planner.reset()

    def select(self, inp: IntermediateInput) -> str:
        """The mode for this call (updates the sticky polite flag)."""
        p = self.params
        d = pedestrian_distances(inp)
        kinds = np.asarray(inp.pedestrians.kinds, dtype=np.int64).reshape(-1)
        if kinds.shape == d.shape and bool(np.any((kinds == ELDER) & (d <= p.polite_range))):
            self._polite = True
        pts = np.asarray(inp.obstacle_points, dtype=np.float64).reshape(-1, 2)
        ranges = np.hypot(*(pts - _xy(inp)).T) if len(pts) else np.zeros(0)
        unexplained = np.all(np.abs(ranges[:, None] - d[None, :]) > p.explained_tolerance, axis=1)
        pad = p.polite_padding if self.mode == "polite" else p.sideways_padding
        if bool(np.any(unexplained & (ranges <= p.sideways_range + pad))):
            return "sideways"
        return "polite" if self._polite else "aggressive"

    def plan(self, inp: IntermediateInput) -> IntermediateOutput:
        """Select the mode, then run that planner."""
        mode = self.select(inp)
        if mode != self.mode:
            self._planners[mode].reset()
            self.mode = mode
        out = self._planners[mode].plan(inp)
        out.info["meta_mode"] = mode
        return out
