"""PySocialForce (Gao's implementation of Moussaïd's extended social force model), Arena's default.

Arena 3.0 drives its pedestrians with PySocialForce 1.1.2 (``pysocialforce.Simulator``); this
model computes the same forces from one :class:`~arena.crowd.base.CrowdFrame`, term by term, in
numba, with neighbour lists instead of PySocialForce's all-pairs arrays. With ``cutoff = inf``,
``robot_factor = 0`` and ``force_scale = 1`` the accelerations equal
``pysocialforce.Simulator(state, groups, obstacles).compute_forces()`` to rounding
(``tests/crowd/test_pysocial.py`` checks every term against the package).

Forces per agent ``i`` (all accelerations, m/s², unit mass as in PySocialForce):

* ``desired``: ``(ê_i·v0_i − v_i)/τ`` while the destination is farther than ``goal_threshold``,
  else ``−v_i/τ`` (brake); ``ê_i`` points at the destination, ``v0_i`` is the desired speed.
* ``social`` (Moussaïd et al. 2010, PySocialForce's vectorisation), summed over the others ``j``:
  ``d = |r_i − r_j|``, ``e = (r_i − r_j)/d``, ``D = λ(v_j − v_i) + e``, ``t = D/|D|``,
  ``B = γ|D|``, ``θ = atan2(t) − atan2(e)`` (*not* wrapped to (−π, π]: PySocialForce subtracts
  the two ``arctan2`` angles, so θ lies in (−2π, 2π) and both the Gaussian and the sign see the
  raw difference), ``f = exp(−d/B − (n'Bθ)²)·t − sign(θ)·exp(−d/B − (nBθ)²)·t⊥`` with ``t⊥``
  the left normal ``(−t_y, t_x)``. Both ``e`` and ``D`` are the negatives of the paper's
  (PySocialForce's ``each_diff`` is ``r_a − r_b``, despite its comment), so ``t`` points away
  from the other; θ is unchanged by the double negation.
* ``obstacle``: over the obstacle sample points ``o`` (every wall segment sampled at
  ``resolution`` points per metre), ``Σ (r_i − o)/|r_i − o| · exp(−(|r_i − o| − R)/σ)`` for the
  points with ``|r_i − o| − R < threshold + R``, ``R`` the agent radius (PySocialForce adds the
  radius to the threshold *and* subtracts it from the distance, so the reach is
  ``threshold + 2R`` = 3.7 m by default).
* ``group_coherence`` (PySocialForce's ``GroupCoherenceForceAlt``, the one its simulator uses):
  ``(c − r_i)·(tanh(δ − (k − 1)/2) + 1)/2`` with ``c`` the centre of mass of the ``k`` members.
  pedsim's formula has ``δ = |c − r_i|``, but PySocialForce measures it with
  ``stateutils.speeds``, which takes the norm of columns 2:4 of the ``(k, 2)`` array, an empty
  slice, so ``δ = 0`` always and the pull is linear in ``c − r_i`` with a constant gain
  (0.27 for pairs, 0.12 for triples). We reproduce that; ``coherence_uses_distance = True``
  gives pedsim's intended softening.
* ``group_repulsion``: ``Σ_j (r_i − r_j)`` over the members within ``group_repulsion_threshold``
  (linear in the distance, as in PySocialForce).
* ``group_gaze`` (``GroupGazeForceAlt``): ``|c_i − r_i|·(ê_i·ĉ_i)/|g_i − r_i| · ê_i`` with
  ``c_i`` the centre of mass of the *other* members and ``g_i`` the destination.
* ``robot`` (Arena addition, not in PySocialForce): every robot acts on every pedestrian through
  the social term above, as if it were a pedestrian at its position with its world-frame
  velocity (the robot's radius plays no role, as pedestrians' radii play none in the social
  term), weighted by ``robot_factor``; ``robot_factor = 0`` reproduces PySocialForce.

Conventions matched to PySocialForce (found in its source, documented where they bite):

* **Effective factors.** ``pysocialforce.Simulator`` builds ``DesiredForce``, ``SocialForce``,
  ``ObstacleForce`` and, with ``scene.enable_group``, ``GroupCoherenceForceAlt``,
  ``GroupRepulsiveForce`` and ``GroupGazeForceAlt``. Each force reads the config section named
  after its class in snake case, so the two ``*_alt`` forces find no section and fall back to
  factor 1.0: the ``group_coherence_force.factor = 3.0`` and ``group_gaze_force.factor = 4.0``
  of ``default.toml`` are never applied. Our defaults are the factors PySocialForce applies
  (1.0, 1.0); the toml values are noted on the fields. The toml's ``goal_attractive_force``,
  ``ped_repulsive_force``, ``space_repulsive_force`` and the gaze ``fov_phi`` belong to forces
  the simulator does not build.
* **Speeds.** PySocialForce has no preferred-speed input: ``PedState`` stores the speed of the
  *first* state it sees as ``initial_speeds`` and sets ``max_speeds = max_speed_multiplier
  (1.3) × initial_speeds``; ``DesiredForce`` drives towards ``max_speeds`` and ``step`` caps
  ``|v|`` at the same ``max_speeds``. So its desired speed and its speed cap are one number.
  Ours is ``vmax · vmax_factor`` (the preferred speed, which is also the simulator's hard cap):
  ``v0_i = vmax_i · vmax_factor_i`` corresponds to PySocialForce's ``max_speeds`` =
  1.3 × the agent's initial speed. To replay a PySocialForce scene, set
  ``vmax = 1.3 · |v(t=0)|``.
* **State layout.** PySocialForce's state rows are ``(px, py, vx, vy, gx, gy[, tau])`` with the
  *absolute* goal; the ``tau`` column (``scene.tau``) is read only by the unused
  ``GoalAttractiveForce``, ``DesiredForce`` uses ``desired_force.relaxation_time``. Arena's
  plugin passed ``(gx − px, gy − py)`` in the goal slots (a relative goal read as absolute); we
  use the frame's absolute destinations.
* **Scene settings.** ``Simulator`` reads ``resolution``, ``agent_radius``, ``step_width``,
  ``max_speed_multiplier`` and ``tau`` from the *top level* of its config, where
  ``default.toml`` does not put them (they sit under ``[scene]``), so its code defaults apply:
  resolution 10, agent radius 0.35, multiplier 1.3, tau 0.5, and step width **0.4** s (not the
  toml's 1.0). Only ``scene.enable_group`` is read from its section.
* **Time step.** ``compute_forces`` does not depend on the step width (the time step of
  PySocialForce's own ``step``, which also zeroes velocities within 0.5 m of the goal); the
  arena simulator integrates our accelerations with its ``dt``, so no alignment is needed.
* **Obstacles.** A line ``(x0, x1, y0, y1)`` (x's first) becomes
  ``int(length · resolution)`` points spread by ``np.linspace`` from start to end, both ends
  included; lines sharing an end point give duplicated points, as in PySocialForce. One
  deliberate difference: PySocialForce samples lines shorter than 2/``resolution`` (0.2 m) with
  one or no point, so a small obstacle could be invisible; we sample every non-degenerate
  segment with at least its two end points. ``agent_radius`` is one scene-wide 0.35 m in
  PySocialForce; ``agent_radius = None`` uses each agent's own radius instead.
* **Groups.** A group is the agents sharing a ``state.group`` id ≥ 0 (PySocialForce: a list of
  index lists); members that are not active still count in their group's centre of mass, as
  every listed member does in PySocialForce.
* **Angles.** θ is the raw difference of two ``arctan2`` values, so a pair whose ``e`` and
  ``t`` straddle the negative x-axis gets θ off by 2π and an almost vanishing force (the model
  is not rotation invariant; which pairs are hit depends on their orientation in the world).
  We reproduce it with one ``arctan2`` of the angle from ``e`` to ``t`` plus that ±2π;
  ``wrap_theta = True`` gives Moussaïd's wrapped θ instead. For equal velocities (``D = e``)
  we use θ = 0 exactly, where PySocialForce's two ``arctan2`` values may differ by rounding
  and flip ``sign(θ)``.
* **Degenerate cases.** Where PySocialForce divides by zero (the group gaze of an agent standing
  on its destination, a social pair with ``D = 0``) it produces NaN, which Arena's plugin then
  replaced by 0; we return 0 directly.

Arena scaled PySocialForce's total by 0.3 before handing it to pedsim (``force_scale`` here,
default 1.0 so that the model is PySocialForce's; set 0.3 for Arena's scale). Accelerations are
``force_scale`` times the sum of the terms, zero for inactive agents; ``forces`` holds the scaled
terms, which sum to the accelerations.

Neighbour cutoff: a pair's social magnitude is at most ``√2 · social_factor · exp(−d/B)``
with ``B = γ|D| ≤ γ(λΔv + 1)``, ``Δv`` the relative speed. At 10 m that bound is
1.2e-4 m/s² for Arena's pedestrians (vmax 0.3-0.5 m/s, Δv ≤ 0.8 m/s), 0.024 m/s² for two
people walking head-on at 1 m/s (0.075 at 8 m, 0.23 at 6 m) and 0.072 m/s² at 1.3 m/s each.
Summed over a dense crowd (1000 agents in 40 × 40 m, random headings, all at speed v), cutting
at 10 m changes the total acceleration by 3e-4 m/s² at most for v = 0.4 m/s, and by 0.027 m/s²
RMS / 0.076 m/s² max for v = 1 m/s (0.08 / 0.25 at 8 m, 0.23 / 0.80 at 6 m), against desired
forces of ``v0/τ`` ≈ 2 m/s²: a steady 0.076 m/s² moves the walking velocity by
``F·τ`` < 4 cm/s. Hence the default ``cutoff = 10`` m; ``math.inf`` takes every pair, as
PySocialForce does.

Implementation: the social term visits each unordered pair once for both agents (the reverse
direction has ``e' = −e``, ``D' = −D``, so the same ``|D|``, ``B`` and wrapped angle; only the
±2π correction differs). The pairs come from :meth:`Neighbors.unique_pairs` (a half search,
no CSR). They are processed in blocks: numba kernels for the geometry, the angles and the
accumulation, NumPy's SIMD ``arctan2`` and ``exp`` in between, about 3× faster than calling libm
from inside a numba loop; the geometry and angle kernels are branch-free in the common case so
that LLVM vectorises them (IEEE sqrt and division give the scalar bits), with the rare cases
(signed zeros, coincident agents, ``Δv = 0``) redone by the scalar formula. The obstacle term
scans the point grid directly, skipping cells and runs of points whose bounding box is out of
reach, and evaluates the rest in a vectorised pass before the (libm) exponentials. Every other
term, the factors and the total are one compiled call (:func:`_terms`) that repeats NumPy's
element-wise arithmetic in NumPy's order, so the results are those of the term-by-term NumPy
formulation to the bit (``tests/crowd/test_pysocial.py`` checks the kernels that way).
"""

