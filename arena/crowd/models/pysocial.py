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

import math
from dataclasses import dataclass
from typing import ClassVar, Literal

import numpy as np
from numba import njit
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

from arena.crowd.base import CROWD_MODELS, CrowdFrame, ModelOutput
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

_TWO_PI = 2.0 * math.pi
_CHUNK = 8192
"""Pairs per block of the social pipeline: a block's work arrays (~1 MB) stay in cache."""
_BLOCK = 8
"""Obstacle points per bounding box (0.8 m of wall at PySocialForce's 10 points per metre)."""


@CROWD_MODELS.register("pysocial", tags=("social_force", "default"))
class PySocialModel:
    """PySocialForce's extended social force model (Moussaïd et al. 2010), Arena's default."""

    output: ClassVar[Literal["acceleration", "velocity"]] = "acceleration"

    class Params(BaseModel):
        """Parameters of :class:`PySocialModel`.

        Defaults are PySocialForce 1.1.2's ``default.toml`` as its simulator applies them (see
        the module docstring for the two group factors).
        """

        model_config = ConfigDict(frozen=True, extra="forbid")

        # desired_force
        desired_factor: float = Field(1.0, ge=0, description="dimensionless, desired_force.factor")
        relaxation_time: float = Field(
            0.5, gt=0, description="s, desired_force.relaxation_time (τ)"
        )
        goal_threshold: float = Field(
            0.2,
            ge=0,
            description="m, desired_force.goal_threshold: closer than this the agent brakes",
        )
        # social_force
        social_factor: float = Field(5.1, ge=0, description="m/s², social_force.factor")
        lambda_importance: float = Field(
            2.0,
            ge=0,
            description="s/m, social_force.lambda_importance: weight of the velocity difference",
        )
        gamma: float = Field(0.35, gt=0, description="m, social_force.gamma: B = γ|D|")
        n: float = Field(2.0, ge=0, description="1/m, social_force.n: angular decay (turning)")
        n_prime: float = Field(
            3.0, ge=0, description="1/m, social_force.n_prime: angular decay (braking)"
        )
        # obstacle_force
        obstacle_factor: float = Field(10.0, ge=0, description="m/s², obstacle_force.factor")
        obstacle_sigma: float = Field(
            0.2, gt=0, description="m, obstacle_force.sigma: decay length"
        )
        obstacle_threshold: float = Field(
            3.0,
            ge=0,
            description="m, obstacle_force.threshold (the agent radius is added, as upstream)",
        )
        agent_radius: float | None = Field(
            0.35,
            ge=0,
            description="m, scene.agent_radius; None uses each agent's own radius",
        )
        resolution: float = Field(
            10.0, gt=0, description="1/m, scene.resolution: obstacle sample points per metre"
        )
        # groups
        enable_group: bool = Field(True, description="scene.enable_group: the three group terms")
        group_coherence_factor: float = Field(
            1.0,
            ge=0,
            description="1/s², GroupCoherenceForceAlt factor (toml's 3.0 is never applied)",
        )
        coherence_uses_distance: bool = Field(
            False,
            description="soften the coherence with |c − r_i| as pedsim does; False reproduces "
            "PySocialForce (which always uses 0)",
        )
        group_repulsion_factor: float = Field(
            1.0, ge=0, description="1/s², group_repulsive_force.factor"
        )
        group_repulsion_threshold: float = Field(
            0.55, ge=0, description="m, group_repulsive_force.threshold"
        )
        group_gaze_factor: float = Field(
            1.0,
            ge=0,
            description="m/s², GroupGazeForceAlt factor (toml's 4.0 is never applied)",
        )
        # Arena
        robot_factor: float = Field(
            1.0,
            ge=0,
            description="dimensionless, robots act through the social term × this; "
            "0 reproduces PySocialForce",
        )
        force_scale: float = Field(
            1.0, ge=0, description="dimensionless, scale on the total (Arena used 0.3)"
        )
        wrap_theta: bool = Field(
            False,
            description="wrap the social angle θ into (−π, π] as Moussaïd intends; False "
            "reproduces PySocialForce's raw atan2 difference",
        )
        cutoff: float = Field(
            10.0,
            gt=0,
            description="m, social/robot interaction range; inf = all pairs (exact PySocialForce)",
        )

    def __init__(self, params: Params | None = None) -> None:
        self.params = params or self.Params()
        self._coef_of: PySocialModel.Params | None = None
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

_COEF = (
    "desired_factor",
    "relaxation_time",
    "goal_threshold",
    "social_factor",
    "robot_factor",
    "robot_scale",
    "cutoff",
    "lambda_importance",
    "gamma",
    "n",
    "n_prime",
    "obstacle_factor",
    "obstacle_threshold",
    "obstacle_sigma",
    "group_repulsion_threshold",
    "group_coherence_factor",
    "group_repulsion_factor",
    "group_gaze_factor",
    "force_scale",
)
"""Order of :meth:`PySocialModel._coefficients` (``robot_scale`` = robot × social factor)."""
(
    _C_DESIRED,
    _C_TAU,
    _C_GOAL,
    _C_SOCIAL,
    _C_ROBOT,
    _C_ROBOT_SCALE,
    _C_CUTOFF,
    _C_LAMBDA,
    _C_GAMMA,
    _C_N,
    _C_N_PRIME,
    _C_OBSTACLE,
    _C_OB_THRESHOLD,
    _C_OB_SIGMA,
    _C_REP_THRESHOLD,
    _C_COHERENCE,
    _C_REPULSION,
    _C_GAZE,
    _C_SCALE,
) = range(len(_COEF))


