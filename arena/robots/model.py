"""A robot as validated data: kinematics, footprint, named sensors and action space.

The layout mirrors Arena-Rosnav's ``model_params.yaml`` (radius, actions, laser) plus the flatland
footprint and a kinematics block validated through :data:`~arena.robots.kinematics.KINEMATICS`.
Sensors are a mapping of names to ``{type: <sensor type>, **params}`` blocks validated through
:data:`~arena.sensors.base.SENSORS`; Arena's single ``laser:`` block is read as
``sensors: {laser: {type: lidar2d, ...}}``.
Presets live in ``arena/robots/presets/*.yaml`` and load with
:func:`arena.robots.presets.load_robot`.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from functools import cached_property
from typing import Annotated, Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import (
    AfterValidator,
    BaseModel,
    ConfigDict,
    Field,
    field_validator,
    model_validator,
)

from arena.core.errors import ConfigError, UnknownNameError
from arena.core.geometry import (
    bounding_radius,
    convex_hull,
    point_segment_distance,
    points_in_polygon,
    polygon_area,
)
from arena.robots.kinematics import KINEMATICS, Kinematics
from arena.robots.limits import VelocityLimits
from arena.sensors.base import SENSORS
from arena.sensors.spec import LidarSpec

_TOL = 1e-9  # slack for comparing configured numbers with derived limits


def _ordered_pair(v: tuple[float, float]) -> tuple[float, float]:
    if not v[0] <= v[1]:
        raise ValueError(f"expected [min, max] with min <= max, got {list(v)}")
    return v


_SENSOR_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")  # keys, columns and file names


def _sensor_params(name: str, block: Any, path: str) -> BaseModel:
    """One sensor block (a mapping or already validated params) as its validated params."""
    if isinstance(block, BaseModel):  # built in code: params of a registered type
        kind = getattr(block, "type", None)
        if not isinstance(kind, str) or kind not in SENSORS:
            raise ConfigError(
                f"{type(block).__name__} is not the params of a registered sensor type "
                f"(one of: {', '.join(SENSORS.names())})",
                path=path,
            )
        return block
    try:
        params = SENSORS.check(block, path=path)
    except UnknownNameError as e:  # a bad field of this robot, not an unknown robot
        raise ConfigError(e.message, path=e.path) from None
    kind = block["type"] if isinstance(block, Mapping) else block
    if params is None or getattr(params, "type", None) != kind:
        raise ConfigError(
            f"sensor type {kind!r}: its Params must declare a field "
            f"type: Literal[{kind!r}] = {kind!r}",
            path=path,
        )
    rate = getattr(params, "update_rate", None)
    if not isinstance(rate, int | float) or not rate > 0:
        raise ConfigError(
            f"sensor type {kind!r}: its Params must declare update_rate (Hz, > 0)", path=path
        )
    return params


Range = Annotated[tuple[float, float], AfterValidator(_ordered_pair)]
"""``[min, max]`` (units of the field)."""


class CircleFootprint(BaseModel):
    """A circular footprint centred on the robot origin."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    type: Literal["circle"]
    radius: float = Field(gt=0, description="m")


class PolygonFootprint(BaseModel):
    """A polygonal footprint in the robot (body) frame, x forward, y left."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    type: Literal["polygon"]
    points: tuple[tuple[float, float], ...] = Field(
        min_length=3, description="vertices [x m, y m] in order (either orientation)"
    )

    @field_validator("points")
    @classmethod
    def _non_degenerate(cls, v: tuple[tuple[float, float], ...]) -> tuple[tuple[float, float], ...]:
        arr = np.asarray(v, dtype=np.float64)
        if not np.all(np.isfinite(arr)):
            raise ValueError("polygon points must be finite")
        if abs(polygon_area(arr)) < 1e-9:
            raise ValueError("polygon has zero area")
        return v


Footprint = Annotated[CircleFootprint | PolygonFootprint, Field(discriminator="type")]


class DiscreteAction(BaseModel):
    """One entry of Arena's discrete action list."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    name: str = Field(min_length=1)
    linear: float = Field(description="m/s, forward speed")
    angular: float = Field(description="rad/s, yaw rate")


