r"""Deep Social Force: a social force model whose pedestrian potential is a small trained MLP.

After Kreiss, S. (2021) "Deep Social Force" (arXiv:2109.12081; package ``socialforce`` 0.2.x).
Per unit mass, pedestrian ``a`` feels

.. math::

    \mathbf a_a = \frac{v_a^0 \mathbf e_a - \mathbf v_a}{\tau}
      - \sum_{b \ne a} w_{ab}\, V'(b_{ab})\, \nabla_{\mathbf r_{ab}} b_{ab}
      - \sum_B \nabla_{\mathbf r_{aB}} U(\lVert \mathbf r_{aB} \rVert),

* ``b_ab = ½·sqrt((|r_ab| + |r_ab − s·e_b|)² − s²)`` is Helbing & Molnár's (1995) semi-minor
  axis of the ellipse around ``b`` that ``a`` keeps out of, with ``r_ab = x_a − x_b``,
  ``s = Δt·|v_b|`` (``Δt = 0.4 s``) and ``e_b`` the desired direction of ``b``; its gradient is
  ``∇b = (|r| + |u|)/(4b)·(r/|r| + u/|u|)``, ``u = r_ab − s·e_b``.
* ``V(b)`` is the learned potential ``softplus(w2·softplus(w1·b + b1) + b2)`` (m²/s²), 1-16-1
  (Kreiss's MLP shape; he used 5 hidden units by default). Inference is numpy/numba: the
  derivative ``V'(b) = σ(z2)·Σ_k w2_k σ(z1_k) w1_k`` (σ the logistic function, the derivative of
  softplus) is evaluated in closed form. No torch at runtime.
* ``w_ab = 1`` if ``b`` lies within ``a``'s 200° field of view around ``e_a``, else 0.5.
* ``U(d) = u0·exp(−d/r)`` (``u0 = 10 m²/s²``, ``r = 0.2 m``) is Kreiss's pedestrian–space
  potential, summed over the distinct wall segments within ``wall_cutoff`` at their closest
  points (Kreiss: the closest point of each boundary).
* ``τ = 0.5 s``; desired speed ``v_a^0 = vmax·vmax_factor``; ``e_a`` toward the frame's
  destination.

**What the shipped weights were trained on** (``weights/deep_social_force.npz``, written by
``tools/train_deep_social_force.py``; the file's ``metadata`` records the exact command, steps,
wall time and loss): synthetic trajectories only, no real pedestrian data. Following Kreiss's
synthetic experiment, two-pedestrian circle-crossing and opposing-flow scenes were simulated
with the *analytic* Helbing–Molnár potential ``V(b) = 2.1·exp(−b/0.3)`` (``τ = 0.5 s``, 200°
field of view, speed cap 1.3·preferred speed, state step 0.4 s in 10 sub-steps), and the MLP was
fitted so that the same simulator driven by ``−∇V_θ`` predicts the next state (L1 on positions).
The MLP therefore reproduces that analytic potential's force (to a few per cent for
``0.3 ≤ b ≤ 2 m``, the range the data covers), not any measured crowd; it stays monotonically
decreasing on ``[0.1, 3] m`` but is extrapolated below ``b ≈ 0.3 m``. Retrain the same way on
real trajectories to get a data-driven potential.

``potential="analytic"`` uses ``V = v0·exp(−b/σ)`` instead. Arena's ``deepsocialforce`` plugin ran
``socialforce.Simulator`` with the *analytic* ``PedPedPotential(sigma=1)`` (no trained MLP);
``potential="analytic", sigma=1.0`` reproduces that potential.

Robots are treated as pedestrians ``b`` whose desired direction is their velocity direction
(``robots_as_pedestrians``). Terms in :attr:`~arena.crowd.base.ModelOutput.forces` (m/s²,
summing to the acceleration): ``desired``, ``social``, ``obstacle``, ``robot``, ``speed_cap``
(velocity removed by the simulator's speed cap, applied here already) and ``carry`` (zero unless
sub-stepping).

Integration: unlike the escape-panic contact forces this model is soft. The stiffest term is
the wall potential, ``U''(d) = (u0/r²)·e^(−d/r)``: 56 s⁻² at ``d = 0.3 m`` and 118 s⁻² at the
integrator's wall clearance (0.15 m for 0.3 m radii), i.e. ``ω·dt ≤ 1.1 < 2`` at ``dt = 0.1 s``;
the pair potential's ``V'' ≤ v0/σ² ≈ 23 s⁻²`` and ``dt/τ = 0.2`` are milder. So by default
:meth:`DeepSocialForce.compute` evaluates the forces once per step. A smaller ``max_substep``
sub-steps like the evacuation model (neighbour and wall lists fixed over the step; the simulator
lands on the sub-stepped positions and the true velocity is carried to the next step).
``max_substep = 0.04`` reproduces socialforce's internal step (0.4 s / 10); it changed the
closest approach of a head-on pair by under 0.02 m in our tests, at 3× the cost.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, ClassVar, Literal

import numpy as np
from numba import njit
from numpy.typing import NDArray

from arena.crowd.base import CROWD_MODELS, CrowdFrame, ModelOutput
from arena.crowd.models.deep_social_force_params import (
    WEIGHTS,
    DeepSocialForceParams,
    MLPPotential,
)
from arena.crowd.models.evacuation.model import SegmentWalls, SubstepMemory
from arena.crowd.walls import world_segments

if TYPE_CHECKING:
    from arena.crowd.state import CrowdState
    from arena.scene.state import StaticWorld

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

TERMS: tuple[str, ...] = ("desired", "social", "obstacle", "robot", "speed_cap", "carry")
_KIND = {"mlp": 0, "analytic": 1}


@CROWD_MODELS.register("deep_social_force", tags=("learned",))
class DeepSocialForce:
    """Kreiss's Deep Social Force: MLP ped-ped potential over Helbing–Molnár's ``b``.

    The shipped MLP was trained on synthetic trajectories generated with the analytic
    Helbing–Molnár potential ``2.1·exp(−b/0.3)`` in two-person circle-crossing and
    opposing-flow scenes (no real pedestrian data); see the module docstring.
    """

    output: ClassVar[Literal["acceleration", "velocity"]] = "acceleration"

    Params = DeepSocialForceParams

    def __init__(self, params: DeepSocialForceParams | None = None) -> None:
        self.params = params or self.Params()
        p = self.params
        if p.potential == "mlp":
            self.mlp: MLPPotential | None = MLPPotential.load(p.weights or WEIGHTS)
            w = self.mlp
            self._net = (w.w1, w.b1, w.w2, w.b2)
        else:
            self.mlp = None
            self._net = (np.zeros(1), np.zeros(1), np.zeros(1), 0.0)
        self._walls: SegmentWalls | None = None
        self._memory = SubstepMemory()

    def neighbor_cutoff(self) -> float:
        """Pedestrians beyond ``interaction_range`` (m) are ignored."""
        return self.params.interaction_range

    def reset(self, state: CrowdState, world: StaticWorld, rng: np.random.Generator) -> None:
        """Index the world's wall and obstacle segments for the episode."""
        self._walls = SegmentWalls(*world_segments(world))
        self._memory.clear()

    def compute(self, frame: CrowdFrame) -> ModelOutput:
        """Accelerations at the current state (one step), or sub-stepped; zero if inactive.

        With sub-steps the simulator is handed the mean sub-stepped velocity and the true end
        velocity is carried to the next step, as in the evacuation model
        (:class:`~arena.crowd.models.evacuation.SubstepMemory`).
        """
        s = frame.state
        n = len(s)
        p = self.params
        terms = np.zeros((len(TERMS), n, 2))
        if n == 0:
            return self._output(terms)
        dt = float(frame.dt)
        n_sub = max(1, math.ceil(dt / p.max_substep - 1e-9))
        h = dt / n_sub
        walls = self._walls
        if walls is None or not walls.matches(frame.walls_a, frame.walls_b):
            walls = self._walls = SegmentWalls(frame.walls_a, frame.walls_b)
        cap = np.ascontiguousarray(s.vmax * s.vmax_factor, dtype=np.float64)
        reach = p.wall_cutoff + (float(cap.max(initial=0.0)) * dt if n_sub > 1 else 0.0)
        w_ptr, w_idx = walls.near(s.positions, reach)
        active = np.ascontiguousarray(frame.active, dtype=np.bool_)
        dest = np.ascontiguousarray(frame.destinations, dtype=np.float64)
        pos0 = np.ascontiguousarray(s.positions, dtype=np.float64)
        vel0 = np.ascontiguousarray(s.velocities, dtype=np.float64)
        vel = self._memory.start(pos0, vel0) if n_sub > 1 else vel0.copy()
        vel[~active] = vel0[~active]
        terms[-1] = vel - vel0  # carry
        pos = pos0.copy()
        robots = frame.robots
        use_robots = p.robots_as_pedestrians and len(robots) > 0
        r_pos0 = np.ascontiguousarray(robots.positions if use_robots else np.zeros((0, 2)))
        r_vel = np.ascontiguousarray(robots.velocities if use_robots else np.zeros((0, 2)))
        w1, b1, w2, b2 = self._net
        cos_phi = math.cos(math.radians(0.5 * p.field_of_view))
        acc = np.empty((n, 2))
        for k in range(n_sub):  # a few sub-steps per step, each vectorised over all agents
            # A velocity change in sub-step k moves the agent for the rest of the step: its
            # share of the mean velocity (x_end − x_0)/dt is (n_sub − k)/n_sub.
            w = (n_sub - k) / n_sub
            dsf_accelerations(
                pos, vel, dest, cap, active, p.tau,
                frame.neighbors.indptr, frame.neighbors.indices,
                _KIND[p.potential], w1, b1, w2, b2, p.v0, p.sigma, p.delta_t,
                cos_phi, p.out_of_view_factor,
                w_ptr, w_idx, walls.a, walls.b, p.wall_strength, p.wall_range,
                r_pos0 + r_vel * (k * h), r_vel, p.interaction_range,
                terms, h * w, acc,
            )  # fmt: skip
            v_new = vel + acc * h
            speed = np.hypot(v_new[:, 0], v_new[:, 1])
            scale = np.where(speed > cap, cap / np.maximum(speed, 1e-12), 1.0)
            capped = v_new * scale[:, None]
            terms[-2][active] += w * (capped - v_new)[active]
            vel[active] = capped[active]
            pos[active] += capped[active] * h
        terms /= dt
        terms[:, ~active] = 0.0
        out = self._output(terms)
        if n_sub > 1:
            assert out.accelerations is not None
            told = vel0 + out.accelerations * dt
            self._memory.remember(pos0 + told * dt, told, vel)
        return out

    @staticmethod
    def _output(terms: FloatArray) -> ModelOutput:
        forces = {name: terms[k].copy() for k, name in enumerate(TERMS)}
        return ModelOutput(accelerations=terms.sum(axis=0), forces=forces)