@dataclass(frozen=True, eq=False)
class _PairWork:
    """Scratch arrays of the social pipeline for blocks of up to ``k`` pairs."""

    gather: FloatArray
    """``(4, k)`` gathered position and velocity differences."""
    geo: FloatArray
    """``(6, k)`` :func:`_pair_geometry`'s rows (one array: the vectorised kernel needs few base
    pointers)."""
    code: IntArray
    """``(k,)`` half-plane bits."""
    w: FloatArray
    """``(k,)`` wrapped angles (rad)."""
    args: FloatArray
    """``(4k,)`` exponents, ``(4, c)`` row-major in the first ``4c`` for a block of ``c`` pairs:
    contiguous, so that one SIMD ``exp`` loop covers them (per element the same function as row
    by row)."""
    ex: FloatArray
    """``(4k,)`` their exponentials, likewise."""
    sg: FloatArray
    """``(2, k)`` signs of θ."""

    @classmethod
    def allocate(cls, k: int) -> _PairWork:
        """Uninitialised arrays for ``k`` pairs."""
        return cls(
            gather=np.empty((4, k)),
            geo=np.empty((6, k)),
            code=np.empty(k, dtype=np.int64),
            w=np.empty(k),
            args=np.empty(4 * k),
            ex=np.empty(4 * k),
            sg=np.empty((2, k)),
        )


@dataclass(frozen=True, eq=False)
class _ObstacleIndex:
    """The obstacle points of a :class:`CellList`, stored in its cell order, cut into blocks.

    Storing the points in scan order (rather than indexing through ``order``) keeps a block's
    points on a few cache lines; the scan visits them in the same order, so sums are unchanged.
    """

    xy: FloatArray
    """``(2, m)`` the points' x and y rows, cell by cell (m)."""
    cell_blocks: IntArray
    """``(cells + 1,)`` the blocks of cell ``c`` are ``cell_blocks[c]:cell_blocks[c + 1]``."""
    block_lo: IntArray
    """``(b + 1,)`` block ``k`` holds points ``block_lo[k]:block_lo[k + 1]``."""
    bbox: FloatArray
    """``(b, 4)`` ``(x_min, x_max, y_min, y_max)`` of each block (m)."""
    cell_box: FloatArray
    """``(cells, 4)`` the same of each cell's points (inf, -inf for an empty cell)."""
    grid: FloatArray
    """``(3,)`` grid origin x, y and cell size (m)."""
    shape: IntArray
    """``(2,)`` cells along x and y."""
    work: FloatArray
    """``(4, m)`` scratch for one agent's candidate points."""

    @classmethod
    def build(cls, cells: CellList) -> _ObstacleIndex:
        """Index the points of ``cells``."""
        cell_blocks, block_lo, bbox = _point_blocks(cells.points, cells.order, cells.starts)
        xy = np.ascontiguousarray(cells.points[cells.order].T)
        return cls(
            xy=xy,
            cell_blocks=cell_blocks,
            block_lo=block_lo,
            bbox=bbox,
            cell_box=_cell_boxes(bbox, cell_blocks),
            grid=np.array([cells.origin[0], cells.origin[1], cells.cell], dtype=np.float64),
            shape=np.array(cells.shape, dtype=np.int64),
            work=np.empty((4, xy.shape[1])),
        )


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


@njit(cache=True, inline="always")
def _upper(x: float, y: float) -> int:
    """1 if ``atan2(y, x) > 0``, else 0 (signed zeros included: ``atan2(+0, x < 0) = +π``)."""
    if y == 0.0:  # rare: only exact zeros need the sign bit
        return 1 if (x < 0.0 and math.copysign(1.0, y) > 0.0) else 0
    return 1 if y > 0.0 else 0


