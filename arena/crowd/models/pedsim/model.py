"""libpedsim's social force model (Helbing–Molnár / Moussaïd 2009), as Arena's pedsim runs it.

Every term is computed the way libpedsim's ``Ped::Tagent`` computes it (``ped_agent.cpp``,
``ped_waypoint.cpp``, ``ped_vector.cpp``/``ped_angle.h`` for the angle conventions) plus the
pedsim simulator's random force (``pedsim_simulator/src/force/randomforce.cpp``); agent ``i``
at ``p_i`` with velocity ``v_i``, radius ``r_i`` and speed limit ``vmax_i`` (``vmax ·
vmax_factor``):

* desired: ``F = (ê·vmax_i − v_i) / τ`` with ``ê`` the unit vector to the destination
  (``ê = 0`` when the agent stands on it or has none, so ``F = −v_i/τ``: it brakes).
* social, over the pedestrian neighbours ``j`` within ``neighborhood_range``:
  ``ê = (p_j − p_i)/|p_j − p_i|``, ``t = λ·(v_i − v_j) + ê`` (interaction vector),
  ``B = γ·|t|``, ``θ = angle(ê) − angle(t)`` wrapped to (−π, π], ``d`` the distance, and
  ``F += −exp(−d/B − (n'·B·θ)²)·t̂ − sign(θ)·exp(−d/B − (n·B·θ)²)·left(t̂)``.
  Arena's libpedsim measures ``d`` edge to edge, ``|p_j − p_i| − r_i − r_j`` (0.01 m when the
  bodies overlap); ``subtract_radii=False`` gives upstream libpedsim's centre distance. Pairs
  closer than √0.001 m have no direction and are skipped (Arena's ``pedsim_engine`` copy drops
  the agent's whole social force then; upstream gets NaN). That copy also stopped normalising
  ``t`` (a regression); upstream's unit ``t̂`` is used. Since ``t_ji = −t_ij`` and
  ``θ_ji = θ_ij`` the pair force is exactly antisymmetric, so each pair is evaluated once and
  applied to both agents.
* obstacle: only the NEAREST wall point ``c`` counts (libpedsim's ``obstacleForce``):
  ``F = exp(−(|p_i − c| − r_i)/σ_obs)·(p_i − c)/|p_i − c|`` (upstream and Arena's agent
  defaults; some Arena revisions swapped in ``1/distance``), for walls within
  ``obstacle_force_range`` of the centre (Arena's ``obstacleForceRange``; upstream takes the
  nearest wall anywhere: set the range to ``inf``). The range leaves a step of
  10·exp(−(2 − 0.35)/0.8) ≈ 1.3 m/s² at 2 m with the defaults.
* robot: robots are agents of type ROBOT to libpedsim; the social force skips them and this
  term (Arena's ``robotForce``) pushes off every robot within ``neighborhood_range``:
  ``F += −exp(−(|d| − r_i − R_k)/σ_robot,i)·d̂`` with ``d = p_robot − p_i`` and
  ``σ_robot,i = 0.3·vmax_i/0.4`` (libpedsim's ``forceSigmaRobot``). libpedsim hard-codes the
  robot radius as 0.7 m; the robots' own circumscribed radii ``R_k`` are used here.
* keep distance (``keepDistanceForce``): a spring ``F = −g·(|p_i − c_i| − d)·unit(p_i − c_i)``
  (``g = keep_distance_gain``, libpedsim's hard-coded 10 /s²; ``d = keep_distance``, 0.8 m)
  holding the agent at ``d`` from a centre ``c_i`` (a talking partner or a group's talking
  centre). Arena disables it (``disableForce("KeepDistance")``) unless one of pedsim's legacy
  listening states sets a centre, so it is zero until
  :meth:`PedsimModel.set_keep_distance_targets` gives centres.
* random: pedsim's ``RandomForce``: every ``random_fading_time`` seconds a new deviation
  ``δ = N(0, 1)·(cos φ, sin φ)``, ``φ ~ U[0, 2π)``, is drawn per agent from ``frame.rng`` and the
  force fades linearly from the previous deviation to the new one, scaled by its factor (pedsim
  fades over ``fmod(t, T)`` seconds, not ``fmod(t, T)/T``; the same for its default T = 1 s).
  The period is read from ``state.time``, so the model keeps the two deviations between calls.

Total: ``a = f_des·F_des + f_soc·F_soc + f_obs·F_obs + f_robot·F_robot + F_keep + F_random``;
``forces`` holds each (scaled) term, so they sum to the acceleration. Inactive agents get zero
in every term but still repel the others.

Integration is the simulator's: ``v += a·dt``, hard cap ``|v| ≤ vmax·vmax_factor``, ``p += v·dt``.
libpedsim's soft cap quirk (``v = v̂·sqrt(vmax·|v|)`` when too fast) is deliberately not used.

Performance: everything is compiled (numba) and vectorised over agents; the social pairs come
from the frame's CSR neighbour lists and are evaluated in SIMD batches, with in-house ``atan2``
and ``exp`` (within 1e-15 of libm) because libm calls block vectorisation. About 1.7 ms per
step for 1,000 agents in a 40 × 40 m room (~85,000 pairs within 10 m) on one core.
"""

