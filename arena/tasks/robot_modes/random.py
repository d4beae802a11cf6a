"""``robots.random``: a random start and goal per robot (Arena specs §2.5).

Unlike Arena (box-filter clearance, garbage positions when the map is full), start and goal
keep ``clearance`` beyond the robot's body (:func:`spawn_radius`: every heading fits) from walls,
obstacles and forbidden zones exactly, lie in the same connected free region at that clearance
(so a path exists for the robot's body), are at least ``min_goal_distance`` apart, and become
forbidden discs so nothing is placed on them.

``min_goal_distance`` is strict: a map too small for it is an error. ``goal_distance`` (what the
demo preset gives: 12 m) is a wish instead: on a map whose largest free region cannot hold it
(Arena's bookstore, experiment_rooms ...) it is lowered to :func:`fitting_goal_distance`, and a
warning says so once per map.
"""

from __future__ import annotations

import warnings

import numpy as np
from numba import njit
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field
from scipy.spatial import ConvexHull, QhullError

from arena.core.errors import SamplingError
from arena.core.types import Pose2D
from arena.maps.distance import grid_memo
from arena.robots.model import RobotModel
from arena.scene.episode import RobotSpawn
from arena.tasks.base import ResetContext, SingleGoal, register_mode
from arena.tasks.sampling import components
from arena.tasks.world import WorldSampler


def spawn_radius(model: RobotModel) -> float:
    """Radius (m) of the disc a start or goal must keep clear for the robot's body.

    The larger of Arena's ``robot_radius`` and the footprint's circumscribed radius: the
    heading is drawn after the position, so every heading must fit (``buddy``'s radius,
    0.347 m, plus the 0.25 m clearance fell short of its 0.615 m footprint).
    """
    return max(float(model.radius), model.circumscribed_radius)


def robot_name(k: int, n: int, model_name: str) -> str:
    """``jackal`` for a single robot, ``robot0, robot1, ...`` for several."""
    return f"robot{k}" if n > 1 else model_name


def sample_pose(
    world: WorldSampler,
    clearance: float,
    rng: np.random.Generator,
    *,
    what: str,
    within: np.ndarray | None = None,
    cells: np.ndarray | None = None,
    polygon: np.ndarray | None = None,
    forbid: bool = False,
) -> Pose2D:
    """One position with ``clearance`` and a uniform heading in ``[-π, π)``.

    ``within``, ``cells`` and ``polygon`` restrict it as in :meth:`WorldSampler.sample`.
    """
    xy = world.sample(1, clearance, rng, what=what, within=within, cells=cells,
                      polygon=polygon, forbid=forbid)[0]
    return Pose2D(float(xy[0]), float(xy[1]), float(rng.uniform(-np.pi, np.pi)))


def sample_start_goal(
    world: WorldSampler,
    clearance: float,
    min_distance: float,
    rng: np.random.Generator,
    *,
    what: str,
    max_attempts: int = 50,
) -> tuple[Pose2D, Pose2D]:
    """A start and a goal ≥ ``min_distance`` apart and connected at ``clearance``.

    Both become forbidden discs of radius ``clearance`` afterwards.
    """
    grid = world.grid
    regions = world.candidate_regions(clearance)
    # Goal cells: every point ≥ min_distance from the start (half a diagonal margin).
    far = min_distance + grid.resolution
    for _ in range(max_attempts):
        start = sample_pose(world, clearance, rng, what=f"{what} start")
        r, c = grid.world_to_cell(start.xy)
        cells = _far_cells(
            regions.cells(r, c), float(grid.origin[0]), float(grid.origin[1]),
            grid.resolution, grid.width, start.x, start.y, far,
        )
        try:
            goal = sample_pose(world, clearance, rng, what=f"{what} goal", cells=cells)
        except SamplingError:
            continue  # this start's region is too small: draw another start
        world.forbid(start.xy, clearance)
        world.forbid(goal.xy, clearance)
        return start, goal
    raise SamplingError(
        f"no start/goal pair for {what} {min_distance:g} m apart in one connected free region "
        f"with clearance {clearance:g} m after {max_attempts} starts{_extent(world, clearance)}; "
        "lower task.robots.min_goal_distance or task.robots.clearance, or use a larger map"
    )


