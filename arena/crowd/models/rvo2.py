"""RVO2: ORCA among pedestrians plus ORCA lines for the static walls and obstacles.

The full RVO2 library behaviour (van den Berg, Guy, Snape, Lin, Manocha): on top of
:mod:`arena.crowd.models.orca`, every wall or obstacle edge within
``time_horizon_obst · max_speed + radius`` of an agent adds a hard ORCA line, with RVO2's vertex
handling (cut-off circles and legs, convex/non-convex vertices, "foreign" legs, edges already
covered by earlier lines). The obstacle lines are hard: in the 3-D fallback linear program the
agent may violate pedestrian lines, never obstacle lines.

Walls come as segments (:func:`arena.crowd.walls.world_segments`: merged grid-wall runs and
obstacle edges). Each segment becomes a 2-vertex RVO2 obstacle, which RVO2 supports: edges
``a → b`` and ``b → a``, both vertices convex; an agent only sees the edge that has it on its
right, so a segment blocks from both sides. Outlines are not merged into polygons: at a shared
corner each segment contributes its own convex end vertex, so near inner corners the
constraints can differ slightly from those of a closed polygon (whose reflex vertices RVO2
marks non-convex).

The conversion then runs RVO2's ``processObstacles``: its obstacle k-d tree build splits every
edge crossing a splitting edge's line into collinear pieces, and we do the same, so the edges
(and vertex numbers) are RVO2's. The tree itself is only used to order exactly equidistant
edges as RVO2's query meets them; the "edges within range" search uses a uniform grid
(:class:`~arena.crowd.models.orca.Obstacles`). Neighbours are sorted by distance as RVO2's
insertion sort does, which matters for its "already covered" checks.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np
from pydantic import Field

from arena.crowd.base import CROWD_MODELS, CrowdFrame
from arena.crowd.models.orca import (
    FloatArray,
    Obstacles,
    OrcaModel,
    OrcaParams,
    preferred_velocities,
)
from arena.crowd.state import CrowdState
from arena.crowd.walls import world_segments
from arena.sim.state import StaticWorld

__all__ = ["Obstacles", "Rvo2Model", "Rvo2Params", "preferred_velocities"]


class Rvo2Params(OrcaParams):
    """Parameters of :class:`Rvo2Model`: those of ORCA plus the obstacle horizon."""

    time_horizon_obst: float = Field(
        2.0,
        gt=0,
        description="s, collisions with walls this far ahead are avoided (RVO2 timeHorizonObst)",
    )


@CROWD_MODELS.register("rvo2", tags=("velocity_obstacle",))
class Rvo2Model(OrcaModel):
    """RVO2: ORCA among pedestrians plus hard ORCA lines for walls and obstacles."""

    Params: ClassVar[type[Rvo2Params]] = Rvo2Params  # type: ignore[assignment]
    params: Rvo2Params

    def __init__(self, params: Rvo2Params | None = None) -> None:
        super().__init__(params or self.Params())
        self._walls: tuple[FloatArray, FloatArray] | None = None
        self._ob: Obstacles | None = None

    def reset(self, state: CrowdState, world: StaticWorld, rng: np.random.Generator) -> None:
        """Convert the world's walls to RVO2 obstacles (once per episode; may take a moment)."""
        a, b = world_segments(world)
        self._convert(a, b, state)

    def _time_horizon_obst(self) -> float:
        return float(self.params.time_horizon_obst)

    def _convert(self, a: FloatArray, b: FloatArray, state: CrowdState) -> None:
        # Grid cells about one obstacle range wide: a query then looks at 2 x 2 to 3 x 3 cells.
        vmax = float(np.max(state.vmax * state.vmax_factor, initial=1.0))
        reach = self.params.time_horizon_obst * vmax + float(np.max(state.radii, initial=0.3))
        self._ob = Obstacles.from_segments(a, b, cell=max(reach, 1.0))
        self._walls = (a, b)

    def _obstacles(self, frame: CrowdFrame) -> Obstacles | None:
        walls = self._walls
        if walls is None or not (walls[0] is frame.walls_a and walls[1] is frame.walls_b):
            # The walls are static: the segments converted at reset (the simulator builds its
            # own arrays of them) are adopted, different ones (a hand-built frame) converted.
            same = (
                walls is not None
                and np.array_equal(walls[0], frame.walls_a)
                and np.array_equal(walls[1], frame.walls_b)
            )
            if same:
                self._walls = (frame.walls_a, frame.walls_b)
            else:
                self._convert(frame.walls_a, frame.walls_b, frame.state)
        return self._ob