from __future__ import annotations

import math
from typing import ClassVar, Literal

import numpy as np
from numpy.typing import NDArray

from arena.crowd.base import CROWD_MODELS, CrowdFrame, ModelOutput
from arena.crowd.models.pedsim.kernels import _agent_terms, _social_terms
from arena.crowd.models.pedsim.params import PedsimParams
from arena.crowd.state import CrowdState
from arena.crowd.walls import WallIndex, world_segments
from arena.scene.state import StaticWorld

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]


TERMS = ("desired", "social", "obstacle", "robot", "keep_distance", "random")
"""Names of the per-term forces in :attr:`ModelOutput.forces`, in summation order."""


@CROWD_MODELS.register("pedsim", tags=("social_force",))
class PedsimModel:
    """libpedsim's social force model with Arena's pedsim defaults (see the module docstring)."""

    output: ClassVar[Literal["acceleration", "velocity"]] = "acceleration"

    Params = PedsimParams

    def __init__(self, params: PedsimParams | None = None) -> None:
        self.params = params or self.Params()
        self._walls: WallIndex | None = None
        self._walls_key: tuple[FloatArray, FloatArray] | None = None
        self._keep_to: FloatArray | None = None
        self._rand_last = np.zeros((0, 2))
        self._rand_next = np.zeros((0, 2))
        self._fade_index: int | None = None

    # -- CrowdModel ----------------------------------------------------------------------------
    def neighbor_cutoff(self) -> float:
        """The neighbourhood range (m) of libpedsim's ``computeForces``."""
        return float(self.params.neighborhood_range)

    def reset(self, state: CrowdState, world: StaticWorld, rng: np.random.Generator) -> None:
        """Index the world's walls and clear the per-episode random and keep-distance state."""
        a, b = world_segments(world)
        self._set_walls(a, b)
        self._keep_to = None
        self._rand_last = np.zeros((len(state), 2))
        self._rand_next = np.zeros((len(state), 2))
        self._fade_index = None

    def compute(self, frame: CrowdFrame) -> ModelOutput:
        """Accelerations ``(n, 2)`` (m/s²) and the six named terms; zero for inactive agents."""
        acc, forces = self._pedsim(frame)
        return ModelOutput(accelerations=acc, forces=forces)

    # -- extras ------------------------------------------------------------------------------------
    def set_keep_distance_targets(self, targets: FloatArray | None) -> None:
        """Centres ``(n, 2)`` (m) the keep-distance spring holds agents ``keep_distance`` from.

        Rows of NaN (or ``None`` for all) switch the term off, as Arena does for every agent not
        in a listening state. Kept until changed or until :meth:`reset`.
        """
        self._keep_to = None if targets is None else np.array(targets, dtype=np.float64)

    # -- implementation ----------------------------------------------------------------------------
    def _pedsim(self, frame: CrowdFrame) -> tuple[FloatArray, dict[str, FloatArray]]:
        """The pedsim force for ``frame``: ``(accelerations, forces)``."""
        p = self.params
        s = frame.state
        n = len(s)
        pos = np.ascontiguousarray(s.positions, dtype=np.float64)
        vel = np.ascontiguousarray(s.velocities, dtype=np.float64)
        radii = np.ascontiguousarray(s.radii, dtype=np.float64)
        vmax = np.ascontiguousarray(s.vmax * s.vmax_factor, dtype=np.float64)
        active = np.ascontiguousarray(frame.active, dtype=np.bool_)
        keep_to = self._keep_to
        if keep_to is None or keep_to.shape != (n, 2):
            keep_to = np.full((n, 2), np.nan)
        # libpedsim derives σ_robot from the agent's base vmax; the floor keeps a standing agent
        # (vmax 0) finite instead of dividing by zero.
        sigma_robot = np.maximum(p.robot_sigma_per_vmax * s.vmax, 1e-3)

        social = _social_terms(
            pos,
            vel,
            radii,
            active,
            frame.neighbors.indptr,
            frame.neighbors.indices,
            p.neighborhood_range,
            p.lambda_importance,
            p.gamma,
            p.n,
            p.n_prime,
            p.subtract_radii,
        )
        desired, robot, keep = _agent_terms(
            pos,
            vel,
            radii,
            vmax,
            np.ascontiguousarray(frame.destinations, dtype=np.float64),
            active,
            p.neighborhood_range,
            np.ascontiguousarray(frame.robots.positions, dtype=np.float64).reshape(-1, 2),
            np.ascontiguousarray(frame.robots.radii, dtype=np.float64).reshape(-1),
            np.ascontiguousarray(sigma_robot, dtype=np.float64),
            np.ascontiguousarray(keep_to, dtype=np.float64),
            p.relaxation_time,
            p.keep_distance,
            p.keep_distance_gain,
        )
        desired *= p.force_factor_desired
        social *= p.force_factor_social
        robot *= p.force_factor_robot
        obstacle = self._obstacle(frame, pos, radii, active)
        random = self._random(frame, n, active)
        acc = desired + social + obstacle + robot + keep + random
        forces = {
            "desired": desired,
            "social": social,
            "obstacle": obstacle,
            "robot": robot,
            "keep_distance": keep,
            "random": random,
        }
        return acc, forces

    def _set_walls(self, a: FloatArray, b: FloatArray) -> None:
        self._walls = WallIndex(a, b)
        self._walls_key = (a, b)

    def _wall_index(self, frame: CrowdFrame) -> WallIndex:
        """The wall index for the frame's segments (built in reset; rebuilt if they differ)."""
        key = self._walls_key
        a, b = frame.walls_a, frame.walls_b
        same = key is not None and (
            (key[0] is a and key[1] is b)
            or (key[0].shape == a.shape and np.array_equal(key[0], a) and np.array_equal(key[1], b))
        )
        if not same or self._walls is None:
            self._set_walls(np.array(a, dtype=np.float64), np.array(b, dtype=np.float64))
        self._walls_key = (a, b)  # next time the identity check suffices
        assert self._walls is not None
        return self._walls

    def _obstacle(
        self, frame: CrowdFrame, pos: FloatArray, radii: FloatArray, active: BoolArray
    ) -> FloatArray:
        """``f_obs·exp(−(dist − r)/σ)`` away from the nearest wall point within range."""
        p = self.params
        out = np.zeros_like(pos)
        if p.force_factor_obstacle == 0.0 or frame.walls_a.shape[0] == 0 or pos.shape[0] == 0:
            return out
        walls = self._wall_index(frame)
        closest, dist = walls.nearest(pos, p.obstacle_force_range)
        # An agent centred exactly on a wall has no direction to be pushed (libpedsim's
        # normalized() of a zero vector is zero), so it gets none.
        hit = active & np.isfinite(dist) & (dist > 0.0)
        d = dist[hit]
        amount = p.force_factor_obstacle * np.exp(-(d - radii[hit]) / p.sigma_obstacle)
        out[hit] = (pos[hit] - closest[hit]) * (amount / d)[:, None]
        return out

    def _random(self, frame: CrowdFrame, n: int, active: BoolArray) -> FloatArray:
        """The pedsim simulator's fading random force (draws from ``frame.rng`` per period)."""
        p = self.params
        if p.force_factor_random == 0.0 or n == 0:
            return np.zeros((n, 2))
        period = p.random_fading_time
        # The small tolerance keeps t = k·period accumulated in floating point from landing just
        # below the period boundary and drawing one step late.
        phase = frame.state.time / period + 1e-9
        k = math.floor(phase)
        if self._rand_next.shape != (n, 2):  # compute() without reset(): start afresh
            self._fade_index = None
        if k != self._fade_index:
            if self._fade_index is not None and k == self._fade_index + 1:
                self._rand_last = self._rand_next
            else:  # first call, or time jumped: pedsim starts from one drawn deviation
                self._rand_last = _deviation(frame.rng, n)
            self._rand_next = _deviation(frame.rng, n)
            self._fade_index = k
        progress = min(max(phase - k, 0.0), 1.0)
        out = ((1.0 - progress) * self._rand_last + progress * self._rand_next) * (
            p.force_factor_random
        )
        out[~active] = 0.0
        return out


@CROWD_MODELS.register("passthrough", tags=("social_force",))
class PassthroughModel(PedsimModel):
    """Arena's "pedsim unchanged" plugin: exactly the ``pedsim`` force, same parameters.

    Arena runs plain libpedsim motion under two names: the pedsim simulator on its own, and the
    crowd plugin (``crowdsim_agents``) with its ``passthrough`` force model (``sfm:=
    passthrough``), which hands pedsim's own summed force back unchanged. Configs and scenarios
    written for either name load here, so both are registered; this class only renames
    :class:`PedsimModel` (no code of its own), so the output is bit-identical.
    """


def _deviation(rng: np.random.Generator, n: int) -> FloatArray:
    """Random deviations ``(n, 2)`` as pedsim draws them: ``N(0, 1)`` long, ``U[0, 2π)`` angle."""
    angle = rng.uniform(0.0, 2.0 * math.pi, n)
    length = rng.standard_normal(n)
    return np.stack([length * np.cos(angle), length * np.sin(angle)], axis=1)