from __future__ import annotations

from typing import ClassVar, Literal

import numpy as np
from numpy.typing import NDArray

from arena.crowd.base import CROWD_MODELS, CrowdFrame, ModelOutput
from arena.crowd.models.pysocial.kernels import _COEF, _same_ints, _terms
from arena.crowd.models.pysocial.obstacle_kernels import _ObstacleIndex
from arena.crowd.models.pysocial.pair_kernels import (
    _pair_accumulate,
    _pair_exponents,
    _pair_geometry,
    _PairWork,
)
from arena.crowd.models.pysocial.params import PySocialParams
from arena.crowd.neighbors import CellList
from arena.crowd.state import CrowdState
from arena.crowd.walls import grid_walls
from arena.maps.distance import grid_memo
from arena.scene.state import StaticWorld

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

TERMS = (
    "desired",
    "social",
    "obstacle",
    "group_coherence",
    "group_repulsion",
    "group_gaze",
    "robot",
)
"""Keys of :attr:`ModelOutput.forces`, in summation order."""

_CHUNK = 8192
"""Pairs per block of the social pipeline: a block's work arrays (~1 MB) stay in cache."""


@CROWD_MODELS.register("pysocial", tags=("social_force", "default"))
class PySocialModel:
    """PySocialForce's extended social force model (Moussaïd et al. 2010), Arena's default."""

    output: ClassVar[Literal["acceleration", "velocity"]] = "acceleration"

    Params = PySocialParams

    def __init__(self, params: PySocialParams | None = None) -> None:
        self.params = params or self.Params()
        self._coef_of: PySocialParams | None = None
        self._coef: FloatArray = np.zeros(len(_COEF))
        self.set_obstacles(np.zeros((0, 2)), np.zeros((0, 2)))
        self._work: _PairWork | None = None
        self._groups_cache: tuple[IntArray, IntArray, IntArray] | None = None
        self._radii: FloatArray = np.zeros(0)

    def neighbor_cutoff(self) -> float:
        """The social interaction range ``cutoff`` (m)."""
        return float(self.params.cutoff)

    def reset(self, state: CrowdState, world: StaticWorld, rng: np.random.Generator) -> None:
        """Sample the episode's walls and obstacle edges into points, once."""
        res = self.params.resolution

        def wall_points() -> FloatArray:
            pts = sample_segments(*grid_walls(world.grid), res)
            pts.setflags(write=False)
            return pts

        # set_obstacles(*episode_segments(world)): segments are sampled one by one, so the
        # map's walls (the same every episode on a map) are sampled once per map and the
        # episode's obstacle edges appended.
        walls = grid_memo(world.grid, ("pysocial wall points", float(res)), wall_points)
        r = self.params.agent_radius
        r_max = float(r) if r is not None else float(np.max(state.radii, initial=0.0))
        self._use_points(
            np.concatenate([walls, sample_segments(world.segments_a, world.segments_b, res)]),
            r_max,
        )

    def set_obstacles(self, a: FloatArray, b: FloatArray, *, max_radius: float = 0.35) -> None:
        """Use these segments as the obstacles (what :meth:`reset` does with the world's).

        Args:
            a: ``(s, 2)`` segment starts (m).
            b: ``(s, 2)`` segment ends (m).
            max_radius: largest agent radius to expect (m); sizes the point index.
        """
        self._use_points(sample_segments(a, b, self.params.resolution), max_radius)

    def _use_points(self, points: FloatArray, max_radius: float) -> None:
        """Index ``(m, 2)`` obstacle points (m) (see :meth:`set_obstacles`)."""
        self.obstacle_points = points
        p = self.params
        r = p.agent_radius if p.agent_radius is not None else max_radius
        self._cells = CellList(self.obstacle_points, p.obstacle_threshold + 2.0 * r)
        self._obstacles = _ObstacleIndex.build(self._cells)

    def compute(self, frame: CrowdFrame) -> ModelOutput:
        """PySocialForce's forces for every active agent (zero for inactive ones)."""
        p = self.params
        s = frame.state
        n = len(s)
        # One block for the seven terms: the kernel fills it, the dict hands out its rows.
        forces = np.zeros((len(TERMS), n, 2))
        terms = dict(zip(TERMS, forces, strict=True))  # rows: views of the block
        if n == 0:
            return ModelOutput(accelerations=np.zeros((0, 2)), forces=terms)
        pos = np.ascontiguousarray(s.positions, dtype=np.float64)
        vel = np.ascontiguousarray(s.velocities, dtype=np.float64)
        active = np.ascontiguousarray(frame.active, dtype=np.bool_)

        pi, pj = frame.neighbors.unique_pairs()
        # pairs of two inactive agents exert nothing on anyone (count_nonzero: cheaper than all)
        if np.count_nonzero(active) != active.shape[0]:
            keep = active[pi] | active[pj]
            pi, pj = pi[keep], pj[keep]
        self._social_term(pos, vel, pi, pj, forces[_SOCIAL])

        radii = self._agent_radii(s)
        order, starts = self._group_members(s.group) if p.enable_group else _NO_GROUPS
        ob = self._obstacles
        acc = np.empty((n, 2))
        _terms(
            pos,
            vel,
            np.ascontiguousarray(frame.destinations, dtype=np.float64),
            np.ascontiguousarray(s.vmax, dtype=np.float64),
            np.ascontiguousarray(s.vmax_factor, dtype=np.float64),
            active,
            np.ascontiguousarray(frame.robots.positions, dtype=np.float64),
            np.ascontiguousarray(frame.robots.velocities, dtype=np.float64),
            radii,
            ob.xy,
            ob.cell_blocks,
            ob.block_lo,
            ob.bbox,
            ob.cell_box,
            ob.grid,
            ob.shape,
            ob.work,
            order,
            starts,
            self._coefficients(),
            p.wrap_theta,
            p.coherence_uses_distance,
            forces,
            acc,
        )
        return ModelOutput(accelerations=acc, forces=terms)

    def _coefficients(self) -> FloatArray:
        """The parameters as the kernel reads them (:data:`_COEF` order), rebuilt if replaced."""
        if self._coef_of is not self.params:
            p = self.params
            values = {k: float(getattr(p, k)) for k in _COEF if hasattr(p, k)}
            # The robot term's factor, formed first and then applied, as it always was.
            values["robot_scale"] = p.robot_factor * p.social_factor
            self._coef = np.array([values[k] for k in _COEF])
            self._coef_of = p
        return self._coef

    def _agent_radii(self, state: CrowdState) -> FloatArray:
        """``(n,)`` the radius each agent has in the obstacle term (m)."""
        r = self.params.agent_radius
        if r is None:
            return np.ascontiguousarray(state.radii, dtype=np.float64)
        n = len(state)
        if self._radii.shape[0] != n or self._radii[0] != r:  # one scene-wide radius: cached
            self._radii = np.full(n, float(r))
        return self._radii

    def _group_members(self, group: IntArray) -> tuple[IntArray, IntArray]:
        """:func:`group_members` of ``group``, recomputed only when the groups change.

        Groups are fixed for an episode, so the copy compared here nearly always matches.
        """
        cached = self._groups_cache
        if cached is not None and _same_ints(cached[0], np.ascontiguousarray(group)):
            return cached[1], cached[2]
        order, starts = group_members(group)
        self._groups_cache = (np.array(group, dtype=np.int64, copy=True), order, starts)
        return order, starts

    def _social_term(
        self,
        pos: FloatArray,
        vel: FloatArray,
        pi: IntArray,
        pj: IntArray,
        out: FloatArray,
    ) -> None:
        """Add the pedestrian interaction (before its factor) to ``out`` ``(n, 2)``.

        ``pi``, ``pj``: ``(m,)`` the unordered pairs ``i < j`` to evaluate.

        Each unordered pair is evaluated once for both agents, in blocks: numba kernels for the
        geometry, the angles and the accumulation, NumPy's SIMD ``arctan2`` and ``exp`` in
        between (several times faster than scalar libm calls from inside a numba loop).
        """
        p = self.params
        m = pi.shape[0]
        if m == 0:
            return
        # Work arrays live across steps: fresh large arrays would page-fault every step.
        k = min(m, _CHUNK)
        if self._work is None or self._work.w.shape[0] < k:
            self._work = _PairWork.allocate(k)
        wk = self._work
        for lo in range(0, m, _CHUNK):  # a few blocks per step; the per-pair work is compiled
            hi = min(lo + _CHUNK, m)
            c = hi - lo
            _pair_geometry(
                pos,
                vel,
                pi,
                pj,
                lo,
                hi,
                float(p.cutoff),
                p.lambda_importance,
                p.gamma,
                wk.gather,
                wk.geo,
                wk.code,
            )
            geo = wk.geo
            np.arctan2(geo[0, :c], geo[1, :c], out=wk.w[:c])
            _pair_exponents(wk.w, wk.code, geo, c, p.n, p.n_prime, p.wrap_theta, wk.args, wk.sg)
            with np.errstate(under="ignore"):  # distant pairs: exp → 0 is the right answer
                np.exp(wk.args[: 4 * c], out=wk.ex[: 4 * c])
            _pair_accumulate(pi, pj, lo, hi, geo, wk.ex, wk.sg, out)


