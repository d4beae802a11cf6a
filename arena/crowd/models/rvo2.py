"""RVO2: ORCA among pedestrians plus ORCA lines for the static walls and obstacles.

The full RVO2 library behaviour (van den Berg, Guy, Snape, Lin, Manocha): on top of
:mod:`arena.crowd.models.orca`, every wall or obstacle edge within
``time_horizon_obst · max_speed + radius`` of an agent adds a hard ORCA line, with RVO2's vertex
handling (cut-off circles and legs, convex/non-convex vertices, "foreign" legs, edges already
covered by earlier lines). The obstacle lines are hard: in the 3-D fallback linear program the
agent may violate pedestrian lines, never obstacle lines.

Obstacles are fed as RVO2 takes them (:func:`world_polygons`): every placed obstacle of the
world as one closed counter-clockwise polygon (RVO2's ``addObstacle``: edges linked vertex to
vertex, reflex vertices marked non-convex), and the map's walls (merged grid-wall runs, which
have no polygon) as 2-vertex obstacles: edges ``a → b`` and ``b → a``, both vertices convex; an
agent only sees the edge that has it on its right, so a segment blocks from both sides. A frame
whose walls are not the episode's (a hand-built frame) has only segments to give: each becomes a
2-vertex obstacle.

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

from arena.crowd.base import CROWD_MODELS, CrowdFrame
from arena.crowd.models.orca.model import FloatArray, OrcaModel, preferred_velocities
from arena.crowd.models.orca.obstacles import Obstacles
from arena.crowd.models.orca.params import Rvo2Params
from arena.crowd.simulator import episode_segments
from arena.crowd.state import CrowdState
from arena.crowd.walls import grid_walls
from arena.scene.state import StaticWorld

__all__ = ["Obstacles", "Rvo2Model", "Rvo2Params", "preferred_velocities", "world_polygons"]


def counter_clockwise(polygon: FloatArray) -> FloatArray:
    """``(k, 2)`` vertices (m) as a closed RVO2 polygon: counter-clockwise, no repeated vertex.

    Consecutive duplicates (a closing copy of the first vertex included) are dropped, as RVO2
    would divide by their zero-length edge; a clockwise polygon is reversed. What is left may
    have fewer than 3 vertices (2: a segment; fewer: nothing).
    """
    v = np.asarray(polygon, dtype=np.float64).reshape(-1, 2)
    v = v[np.r_[True, np.any(v[1:] != v[:-1], axis=1)]] if len(v) else v
    if len(v) > 1 and np.array_equal(v[0], v[-1]):
        v = v[:-1]
    if len(v) > 2:
        x, y = v[:, 0], v[:, 1]
        if np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y) < 0.0:  # 2 x signed area
            v = v[::-1].copy()
    return v


def world_polygons(world: StaticWorld) -> list[FloatArray]:
    """RVO2 obstacles of ``world``: the map's wall segments, then each placed obstacle.

    Returns:
        ``(2, 2)`` segments (m) of :func:`~arena.crowd.walls.grid_wall_segments` (zero-length
        ones dropped), followed by one closed counter-clockwise ``(k, 2)`` polygon (m) per
        obstacle of ``world.obstacles``, in order: what :meth:`Obstacles.from_polygons` (RVO2's
        ``addObstacle`` for each) takes.
    """
    ga, gb = grid_walls(world.grid)
    keep = np.any(ga != gb, axis=1)
    polys: list[FloatArray] = list(np.stack([ga[keep], gb[keep]], axis=1))
    for ob in world.obstacles:
        poly = counter_clockwise(ob.polygon)
        if len(poly) >= 2:
            polys.append(poly)
    return polys


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
        """Convert the world to RVO2 obstacles (once per episode; may take a moment).

        The placed obstacles become closed polygons, the map's walls segments
        (:func:`world_polygons`); frames whose walls are the world's segments
        (:func:`~arena.crowd.walls.world_segments`, as the simulator passes them) use them.
        """
        a, b = episode_segments(world)
        self._convert(a, b, state, world_polygons(world))

    def _time_horizon_obst(self) -> float:
        return float(self.params.time_horizon_obst)

    def _convert(
        self,
        a: FloatArray,
        b: FloatArray,
        state: CrowdState,
        polygons: list[FloatArray] | None = None,
    ) -> None:
        """Obstacles for walls ``a → b`` ``(s, 2)``: ``polygons`` if given, else the segments."""
        # Grid cells about one obstacle range wide: a query then looks at 2 x 2 to 3 x 3 cells.
        vmax = float(np.max(state.vmax * state.vmax_factor, initial=1.0))
        reach = self.params.time_horizon_obst * vmax + float(np.max(state.radii, initial=0.3))
        cell = max(reach, 1.0)
        if polygons is None:
            self._ob = Obstacles.from_segments(a, b, cell=cell)
        else:
            self._ob = Obstacles.from_polygons(polygons, cell=cell)
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
