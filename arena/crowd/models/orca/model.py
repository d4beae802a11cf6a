"""ORCA: optimal reciprocal collision avoidance among pedestrians, computed as RVO2 does.

Each agent picks the velocity closest to its preferred velocity that lies outside every
neighbour's velocity obstacle truncated at ``time_horizon`` (van den Berg, Guy, Lin, Manocha,
"Reciprocal n-body collision avoidance", ISRR 2009). Each velocity obstacle becomes one ORCA
half-plane (each of two reciprocating agents takes half the avoidance); the 2-D linear program
over the half-planes inside the max-speed disk is solved incrementally (RVO2's
``linearProgram1/2``), and when it is infeasible the 3-D fallback (``linearProgram3``) finds the
velocity that violates the soft (agent) constraints least while keeping the hard (obstacle) ones.

This module re-implements RVO2's ``Agent::computeNeighbors``/``computeNewVelocity`` and its
obstacle processing (v2.0, Apache-2.0, https://gamma.cs.unc.edu/RVO2/) in numba, with the same
order of floating-point operations: run in float32 (the C++ library's ``float``), the kernel
reproduces the library step for step; the models run in float64 and differ from it by float32
rounding only (below a millimetre over 100 steps of the reference scenarios; a chaotic crowd
amplifies any difference eventually). What differs, and why:

* Neighbour search: the simulator's cell list lists every pedestrian closer than
  ``neighbor_dist``; the kernel keeps the ``max_neighbors`` nearest of them, nearest first, as
  RVO2's k-d tree query does. Exact distance ties are broken by agent index (RVO2: by k-d tree
  traversal order).
* Robots are non-reciprocating moving obstacles: an ORCA line with the robot's velocity and
  full responsibility (the robot does not make room), after the pedestrian lines, not counted
  in ``max_neighbors``. Inactive agents (not started or finished) stand still, so their
  neighbours take full responsibility for them too.
* Agent parameters are per model (``Params``), except the radius (``state.radii`` plus a
  ``safety_margin``) and the max speed (``state.vmax · state.vmax_factor``, the simulator's
  speed cap), which are per agent. The preferred velocity is RVO2's examples' (toward the
  destination at the max speed, slowing on the last metre), with their tiny random nudge.

Static obstacles (RVO2's obstacle ORCA lines) are in the same kernel; the ``orca`` model passes
none, :mod:`arena.crowd.models.rvo2` passes the world's walls.
"""

from __future__ import annotations

from typing import ClassVar, Literal

import numpy as np
from numpy.typing import NDArray

from arena.crowd.base import CROWD_MODELS, CrowdFrame, ModelOutput
from arena.crowd.models.orca.kernels import orca_kernel
from arena.crowd.models.orca.obstacles import Obstacles
from arena.crowd.models.orca.params import OrcaParams
from arena.crowd.state import CrowdState
from arena.scene.state import StaticWorld

FloatArray = NDArray[np.floating]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]


# ---------------------------------------------------------------------------------------------
# Preferred velocity
# ---------------------------------------------------------------------------------------------
def preferred_velocities(
    positions: FloatArray, destinations: FloatArray, speeds: FloatArray, arrival_time: float
) -> FloatArray:
    """Toward the destination at ``speeds``, slowing to arrive within ``arrival_time``.

    RVO2's examples (``Circle``, ``Blocks``) use the goal vector, normalised when longer than
    1 m, with unit preferred speed: that is ``speeds = 1``, ``arrival_time = 1``. In general the
    preferred velocity is ``d · min(speed / |d|, 1 / arrival_time)`` for ``d = destination − p``.

    Args:
        positions: ``(n, 2)`` m.
        destinations: ``(n, 2)`` m.
        speeds: ``(n,)`` preferred speed (m/s).
        arrival_time: s, the preferred velocity on the last ``speed · arrival_time`` metres.

    Returns:
        ``(n, 2)`` m/s.
    """
    d = np.asarray(destinations, dtype=np.float64) - positions
    dist = np.hypot(d[:, 0], d[:, 1])
    far = dist > speeds * arrival_time
    scale = np.where(far, speeds / np.where(far, dist, 1.0), 1.0 / arrival_time)
    return d * scale[:, None]