def _extent(world: WorldSampler, clearance: float) -> str:
    """How far apart free positions can be, for the error (e.g. 12 m asked in an 8 m room).

    The largest region's diameter (:func:`free_extent`), and the diagonal of the bounding box
    of all free positions: an upper bound on any start-goal distance the map allows.
    """
    rows, cols = np.nonzero(world.candidate_mask(clearance))
    if rows.size == 0:
        return " (no free position at that clearance)"
    res = world.grid.resolution
    span = float(np.hypot(np.ptp(rows) + 1, np.ptp(cols) + 1)) * res
    return (
        f" (the largest free region is {free_extent(world, clearance):.1f} m across; free "
        f"positions here are at most {span:.1f} m apart)"
    )


def free_extent(world: WorldSampler, clearance: float) -> float:
    """Diameter (m) of the largest free region at ``clearance``: 0 if there is none.

    The region is the 8-connected component of :meth:`WorldSampler.candidate_mask` with the
    most cells (the lowest label on a tie), the component starts and goals are drawn from;
    its diameter is the largest distance between two of its cell centres. Memoised per map by
    the mask's content.
    """
    mask = world.candidate_mask(clearance)
    key = ("free extent", mask.shape, np.packbits(mask).tobytes())
    res = world.grid.resolution
    return grid_memo(world.grid, key, lambda: _largest_region_diameter(mask) * res)


def _largest_region_diameter(mask: NDArray[np.bool_]) -> float:
    """Diameter (cells) of the largest 8-connected region of ``mask`` (cell centres)."""
    labels = components(mask)
    counts = np.bincount(labels.ravel())
    if counts.size < 2:
        return 0.0
    rows, cols = np.nonzero(labels == int(np.argmax(counts[1:])) + 1)  # row-major order
    # The farthest pair are hull vertices, and those are each row's first or last cell.
    _, first = np.unique(rows, return_index=True)
    last = np.r_[first[1:], rows.size] - 1
    ends = np.unique(np.r_[first, last])
    pts = np.stack([rows[ends], cols[ends]], axis=1).astype(np.float64)
    try:
        pts = pts[ConvexHull(pts).vertices]
    except QhullError:  # fewer than 3 cells, or all on one line: the ends of the line
        return float(np.hypot(*np.ptp(pts, axis=0)))
    d = pts[:, None, :] - pts[None, :, :]
    return float(np.sqrt(np.max(np.einsum("ijk,ijk->ij", d, d))))


def fitting_goal_distance(world: WorldSampler, clearance: float) -> float:
    """The largest start-goal distance (m) every start in the largest free region can have.

    Half the region's diameter ``D`` less one cell: from any point ``x``, one end of the
    diameter ``a, b`` is at least ``D / 2`` away (``|xa| + |xb| ≥ |ab|``), and
    :func:`sample_start_goal` keeps one cell of margin on the distance.
    """
    return max(0.5 * free_extent(world, clearance) - world.grid.resolution, 0.0)


def random_spawns(
    ctx: ResetContext,
    min_goal_distance: float,
    clearance: float,
    *,
    goal_distance: float | None = None,
    warned: set[str] | None = None,
) -> list[RobotSpawn]:
    """A random start and goal for every robot of ``ctx`` (``clearance`` beyond its body).

    ``goal_distance`` (m), when given, replaces ``min_goal_distance`` and may be lowered: see
    :func:`_fitted_start_goal`. Its warning is given unless its text is in ``warned`` (to which
    it is added: one warning per map and run).
    """
    rng = ctx.rng("robots")
    n = len(ctx.robots)
    spawns = []
    for k, model in enumerate(ctx.robots):
        name = robot_name(k, n, model.name)
        c = spawn_radius(model) + clearance
        what = f"robot {name!r}"
        if goal_distance is None:
            start, goal = sample_start_goal(ctx.sampler, c, min_goal_distance, rng, what=what)
        else:
            start, goal = _fitted_start_goal(
                ctx, c, goal_distance, rng, what=what,
                warned=set() if warned is None else warned,
            )
        spawns.append(RobotSpawn(name, model, start, goal))
    return spawns