_SOCIAL = TERMS.index("social")
_NO_GROUPS = (np.zeros(0, dtype=np.int64), np.zeros(1, dtype=np.int64))
"""``(order, starts)`` of no groups (the group terms switched off)."""


def desired_force(
    pos: FloatArray,
    vel: FloatArray,
    dest: FloatArray,
    speed: FloatArray,
    relaxation_time: float,
    goal_threshold: float,
) -> FloatArray:
    """PySocialForce's ``DesiredForce`` before its factor.

    Args:
        pos: ``(n, 2)`` positions (m).
        vel: ``(n, 2)`` velocities (m/s).
        dest: ``(n, 2)`` destinations (m).
        speed: ``(n,)`` desired speeds (m/s).
        relaxation_time: τ (s).
        goal_threshold: distance (m) within which the agent brakes instead.

    Returns:
        ``(n, 2)`` m/s².
    """
    delta = dest - pos
    dist = np.hypot(delta[:, 0], delta[:, 1])
    direction = np.divide(delta, dist[:, None], out=np.zeros_like(delta), where=dist[:, None] > 0)
    far = (dist > goal_threshold)[:, None]
    return np.where(far, direction * speed[:, None] - vel, -vel) / relaxation_time


def sample_segments(a: FloatArray, b: FloatArray, resolution: float) -> FloatArray:
    """Obstacle points along segments the way PySocialForce's ``EnvState`` samples lines.

    ``int(length · resolution)`` points per segment by ``np.linspace`` arithmetic (start plus
    ``k`` steps of ``(end − start)/(count − 1)``, the last point exactly the end), at least the
    two end points; zero-length segments give none.

    Args:
        a: ``(s, 2)`` segment starts (m).
        b: ``(s, 2)`` segment ends (m).
        resolution: points per metre.

    Returns:
        ``(m, 2)`` points (m), segment by segment.
    """
    a = np.asarray(a, dtype=np.float64).reshape(-1, 2)
    b = np.asarray(b, dtype=np.float64).reshape(-1, 2)
    # Each length exactly as PySocialForce computes it (a 2-vector norm, i.e. a dot product
    # that may fuse multiply-adds): int() truncation turns a last-bit difference, e.g. 6 m as
    # 59.99999999999999 samples, into one point more or less. Once per episode, per segment.
    length = np.array([np.linalg.norm(d) for d in a - b], dtype=np.float64)
    counts = np.where(length > 0, np.maximum((length * resolution).astype(np.int64), 2), 0)
    total = int(counts.sum())
    if total == 0:
        return np.zeros((0, 2))
    owner = np.repeat(np.arange(a.shape[0]), counts)
    k = np.arange(total) - np.repeat(np.cumsum(counts) - counts, counts)
    step = (b - a) / np.maximum(counts - 1, 1)[:, None]
    pts: FloatArray = a[owner] + k[:, None] * step[owner]
    last = np.cumsum(counts)[counts > 0] - 1
    pts[last] = b[counts > 0]
    return pts


def group_members(group: IntArray) -> tuple[IntArray, IntArray]:
    """Agents of each group (id ≥ 0) contiguous, in index order within a group.

    Returns:
        ``(order, starts)``: the members of the ``g``-th group are
        ``order[starts[g]:starts[g + 1]]``.
    """
    g = np.asarray(group, dtype=np.int64)
    grouped = np.flatnonzero(g >= 0)
    if grouped.size == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(1, dtype=np.int64)
    order = grouped[np.argsort(g[grouped], kind="stable")]
    ids = g[order]
    starts = np.concatenate(([0], np.flatnonzero(np.diff(ids)) + 1, [ids.size])).astype(np.int64)
    return order.astype(np.int64), starts
