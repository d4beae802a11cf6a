"""Social term of :mod:`arena.crowd.models.pysocial`: the unordered-pair pipeline.

Each block of pairs goes through :func:`_pair_geometry`, NumPy's ``arctan2``,
:func:`_pair_exponents`, NumPy's ``exp`` and :func:`_pair_accumulate` (see the model's
docstring, "Implementation"); :class:`_PairWork` holds a block's scratch arrays.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

_TWO_PI = 2.0 * math.pi


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
