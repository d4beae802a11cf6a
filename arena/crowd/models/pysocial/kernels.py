"""Per-agent terms of :mod:`arena.crowd.models.pysocial` in one compiled call (:func:`_terms`).

Desired, robot, obstacle (sums of :mod:`.obstacle_kernels`), group coherence, repulsion and
gaze, the factors and the total, in NumPy's element-wise order; :data:`_COEF` names the
entries of the coefficient vector.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

from arena.crowd.models.pysocial.obstacle_kernels import _obstacle
from arena.crowd.models.pysocial.pair_kernels import _TWO_PI

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

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
