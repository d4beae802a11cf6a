"""The numerical core of BRNE: Gaussian-process samples, pairwise costs, Bayes-rule Nash weights.

Kept apart from :mod:`arena.nav.local_planners.brne` (observation handling and the command) so
that the game itself is testable without a robot: a set of agents, each with ``M`` sampled
trajectories over ``T`` time steps, and the weights that play them.

Layout: trajectories are ``xs, ys`` arrays of shape ``(A, M, T)`` (m, world frame; agent 0 is the
robot), ``T`` contiguous so that the distance loops vectorise. The cost tensor is ``(A, M, A,
M)``: ``costs[a, p, b, q]`` is the collision cost of sample ``p`` of agent ``a`` against sample
``q`` of agent ``b``; symmetric, zero on the ``a == b`` blocks.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

def gp_cholesky(times: FloatArray, length_scale: float, std: float) -> FloatArray:
    """Cholesky factor ``(T, T)`` of an RBF Gaussian process conditioned on ``f(0) = 0``.

    The kernel is ``k(t, t') = std² · exp(-(t - t')² / (2 · length_scale²))``; conditioning on a
    zero value at ``t = 0`` makes every sample start where its nominal trajectory starts and
    spread as time goes on (posterior variance ``std² · (1 - exp(-t² / length_scale²))``).

    Args:
        times: ``(T,)`` sample times (s), all > 0.
        length_scale: s, how long a perturbation stays correlated (larger: straighter samples).
        std: m, standard deviation of a perturbation far from ``t = 0``.

    Returns:
        Lower-triangular ``L`` with ``L @ L.T`` the posterior covariance (m²), a small jitter
        added to the diagonal so that the factorisation exists.
    """
    t = np.asarray(times, dtype=np.float64).reshape(-1)
    var = std * std
    inv = 1.0 / (2.0 * length_scale * length_scale)
    k22 = var * np.exp(-((t[:, None] - t[None, :]) ** 2) * inv)
    k20 = var * np.exp(-(t**2) * inv)  # covariance of f(t) with f(0)
    cov = k22 - np.outer(k20, k20) / var
    cov += np.eye(len(t)) * (1e-6 * var + 1e-12)
    return np.asarray(np.linalg.cholesky(cov), dtype=np.float64)


def gp_perturbations(
    chol: FloatArray, agents: int, samples: int, rng: np.random.Generator
) -> FloatArray:
    """``(agents, samples, T, 2)`` planar GP perturbations (m) with factor ``chol`` ``(T, T)``.

    Each sample's x and y are independent draws. Sample 0 of every agent is zero, so that the
    nominal trajectory itself is always a candidate (a narrow corridor may reject every
    perturbed one); the others come in antithetic pairs ``(δ, -δ)`` (a zero again if one is left
    over), so that the samples' mean is exactly the nominal: with uniform weights the plan is
    the nominal, and neither side of an obstacle is favoured by the draw.
    """
    steps = chol.shape[0]
    pairs = (samples - 1) // 2
    white = rng.standard_normal((agents, pairs, 2, steps))
    half = np.einsum("ts,amks->amtk", chol, white)
    out = np.zeros((agents, samples, steps, 2))
    out[:, 1:1 + pairs] = half
    out[:, 1 + pairs:1 + 2 * pairs] = -half
    return out


@njit(cache=True)
def pair_costs(
    xs: FloatArray, ys: FloatArray, radii: FloatArray, reach: float, weight: float
) -> tuple[NDArray[np.float32], NDArray[np.bool_]]:
    """Collision cost of every sample of every agent against every sample of every other agent.

    The cost of two trajectories is a quadratic hinge on their closest approach over the
    horizon, ``d = min_t |x_a(t) - x_b(t)|``: ``weight · ((r_a + r_b + reach - d) / reach)²``
    while ``d < r_a + r_b + reach``, else 0. It equals ``weight`` at contact and keeps growing
    with the overlap, so samples that collide deeper rank worse. Agent pairs whose samples'
    bounding boxes lie farther apart than that never interact: their block stays zero and is
    marked inactive, so that :func:`nash_weights` skips it.

    Args:
        xs: ``(A, T, M)`` x coordinates (m) of ``M`` samples over ``T`` steps per agent.
        ys: ``(A, T, M)`` y coordinates (m).
        radii: ``(A,)`` agent radii (m).
        reach: m, clearance beyond contact at which the cost falls to zero.
        weight: cost at contact.

    Returns:
        ``(A, M, A, M)`` float32 costs, symmetric, zero on the diagonal blocks; and ``(A, A)``
        whether each block may be non-zero.
    """
    n_a, n_t, n_m = xs.shape
    out = np.zeros((n_a, n_m, n_a, n_m), dtype=np.float32)
    active = np.zeros((n_a, n_a), dtype=np.bool_)
    lo_x = np.empty(n_a)
    hi_x = np.empty(n_a)
    lo_y = np.empty(n_a)
    hi_y = np.empty(n_a)
    for a in range(n_a):
        lo_x[a] = xs[a].min()
        hi_x[a] = xs[a].max()
        lo_y[a] = ys[a].min()
        hi_y[a] = ys[a].max()
    d2 = np.empty(n_m)
    for a in range(n_a):
        for b in range(a + 1, n_a):
            zone = radii[a] + radii[b] + reach
            zone2 = zone * zone
            gap_x = max(lo_x[b] - hi_x[a], lo_x[a] - hi_x[b], 0.0)
            gap_y = max(lo_y[b] - hi_y[a], lo_y[a] - hi_y[b], 0.0)
            if gap_x * gap_x + gap_y * gap_y >= zone2:
                continue  # every pair of samples stays out of each other's zone
            active[a, b] = True
            active[b, a] = True
            xb = xs[b]
            yb = ys[b]
            for p in range(n_m):
                # Samples of b in the innermost loop: contiguous, so it vectorises.
                d2[:] = np.inf
                for t in range(n_t):
                    xa = xs[a, t, p]
                    ya = ys[a, t, p]
                    for q in range(n_m):
                        dx = xa - xb[t, q]
                        dy = ya - yb[t, q]
                        d2[q] = min(d2[q], dx * dx + dy * dy)
                for q in range(n_m):
                    if d2[q] < zone2:
                        h = (zone - math.sqrt(d2[q])) / reach
                        c = np.float32(weight * h * h)
                        out[a, p, b, q] = c
                        out[b, q, a, p] = c
    return out, active


# Reassociation lets the expected-cost sums vectorise; no infinities/NaNs are assumed away.
@njit(cache=True, fastmath={"reassoc", "contract"})
def nash_weights(
    costs: NDArray[np.float32], active: NDArray[np.bool_], prior: FloatArray, iterations: int
) -> FloatArray:
    """Bayes-rule Nash-equilibrium weights ``(A, M)`` of every agent's samples.

    Starting from the prior, each iteration visits the agents in turn (Gauss–Seidel, as the
    authors' code does) and sets agent ``a``'s weights to the posterior
    ``w_a(p) ∝ prior_a(p) · exp(-Σ_{b≠a} Σ_q costs[a, p, b, q] · w_b(q))``: the prior reweighted
    by the expected collision cost of sample ``p`` against everyone else's current mixed
    strategy. The exponent is shifted by its minimum before ``exp`` (the normalisation cancels
    it), so large costs do not underflow every weight to zero.

    Args:
        costs: ``(A, M, A, M)`` from :func:`pair_costs`.
        active: ``(A, A)`` blocks of ``costs`` that may be non-zero (the others are skipped).
        prior: ``(A, M)`` non-negative prior weights, each row with a positive sum.
        iterations: number of sweeps over the agents.

    Returns:
        ``(A, M)`` weights, each row non-negative and summing to 1.
    """
    n_a, n_m = prior.shape
    w = np.empty((n_a, n_m))
    for a in range(n_a):
        w[a] = prior[a] / prior[a].sum()
    expected = np.empty(n_m)
    for _ in range(iterations):
        for a in range(n_a):
            for p in range(n_m):
                e = 0.0
                for b in range(n_a):
                    if not active[a, b]:
                        continue
                    row = costs[a, p, b]
                    wb = w[b]
                    for q in range(n_m):
                        e += row[q] * wb[q]
                expected[p] = e
            low = np.inf
            for p in range(n_m):
                if prior[a, p] > 0.0 and expected[p] < low:
                    low = expected[p]
            total = 0.0
            for p in range(n_m):
                v = prior[a, p] * math.exp(low - expected[p]) if prior[a, p] > 0.0 else 0.0
                w[a, p] = v
                total += v
            for p in range(n_m):
                w[a, p] /= total
    return w


def expected_cost(costs: NDArray[np.float32], weights: FloatArray) -> float:
    """Expected total collision cost ``Σ_{a<b} w_aᵀ C_ab w_b`` of mixed strategies ``(A, M)``."""
    full = float(np.einsum("ap,apbq,bq->", weights, costs.astype(np.float64), weights))
    return 0.5 * full  # every unordered pair appears twice in the symmetric tensor


@njit(cache=True, fastmath=True)
def sample_clearance(xs: FloatArray, ys: FloatArray, points: FloatArray) -> FloatArray:
    """Smallest distance (m) of each of ``M`` trajectories ``(T, M)`` to any of ``points``.

    Args:
        xs: ``(T, M)`` x coordinates (m).
        ys: ``(T, M)`` y coordinates (m).
        points: ``(P, 2)`` obstacle points (m), same frame.

    Returns:
        ``(M,)`` distances (m); ``inf`` when there are no points.
    """
    n_t, n_m = xs.shape
    best = np.full(n_m, np.inf)
    for k in range(points.shape[0]):
        px = points[k, 0]
        py = points[k, 1]
        for t in range(n_t):
            for p in range(n_m):
                dx = px - xs[t, p]
                dy = py - ys[t, p]
                best[p] = min(best[p], dx * dx + dy * dy)
    return np.sqrt(best)  # type: ignore[no-any-return]
