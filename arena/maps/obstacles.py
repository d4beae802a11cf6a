"""The static obstacle model library: footprints and heights as data (``obstacle_models.yaml``).

Scenario files, task modes and map generators place obstacles by model name; this module turns
a name and a pose into an :class:`~arena.scene.state.Obstacle` with a real footprint polygon
(circles become 16-gons, so lidar and collisions see their true shape within 2 % of the radius).
"""

from __future__ import annotations

import difflib
from functools import cache
from pathlib import Path
from typing import Annotated, Literal

import numpy as np
import yaml
from numpy.typing import ArrayLike, NDArray
from pydantic import BaseModel, ConfigDict, Field, TypeAdapter, ValidationError

from arena.core.errors import UnknownNameError, from_validation_error
from arena.core.geometry import rectangle, regular_polygon
from arena.scene.state import Obstacle

LIBRARY = Path(__file__).with_name("obstacle_models.yaml")
CIRCLE_SIDES = 16


class CircleFootprint(BaseModel):
    """A round footprint."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    type: Literal["circle"]
    radius: float = Field(gt=0, description="m")


class BoxFootprint(BaseModel):
    """A rectangular footprint centred on the model origin."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    type: Literal["box"]
    length: float = Field(gt=0, description="m, along the model's x axis")
    width: float = Field(gt=0, description="m, along the model's y axis")


class PolygonFootprint(BaseModel):
    """Any polygon in the model frame."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    type: Literal["polygon"]
    points: list[tuple[float, float]] = Field(min_length=3, description="m, [[x, y], ...]")


Footprint = Annotated[
    CircleFootprint | BoxFootprint | PolygonFootprint, Field(discriminator="type")
]


SHAPE3D_KINDS = ("box", "cylinder", "table", "chair", "shelf", "rack", "pallet", "pallet_jack",
                 "desk", "office_chair", "panel", "tree")
"""How a model may be assembled in 3-D (see :mod:`arena.sim.mujoco.shapes`)."""


class Shape3D(BaseModel):
    """How the 3-D world builder assembles a model from primitives (scaled to footprint, height).

    Only the parameters a kind uses matter; each has a default that suits common furniture.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")
    kind: Literal[SHAPE3D_KINDS]  # type: ignore[valid-type]
    legs: int = Field(4, ge=3, le=8, description="table legs")
    levels: int = Field(4, ge=1, le=12, description="shelf boards / rack beam levels")
    seat_height: float = Field(0.45, gt=0, description="m, chairs")
    mast: bool = Field(False, description="pallet jack: a lifting mast instead of a handle")
    crown_radius: float = Field(1.5, gt=0, description="m, tree crown (above the footprint)")


class ObstacleModel(BaseModel):
    """One entry of the library."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    footprint: Footprint
    height: float = Field(gt=0, description="m")
    description: str = ""
    shape3d: Shape3D | None = Field(
        None, description="3-D assembly; a model without one cannot be built in a 3-D world"
    )

    def polygon(self) -> NDArray[np.float64]:
        """``(k, 2)`` footprint polygon in the model frame (m)."""
        fp = self.footprint
        if isinstance(fp, CircleFootprint):
            return regular_polygon(fp.radius, CIRCLE_SIDES)
        if isinstance(fp, BoxFootprint):
            return rectangle(fp.length, fp.width)
        return np.array(fp.points, dtype=np.float64)

    @property
    def radius(self) -> float:
        """Circumscribed radius about the model origin (m)."""
        return float(np.max(np.hypot(*self.polygon().T)))


_MODELS = TypeAdapter(dict[str, ObstacleModel])


@cache
def obstacle_models() -> dict[str, ObstacleModel]:
    """Every model of the library, by name."""
    data = yaml.safe_load(LIBRARY.read_text(encoding="utf-8"))
    try:
        return _MODELS.validate_python(data)
    except ValidationError as e:
        raise from_validation_error(e, source=str(LIBRARY)) from None


def obstacle_model(name: str) -> ObstacleModel:
    """The library entry ``name``; unknown names raise with a close match."""
    models = obstacle_models()
    if name not in models:
        close = difflib.get_close_matches(name, list(models), n=1, cutoff=0.5)
        hint = f"did you mean {close[0]!r}? " if close else ""
        raise UnknownNameError(
            f"unknown obstacle model {name!r}; {hint}known: {', '.join(sorted(models))}"
        )
    return models[name]


def make_obstacle(name: str, model: str, pose: ArrayLike) -> Obstacle:
    """An :class:`Obstacle` of library ``model`` at ``pose = [x, y, yaw]``."""
    m = obstacle_model(model)
    return Obstacle(
        name=name,
        model=model,
        pose=np.asarray(pose, dtype=np.float64).reshape(3),
        footprint=m.polygon(),
        height=m.height,
    )