@njit(cache=True, inline="always")
def _dvdb(
    b: float,
    kind: int,
    w1: FloatArray,
    b1: FloatArray,
    w2: FloatArray,
    b2: float,
    v0: float,
    sigma: float,
) -> float:
    """``dV/db`` of the MLP (kind 0) or of ``v0·exp(−b/σ)`` (kind 1)."""
    if kind == 1:
        return -v0 / sigma * math.exp(-b / sigma)
    if b > 100.0:
        return 0.0
    z2 = b2
    acc = 0.0
    for k in range(w1.shape[0]):
        z1 = w1[k] * b + b1[k]
        # One exp serves both softplus(z1) and its derivative σ(z1), overflow-free.
        t = math.exp(-abs(z1))
        z2 += w2[k] * (max(z1, 0.0) + math.log1p(t))
        acc += w2[k] * w1[k] * (1.0 / (1.0 + t) if z1 >= 0.0 else t / (1.0 + t))
    t = math.exp(-abs(z2))
    return (1.0 / (1.0 + t) if z2 >= 0.0 else t / (1.0 + t)) * acc


@njit(cache=True, inline="always")
def _pair(
    rx: float,
    ry: float,
    s: float,
    ebx: float,
    eby: float,
    kind: int,
    w1: FloatArray,
    b1: FloatArray,
    w2: FloatArray,
    b2: float,
    v0: float,
    sigma: float,
) -> tuple[float, float]:
    """``−V'(b)·∇_r b`` for ``r = x_a − x_b``, ``s = Δt·|v_b|``, ``e_b``; zero when degenerate."""
    ux, uy = rx - s * ebx, ry - s * eby
    rn = math.sqrt(rx * rx + ry * ry)
    un = math.sqrt(ux * ux + uy * uy)
    q = (rn + un) ** 2 - s * s
    if q <= 1e-8 or rn < 1e-12 or un < 1e-12:
        return 0.0, 0.0  # Kreiss clamps q at 1e-8, which zeroes the gradient there
    b = 0.5 * math.sqrt(q)
    g = (rn + un) / (4.0 * b)
    f = -_dvdb(b, kind, w1, b1, w2, b2, v0, sigma) * g
    return f * (rx / rn + ux / un), f * (ry / rn + uy / un)


