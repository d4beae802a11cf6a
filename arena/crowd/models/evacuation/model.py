r"""Escape panic: Helbing, Farkas & Vicsek's social force model with body contact and friction.

Helbing, D., Farkas, I. & Vicsek, T. (2000) "Simulating dynamical features of escape panic",
*Nature* 407, 487–490. Each pedestrian ``i`` (mass ``m``, radius ``r_i``) obeys

.. math::

    m \frac{d\mathbf v_i}{dt} = m\frac{v_i^0 \mathbf e_i - \mathbf v_i}{\tau}
      + \sum_{j \ne i} \mathbf f_{ij} + \sum_W \mathbf f_{iW},

    \mathbf f_{ij} = \big[A e^{(r_{ij} - d_{ij})/B} + k\,g(r_{ij} - d_{ij})\big]\,\mathbf n_{ij}
      + \kappa\, g(r_{ij} - d_{ij})\, \Delta v^t_{ji}\, \mathbf t_{ij},

    \mathbf f_{iW} = \big[A e^{(r_i - d_{iW})/B} + k\,g(r_i - d_{iW})\big]\,\mathbf n_{iW}
      - \kappa\, g(r_i - d_{iW})\, (\mathbf v_i \cdot \mathbf t_{iW})\, \mathbf t_{iW},

with ``r_ij = r_i + r_j``, ``d_ij`` the centre distance, ``n_ij = (x_i − x_j)/d_ij`` (from ``j``
to ``i``), ``t_ij = (−n_2, n_1)``, ``Δv^t_ji = (v_j − v_i)·t_ij``, ``g(x) = max(x, 0)`` (the
body force and sliding friction act only on contact), and for walls ``d_iW`` the distance to the
closest wall point, ``n_iW`` pointing from that point to the agent.

Terms reported in :attr:`~arena.crowd.base.ModelOutput.forces` (accelerations, m/s², summing to
the returned acceleration): ``desired``, ``social`` (the exponential term between pedestrians),
``body`` (``k·g``), ``friction`` (``κ·g·Δv``), ``obstacle`` (all wall terms), ``robot`` (all
terms from robots, which are treated as extra bodies with their radius and velocity when
``robots_as_bodies``), ``speed_cap`` (velocity removed by the speed cap inside the sub-steps)
and ``carry`` (see below). With sub-steps each term is its time-weighted share of the step.

Desired velocity: toward the frame's destination at ``state.vmax · state.vmax_factor`` (the
simulator's speed cap), so panic is expressed by the social states raising ``vmax_factor``.
The paper's desired speeds are 0.6 m/s (relaxed) up to 5 m/s (panic).

**Stiffness and sub-stepping.** The contact terms are stiff: a pair in contact oscillates at
``ω = sqrt(2k/m) ≈ 55 rad/s`` (more with several contacts and with the exponential term, whose
stiffness ``A/B·e^{overlap/B}`` is 25 000 N/m at touching), and sliding friction damps relative
tangential motion at ``2κ·overlap/m ≈ 300 1/s`` for a 5 cm overlap. Explicit (semi-implicit
Euler) integration is stable only for ``h·ω < 2`` and ``h·rate < 2``: a few milliseconds in
contact, far below the platform's usual ``dt = 0.1 s``. So :meth:`Evacuation.compute`
integrates the crowd itself with the simulator's scheme (``v += a·h``, speed cap, ``x += v·h``;
robots move on straight lines at their current velocity; inactive agents stay put; neighbour
and wall lists fixed over the step) in
``n = ceil(dt/h)`` sub-steps, ``h = min(max_substep, 1/ω, 1/rate)`` with ``ω`` and ``rate``
Gershgorin bounds over the current contacts (:func:`substeps`; a factor 2 of margin for contacts
that deepen during the step). Default ``max_substep = 0.005 s``: 20 sub-steps at 0.1 s without
deep contact, more while bodies overlap strongly (at most ``max_substeps = 400``, reached only
for agents placed almost on top of each other).

The simulator then integrates once, ``v += a·dt``, ``x += v·dt``, so it can reproduce either the
sub-stepped end position or the end velocity, not both. Positions matter more (an overlap the
sub-steps resolve must be resolved: returning the end velocity left overlapping agents stuck
in our crowd tests), so the model returns the acceleration that makes the simulator's velocity
the *mean* sub-stepped velocity ``(x_end − x_0)/dt``: the simulator lands exactly on the
sub-stepped positions (up to rounding). The true end velocity is remembered
(:class:`SubstepMemory`) and the next step starts from it for every agent whose state the
simulator left untouched; the ``carry`` term is that difference. So the crowd follows the
finely integrated trajectory, and the velocity the platform reports is the displacement per
step. If ``dt ≤ h`` there is one sub-step and the output is the plain force at the state.
The simulator also caps ``|v| ≤ vmax·vmax_factor`` (the force is enormous at contact, tens of
thousands of newtons, and would otherwise launch agents); the same cap acts inside the
sub-steps, and the mean of capped velocities never exceeds the cap, so the simulator's cap
does not change the result.

**Differences from Arena's plugin.** Arena's ``evacuation`` force model (crowdsim, after the
ETH student project `fschur/Evacuation-Bottleneck`_) uses the same ``A, B, k, κ`` but: mass
180 kg (we use the paper's 80 kg), relaxation time 1 s (named "time-step" there; the paper has
0.5 s), radii fixed at 0.3 m (we use each agent's radius), desired speed fixed at 1.5 m/s
(we use ``vmax·vmax_factor``), every agent heading to one "door" of an assumed 40 m room
(we use each agent's destination), velocities reset to zero on every call (we use the real
ones), and one leap-frog step of 1 s whose first force evaluation is returned (we sub-step).
Set ``mass=180, tau=1.0`` to get Arena's force scale.

**Walls.** The static world comes as line segments (:func:`~arena.crowd.walls.world_segments`,
merged maximal runs); each distinct segment within ``interaction_range`` contributes one term
computed at its closest point, as the paper sums over walls. A one-cell-thick wall has two
parallel segments ``resolution`` apart; the far one adds ``exp(−resolution/B)`` (≈ 0.5 at
0.05 m) of the near one's psychological term. Corners get a term from each segment.

.. _fschur/Evacuation-Bottleneck: https://github.com/fschur/Evacuation-Bottleneck
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, ClassVar, Literal

import numpy as np
from numpy.typing import NDArray

from arena.crowd.base import CROWD_MODELS, CrowdFrame, ModelOutput
from arena.crowd.models.evacuation.kernels import _distinct_owners, _helbing_substeps, _stiffness
from arena.crowd.models.evacuation.params import EvacuationParams
from arena.crowd.walls import WallIndex, world_segments

if TYPE_CHECKING:
    from arena.crowd.state import CrowdState
    from arena.scene.state import StaticWorld

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


#: Names of the rows of the kernel's term accumulator, in order.
TERMS: tuple[str, ...] = (
    "desired",
    "social",
    "body",
    "friction",
    "obstacle",
    "robot",
    "bonding",
    "speed_cap",
    "carry",
)


class SubstepMemory:
    """Lets a sub-stepping model hand the simulator exact positions and keep exact velocities.

    The simulator integrates ``v += a·dt``, ``x += v·dt`` once per step, so a model that
    sub-steps internally can make it reproduce only one of the sub-stepped end position and end
    velocity. Positions matter most (an overlap that the sub-steps resolve must be resolved), so
    the model returns the acceleration that makes the simulator's velocity the *mean* velocity
    ``(x_end − x_0)/dt`` of its sub-steps, and remembers the true end velocity here. Next step,
    for every agent whose position and velocity are still exactly what the simulator was told
    (no wall guard, social state or reset intervened), sub-stepping resumes from the remembered
    true velocity; otherwise from the frame's. The difference appears as the ``carry`` term.
    """

    def __init__(self, tol: float = 1e-9) -> None:
        self.tol = tol  # m and m/s: float rounding of the simulator's update is ~1e-15
        self.clear()

    def clear(self) -> None:
        """Forget everything (new episode)."""
        self._last: tuple[FloatArray, FloatArray, FloatArray] | None = None

    def start(self, pos: FloatArray, vel: FloatArray) -> FloatArray:
        """Velocities ``(n, 2)`` to start sub-stepping from (m/s), given the frame's state."""
        v = np.array(vel, dtype=np.float64)
        if self._last is None or self._last[0].shape != pos.shape:
            return v
        last_pos, told, true = self._last
        same = np.all(np.abs(pos - last_pos) <= self.tol, axis=1) & np.all(
            np.abs(vel - told) <= self.tol, axis=1
        )
        v[same] = true[same]
        return v

    def remember(self, pos: FloatArray, told: FloatArray, true: FloatArray) -> None:
        """Store the positions and velocities the simulator will hold, and the true velocities."""
        self._last = (pos.copy(), told.copy(), true.copy())