def orca_velocities(
    positions: FloatArray,
    velocities: FloatArray,
    radii: FloatArray,
    max_speeds: FloatArray,
    pref: FloatArray,
    active: BoolArray,
    neighbors: tuple[IntArray, IntArray],
    *,
    max_neighbors: int,
    neighbor_dist: float,
    time_horizon: float,
    time_horizon_obst: float,
    dt: float,
    robots: tuple[FloatArray, FloatArray, FloatArray] | None = None,
    obstacles: Obstacles | None = None,
    dtype: type = np.float64,
) -> FloatArray:
    """New ORCA velocities for every agent (arrays are cast to ``dtype``).

    Args:
        positions: ``(n, 2)`` m.
        velocities: ``(n, 2)`` current velocities (m/s).
        radii: ``(n,)`` m.
        max_speeds: ``(n,)`` m/s.
        pref: ``(n, 2)`` preferred velocities (m/s).
        active: ``(n,)`` bool; inactive agents get zero and are avoided with full share.
        neighbors: ``(indptr, indices)`` CSR candidate pedestrian neighbours.
        max_neighbors: pedestrians considered per agent (nearest first).
        neighbor_dist: m.
        time_horizon: s.
        time_horizon_obst: s.
        dt: s.
        robots: ``(positions (r, 2) m, velocities (r, 2) m/s, radii (r,) m)`` or ``None``.
        obstacles: static obstacles or ``None``.
        dtype: float type of the computation (float32 reproduces the C++ RVO2 library).

    Returns:
        ``(n, 2)`` m/s, ``dtype``.
    """
    t = np.dtype(dtype).type

    def arr(x: FloatArray, shape: tuple[int, ...]) -> FloatArray:
        return np.ascontiguousarray(x, dtype=dtype).reshape(shape)

    n = np.asarray(positions).shape[0]
    if robots is None:
        robots = (np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0))
    r = np.asarray(robots[0]).shape[0]
    ob = obstacles if obstacles is not None else Obstacles.empty(dtype)
    agents = (
        arr(positions, (n, 2)),
        arr(velocities, (n, 2)),
        arr(radii, (n,)),
        arr(max_speeds, (n,)),
        arr(pref, (n, 2)),
        np.ascontiguousarray(active, dtype=np.bool_),
    )
    nbrs = (
        np.ascontiguousarray(neighbors[0], dtype=np.int64),
        np.ascontiguousarray(neighbors[1], dtype=np.int64),
    )
    rob = (arr(robots[0], (r, 2)), arr(robots[1], (r, 2)), arr(robots[2], (r,)))
    horizons = (t(neighbor_dist), t(time_horizon), t(time_horizon_obst), t(dt))
    out: FloatArray = orca_kernel(
        agents, nbrs, rob, ob.kernel_args(dtype), horizons, int(max_neighbors)
    )
    return out


# ---------------------------------------------------------------------------------------------
# The model (parameters: :mod:`.params`)
# ---------------------------------------------------------------------------------------------
@CROWD_MODELS.register("orca", tags=("velocity_obstacle",))
class OrcaModel:
    """ORCA reciprocal collision avoidance among pedestrians (RVO2's algorithm, no obstacles)."""

    output: ClassVar[Literal["acceleration", "velocity"]] = "velocity"
    Params: ClassVar[type[OrcaParams]] = OrcaParams

    def __init__(self, params: OrcaParams | None = None) -> None:
        self.params = params or self.Params()

    def neighbor_cutoff(self) -> float:
        """``neighbor_dist`` (m)."""
        return float(self.params.neighbor_dist)

    def reset(self, state: CrowdState, world: StaticWorld, rng: np.random.Generator) -> None:
        """Nothing to prepare: ORCA keeps no state between steps."""

    def _obstacles(self, frame: CrowdFrame) -> Obstacles | None:
        return None

    def _time_horizon_obst(self) -> float:
        return 1.0  # unused without obstacles

    def compute(self, frame: CrowdFrame) -> ModelOutput:
        """New velocities (m/s): the ORCA optimum nearest each agent's preferred velocity."""
        p = self.params
        s = frame.state
        vmax = s.vmax * s.vmax_factor
        pref = preferred_velocities(
            s.positions, frame.destinations, vmax * p.pref_speed_factor, p.arrival_time
        )
        if p.pref_perturbation > 0:
            # As RVO2's Blocks example does: perfect symmetry can leave ORCA agents stalled.
            u = frame.rng.random((len(s), 2))
            angle, dist = 2.0 * np.pi * u[:, 0], p.pref_perturbation * u[:, 1]
            pref = pref + dist[:, None] * np.stack([np.cos(angle), np.sin(angle)], axis=1)
        rob = frame.robots
        v = orca_velocities(
            s.positions,
            s.velocities,
            s.radii + p.safety_margin,
            vmax,
            pref,
            frame.active,
            (frame.neighbors.indptr, frame.neighbors.indices),
            max_neighbors=p.max_neighbors,
            neighbor_dist=p.neighbor_dist,
            time_horizon=p.time_horizon,
            time_horizon_obst=self._time_horizon_obst(),
            dt=frame.dt,
            robots=(rob.positions, rob.velocities, rob.radii) if p.avoid_robots else None,
            obstacles=self._obstacles(frame),
        )
        return ModelOutput(velocities=v)
