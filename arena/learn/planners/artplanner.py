"""ArtPlanner: a roadmap on a 2.5-D height map with a learned motion cost (legged robots).

After Wellhausen & Hutter, "ArtPlanner: Robust Legged Robot Navigation in the Field" (Field
Robotics 2023). Per plan:

1. **Standable cells** (:func:`~arena.nav.global_planners.roadmap.standable`): the 2.5-D form
   of ArtPlanner's reachability check (torso clear, a foothold under each foot): a plane fitted
   under the stance no steeper than ``max_slope``, the ground within ``max_roughness`` of it.
2. **Roadmap** (:mod:`~arena.nav.global_planners.roadmap`): nodes on a jittered lattice and by
   the bridge test over free, standable cells of the inflated map, plus start and goal; pairs
   within ``connect_radius`` joined by a collision-free segment become edges both ways.
3. **Learned motion cost** (:class:`~arena.learn.artplanner.model.MotionCostModel`): an MLP rates
   every directed edge from the height patch along it: feasibility ``p`` and time per metre.
   An edge with ``p < feasibility_threshold`` is dropped (the paper's risk threshold, 0.5);
   the others cost ``time + risk_weight · (1 - p)`` (s), as the paper's ``time + w · risk``;
   as A*'s, every cost is scaled by a clearance factor near the inflated walls.
4. **Search**: Dijkstra over the directed roadmap from the start (uphill and downhill differ).
5. **Shortening**: from each kept waypoint, the farthest later one whose straight chord is
   collision-free, feasible (split into pieces the network rates) and no costlier than the path
   it replaces. ArtPlanner's further path optimisation is not done.

Where the roadmap is too coarse to link start and goal although the free cells link them, the
lattice is halved (up to ``refinements`` times) before :class:`NoPathFound` is raised.

**Without a height map** (Arena's flat worlds, ``height_map: null``) steps 1 and 3 fall away:
what remains of ArtPlanner is a PRM on the occupancy grid, edges costing their length, with the
same search and shortening.

The paper's network was trained on rollouts of ANYmal's locomotion policy; ours on labels of a
kinematic stepping model of a Go1-sized quadruped (:mod:`arena.learn.artplanner.stepping`),
trained by ``python -m arena.learn.artplanner.train -o RUN``; see docs/learning.md.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, model_validator
from scipy import ndimage
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

from arena.core.errors import GoalOccupied, NoPathFound
from arena.core.types import Pose2D
from arena.maps.grid import OccupancyGrid
from arena.maps.terrain import HeightMap
from arena.nav.global_planners.base import GLOBAL_PLANNERS, endpoint_cells
from arena.nav.global_planners.roadmap import (
    free_pairs,
    sample_nodes,
    segments_free,
    standable,
)

if TYPE_CHECKING:
    from arena.learn.artplanner.model import MotionCostModel


@dataclass(frozen=True)
class Roadmap:
    """One plan's roadmap (kept on the planner as :attr:`ArtPlanner.last_roadmap`).

    Attributes:
        nodes: ``(n, 2)`` node positions (m); node 0 is the start, node 1 the goal.
        edges: ``(m, 2)`` directed edges ``[from, to]`` that passed every check.
        cost: ``(m,)`` their costs (s, or m without a height map).
        rejected: directed edges the motion-cost model found infeasible.
    """

    nodes: NDArray[np.float64]
    edges: NDArray[np.int64]
    cost: NDArray[np.float64]
    rejected: int


@GLOBAL_PLANNERS.register("artplanner", tags=("learned", "legged", "sampling"))
class ArtPlanner:
    """ArtPlanner: a PRM on the height map with a learned motion cost (a plain PRM when flat).

    Args:
        params: validated :class:`ArtPlanner.Params`.
        terrain: the ground's heights, instead of ``params.height_map``.

    Raises:
        ConfigError: an unreadable motion-cost model file; MapError: an unreadable height map.
    """

    class Params(BaseModel):
        """Parameters of :class:`ArtPlanner`."""

        model_config = ConfigDict(frozen=True, extra="forbid")
        height_map: str | None = Field(
            None, description="height map file (heights.npz beside a world's map.yaml); "
            "None: flat ground (a PRM on the occupancy grid)",
        )
        weights: str | None = Field(
            None, description="motion-cost model (.npz, RUN/model.npz); None: the packaged one"
        )
        spacing: float = Field(0.35, gt=0, description="m between roadmap lattice nodes")
        connect_radius: float = Field(
            0.85, gt=0, description="m, longest roadmap edge (at most the model's max_length)"
        )
        bridges: int = Field(4000, ge=0, le=1_000_000,
                             description="bridge-test pairs drawn (narrow-passage nodes)")
        refinements: int = Field(2, ge=0, le=4,
                                 description="times the lattice is halved when no path is found")
        terrain_margin: float = Field(
            0.25, ge=0, description="m kept between the path and ground the robot cannot stand "
            "on (ArtPlanner's foothold margin, 0.3 m): room for the local planner's tracking error",
        )
        feasibility_threshold: float = Field(
            0.5, gt=0, lt=1, description="least predicted feasibility of an edge kept"
        )
        risk_weight: float = Field(2.0, ge=0, description="s added per unit of (1 - feasibility)")
        clearance_weight: float = Field(
            1.0, ge=0, description="edge cost x (1 + w · mean exp(-d / clearance_scale)) along "
            "it, d the distance to the inflated walls (as astar's); 0 disables",
        )
        clearance_scale: float = Field(0.3, gt=0, description="m, decay of the clearance cost")
        shorten: bool = Field(True, description="shortcut the roadmap path")
        seed: int = Field(0, ge=0, description="seed of the node sampling (same seed, same path)")

        @model_validator(mode="after")
        def _radius_covers_spacing(self) -> ArtPlanner.Params:
            if self.connect_radius < 1.5 * self.spacing:
                raise ValueError(
                    f"connect_radius ({self.connect_radius} m) must be at least 1.5 x spacing "
                    f"({self.spacing} m), else lattice neighbours are not linked"
                )
            return self

    def __init__(self, params: Params | None = None, terrain: HeightMap | None = None) -> None:
        from arena.core.errors import ConfigError
        from arena.learn.artplanner.model import ARTPLANNER_WEIGHTS, MotionCostModel

        self.params = p = params if params is not None else self.Params()
        self.model: MotionCostModel = MotionCostModel.load(
            p.weights if p.weights is not None else ARTPLANNER_WEIGHTS)
        if p.connect_radius > self.model.features.max_length + 1e-9:
            raise ConfigError(
                f"connect_radius ({p.connect_radius} m) exceeds the motion-cost model's "
                f"max_length ({self.model.features.max_length} m)",
                path="navigation.global_planner.connect_radius")
        if terrain is None and p.height_map is not None:
            terrain = HeightMap.load(p.height_map)
        self.terrain = terrain
        self.last_roadmap: Roadmap | None = None
        self._mask_key: HeightMap | None = None
        self._mask: NDArray[np.bool_] | None = None
        self._safe: NDArray[np.bool_] | None = None

    # -- terrain ----------------------------------------------------------------------------------
    def _standable(self) -> tuple[NDArray[np.bool_], NDArray[np.bool_]] | None:
        """``(standable, safe)`` masks of :attr:`terrain`, cached per map; ``None`` when flat.

        Safe cells lie more than ``terrain_margin`` from any cell not standable.
        """
        t = self.terrain
        if t is None:
            return None
        if self._mask_key is not t:
            s = self.model.stepping
            # The labels bound the largest deviation of a foothold, about two standard
            # deviations of the ground about its plane: the mask bounds the deviation at half.
            self._mask = standable(t, s.stance_length, s.max_slope, s.max_roughness / 2)
            clear = ndimage.distance_transform_edt(self._mask) * t.resolution
            self._safe = clear > self.params.terrain_margin
            self._mask_key = t
        assert self._mask is not None
        assert self._safe is not None
        return self._mask, self._safe

    def _on_safe_ground(self, a: NDArray[np.float64], b: NDArray[np.float64],
                        ends: NDArray[np.float64]) -> NDArray[np.bool_]:
        """Whether segments ``a→b`` (``(n, 2)``) stay on safe cells, every half cell checked.

        Points within ``terrain_margin`` of the start or goal (``ends`` ``(2, 2)``) are exempt:
        the robot stands at the start already, and the goal was checked standable.
        """
        masks = self._standable()
        if masks is None or len(a) == 0:
            return np.ones(len(a), dtype=bool)
        t, safe = self.terrain, masks[1]
        assert t is not None
        length = np.hypot(*(b - a).T)
        n = max(2, int(np.ceil(length.max() / (t.resolution / 2))) + 1)
        s = np.linspace(0.0, 1.0, n)
        pts = a[:, None, :] + s[None, :, None] * (b - a)[:, None, :]  # (m, n, 2)
        rows, cols = t.shape
        c = np.clip(np.floor((pts[..., 0] - t.origin[0]) / t.resolution), 0, cols - 1)
        r = np.clip(np.floor((pts[..., 1] - t.origin[1]) / t.resolution), 0, rows - 1)
        ok = safe[r.astype(np.int64), c.astype(np.int64)]
        near = np.min(np.hypot(pts[..., None, 0] - ends[:, 0], pts[..., None, 1] - ends[:, 1]),
                      axis=-1) <= self.params.terrain_margin + t.resolution
        return np.asarray(np.all(ok | near, axis=1))

    def _clearance_factor(self, grid: OccupancyGrid | None, a: NDArray[np.float64],
                          b: NDArray[np.float64]) -> NDArray[np.float64] | float:
        """``1 + w · mean exp(-d / scale)`` over points along each move ``a→b``.

        The points lie a cell apart, at least 0.1 m (a penalty decaying over 0.3 m needs no
        finer sampling; on 5 cm maps this halves the work).
        """
        w = self.params.clearance_weight
        if grid is None or w == 0 or len(a) == 0:
            return 1.0
        length = np.hypot(*(b - a).T)
        n = max(2, int(np.ceil(length.max() / max(grid.resolution, 0.1))) + 1)
        s = np.linspace(0.0, 1.0, n)
        pts = a[:, None, :] + s[None, :, None] * (b - a)[:, None, :]
        pen = np.exp(-grid.distance_at(pts) / self.params.clearance_scale)
        return np.asarray(1.0 + w * pen.mean(axis=1), dtype=np.float64)

    def edge_costs(self, a: NDArray[np.float64], b: NDArray[np.float64],
                   grid: OccupancyGrid | None = None
                   ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``(feasibility (n,), cost (n,))`` of straight moves ``a→b`` (``(n, 2)`` m).

        With a height map the cost is in seconds (the network's time plus the risk term), else
        the length (m). A move longer than the model's ``max_length`` is split into equal
        pieces: feasibility is the least of the pieces', cost the sum. Given the (inflated)
        ``grid``, the cost is scaled by the clearance factor (``clearance_weight``).
        """
        a = np.asarray(a, dtype=np.float64).reshape(-1, 2)
        b = np.asarray(b, dtype=np.float64).reshape(-1, 2)
        length = np.hypot(*(b - a).T)
        factor = self._clearance_factor(grid, a, b)
        if self.terrain is None:
            return np.ones(len(a)), length * factor
        from arena.learn.artplanner.features import edge_features

        pieces = np.maximum(np.ceil(length / self.model.features.max_length - 1e-9), 1)
        pieces = pieces.astype(np.int64)
        owner = np.repeat(np.arange(len(a)), pieces)
        first = np.cumsum(pieces) - pieces
        k = np.arange(len(owner)) - np.repeat(first, pieces)
        t0 = (k / pieces[owner])[:, None]
        t1 = ((k + 1) / pieces[owner])[:, None]
        pa = a[owner] + t0 * (b - a)[owner]
        pb = a[owner] + t1 * (b - a)[owner]
        x = edge_features(self.terrain.at, pa, pb, self.model.features)
        prob, per_m = self.model.predict(x)
        piece_cost = np.hypot(*(pb - pa).T) * per_m \
            + self.params.risk_weight * (1.0 - prob)
        feas = np.ones(len(a))
        np.minimum.at(feas, owner, prob)
        cost = np.zeros(len(a))
        np.add.at(cost, owner, piece_cost)
        return feas, cost * factor

    # -- planning ---------------------------------------------------------------------------------
    def plan(self, grid: OccupancyGrid, start: Pose2D, goal: Pose2D) -> NDArray[np.float64]:
        """Plan from ``start`` to ``goal`` on the inflated ``grid`` (and the height map).

        Returns:
            ``(k, 2)`` world waypoints (m), ``k ≥ 2``, from the start to the goal position.

        Raises:
            StartOccupied: start off the map or in an occupied cell.
            GoalOccupied: goal off the map, in an occupied cell or on ground the robot cannot
                stand on (too steep or rough).
            NoPathFound: no free route links the two cells, or none the robot can walk.
            MapError: the height map does not cover the grid.
        """
        (sr, sc), (gr, gc) = endpoint_cells(grid, start, goal)
        masks = self._standable()
        if self.terrain is not None:
            self.terrain.check_covers(grid)
            assert masks is not None
            mask = masks[0]
            cell = self.terrain.shape
            res, (ox, oy) = self.terrain.resolution, self.terrain.origin
            c = min(max(math.floor((goal.x - ox) / res), 0), cell[1] - 1)
            r = min(max(math.floor((goal.y - oy) / res), 0), cell[0] - 1)
            if not mask[r, c]:
                st = self.model.stepping
                raise GoalOccupied(
                    f"the goal ({goal.x:.3f}, {goal.y:.3f}) m lies on ground the robot cannot "
                    f"stand on (steeper than {math.degrees(st.max_slope):.0f} deg, or deviating "
                    f"from its plane by over {st.max_roughness / 2:g} m std)")
        labels, _ = ndimage.label(~grid.occupied, structure=np.ones((3, 3), dtype=bool))
        if labels[sr, sc] != labels[gr, gc]:
            raise NoPathFound(
                f"no path from ({start.x:.3f}, {start.y:.3f}) m to ({goal.x:.3f}, {goal.y:.3f}) "
                "m: the goal is not connected to the start through free cells of the inflated map")
        p = self.params
        ends = np.array([start.xy, goal.xy], dtype=np.float64)
        if segments_free(grid, ends[:1], ends[1:])[0] \
                and self._on_safe_ground(ends[:1], ends[1:], ends)[0]:
            feas, cost = self.edge_costs(ends[:1], ends[1:], grid)
            if feas[0] >= p.feasibility_threshold:  # in sight and walkable: the direct line
                self.last_roadmap = Roadmap(ends, np.array([[0, 1]]), cost, 0)
                return ends.copy()
        rng = np.random.default_rng(p.seed)
        spacing = p.spacing
        for attempt in range(p.refinements + 1):
            safe = None if masks is None else masks[1]
            nodes = np.concatenate([ends, sample_nodes(grid, spacing, p.bridges * 2**attempt, rng,
                                                       safe, self.terrain)])
            path = self._search(grid, nodes, p.connect_radius * spacing / p.spacing)
            if path is not None:
                return path
            spacing /= 2
        what = "walkable on the terrain" if self.terrain is not None else "in the roadmap"
        raise NoPathFound(
            f"no path from ({start.x:.3f}, {start.y:.3f}) m to ({goal.x:.3f}, {goal.y:.3f}) m "
            f"{what} (last roadmap: {len(nodes)} nodes, lattice {spacing * 2:.3g} m)")

    def _search(self, grid: OccupancyGrid, nodes: NDArray[np.float64], radius: float
                ) -> NDArray[np.float64] | None:
        """Build the roadmap on ``nodes``, search it; the path or ``None`` if not linked."""
        pairs = free_pairs(grid, nodes, radius)
        pairs = pairs[self._on_safe_ground(nodes[pairs[:, 0]], nodes[pairs[:, 1]], nodes[:2])]
        edges = np.concatenate([pairs, pairs[:, ::-1]])
        feas, cost = self.edge_costs(nodes[edges[:, 0]], nodes[edges[:, 1]], grid)
        keep = feas >= self.params.feasibility_threshold
        edges, cost = edges[keep], cost[keep]
        self.last_roadmap = Roadmap(nodes, edges, cost, int((~keep).sum()))
        n = len(nodes)
        # Costs are > 0 (length or time); csgraph treats explicit zeros as missing edges.
        graph = csr_matrix((np.maximum(cost, 1e-9), (edges[:, 0], edges[:, 1])), shape=(n, n))
        dist, pred = dijkstra(graph, directed=True, indices=0, return_predecessors=True)
        if not np.isfinite(dist[1]):
            return None
        order = [1]
        while order[-1] != 0:
            order.append(int(pred[order[-1]]))
        idx = np.array(order[::-1])
        pts = nodes[idx]
        if self.params.shorten and len(pts) > 2:
            pts = self._shorten(grid, pts, np.diff(dist[idx]))
        return np.asarray(pts, dtype=np.float64)

    def _shorten(self, grid: OccupancyGrid, pts: NDArray[np.float64],
                 step_cost: NDArray[np.float64]) -> NDArray[np.float64]:
        """Greedy shortcutting: from each kept point, the farthest acceptable later point."""
        prefix = np.concatenate([[0.0], np.cumsum(step_cost)])
        keep = [0]
        i = 0
        k = len(pts)
        while i < k - 1:
            j = np.arange(i + 2, k)
            best = i + 1
            if len(j):
                a = np.repeat(pts[i:i + 1], len(j), axis=0)
                ok = segments_free(grid, a, pts[j])
                ok &= self._on_safe_ground(a, pts[j], pts[[0, -1]])
                feas, cost = self.edge_costs(a, pts[j], grid)
                ok &= feas >= self.params.feasibility_threshold
                ok &= cost <= (prefix[j] - prefix[i]) * (1 + 1e-9) + 1e-12
                if ok.any():
                    best = int(j[np.flatnonzero(ok)[-1]])
            keep.append(best)
            i = best
        return pts[keep]