def _fitted_start_goal(
    ctx: ResetContext,
    clearance: float,
    wanted: float,
    rng: np.random.Generator,
    *,
    what: str,
    warned: set[str],
) -> tuple[Pose2D, Pose2D]:
    """A start and goal ``wanted`` m apart, or :func:`fitting_goal_distance` apart.

    ``wanted`` is drawn as asked when every start of the largest free region has a goal that
    far, and tried first when some have; where that draw fails, or no two free positions are
    that far apart, the distance is lowered to the fitting one (rounded down to 0.1 m) with a
    warning. So a map that held ``wanted`` before still gets it, draw for draw.
    """
    world = ctx.sampler
    fit = fitting_goal_distance(world, clearance)
    if wanted <= fit:
        return sample_start_goal(world, clearance, wanted, rng, what=what)
    extent = free_extent(world, clearance)
    if wanted + world.grid.resolution < extent:
        try:
            return sample_start_goal(world, clearance, wanted, rng, what=what)
        except SamplingError:
            pass
    lowered = float(np.floor(fit * 10.0) / 10.0)
    text = (
        f"map {ctx.map.name!r}: goal distance lowered from {wanted:g} m to {lowered:g} m: the "
        f"largest free region (at the robot's clearance {clearance:.2f} m) is {extent:.1f} m "
        "across (set task.robots.min_goal_distance for a distance that must hold)"
    )
    if text not in warned:
        warned.add(text)
        warnings.warn(text, UserWarning, stacklevel=2)
    return sample_start_goal(world, clearance, lowered, rng, what=what)


@register_mode("robots", "random", tags=("default",))
class RandomRobots(SingleGoal):
    """Random start and goal per robot, reachable for its body, ``min_goal_distance`` apart."""

    class Params(BaseModel):
        """Parameters of ``robots.random``."""

        model_config = ConfigDict(frozen=True, extra="forbid")
        min_goal_distance: float = Field(
            5.0, ge=0,
            description="m, straight start-goal distance; a map too small for it is an error",
        )
        goal_distance: float | None = Field(
            None, ge=0,
            description="m, start-goal distance wanted when min_goal_distance is not set: "
            "lowered, with a warning, to what the map's largest free region allows",
        )
        clearance: float = Field(
            0.25, ge=0, description="m kept beyond the robot body (Arena SPAWN_ROBOT_SAFE_DIST)"
        )

    def __init__(self, params: Params | None = None) -> None:
        self.params = params or self.Params()
        self._warned: set[str] = set()

    def reset(self, ctx: ResetContext) -> list[RobotSpawn]:
        """Start and goal for every robot model of the episode."""
        p = self.params
        explicit = "min_goal_distance" in p.model_fields_set
        return random_spawns(
            ctx, p.min_goal_distance, p.clearance,
            goal_distance=None if explicit else p.goal_distance, warned=self._warned,
        )


@njit(cache=True)
def _far_cells(
    cells: NDArray[np.int64],
    ox: float,
    oy: float,
    res: float,
    width: int,
    x: float,
    y: float,
    far: float,
) -> NDArray[np.intp]:
    """Flat indices of the ``[row, col]`` cells ``(k, 2)`` whose centre is ``far`` from ``(x, y)``.

    Centres ``origin + (index + 0.5) · res`` and ``np.hypot(cx - x, cy - y) >= far``, as the
    full-map mask this replaced computed them, so the same cells (in the same order). The
    squared distance settles all but a thin shell of cells: it is within 4e-16 (relative) of
    the true one and ``hypot`` within 2.3e-16 of its root, so outside ``far² · (1 ± 1e-9)``
    both sides agree; only the shell pays for ``hypot``.
    """
    out = np.empty(cells.shape[0], dtype=np.intp)
    hi = far * far * (1.0 + 1e-9)
    lo = far * far * (1.0 - 1e-9)
    sure = far > 0.0 and np.isfinite(far)
    k = 0
    for i in range(cells.shape[0]):
        dx = (ox + (float(cells[i, 1]) + 0.5) * res) - x
        dy = (oy + (float(cells[i, 0]) + 0.5) * res) - y
        sq = dx * dx + dy * dy
        if sure and sq > hi:
            keep = True
        elif sure and sq < lo:
            keep = False
        else:
            keep = np.hypot(dx, dy) >= far
        if keep:
            out[k] = cells[i, 0] * width + cells[i, 1]
            k += 1
    return out[:k]
