"""The numba kernels of :mod:`arena.crowd.models.evacuation`: contact stiffness and the sub-steps.

:func:`_stiffness` gives the Gershgorin bounds that set the number of sub-steps,
:func:`_helbing_substeps` integrates them (forces, contact, friction, walls, robots, bonds);
:func:`_distinct_owners` lists each wall segment near an agent once.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


@njit(cache=True)
def _distinct_owners(
    indptr: IntArray, indices: IntArray, owner: IntArray, n_owners: int
) -> tuple[IntArray, IntArray]:
    q = indptr.shape[0] - 1
    stamp = np.full(n_owners, -1, dtype=np.int64)
    out_ptr = np.zeros(q + 1, dtype=np.int64)
    out = np.empty(indices.shape[0], dtype=np.int64)
    m = 0
    for i in range(q):
        for k in range(indptr[i], indptr[i + 1]):
            o = owner[indices[k]]
            if stamp[o] != i:  # a segment split into several pieces is listed once
                stamp[o] = i
                out[m] = o
                m += 1
        out_ptr[i + 1] = m
    return out_ptr, out[:m]


@njit(cache=True)
def _stiffness(
    pos: FloatArray,
    radii: FloatArray,
    active: NDArray[np.bool_],
    mass: float,
    a_soc: float,
    b_soc: float,
    k_body: float,
    kappa: float,
    nb_ptr: IntArray,
    nb_idx: IntArray,
    w_ptr: IntArray,
    w_idx: IntArray,
    seg_a: FloatArray,
    seg_b: FloatArray,
    r_pos: FloatArray,
    r_rad: FloatArray,
) -> tuple[float, float]:
    """Upper bounds on the current oscillation frequency ω (rad/s) and friction rate (1/s).

    Gershgorin bounds on the linearised system: agent ``i``'s row holds its own stiffness
    ``Σ_j (A/B·e^{(r_ij−d_ij)/B} + k·[contact])/m`` and as much again off the diagonal
    (``ω² ≤ 2·max_i Σ_j``); likewise ``rate ≤ 2·max_i Σ_j κ·g(r_ij − d_ij)/m``. Walls and
    robots count once (they do not move in response).
    """
    n = pos.shape[0]
    s_max = 0.0
    f_max = 0.0
    for i in range(n):
        if not active[i]:
            continue
        px, py = pos[i, 0], pos[i, 1]
        s_i = 0.0
        f_i = 0.0
        for kk in range(nb_ptr[i], nb_ptr[i + 1]):
            j = nb_idx[kk]
            d = math.sqrt((px - pos[j, 0]) ** 2 + (py - pos[j, 1]) ** 2)
            ov = radii[i] + radii[j] - d
            s_i += 2.0 * a_soc / b_soc * math.exp(ov / b_soc)
            if ov > 0.0:
                s_i += 2.0 * k_body
                f_i += 2.0 * kappa * ov
        for kk in range(w_ptr[i], w_ptr[i + 1]):
            w = w_idx[kk]
            sx, sy = seg_a[w, 0], seg_a[w, 1]
            lx, ly = seg_b[w, 0] - sx, seg_b[w, 1] - sy
            ll = lx * lx + ly * ly
            t = ((px - sx) * lx + (py - sy) * ly) / ll if ll > 0.0 else 0.0
            t = min(max(t, 0.0), 1.0)
            d = math.sqrt((px - sx - t * lx) ** 2 + (py - sy - t * ly) ** 2)
            ov = radii[i] - d
            s_i += a_soc / b_soc * math.exp(ov / b_soc)
            if ov > 0.0:
                s_i += k_body
                f_i += kappa * ov
        for r in range(r_pos.shape[0]):
            d = math.sqrt((px - r_pos[r, 0]) ** 2 + (py - r_pos[r, 1]) ** 2)
            ov = radii[i] + r_rad[r] - d
            s_i += a_soc / b_soc * math.exp(ov / b_soc)
            if ov > 0.0:
                s_i += k_body
                f_i += kappa * ov
        s_max = max(s_max, s_i)
        f_max = max(f_max, f_i)
    return math.sqrt(s_max / mass), f_max / mass


@njit(cache=True)
def _helbing_substeps(
    pos0: FloatArray,
    vel0: FloatArray,
    radii: FloatArray,
    cap: FloatArray,
    dest: FloatArray,
    active: NDArray[np.bool_],
    inv_mass: float,
    tau: float,
    a_soc: float,
    b_soc: float,
    k_body: float,
    kappa: float,
    nb_ptr: IntArray,
    nb_idx: IntArray,
    w_ptr: IntArray,
    w_idx: IntArray,
    seg_a: FloatArray,
    seg_b: FloatArray,
    r_pos0: FloatArray,
    r_vel: FloatArray,
    r_rad: FloatArray,
    cutoff: float,
    bd_ptr: IntArray,
    bd_idx: IntArray,
    bd_strength: float,
    bd_range: float,
    bd_comfort: float,
    dt: float,
    n_sub: int,
    terms: FloatArray,
) -> tuple[FloatArray, FloatArray]:
    """Integrate ``n_sub`` sub-steps from ``(pos0, vel0)``; return the end ``(pos, vel)``.

    ``terms`` ``(8, n, 2)`` (:data:`TERMS` order) receives each term's share of the mean
    velocity change: ``Σ_k term_k·h·(n_sub − k)/n_sub`` (m/s), so that
    ``vel0 + terms.sum(0) = (pos_end − pos0)/dt``. Desired speed = ``cap``.
    """
    n = pos0.shape[0]
    h = dt / n_sub
    pos = pos0.copy()
    vel = vel0.copy()
    acc = np.zeros((n, 2))
    n_rob = r_pos0.shape[0]
    for step in range(n_sub):
        t_now = step * h
        # A velocity change in sub-step `step` moves the agent for the rest of the step: its
        # share of the mean velocity (p_end − p_0)/dt is (n_sub − step)/n_sub.
        w = (n_sub - step) / n_sub
        hw = h * w
        for i in range(n):
            if not active[i]:
                continue
            px, py = pos[i, 0], pos[i, 1]
            vx, vy = vel[i, 0], vel[i, 1]
            ri = radii[i]
            # Desired: relax toward v0·e within τ.
            ex, ey = dest[i, 0] - px, dest[i, 1] - py
            de = math.sqrt(ex * ex + ey * ey)
            if de > 1e-9:
                ex, ey = ex / de, ey / de
            else:
                ex, ey = 0.0, 0.0
            fx = (cap[i] * ex - vx) / tau
            fy = (cap[i] * ey - vy) / tau
            terms[0, i, 0] += fx * hw
            terms[0, i, 1] += fy * hw
            ax, ay = fx, fy
            # Other pedestrians.
            for kk in range(nb_ptr[i], nb_ptr[i + 1]):
                j = nb_idx[kk]
                nx, ny = px - pos[j, 0], py - pos[j, 1]
                d = math.sqrt(nx * nx + ny * ny)
                if d > 1e-12:
                    nx, ny = nx / d, ny / d
                else:
                    # Coincident centres: push apart along ±x by index so they separate.
                    nx, ny = (1.0, 0.0) if i < j else (-1.0, 0.0)
                    d = 0.0
                overlap = ri + radii[j] - d
                soc = a_soc * math.exp(overlap / b_soc) * inv_mass
                terms[1, i, 0] += soc * nx * hw
                terms[1, i, 1] += soc * ny * hw
                ax += soc * nx
                ay += soc * ny
                if overlap > 0.0:
                    body = k_body * overlap * inv_mass
                    tx, ty = -ny, nx
                    dvt = (vel[j, 0] - vx) * tx + (vel[j, 1] - vy) * ty
                    fr = kappa * overlap * dvt * inv_mass
                    terms[2, i, 0] += body * nx * hw
                    terms[2, i, 1] += body * ny * hw
                    terms[3, i, 0] += fr * tx * hw
                    terms[3, i, 1] += fr * ty * hw
                    ax += body * nx + fr * tx
                    ay += body * ny + fr * ty
            # Walls: one term per distinct segment, at its closest point.
            for kk in range(w_ptr[i], w_ptr[i + 1]):
                wseg = w_idx[kk]
                sx, sy = seg_a[wseg, 0], seg_a[wseg, 1]
                lx, ly = seg_b[wseg, 0] - sx, seg_b[wseg, 1] - sy
                ll = lx * lx + ly * ly
                t = ((px - sx) * lx + (py - sy) * ly) / ll if ll > 0.0 else 0.0
                t = min(max(t, 0.0), 1.0)
                nx, ny = px - (sx + t * lx), py - (sy + t * ly)
                d = math.sqrt(nx * nx + ny * ny)
                if d < 1e-12:
                    continue  # on the wall line: no side to push to (the wall guard prevents it)
                nx, ny = nx / d, ny / d
                overlap = ri - d
                mag = a_soc * math.exp(overlap / b_soc)
                fx, fy = 0.0, 0.0
                if overlap > 0.0:
                    mag += k_body * overlap
                    tx, ty = -ny, nx
                    fr = -kappa * overlap * (vx * tx + vy * ty)
                    fx, fy = fr * tx, fr * ty
                fx = (fx + mag * nx) * inv_mass
                fy = (fy + mag * ny) * inv_mass
                terms[4, i, 0] += fx * hw
                terms[4, i, 1] += fy * hw
                ax += fx
                ay += fy
            # Robots: extra bodies moving straight at their current velocity.
            for r in range(n_rob):
                rx = r_pos0[r, 0] + r_vel[r, 0] * t_now
                ry = r_pos0[r, 1] + r_vel[r, 1] * t_now
                nx, ny = px - rx, py - ry
                d = math.sqrt(nx * nx + ny * ny)
                if d >= cutoff + r_rad[r] or d < 1e-12:
                    continue
                nx, ny = nx / d, ny / d
                overlap = ri + r_rad[r] - d
                mag = a_soc * math.exp(overlap / b_soc)
                fx, fy = 0.0, 0.0
                if overlap > 0.0:
                    mag += k_body * overlap
                    tx, ty = -ny, nx
                    fr = kappa * overlap * ((r_vel[r, 0] - vx) * tx + (r_vel[r, 1] - vy) * ty)
                    fx, fy = fr * tx, fr * ty
                fx = (fx + mag * nx) * inv_mass
                fy = (fy + mag * ny) * inv_mass
                terms[5, i, 0] += fx * hw
                terms[5, i, 1] += fy * hw
                ax += fx
                ay += fy
            # Bonding: saturating attraction toward partners beyond the comfort gap.
            for kk in range(bd_ptr[i], bd_ptr[i + 1]):
                j = bd_idx[kk]
                nx, ny = pos[j, 0] - px, pos[j, 1] - py
                d = math.sqrt(nx * nx + ny * ny)
                gap = d - ri - radii[j] - bd_comfort
                if gap <= 0.0 or d < 1e-12:
                    continue
                mag = bd_strength * (1.0 - math.exp(-gap / bd_range)) * inv_mass / d
                terms[6, i, 0] += mag * nx * hw
                terms[6, i, 1] += mag * ny * hw
                ax += mag * nx
                ay += mag * ny
            acc[i, 0] = ax
            acc[i, 1] = ay
        # Synchronous update with the simulator's scheme, capped like the simulator.
        for i in range(n):
            if not active[i]:
                continue
            ux = vel[i, 0] + acc[i, 0] * h
            uy = vel[i, 1] + acc[i, 1] * h
            sp = math.sqrt(ux * ux + uy * uy)
            if sp > cap[i]:
                scale = cap[i] / sp
                terms[7, i, 0] += (ux * scale - ux) * w
                terms[7, i, 1] += (uy * scale - uy) * w
                ux *= scale
                uy *= scale
            vel[i, 0], vel[i, 1] = ux, uy
            pos[i, 0] += ux * h
            pos[i, 1] += uy * h
    return pos, vel