@njit(cache=True)
def _pair_geometry(
    pos: FloatArray,
    vel: FloatArray,
    pi: IntArray,
    pj: IntArray,
    lo: int,
    hi: int,
    cutoff: float,
    lam: float,
    gamma: float,
    gather: FloatArray,
    geo: FloatArray,
    code: IntArray,
) -> None:
    """Per pair ``lo..hi``: the atan2 arguments, ``−d/B``, ``B``, ``t`` and the half-plane bits.

    ``e``, ``D`` and ``t`` are PySocialForce's for agent ``i`` (``e = (r_i − r_j)/d``,
    ``D = λ(v_j − v_i) + e``); agent ``j`` sees ``−e`` and ``−D``, hence the same ``|D|``, ``B``
    and wrapped angle ``w`` from ``e`` to ``t``. PySocialForce's raw ``θ = atan2(t) − atan2(e)``
    is ``w`` shifted by ∓2π where the rotation from ``e`` to ``t`` crosses the negative x-axis;
    the bits record which half-plane each of the four vectors lies in (from the reverse vectors
    formed as PySocialForce forms them, so signed zeros match) and ``d = 0``.

    Args:
        pos: ``(n, 2)`` positions (m).
        vel: ``(n, 2)`` velocities (m/s).
        pi: ``(p,)`` first agents of the pairs.
        pj: ``(p,)`` second agents.
        lo: first pair of the block.
        hi: end of the block (exclusive).
        cutoff: interaction range (m); pairs beyond it exert nothing.
        lam: λ (s/m).
        gamma: γ (m).
        gather: ``(4, ≥ hi − lo)`` scratch.
        geo: ``(6, ≥ hi − lo)`` out: rows ``sin w``/``cos w`` (atan2 arguments), ``−d/B``,
            ``B``, ``t_x``, ``t_y``.
        code: ``(≥ hi − lo,)`` out: the half-plane bits, 16 for ``d = 0``.
    """
    c2 = cutoff * cutoff
    c = hi - lo
    for q in range(c):  # gather first: the main loop is then SIMD-vectorised (no indirection)
        i = pi[lo + q]
        j = pj[lo + q]
        gather[0, q] = pos[i, 0] - pos[j, 0]
        gather[1, q] = pos[i, 1] - pos[j, 1]
        gather[2, q] = vel[j, 0] - vel[i, 0]
        gather[3, q] = vel[j, 1] - vel[i, 1]
    rare = 0
    for q in range(c):
        # The common case, branch-free so that LLVM vectorises it (IEEE sqrt and division are
        # exact in SIMD too: the same bits as the scalar formula). With ``e_y ≠ 0``,
        # ``t_y ≠ 0``, ``Δv ≠ 0`` and ``d < cutoff`` the reverse vectors are the exact
        # negatives, so their bits are the opposite signs; the other pairs (flag 32) are
        # redone below by the scalar formula, which handles the signed zeros.
        dx = gather[0, q]
        dy = gather[1, q]
        dvx = gather[2, q]
        dvy = gather[3, q]
        d2 = dx * dx + dy * dy
        d = math.sqrt(d2)
        inv_d = 1.0 / d if d > 0.0 else 0.0  # a select: no division by zero, still SIMD
        ex = dx * inv_d
        ey = dy * inv_d
        ix = lam * dvx + ex
        iy = lam * dvy + ey
        length = math.sqrt(ix * ix + iy * iy)
        inv_l = 1.0 / length if length > 0.0 else 0.0
        t_x = ix * inv_l
        t_y = iy * inv_l
        geo[0, q] = ex * t_y - ey * t_x
        geo[1, q] = ex * t_x + ey * t_y
        geo[2, q] = -d * inv_l / gamma
        geo[3, q] = gamma * length
        geo[4, q] = t_x
        geo[5, q] = t_y
        flag = (ey == 0.0) | (t_y == 0.0) | ((dvx == 0.0) & (dvy == 0.0)) | (d2 >= c2)
        code[q] = (ey > 0.0) + 2 * (t_y > 0.0) + 4 * (ey < 0.0) + 8 * (t_y < 0.0) + 32 * flag
        rare += flag
    if rare == 0:
        return
    for q in range(c):
        if code[q] >= 32:
            _pair_geometry_one(pos, vel, pi[lo + q], pj[lo + q], q, c2, lam, gamma, geo, code)


@njit(cache=True, inline="always")
def _pair_geometry_one(
    pos: FloatArray,
    vel: FloatArray,
    i: int,
    j: int,
    q: int,
    c2: float,
    lam: float,
    gamma: float,
    geo: FloatArray,
    code: IntArray,
) -> None:
    """:func:`_pair_geometry` for the pair ``(i, j)`` into column ``q``, every case handled."""
    px = pos[i, 0]
    py = pos[i, 1]
    ox = pos[j, 0]
    oy = pos[j, 1]
    dvx = vel[j, 0] - vel[i, 0]
    dvy = vel[j, 1] - vel[i, 1]
    dx = px - ox
    dy = py - oy
    d2 = dx * dx + dy * dy
    d = math.sqrt(d2)
    inv_d = 1.0 / d if d > 0.0 else 0.0  # e = 0 for coincident agents, as upstream
    ex = dx * inv_d
    ey = dy * inv_d
    rex = (ox - px) * inv_d
    rey = (oy - py) * inv_d
    ix = lam * dvx + ex
    iy = lam * dvy + ey
    length = math.sqrt(ix * ix + iy * iy)
    inv_l = 1.0 / length if length > 0.0 else 0.0
    t_x = ix * inv_l
    t_y = iy * inv_l
    rtx = (lam * (vel[i, 0] - vel[j, 0]) + rex) * inv_l
    rty = (lam * (vel[i, 1] - vel[j, 1]) + rey) * inv_l
    if d == 0.0:
        geo[0, q] = t_y  # e = 0: θ = atan2(t)
        geo[1, q] = t_x
    elif dvx == 0.0 and dvy == 0.0:
        geo[0, q] = 0.0  # D = e: θ = 0 exactly, not ±1 ulp of rounding noise
        geo[1, q] = 1.0
    else:
        geo[0, q] = ex * t_y - ey * t_x
        geo[1, q] = ex * t_x + ey * t_y
    # Outside the cutoff (a wider neighbour search) or D = 0: both directions exactly 0
    # (upstream's 0·exp(−d/0); NaN if d = 0 too, which Arena zeroed).
    geo[2, q] = -d * inv_l / gamma if (length > 0.0 and d2 < c2) else -math.inf
    geo[3, q] = gamma * length
    geo[4, q] = t_x
    geo[5, q] = t_y
    if ey == 0.0 or t_y == 0.0 or rey == 0.0 or rty == 0.0:  # rare: signed zeros matter
        code[q] = (
            _upper(ex, ey)
            + 2 * _upper(t_x, t_y)
            + 4 * _upper(rex, rey)
            + 8 * _upper(rtx, rty)
            + (16 if d == 0.0 else 0)
        )
    else:
        code[q] = (ey > 0.0) + 2 * (t_y > 0.0) + 4 * (rey > 0.0) + 8 * (rty > 0.0)