class SegmentWalls:
    """Wall segments and a cell-list index, answering "which whole segments are near".

    :class:`~arena.crowd.walls.WallIndex` splits segments into pieces of at most ``piece``
    metres for its grid; force models that sum one term per wall (Helbing's ``Σ_W``) need the
    distinct original segments instead, so this maps the pieces back to their owners.

    Args:
        a: ``(s, 2)`` segment starts (m).
        b: ``(s, 2)`` segment ends (m).
    """

    def __init__(self, a: FloatArray, b: FloatArray) -> None:
        self.a = np.ascontiguousarray(a, dtype=np.float64).reshape(-1, 2)
        self.b = np.ascontiguousarray(b, dtype=np.float64).reshape(-1, 2)
        self.index = WallIndex(self.a, self.b)

    def __len__(self) -> int:
        return int(self.a.shape[0])

    def matches(self, a: FloatArray, b: FloatArray) -> bool:
        """Whether ``(a, b)`` are the segments this index was built from."""
        return (
            a.shape == self.a.shape
            and b.shape == self.b.shape
            and bool(np.array_equal(a, self.a))
            and bool(np.array_equal(b, self.b))
        )

    def near(self, points: FloatArray, radius: float) -> tuple[IntArray, IntArray]:
        """Distinct segments with a point strictly within ``radius`` of each query.

        Args:
            points: ``(q, 2)`` query points (m).
            radius: m.

        Returns:
            ``(indptr, indices)``: CSR lists of segment indices, ``(q + 1,)`` and ``(m,)``.
        """
        q = np.asarray(points).reshape(-1, 2).shape[0]
        if len(self) == 0 or q == 0:
            return np.zeros(q + 1, dtype=np.int64), np.zeros(0, dtype=np.int64)
        pieces = self.index.query(points, radius)
        return _distinct_owners(pieces.indptr, pieces.indices, self.index.owner, len(self))


