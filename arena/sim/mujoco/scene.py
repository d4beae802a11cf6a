"""The simulator-neutral 3-D scene: bodies made of primitive geoms, lights and colours.

Frames: x east, y north, z up (m); a body's pose is ``(x, y, z)`` plus a yaw (rad) about z,
geoms sit in their body's frame without rotation of their own, so every exporter (MJCF, SDF)
writes the same numbers. Sizes follow MuJoCo: box half-extents ``(hx, hy, hz)``, cylinder
``(radius, half_length)``, sphere/ellipsoid radii, capsule ``(radius, half_length)``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Literal

from pydantic import BaseModel, ConfigDict, Field

if TYPE_CHECKING:
    from arena.sim.mujoco.terrain import HeightField

GeomType = Literal["box", "cylinder", "sphere", "capsule", "ellipsoid"]

Rgba = tuple[float, float, float, float]

PALETTE: dict[str, Rgba] = {
    "wall": (0.78, 0.76, 0.72, 1.0),
    "floor": (0.42, 0.45, 0.48, 1.0),
    "wood": (0.62, 0.45, 0.28, 1.0),
    "dark_wood": (0.40, 0.28, 0.18, 1.0),
    "metal": (0.55, 0.57, 0.60, 1.0),
    "steel_blue": (0.18, 0.32, 0.62, 1.0),
    "orange": (0.95, 0.50, 0.10, 1.0),
    "fabric": (0.20, 0.30, 0.45, 1.0),
    "plastic": (0.15, 0.15, 0.16, 1.0),
    "panel": (0.55, 0.62, 0.58, 1.0),
    "bark": (0.36, 0.25, 0.16, 1.0),
    "leaves": (0.22, 0.50, 0.20, 1.0),
    "box": (0.70, 0.55, 0.35, 1.0),
    "robot": (0.85, 0.20, 0.15, 1.0),
    "skin": (0.87, 0.70, 0.58, 1.0),
    "adult": (0.25, 0.45, 0.75, 1.0),
    "elder": (0.55, 0.40, 0.60, 1.0),
    "child": (0.90, 0.75, 0.20, 1.0),
    "trousers": (0.18, 0.18, 0.22, 1.0),
    "terrain": (0.52, 0.48, 0.38, 1.0),
}
"""Material name -> RGBA (0..1). :class:`WorldParams.colours` overrides any of them."""


class WorldParams(BaseModel):
    """How a 2-D scene becomes a 3-D world."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    wall_height: float = Field(2.0, gt=0, le=100, description="m, height of the map's walls")
    floor: bool = Field(True, description="add a floor plane under the map")
    lights: int = Field(2, ge=0, le=8, description="directional lights (plus a headlight)")
    colours: dict[str, tuple[float, float, float, float]] = Field(
        default_factory=dict, description="material name -> RGBA in [0, 1], overrides PALETTE"
    )
    max_wall_boxes: int = Field(
        20_000, ge=1, description="most wall boxes after merging (a larger map is refused)"
    )
    terrain: Literal["hfield", "boxes"] = Field(
        "hfield", description="how a height map becomes geometry: a MuJoCo height field, or "
        "merged boxes (SDF always gets boxes)",
    )

    def light_directions(self) -> list[tuple[float, float, float]]:
        """Directions of the ``lights`` directional lights: from above, spread around z."""
        import math

        return [(0.4 * math.cos(a), 0.4 * math.sin(a), -1.0)
                for a in (2 * math.pi * k / self.lights for k in range(self.lights))]

    def rgba(self, material: str) -> Rgba:
        """The colour of ``material``."""
        return self.colours.get(material, PALETTE[material])


@dataclass(frozen=True)
class Geom:
    """A primitive in its body's frame."""

    name: str
    type: GeomType
    size: tuple[float, ...]
    pos: tuple[float, float, float]
    material: str


@dataclass(frozen=True)
class Body:
    """A rigid body: ``kind`` is ``wall``, ``obstacle``, ``robot``, ``person`` or ``person_leg``.

    ``mocap`` bodies are placed by the simulator each step (robots, people); ``free`` bodies
    have a free joint instead (the simulator backend's robots: MuJoCo reports contacts between
    them and static or mocap bodies, never between two bodies without degrees of freedom);
    ``person_id`` is the pedestrian id for per-pixel segmentation (``-1`` for anything else).
    """

    name: str
    kind: str
    pos: tuple[float, float, float]
    yaw: float
    geoms: tuple[Geom, ...]
    mocap: bool = False
    person_id: int = -1
    free: bool = False


@dataclass(frozen=True)
class Actor:
    """A pedestrian with a waypoint route, for exporters with scripted people (SDF actors).

    ``route`` is ``((t, x, y, yaw), ...)``: time (s) and pose of each waypoint.
    """

    name: str
    person_id: int
    route: tuple[tuple[float, float, float, float], ...]
    loop: bool


@dataclass(frozen=True)
class Scene3D:
    """A whole 3-D world.

    Attributes:
        name: world name (MJCF model / SDF world name).
        bounds: map extent ``(xmin, ymin, xmax, ymax)`` (m).
        static: walls (one body holding every wall box) and obstacles.
        robots: one mocap body per robot, named ``robot/<name>``.
        people: per person a mocap body ``person/<id>`` and two leg bodies
            ``person/<id>/leg_l``, ``person/<id>/leg_r``.
        actors: people with waypoint routes (what SDF writes as ``<actor>``).
        params: the build parameters (colours, lights).
        terrain: the ground's height map, if any: a height field, or a static body of boxes
            (:mod:`arena.sim.mujoco.terrain`); not among :attr:`bodies`.
    """

    name: str
    bounds: tuple[float, float, float, float]
    static: tuple[Body, ...]
    robots: tuple[Body, ...] = ()
    people: tuple[Body, ...] = ()
    actors: tuple[Actor, ...] = ()
    params: WorldParams = field(default_factory=WorldParams)
    terrain: HeightField | Body | None = None

    @property
    def bodies(self) -> tuple[Body, ...]:
        """Every body in the order the exporters write them."""
        return self.static + self.robots + self.people

    @property
    def wall_boxes(self) -> int:
        """Number of wall boxes."""
        return sum(len(b.geoms) for b in self.static if b.kind == "wall")