@njit(cache=True, inline="always")
def _unwrap(w: float, upper_e: bool, upper_t: bool) -> float:
    """``atan2(t) − atan2(e)`` from the wrapped angle ``w`` from ``e`` to ``t``."""
    if upper_e and not upper_t and w > 0.0:
        return w - _TWO_PI  # counter-clockwise through the negative x-axis
    if upper_t and not upper_e and w < 0.0:
        return w + _TWO_PI  # clockwise through it
    return w


@njit(cache=True)
def _pair_exponents(
    w: FloatArray,
    code: IntArray,
    geo: FloatArray,
    m: int,
    n: float,
    n_prime: float,
    wrap: bool,
    args: FloatArray,
    sg: FloatArray,
) -> None:
    """θ for both agents of each pair, the four exponents and the signs of θ.

    Args:
        w: ``(≥ m,)`` wrapped angles from ``e`` to ``t`` (rad).
        code: ``(≥ m,)`` half-plane bits of :func:`_pair_geometry`.
        geo: ``(6, ≥ m)`` :func:`_pair_geometry`'s rows (``−d/B``, ``B``, ``t`` used here).
        m: pairs in the block.
        n: angular decay n (1/m).
        n_prime: angular decay n' (1/m).
        wrap: θ wrapped into (−π, π] instead of PySocialForce's raw difference.
        args: ``(≥ 4m,)`` out: exponents, ``(4, m)`` row-major in the first ``4m``: braking and
            turning for ``i``, then for ``j`` (one contiguous block for one ``exp`` call).
        sg: ``(2, ≥ m)`` out: ``sign θ`` for ``i`` and ``j``.
    """
    coincident = 0
    for q in range(m):
        # Branch-free (selects) so that it vectorises; _unwrap written out. Coincident pairs
        # (bit 16) are redone below.
        cd = code[q]
        wq = w[q]
        ue = (cd & 1) != 0
        ut = (cd & 2) != 0
        re = (cd & 4) != 0
        rt = (cd & 8) != 0
        down_i = ue & (~ut) & (wq > 0.0)
        up_i = ut & (~ue) & (wq < 0.0)
        down_j = re & (~rt) & (wq > 0.0)
        up_j = rt & (~re) & (wq < 0.0)
        th_i = wq - _TWO_PI if down_i else (wq + _TWO_PI if up_i else wq)
        th_j = wq - _TWO_PI if down_j else (wq + _TWO_PI if up_j else wq)
        th_i = wq if wrap else th_i
        th_j = wq if wrap else th_j
        b = geo[3, q]
        bs = geo[2, q]
        args[q] = bs - (n_prime * b * th_i) ** 2
        args[1 * m + q] = bs - (n * b * th_i) ** 2
        args[2 * m + q] = bs - (n_prime * b * th_j) ** 2
        args[3 * m + q] = bs - (n * b * th_j) ** 2
        sg[0, q] = (th_i > 0.0) - (th_i < 0.0)
        sg[1, q] = (th_j > 0.0) - (th_j < 0.0)
        coincident += (cd & 16) != 0
    if coincident == 0:
        return
    for q in range(m):
        if code[q] & 16:  # d = 0: each agent's θ is the angle of its own t (upstream e = 0)
            th_i = w[q]
            rtx = -geo[4, q] if geo[4, q] != 0.0 else 0.0
            rty = -geo[5, q] if geo[5, q] != 0.0 else 0.0
            th_j = math.atan2(rty, rtx)
            b = geo[3, q]
            bs = geo[2, q]
            args[q] = bs - (n_prime * b * th_i) ** 2
            args[1 * m + q] = bs - (n * b * th_i) ** 2
            args[2 * m + q] = bs - (n_prime * b * th_j) ** 2
            args[3 * m + q] = bs - (n * b * th_j) ** 2
            sg[0, q] = (th_i > 0.0) - (th_i < 0.0)
            sg[1, q] = (th_j > 0.0) - (th_j < 0.0)


@njit(cache=True)
def _pair_accumulate(
    pi: IntArray,
    pj: IntArray,
    lo: int,
    hi: int,
    geo: FloatArray,
    ex: FloatArray,
    sg: FloatArray,
    out: FloatArray,
) -> None:
    """``exp(..)·t − sign(θ)·exp(..)·t⊥`` on ``i`` and, with ``t' = −t``, on ``j``.

    ``geo``: :func:`_pair_geometry`'s ``(6, ≥ m)`` rows (``t`` in rows 4, 5); ``ex``: the
    exponentials of :func:`_pair_exponents`' ``args`` (``(4, m)`` row-major); ``sg``: its
    signs; ``m = hi − lo`` pairs ``pi[lo:hi]``, ``pj[lo:hi]``; ``out`` ``(n, 2)``: added to.
    """
    m = hi - lo
    for p in range(lo, hi):
        q = p - lo
        i = pi[p]
        j = pj[p]
        t_x = geo[4, q]
        t_y = geo[5, q]
        fv = ex[q]
        fa = -sg[0, q] * ex[m + q]
        out[i, 0] += fv * t_x - fa * t_y
        out[i, 1] += fv * t_y + fa * t_x
        fv = ex[2 * m + q]
        fa = -sg[1, q] * ex[3 * m + q]
        out[j, 0] -= fv * t_x - fa * t_y
        out[j, 1] -= fv * t_y + fa * t_x