@njit(cache=True)
def dsf_accelerations(
    pos: FloatArray,
    vel: FloatArray,
    dest: FloatArray,
    v_pref: FloatArray,
    active: NDArray[np.bool_],
    tau: float,
    nb_ptr: IntArray,
    nb_idx: IntArray,
    kind: int,
    w1: FloatArray,
    b1: FloatArray,
    w2: FloatArray,
    b2: float,
    v0: float,
    sigma: float,
    delta_t: float,
    cos_phi: float,
    out_of_view: float,
    w_ptr: IntArray,
    w_idx: IntArray,
    seg_a: FloatArray,
    seg_b: FloatArray,
    u0: float,
    r_wall: float,
    r_pos: FloatArray,
    r_vel: FloatArray,
    cutoff: float,
    terms: FloatArray,
    h: float,
    acc: FloatArray,
) -> None:
    """Accelerations ``acc`` ``(n, 2)`` at one state; adds ``term·h`` to ``terms`` rows 0–3.

    Rows of ``terms``: desired, social, obstacle, robot (m/s after the ``h`` weighting).
    Inactive agents get zero.
    """
    n = pos.shape[0]
    e = np.zeros((n, 2))
    for i in range(n):
        dx, dy = dest[i, 0] - pos[i, 0], dest[i, 1] - pos[i, 1]
        d = math.sqrt(dx * dx + dy * dy)
        if d > 1e-9:
            e[i, 0], e[i, 1] = dx / d, dy / d
    for i in range(n):
        acc[i, 0] = 0.0
        acc[i, 1] = 0.0
        if not active[i]:
            continue
        px, py = pos[i, 0], pos[i, 1]
        eax, eay = e[i, 0], e[i, 1]
        fx = (v_pref[i] * eax - vel[i, 0]) / tau
        fy = (v_pref[i] * eay - vel[i, 1]) / tau
        terms[0, i, 0] += fx * h
        terms[0, i, 1] += fy * h
        ax, ay = fx, fy
        sx_, sy_ = 0.0, 0.0
        for kk in range(nb_ptr[i], nb_ptr[i + 1]):
            j = nb_idx[kk]
            rx, ry = px - pos[j, 0], py - pos[j, 1]
            sj = delta_t * math.sqrt(vel[j, 0] ** 2 + vel[j, 1] ** 2)
            gx, gy = _pair(rx, ry, sj, e[j, 0], e[j, 1], kind, w1, b1, w2, b2, v0, sigma)
            # In view: the direction to j within φ of e_a.
            rn = math.sqrt(rx * rx + ry * ry)
            w = 1.0 if -(eax * rx + eay * ry) > rn * cos_phi else out_of_view
            sx_ += w * gx
            sy_ += w * gy
        terms[1, i, 0] += sx_ * h
        terms[1, i, 1] += sy_ * h
        ax += sx_
        ay += sy_
        ox, oy = 0.0, 0.0
        for kk in range(w_ptr[i], w_ptr[i + 1]):
            wseg = w_idx[kk]
            qx, qy = seg_a[wseg, 0], seg_a[wseg, 1]
            lx, ly = seg_b[wseg, 0] - qx, seg_b[wseg, 1] - qy
            ll = lx * lx + ly * ly
            t = ((px - qx) * lx + (py - qy) * ly) / ll if ll > 0.0 else 0.0
            t = min(max(t, 0.0), 1.0)
            nx, ny = px - (qx + t * lx), py - (qy + t * ly)
            d = math.sqrt(nx * nx + ny * ny)
            if d < 1e-12:
                continue
            mag = u0 / r_wall * math.exp(-d / r_wall) / d
            ox += mag * nx
            oy += mag * ny
        terms[2, i, 0] += ox * h
        terms[2, i, 1] += oy * h
        ax += ox
        ay += oy
        qx_, qy_ = 0.0, 0.0
        for r in range(r_pos.shape[0]):
            rx, ry = px - r_pos[r, 0], py - r_pos[r, 1]
            rn = math.sqrt(rx * rx + ry * ry)
            if rn >= cutoff:
                continue
            vr = math.sqrt(r_vel[r, 0] ** 2 + r_vel[r, 1] ** 2)
            ebx, eby = (r_vel[r, 0] / vr, r_vel[r, 1] / vr) if vr > 1e-9 else (0.0, 0.0)
            gx, gy = _pair(rx, ry, delta_t * vr, ebx, eby, kind, w1, b1, w2, b2, v0, sigma)
            w = 1.0 if -(eax * rx + eay * ry) > rn * cos_phi else out_of_view
            qx_ += w * gx
            qy_ += w * gy
        terms[3, i, 0] += qx_ * h
        terms[3, i, 1] += qy_ * h
        acc[i, 0] = ax + qx_
        acc[i, 1] = ay + qy_