@CROWD_MODELS.register("evacuation", tags=("panic",))
class Evacuation:
    """Helbing–Farkas–Vicsek escape-panic model: social, body and friction forces, sub-stepped.

    See the module docstring for the equations, the sub-stepping and how it differs from
    Arena's plugin.
    """

    output: ClassVar[Literal["acceleration", "velocity"]] = "acceleration"

    Params = EvacuationParams

    def __init__(self, params: EvacuationParams | None = None) -> None:
        self.params = params or self.Params()
        self.last_substeps = 0  # sub-steps used by the last compute() (for diagnostics)
        self._memory = SubstepMemory()
        self._walls: SegmentWalls | None = None
        self._wall_src: tuple[FloatArray, FloatArray] | None = None

    # -- CrowdModel -----------------------------------------------------------------------------
    def neighbor_cutoff(self) -> float:
        """Pedestrians farther apart than ``interaction_range`` (m) do not interact."""
        return self.params.interaction_range

    def reset(self, state: CrowdState, world: StaticWorld, rng: np.random.Generator) -> None:
        """Index the world's wall and obstacle segments for the episode."""
        a, b = world_segments(world)
        self._walls = SegmentWalls(a, b)
        self._wall_src = None
        self._memory.clear()

    def compute(self, frame: CrowdFrame) -> ModelOutput:
        """Accelerations that move each agent to its sub-stepped end position; zero if inactive.

        See :class:`SubstepMemory` for how the velocity is carried between steps.
        """
        s = frame.state
        n = len(s)
        terms = np.zeros((len(TERMS), n, 2))
        if n == 0:
            return self._output(np.zeros((0, 2)), terms)
        p = self.params
        dt = float(frame.dt)
        cap = np.ascontiguousarray(s.vmax * s.vmax_factor, dtype=np.float64)
        walls = self._segment_walls(frame)
        # Agents move at most cap·dt during the step: widen the wall search by that much.
        reach = p.interaction_range + float(cap.max(initial=0.0)) * dt
        w_ptr, w_idx = walls.near(s.positions, reach)
        robots = frame.robots
        use_robots = p.robots_as_bodies and len(robots) > 0
        b_ptr, b_idx = self._bond_pairs(frame)
        pos = np.ascontiguousarray(s.positions, dtype=np.float64)
        radii = np.ascontiguousarray(s.radii, dtype=np.float64)
        active = np.ascontiguousarray(frame.active, dtype=np.bool_)
        r_pos = np.ascontiguousarray(robots.positions if use_robots else np.zeros((0, 2)))
        r_vel = np.ascontiguousarray(robots.velocities if use_robots else np.zeros((0, 2)))
        r_rad = np.ascontiguousarray(robots.radii if use_robots else np.zeros(0))
        nb = frame.neighbors
        omega, rate = _stiffness(
            pos, radii, active, p.mass, p.social_strength, p.social_range, p.body_stiffness,
            p.friction, nb.indptr, nb.indices, w_ptr, w_idx, walls.a, walls.b, r_pos, r_rad,
        )  # fmt: skip
        self.last_substeps = n_sub = substeps(dt, p.max_substep, p.max_substeps, omega, rate)
        vel = np.ascontiguousarray(s.velocities, dtype=np.float64)
        v_start = self._memory.start(pos, vel)
        v_start[~active] = vel[~active]
        _, v_end = _helbing_substeps(
            pos, v_start, radii, cap,
            np.ascontiguousarray(frame.destinations, dtype=np.float64), active,
            1.0 / p.mass, p.tau, p.social_strength, p.social_range, p.body_stiffness, p.friction,
            nb.indptr, nb.indices, w_ptr, w_idx, walls.a, walls.b,
            r_pos, r_vel, r_rad, p.interaction_range,
            b_ptr, b_idx, *self._bond_params(),
            dt, n_sub, terms,
        )  # fmt: skip
        terms[-1] = v_start - vel
        terms /= dt  # velocity changes → accelerations
        terms[:, ~active] = 0.0
        acc = terms.sum(axis=0)
        told = vel + acc * dt  # the mean sub-stepped velocity, as the simulator will compute it
        self._memory.remember(pos + told * dt, told, v_end)
        return self._output(acc, terms)

    # -- hooks for variants (bonding) -----------------------------------------------------------
    def _bond_pairs(self, frame: CrowdFrame) -> tuple[IntArray, IntArray]:
        """CSR lists of each agent's bonded partners; none in the plain model."""
        n = len(frame.state)
        return np.zeros(n + 1, dtype=np.int64), np.zeros(0, dtype=np.int64)

    def _bond_params(self) -> tuple[float, float, float]:
        """``(strength N, range m, comfort gap m)`` of the bonding term; zero strength here."""
        return 0.0, 1.0, 0.0

    def _term_names(self) -> tuple[str, ...]:
        return tuple(t for t in TERMS if t != "bonding")

    # -- helpers --------------------------------------------------------------------------------
    def _segment_walls(self, frame: CrowdFrame) -> SegmentWalls:
        """The reset() index, rebuilt only if the frame carries different segments."""
        src = self._wall_src
        if (
            self._walls is not None
            and src is not None
            and src[0] is frame.walls_a
            and src[1] is frame.walls_b
        ):
            return self._walls
        if self._walls is None or not self._walls.matches(frame.walls_a, frame.walls_b):
            self._walls = SegmentWalls(frame.walls_a, frame.walls_b)
        self._wall_src = (frame.walls_a, frame.walls_b)
        return self._walls

    def _output(self, acc: FloatArray, terms: FloatArray) -> ModelOutput:
        names = self._term_names()
        forces = {name: terms[TERMS.index(name)].copy() for name in names}
        return ModelOutput(accelerations=acc, forces=forces)


def substeps(dt: float, max_substep: float, max_substeps: int, omega: float, rate: float) -> int:
    """Number of sub-steps for ``dt`` (s): ``h ≤ max_substep``, ``h·ω ≤ 1``, ``h·rate ≤ 1``.

    Explicit (semi-implicit Euler) integration is stable for ``h·ω < 2`` (springs, ``ω`` in
    rad/s) and ``h·rate < 2`` (damping, 1/s); the factor 2 margin covers overlaps that deepen
    during the step. At most ``max_substeps``.
    """
    h = max_substep
    if omega > 0.0:
        h = min(h, 1.0 / omega)
    if rate > 0.0:
        h = min(h, 1.0 / rate)
    return int(min(max(1, math.ceil(dt / h - 1e-9)), max_substeps))