@njit(cache=True)
def _robots(
    pos: FloatArray,
    vel: FloatArray,
    active: NDArray[np.bool_],
    rpos: FloatArray,
    rvel: FloatArray,
    cutoff: float,
    lam: float,
    gamma: float,
    n: float,
    n_prime: float,
    wrap: bool,
    out: FloatArray,
) -> None:
    """Add the social interaction of every robot within ``cutoff`` on each active agent.

    The pedestrian formula written out directly (few robots, so no pair pipeline).
    """
    c2 = cutoff * cutoff
    for i in range(pos.shape[0]):
        if not active[i]:
            continue
        for r in range(rpos.shape[0]):
            dx = pos[i, 0] - rpos[r, 0]
            dy = pos[i, 1] - rpos[r, 1]
            d2 = dx * dx + dy * dy
            if d2 >= c2:
                continue
            d = math.sqrt(d2)
            ex = dx / d if d > 0.0 else 0.0
            ey = dy / d if d > 0.0 else 0.0
            ix = lam * (rvel[r, 0] - vel[i, 0]) + ex
            iy = lam * (rvel[r, 1] - vel[i, 1]) + ey
            length = math.sqrt(ix * ix + iy * iy)
            if length == 0.0:
                continue
            t_x = ix / length
            t_y = iy / length
            theta = math.atan2(t_y, t_x) - math.atan2(ey, ex)
            if wrap:
                theta = theta - _TWO_PI if theta > math.pi else theta
                theta = theta + _TWO_PI if theta <= -math.pi else theta
            b = gamma * length
            fv = math.exp(-d / b - (n_prime * b * theta) ** 2)
            fa = -((theta > 0.0) - (theta < 0.0)) * math.exp(-d / b - (n * b * theta) ** 2)
            out[i, 0] += fv * t_x - fa * t_y
            out[i, 1] += fv * t_y + fa * t_x