class LinearRangeXY(BaseModel):
    """Forward and lateral speed ranges of a holonomic robot."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    x: Range = Field(description="m/s, [min, max] forward speed")
    y: Range = Field(description="m/s, [min, max] lateral speed")


class ContinuousActions(BaseModel):
    """The continuous action box, as in Arena (``linear_range`` 2-D for holonomic robots)."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    linear_range: tuple[float, float] | LinearRangeXY = Field(
        description="m/s, [min, max] forward speed, or {x: [..], y: [..]} for holonomic robots"
    )
    angular_range: Range = Field(description="rad/s, [min, max] yaw rate")

    @field_validator("linear_range", mode="before")
    @classmethod
    def _ordered_linear(cls, v: Any) -> Any:
        # checked before the union so that an error names the key, not a union member
        if isinstance(v, list | tuple) and len(v) == 2:
            _ordered_pair((float(v[0]), float(v[1])))
        return v


class Actions(BaseModel):
    """Action spaces offered to learning agents (``model_params.yaml`` ``actions`` block)."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    discrete: tuple[DiscreteAction, ...] = ()
    continuous: ContinuousActions

    @field_validator("discrete")
    @classmethod
    def _unique_names(cls, v: tuple[DiscreteAction, ...]) -> tuple[DiscreteAction, ...]:
        names = [a.name for a in v]
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise ValueError(f"duplicate discrete action names: {dup}")
        return v


class RobotModel(BaseModel):
    """A robot model: what the simulator, the planners and the RL agents need to know about it.

    Attributes:
        name: preset name (snake_case), e.g. ``burger``.
        description: one line for tables and the web app.
        kinematics: the validated kinematics block ``{type: name, **params}`` with every
            parameter resolved (defaults filled in); :meth:`build_kinematics` gives the model.
        radius: Arena's ``robot_radius`` (m), used for inflation, spawning clearance and safety
            distances. Taken from Arena as is: it is not always the footprint's circumscribed
            radius (see :attr:`circumscribed_radius`).
        footprint: collision shape in the body frame (m).
        height: body height above the floor (m) for 3-D worlds; ``None`` where unknown (such a
            robot cannot be placed in a 3-D world).
        sensors: the robot's sensors by name (insertion-ordered), each the validated
            ``Params`` of its registered type (:data:`~arena.sensors.base.SENSORS`). Names are
            identifiers. Arena's ``laser:`` block is read as ``sensors: {laser: ...}``.
        laser: (read-only) the primary 2-D lidar, see :attr:`primary_lidar`.
        actions: discrete and continuous action spaces for learning agents.
        sources: where the numbers come from (free text, one citation per entry).
    """

    # Infinity (an unlimited acceleration) survives a JSON round trip as a constant
    model_config = ConfigDict(frozen=True, extra="forbid", ser_json_inf_nan="constants")

    name: str = Field(pattern=r"^[A-Za-z0-9][A-Za-z0-9_\-]*$", description="robot name")
    description: str = ""
    kinematics: dict[str, Any] = Field(description="{type: <kinematics name>, **params}")
    radius: float = Field(gt=0, description="m, Arena's robot_radius (inflation, safety)")
    footprint: Footprint
    height: float | None = Field(None, gt=0, le=5, description="m, body height (3-D worlds)")
    sensors: dict[str, Any] = Field(
        description="{name: {type: <sensor type>, **params}}; Arena's `laser:` block is `laser`"
    )
    actions: Actions
    sources: tuple[str, ...] = Field((), description="citations for the numbers")

    @model_validator(mode="before")
    @classmethod
    def _laser_block(cls, data: Any) -> Any:
        # Arena's model_params.yaml layout: one `laser:` block, the sensor named `laser`
        if not isinstance(data, Mapping) or "laser" not in data:
            if isinstance(data, Mapping) and "sensors" not in data:
                raise ConfigError(
                    "required key is missing: give the robot a `laser` block (Arena's layout) "
                    "or a `sensors` mapping",
                    path="laser",
                )
            return data
        if "sensors" in data:
            raise ConfigError(
                "give either `laser` (Arena's layout) or `sensors`, not both "
                "(`laser: {...}` is `sensors: {laser: {type: lidar2d, ...}}`)",
                path="laser",
            )
        out = dict(data)
        laser = out.pop("laser")
        if isinstance(laser, Mapping):
            laser = {"type": "lidar2d", **laser}
        elif not isinstance(laser, LidarSpec):
            raise ConfigError(f"expected a mapping of lidar fields, got {laser!r}", path="laser")
        out["sensors"] = {"laser": _sensor_params("laser", laser, "laser")}
        return out

    @field_validator("sensors", mode="before")
    @classmethod
    def _validate_sensors(cls, v: Any) -> dict[str, BaseModel]:
        if not isinstance(v, Mapping):
            raise ConfigError(
                f"expected a mapping of sensor names to {{type: ..., ...}} blocks, got {v!r}",
                path="sensors",
            )
        out: dict[str, BaseModel] = {}
        for name, block in v.items():
            if not isinstance(name, str) or not _SENSOR_NAME.match(name):
                raise ConfigError(
                    f"sensor name {name!r} must be an identifier (letters, digits and _, not "
                    "starting with a digit): it names state keys, columns and files",
                    path=f"sensors.{name}",
                )
            out[name] = _sensor_params(name, block, f"sensors.{name}")
        return out

    @field_validator("kinematics", mode="before")
    @classmethod
    def _validate_kinematics(cls, v: Any) -> dict[str, Any]:
        # a ConfigError (not a ValueError) passes through pydantic and keeps its key path
        entry, params = KINEMATICS.validate(v, path="kinematics")
        resolved = params.model_dump() if params is not None else {}
        return {"type": entry.name, **resolved}

    @cached_property
    def _kinematics(self) -> Kinematics:
        # built once per model; kinematics instances are stateless, so sharing them is safe
        return KINEMATICS.build(self.kinematics, path="kinematics")

    @model_validator(mode="after")
    def _actions_within_limits(self) -> RobotModel:
        check_actions(self.actions, self.limits(), holonomic=self.holonomic)
        return self

    # -- derived ---------------------------------------------------------------------------
    @property
    def primary_lidar(self) -> str | None:
        """Name of the primary 2-D lidar: ``laser`` if it is a ``lidar2d``, else the first one.

        ``None`` when the robot carries no ``lidar2d``. :attr:`laser`,
        :attr:`arena.scene.state.RobotStates.scans` and the scan fields of a local observation
        are this sensor's.
        """
        lidars = [k for k, v in self.sensors.items() if isinstance(v, LidarSpec)]
        if "laser" in lidars:
            return "laser"
        return lidars[0] if lidars else None

    def model_copy(
        self, *, update: Mapping[str, Any] | None = None, deep: bool = False
    ) -> RobotModel:
        """A copy with fields replaced; ``update={"laser": spec}`` replaces the primary lidar.

        Like ``model_copy`` everywhere, ``update`` is not validated (the ``laser`` spec must
        be a :class:`LidarSpec`).
        """
        if update is not None and "laser" in update:
            rest = dict(update)
            laser = rest.pop("laser")
            if not isinstance(laser, LidarSpec):
                raise TypeError(f"laser must be a LidarSpec, got {type(laser).__name__}")
            sensors = dict(rest.get("sensors", self.sensors))
            sensors[self.primary_lidar or "laser"] = laser
            rest["sensors"] = sensors
            update = rest
        return super().model_copy(update=update, deep=deep)

    def lidar(self, name: str, *, path: str | None = None) -> LidarSpec:
        """The ``lidar2d`` sensor ``name``.

        Raises:
            ConfigError: at ``path`` (the option that named it), when the robot carries no
                ``lidar2d`` of that name; the message lists its lidars.
        """
        spec = self.sensors.get(name)
        if not isinstance(spec, LidarSpec):
            lidars = [k for k, v in self.sensors.items() if isinstance(v, LidarSpec)]
            raise ConfigError(
                f"robot {self.name!r} has no lidar2d sensor {name!r} "
                f"(its lidar2d sensors: {', '.join(lidars) or 'none'})",
                path=path,
            )
        return spec

    @property
    def laser(self) -> LidarSpec:
        """The primary 2-D lidar's spec (:attr:`primary_lidar`), for Arena files and old code.

        Raises:
            ConfigError: the robot carries no ``lidar2d`` sensor.
        """
        name = self.primary_lidar
        if name is None:
            raise ConfigError(f"robot {self.name!r} carries no lidar2d sensor", path="sensors")
        spec: LidarSpec = self.sensors[name]
        return spec

    @property
    def kinematics_type(self) -> str:
        """The kinematics registry name (``diff_drive``, ``omni``, ``ackermann``, ``legged``)."""
        return str(self.kinematics["type"])

    def build_kinematics(self) -> Kinematics:
        """The kinematics model for this robot (shared, stateless)."""
        return self._kinematics

    @property
    def holonomic(self) -> bool:
        """Whether the robot can move sideways."""
        return bool(self._kinematics.holonomic)

    def limits(self) -> VelocityLimits:
        """Velocity and acceleration limits for planners (from the kinematics model)."""
        return self._kinematics.limits()

    def footprint_polygon(self) -> NDArray[np.float64] | None:
        """``(k, 2)`` footprint vertices (m, body frame, counter-clockwise); ``None``: circle."""
        if isinstance(self.footprint, CircleFootprint):
            return None
        pts = np.array(self.footprint.points, dtype=np.float64)
        return pts if polygon_area(pts) > 0 else pts[::-1].copy()

    @property
    def circumscribed_radius(self) -> float:
        """Radius of the smallest circle about the robot origin that holds the footprint (m)."""
        if isinstance(self.footprint, CircleFootprint):
            return float(self.footprint.radius)
        return bounding_radius(np.asarray(self.footprint.points, dtype=np.float64))

    @property
    def inscribed_radius(self) -> float:
        """Radius of the largest circle about the robot origin inside the footprint (m).

        The distance from the origin to the nearest footprint edge (of the convex hull, as
        collisions use it); 0 when the origin lies outside the footprint.
        """
        if isinstance(self.footprint, CircleFootprint):
            return float(self.footprint.radius)
        hull = convex_hull(np.asarray(self.footprint.points, dtype=np.float64))
        if not bool(points_in_polygon(np.zeros((1, 2)), hull)[0]):
            return 0.0
        d = point_segment_distance(np.zeros((1, 2)), hull, np.roll(hull, -1, axis=0))
        return float(np.min(d))


def check_actions(actions: Actions, limits: VelocityLimits, *, holonomic: bool) -> None:
    """Check that every action lies within ``limits`` and matches the robot's holonomy.

    Raises:
        ConfigError: naming the offending key path under ``actions``.
    """
    vx = (limits.vx_min, limits.vx_max)
    w = (-limits.omega_max, limits.omega_max)
    for i, a in enumerate(actions.discrete):
        if not _inside(a.linear, vx):
            raise ConfigError(
                f"action {a.name!r}: linear {a.linear} m/s outside the robot's range {list(vx)}",
                path=f"actions.discrete[{i}].linear",
            )
        if not _inside(a.angular, w):
            raise ConfigError(
                f"action {a.name!r}: angular {a.angular} rad/s outside the robot's range "
                f"{[round(x, 6) for x in w]}",
                path=f"actions.discrete[{i}].angular",
            )
    cont = actions.continuous
    lin = cont.linear_range
    if isinstance(lin, LinearRangeXY):
        if not holonomic:
            raise ConfigError(
                "the robot cannot move sideways: give linear_range as [min, max]",
                path="actions.continuous.linear_range",
            )
        pairs = [("x", lin.x, vx), ("y", lin.y, (limits.vy_min, limits.vy_max))]
        for key, rng, lim in pairs:
            _check_range(rng, lim, f"actions.continuous.linear_range.{key}", "m/s")
    else:
        if holonomic:
            raise ConfigError(
                "the robot is holonomic: give linear_range as {x: [min, max], y: [min, max]}",
                path="actions.continuous.linear_range",
            )
        _check_range(lin, vx, "actions.continuous.linear_range", "m/s")
    _check_range(cont.angular_range, w, "actions.continuous.angular_range", "rad/s")


def _inside(value: float, bounds: tuple[float, float]) -> bool:
    return bounds[0] - _TOL <= value <= bounds[1] + _TOL


def _check_range(rng: tuple[float, float], lim: tuple[float, float], path: str, unit: str) -> None:
    if not (_inside(rng[0], lim) and _inside(rng[1], lim)):
        raise ConfigError(
            f"range {list(rng)} {unit} exceeds the kinematics limits "
            f"{[round(x, 6) for x in lim]} {unit}",
            path=path,
        )