@njit(cache=True)
def _obstacle(
    pos: FloatArray,
    radii: FloatArray,
    active: NDArray[np.bool_],
    xy: FloatArray,
    cell_blocks: IntArray,
    block_lo: IntArray,
    bbox: FloatArray,
    cell_box: FloatArray,
    gx0: float,
    gy0: float,
    cell: float,
    nx: int,
    ny: int,
    reach: float,
    threshold: float,
    sigma: float,
    work: FloatArray,
    out: FloatArray,
) -> None:
    """PySocialForce's ``ObstacleForce`` (before its factor), scanning the point grid directly.

    The points are a :class:`CellList`'s in its cell order, cut into blocks by
    :func:`_point_blocks` (see :class:`_ObstacleIndex`). A cell or block whose bounding box is
    beyond the prefilter is skipped whole: its points would all fail it (rounded differences
    and squares are monotone), so the sums, in the same order, are the same to the bit. The
    blocks left, merged into runs of consecutive points, go to :func:`_obstacle_terms`
    (vectorised) and :func:`_obstacle_sum` (the exponentials, summed in scan order).

    Args:
        pos: ``(n, 2)`` positions (m).
        radii: ``(n,)`` agent radii ``R`` (m).
        active: ``(n,)`` agents that get the force.
        xy: ``(2, p)`` the points in cell order (m).
        cell_blocks: ``(cells + 1,)`` block ranges of the cells.
        block_lo: ``(b + 1,)`` point ranges of the blocks.
        bbox: ``(b, 4)`` block bounding boxes (m).
        cell_box: ``(cells, 4)`` cell bounding boxes (m).
        gx0: grid origin x (m).
        gy0: grid origin y (m).
        cell: grid cell size (m).
        nx: cells along x.
        ny: cells along y.
        reach: search radius (m), a hair over ``threshold + 2·max(radii)``.
        threshold: PySocialForce's ``threshold`` (m); points count while
            ``|r − o| − R < threshold + R``.
        sigma: decay length σ (m).
        work: ``(4, ≥ p)`` scratch.
        out: ``(n, 2)`` the sums are added here.
    """
    rings = max(1, math.ceil(reach / cell))
    runs = np.empty((2, block_lo.shape[0]), dtype=np.int64)
    for i in range(pos.shape[0]):
        if not active[i]:
            continue
        x, y = pos[i, 0], pos[i, 1]
        r = radii[i]
        thr = threshold + r
        # Cheap squared-distance prefilter, a hair wider than the exact test below.
        far2 = (thr + r) * (thr + r) * (1.0 + 1e-9)
        cx = int((x - gx0) // cell)
        cy = int((y - gy0) // cell)
        nruns = 0
        for gy in range(max(cy - rings, 0), min(cy + rings, ny - 1) + 1):
            for gx in range(max(cx - rings, 0), min(cx + rings, nx - 1) + 1):
                c = gy * nx + gx
                if _box_gap2(cell_box, c, x, y) >= far2:  # the window's far cells, mostly
                    continue
                for blk in range(cell_blocks[c], cell_blocks[c + 1]):
                    if _box_gap2(bbox, blk, x, y) >= far2:
                        continue
                    if nruns > 0 and runs[1, nruns - 1] == block_lo[blk]:
                        runs[1, nruns - 1] = block_lo[blk + 1]  # extends the last run
                    else:
                        runs[0, nruns] = block_lo[blk]
                        runs[1, nruns] = block_lo[blk + 1]
                        nruns += 1
        m = _obstacle_terms(xy, runs, nruns, x, y, r, thr, far2, sigma, work)
        fx, fy = _obstacle_sum(work, m)
        out[i, 0] += fx
        out[i, 1] += fy


@njit(cache=True, error_model="numpy")
def _obstacle_terms(
    xy: FloatArray,
    runs: IntArray,
    nruns: int,
    x: float,
    y: float,
    r: float,
    thr: float,
    far2: float,
    sigma: float,
    work: FloatArray,
) -> int:
    """Unit vectors, exponents and inclusion of the points in ``runs`` seen from ``(x, y)``.

    Writes, per point of the runs ``xy[:, runs[0, k]:runs[1, k]]`` in order, ``(x − o)/|x − o|``
    to ``work`` rows 0-1, ``−(|x − o| − r)/σ`` to row 2 and 1.0 to row 3 where the point
    counts (PySocialForce's ``|x − o| − r < thr``, behind the ``|x − o|² < far2`` prefilter
    and ``|x − o| > 0``), else 0.0. NumPy's error model: the divisions run unguarded (``x/0``
    gives inf or NaN, not an exception) so that the loop vectorises (IEEE sqrt and division
    give the scalar bits); the points they hit are the excluded ones. Returns the count.
    """
    k = 0
    for q in range(nruns):
        lo = runs[0, q]
        c = runs[1, q] - lo
        # Slices indexed from 0: numba then knows the indices are not negative and drops
        # its wraparound selects, which would keep LLVM from vectorising.
        px, py = xy[0, lo : lo + c], xy[1, lo : lo + c]
        ux, uy = work[0, k : k + c], work[1, k : k + c]
        arg, keep = work[2, k : k + c], work[3, k : k + c]
        for j in range(c):
            dx = x - px[j]
            dy = y - py[j]
            d2 = dx * dx + dy * dy
            dist = math.sqrt(d2)
            gap = dist - r
            ux[j] = dx / dist
            uy[j] = dy / dist
            arg[j] = -gap / sigma
            keep[j] = (d2 < far2) & (gap < thr) & (dist > 0.0)
        k += c
    return k


@njit(cache=True)
def _obstacle_sum(work: FloatArray, m: int) -> tuple[float, float]:
    """``Σ u · exp(arg)`` over the first ``m`` entries of :func:`_obstacle_terms`, in order."""
    ux, uy, arg, keep = work[0], work[1], work[2], work[3]
    fx = 0.0
    fy = 0.0
    for k in range(m):
        if keep[k] != 0.0:  # mostly: only the blocks' corners fall outside
            w = math.exp(arg[k])
            fx += ux[k] * w
            fy += uy[k] * w
    return fx, fy


@njit(cache=True)
def _terms(
    pos: FloatArray,
    vel: FloatArray,
    dest: FloatArray,
    vmax: FloatArray,
    vmax_factor: FloatArray,
    active: NDArray[np.bool_],
    rpos: FloatArray,
    rvel: FloatArray,
    radii: FloatArray,
    xy: FloatArray,
    cell_blocks: IntArray,
    block_lo: IntArray,
    bbox: FloatArray,
    cell_box: FloatArray,
    grid: FloatArray,
    shape: IntArray,
    work: FloatArray,
    order: IntArray,
    starts: IntArray,
    coef: FloatArray,
    wrap: bool,
    coherence_uses_distance: bool,
    forces: FloatArray,
    acc: FloatArray,
) -> None:
    """Every term but the social one's pair sums, the factors, and the total, in one call.

    The arithmetic is NumPy's, element by element and in the same order (each term summed
    unscaled, then multiplied by its factor; inactive agents zeroed, then ``force_scale``,
    then the terms added to zero in :data:`TERMS` order), so the bits are those of one NumPy
    call per step of the computation.

    Args:
        pos: ``(n, 2)`` positions (m).
        vel: ``(n, 2)`` velocities (m/s).
        dest: ``(n, 2)`` destinations (m).
        vmax: ``(n,)`` preferred speeds (m/s).
        vmax_factor: ``(n,)`` their factors.
        active: ``(n,)`` agents that get forces.
        rpos: ``(r, 2)`` robot positions (m).
        rvel: ``(r, 2)`` robot world-frame velocities (m/s).
        radii: ``(n ≥ 1,)`` agent radii in the obstacle term (m); their maximum sets the
            obstacle search radius.
        xy: :attr:`_ObstacleIndex.xy` (no columns: no obstacles).
        cell_blocks: :attr:`_ObstacleIndex.cell_blocks`.
        block_lo: :attr:`_ObstacleIndex.block_lo`.
        bbox: :attr:`_ObstacleIndex.bbox`.
        cell_box: :attr:`_ObstacleIndex.cell_box`.
        grid: :attr:`_ObstacleIndex.grid`.
        shape: :attr:`_ObstacleIndex.shape`.
        work: :attr:`_ObstacleIndex.work`.
        order: :func:`group_members`' order.
        starts: its starts (length 1: no groups).
        coef: ``(len(_COEF),)`` the parameters.
        wrap: wrap the social angle (robots here; pedestrians in the pair pipeline).
        coherence_uses_distance: pedsim's softened coherence.
        forces: ``(7, n, 2)`` zeros, plus the unscaled social sums in row ``social``; out: the
            scaled terms (m/s²).
        acc: ``(n, 2)`` out: the accelerations (m/s²).
    """
    d_, s_, o_, gc_, gr_, gg_, r_ = 0, 1, 2, 3, 4, 5, 6  # rows, in TERMS order
    _desired(pos, vel, dest, vmax, vmax_factor, coef[_C_TAU], coef[_C_GOAL], forces[d_])
    _scale(forces[d_], coef[_C_DESIRED])
    _scale(forces[s_], coef[_C_SOCIAL])
    if rpos.shape[0] > 0 and coef[_C_ROBOT] > 0.0:
        _robots(
            pos,
            vel,
            active,
            rpos,
            rvel,
            coef[_C_CUTOFF],
            coef[_C_LAMBDA],
            coef[_C_GAMMA],
            coef[_C_N],
            coef[_C_N_PRIME],
            wrap,
            forces[r_],
        )
        _scale(forces[r_], coef[_C_ROBOT_SCALE])
    if xy.shape[1] > 0:
        # Slightly wider than the reach: _obstacle applies PySocialForce's exact test.
        reach = coef[_C_OB_THRESHOLD] + 2.0 * _nan_max(radii) + 1e-9
        _obstacle(
            pos,
            radii,
            active,
            xy,
            cell_blocks,
            block_lo,
            bbox,
            cell_box,
            grid[0],
            grid[1],
            grid[2],
            shape[0],
            shape[1],
            reach,
            coef[_C_OB_THRESHOLD],
            coef[_C_OB_SIGMA],
            work,
            forces[o_],
        )
        _scale(forces[o_], coef[_C_OBSTACLE])
    if starts.shape[0] > 1:
        _groups(
            pos,
            dest,
            active,
            order,
            starts,
            coef[_C_REP_THRESHOLD],
            coherence_uses_distance,
            forces[gc_],
            forces[gr_],
            forces[gg_],
        )
        _scale(forces[gc_], coef[_C_COHERENCE])
        _scale(forces[gr_], coef[_C_REPULSION])
        _scale(forces[gg_], coef[_C_GAZE])
    scale = coef[_C_SCALE]
    for i in range(pos.shape[0]):
        ax = 0.0
        ay = 0.0
        for k in range(forces.shape[0]):
            if not active[i]:
                forces[k, i, 0] = 0.0
                forces[k, i, 1] = 0.0
            if scale != 1.0:
                forces[k, i, 0] *= scale
                forces[k, i, 1] *= scale
            ax += forces[k, i, 0]
            ay += forces[k, i, 1]
        acc[i, 0] = ax
        acc[i, 1] = ay


@njit(cache=True)
def _nan_max(x: FloatArray) -> float:
    """``x.max()`` of ``(n ≥ 1,)`` values: NumPy's, a NaN anywhere is the maximum."""
    top = x[0]
    for v in x:
        if v != v:
            return v
        top = max(top, v)
    return top


@njit(cache=True, inline="always")
def _scale(f: FloatArray, factor: float) -> None:
    """``f *= factor`` for an ``(n, 2)`` term."""
    for i in range(f.shape[0]):
        f[i, 0] *= factor
        f[i, 1] *= factor


@njit(cache=True)
def _desired(
    pos: FloatArray,
    vel: FloatArray,
    dest: FloatArray,
    vmax: FloatArray,
    vmax_factor: FloatArray,
    relaxation_time: float,
    goal_threshold: float,
    out: FloatArray,
) -> None:
    """:func:`desired_force` with speed ``vmax · vmax_factor`` into ``out``, the same bits.

    ``hypot`` is libm's in both, and each element sees the same operations in the same order.
    """
    for i in range(pos.shape[0]):
        dx = dest[i, 0] - pos[i, 0]
        dy = dest[i, 1] - pos[i, 1]
        dist = math.hypot(dx, dy)
        if dist > goal_threshold:  # False for NaN, as np.where's test
            speed = vmax[i] * vmax_factor[i]
            ux = dx / dist if dist > 0.0 else 0.0
            uy = dy / dist if dist > 0.0 else 0.0
            out[i, 0] = (ux * speed - vel[i, 0]) / relaxation_time
            out[i, 1] = (uy * speed - vel[i, 1]) / relaxation_time
        else:
            out[i, 0] = -vel[i, 0] / relaxation_time
            out[i, 1] = -vel[i, 1] / relaxation_time


@njit(cache=True)
def _same_ints(a: IntArray, b: IntArray) -> bool:
    """``np.array_equal`` for two 1-d integer arrays, without NumPy's call overhead."""
    if a.shape[0] != b.shape[0]:
        return False
    for i in range(a.shape[0]):  # noqa: SIM110 (numba: a loop, not all() of a generator)
        if a[i] != b[i]:
            return False
    return True


@njit(cache=True, inline="always")
def _box_gap2(box: FloatArray, k: int, x: float, y: float) -> float:
    """Squared distance (m²) from ``(x, y)`` to box ``k`` of ``box`` ``(·, 4)``, 0 inside.

    A lower bound of every contained point's ``dx² + dy²`` as rounded (rounding is monotone),
    so ``≥ far2`` rules out the whole box without changing any sum.
    """
    bx: float = max(box[k, 0] - x, x - box[k, 1], 0.0)
    by: float = max(box[k, 2] - y, y - box[k, 3], 0.0)
    return bx * bx + by * by


@njit(cache=True)
def _cell_boxes(bbox: FloatArray, cell_blocks: IntArray) -> FloatArray:
    """``(cells, 4)`` bounding boxes of each cell's blocks ``bbox`` ``(b, 4)`` (m)."""
    cells = cell_blocks.shape[0] - 1
    out = np.empty((cells, 4))
    for c in range(cells):
        out[c, 0] = out[c, 2] = math.inf
        out[c, 1] = out[c, 3] = -math.inf
        for blk in range(cell_blocks[c], cell_blocks[c + 1]):
            out[c, 0] = min(out[c, 0], bbox[blk, 0])
            out[c, 1] = max(out[c, 1], bbox[blk, 1])
            out[c, 2] = min(out[c, 2], bbox[blk, 2])
            out[c, 3] = max(out[c, 3], bbox[blk, 3])
    return out


@njit(cache=True)
def _point_blocks(
    points: FloatArray, order: IntArray, starts: IntArray
) -> tuple[IntArray, IntArray, FloatArray]:
    """Cut each cell's points into runs of ``_BLOCK`` (in cell order) with bounding boxes.

    Wall samples are ordered along their segments, so a run is a short piece of wall with a
    tight box, and most of a cell's runs lie beyond an agent's reach.

    Returns:
        ``(cell_blocks, block_lo, bbox)``: the blocks of cell ``c`` are
        ``cell_blocks[c]:cell_blocks[c + 1]``, block ``b`` holds
        ``order[block_lo[b]:block_lo[b + 1]]``, ``bbox[b]`` is ``(x_min, x_max, y_min, y_max)``
        (m).
    """
    cells = starts.shape[0] - 1
    cell_blocks = np.zeros(cells + 1, dtype=np.int64)
    for c in range(cells):
        cell_blocks[c + 1] = cell_blocks[c] + (starts[c + 1] - starts[c] + _BLOCK - 1) // _BLOCK
    nb = cell_blocks[cells]
    block_lo = np.empty(nb + 1, dtype=np.int64)
    bbox = np.empty((nb, 4))
    block_lo[nb] = starts[cells]
    for c in range(cells):
        for k in range(cell_blocks[c + 1] - cell_blocks[c]):
            blk = cell_blocks[c] + k
            lo = starts[c] + k * _BLOCK
            hi = min(lo + _BLOCK, starts[c + 1])
            block_lo[blk] = lo
            bbox[blk, 0] = bbox[blk, 2] = math.inf
            bbox[blk, 1] = bbox[blk, 3] = -math.inf
            for s in range(lo, hi):
                px = points[order[s], 0]
                py = points[order[s], 1]
                bbox[blk, 0] = min(bbox[blk, 0], px)
                bbox[blk, 1] = max(bbox[blk, 1], px)
                bbox[blk, 2] = min(bbox[blk, 2], py)
                bbox[blk, 3] = max(bbox[blk, 3], py)
    return cell_blocks, block_lo, bbox


@njit(cache=True)
def _groups(
    pos: FloatArray,
    dest: FloatArray,
    active: NDArray[np.bool_],
    order: IntArray,
    starts: IntArray,
    rep_threshold: float,
    coherence_uses_distance: bool,
    coherence: FloatArray,
    repulsion: FloatArray,
    gaze: FloatArray,
) -> None:
    """The three group terms (before their factors), group by group."""
    for g in range(starts.shape[0] - 1):
        lo = starts[g]
        hi = starts[g + 1]
        k = hi - lo
        sx = 0.0
        sy = 0.0
        for a in range(lo, hi):
            sx += pos[order[a], 0]
            sy += pos[order[a], 1]
        cx = sx / k
        cy = sy / k
        half = (k - 1) / 2.0
        for a in range(lo, hi):
            i = order[a]
            if not active[i]:
                continue
            px, py = pos[i, 0], pos[i, 1]
            # Coherence: towards the centre of mass, softened around (k − 1)/2 m (upstream's
            # distance is always 0, see the module docstring).
            wx = cx - px
            wy = cy - py
            delta = math.sqrt(wx * wx + wy * wy) if coherence_uses_distance else 0.0
            soft = (math.tanh(delta - half) + 1.0) / 2.0
            coherence[i, 0] += wx * soft
            coherence[i, 1] += wy * soft
            # Repulsion: linear push from members within the threshold; gaze: others' centre.
            ox = 0.0
            oy = 0.0
            for b in range(lo, hi):
                j = order[b]
                if j == i:
                    continue
                dx = px - pos[j, 0]
                dy = py - pos[j, 1]
                if math.sqrt(dx * dx + dy * dy) <= rep_threshold:
                    repulsion[i, 0] += dx
                    repulsion[i, 1] += dy
                ox += pos[j, 0]
                oy += pos[j, 1]
            if k < 2:
                continue
            rx = ox / (k - 1) - px
            ry = oy / (k - 1) - py
            com_dist = math.sqrt(rx * rx + ry * ry)
            gx = dest[i, 0] - px
            gy = dest[i, 1] - py
            goal_dist = math.sqrt(gx * gx + gy * gy)
            if com_dist == 0.0 or goal_dist == 0.0:
                continue  # upstream: 0 or NaN (zeroed by Arena)
            ux = gx / goal_dist
            uy = gy / goal_dist
            cos = ux * rx / com_dist + uy * ry / com_dist
            scale = com_dist * cos / goal_dist
            gaze[i, 0] += scale * ux
            gaze[i, 1] += scale * uy
