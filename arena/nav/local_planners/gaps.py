"""Gaps in a 2D laser scan: the openings a robot may drive through (gap-based planners).

A *gap* is an angular interval of a scan, bounded by two side points, behind which there is free
space. Two kinds are found, as in the gap-based planners of the BARN challenge (DRAGON) and their
ancestors (nearest-gap and follow-the-gap navigation):

- **swept** gaps: a run of consecutive beams without a return within ``max_range`` (no hit, or
  farther than the gap horizon). Its sides are the returns of the beams just before and just
  after the run (the run's own last beam at ``max_range`` where a partial scan ends open).
- **radial** gaps: a jump of more than ``jump`` between the ranges of two neighbouring beams
  that both return. The nearer of the two returns is one side; the other side is the return
  closest to it on the far side of the jump (searched over half a turn), so the gap's width is
  the narrowest passage next to the edge, not the jump itself. A rising edge (near, then far,
  counter-clockwise) gives the gap's right side, a falling edge its left side.

Sides are ordered counter-clockwise: ``right`` has the smaller bearing. A gap found twice (both
edges of one opening) is kept once. Everything is in the sensor frame (robot axes, origin at the
sensor); :attr:`Gaps.right_points` and :attr:`Gaps.left_points` add the sensor's offset.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

TWO_PI = 2.0 * math.pi


@dataclass(frozen=True)
class Gaps:
    """The ``n`` gaps of one scan.

    Attributes:
        right_angle: ``(n,)`` bearing (rad, sensor frame) of the right side; increasing
            counter-clockwise, ``left_angle > right_angle`` (unwrapped: may exceed π).
        right_range: ``(n,)`` range (m) of the right side from the sensor.
        left_angle: ``(n,)`` bearing (rad) of the left side.
        left_range: ``(n,)`` range (m) of the left side.
        swept: ``(n,)`` bool, True for a swept gap (beams without a return), False for radial.
        origin: ``(2,)`` sensor position in the robot frame (m).
    """

    right_angle: NDArray[np.float64]
    right_range: NDArray[np.float64]
    left_angle: NDArray[np.float64]
    left_range: NDArray[np.float64]
    swept: NDArray[np.bool_]
    origin: NDArray[np.float64]

    def __len__(self) -> int:
        return len(self.right_angle)

    @classmethod
    def empty(cls, origin: NDArray[np.float64] | None = None) -> Gaps:
        """No gaps (sensor at ``origin``, default the robot's centre)."""
        z = np.zeros(0)
        o = np.zeros(2) if origin is None else np.asarray(origin, dtype=np.float64).reshape(2)
        return cls(z, z, z, z, np.zeros(0, dtype=bool), o)

    @property
    def right_points(self) -> NDArray[np.float64]:
        """``(n, 2)`` right side points (m, robot frame)."""
        return _polar(self.right_range, self.right_angle, self.origin)

    @property
    def left_points(self) -> NDArray[np.float64]:
        """``(n, 2)`` left side points (m, robot frame)."""
        return _polar(self.left_range, self.left_angle, self.origin)

    @property
    def width(self) -> NDArray[np.float64]:
        """``(n,)`` distance (m) between the two sides: the widest disc diameter that fits."""
        d = self.left_points - self.right_points
        return np.asarray(np.hypot(d[:, 0], d[:, 1]), dtype=np.float64)

    @property
    def bearing(self) -> NDArray[np.float64]:
        """``(n,)`` bearing (rad, wrapped to ``(-π, π]``) of the middle of the gap's interval."""
        mid = 0.5 * (self.right_angle + self.left_angle)
        return np.asarray(np.angle(np.exp(1j * mid)), dtype=np.float64)


def _polar(r: NDArray[np.float64], a: NDArray[np.float64],
           origin: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.stack([origin[0] + r * np.cos(a), origin[1] + r * np.sin(a)], axis=-1)


def find_gaps(
    ranges: NDArray[np.float64],
    angles: NDArray[np.float64],
    *,
    max_range: float,
    jump: float,
    origin: NDArray[np.float64] | None = None,
) -> Gaps:
    """The swept and radial gaps of a scan (see the module docstring).

    Args:
        ranges: ``(beams,)`` ranges (m); ``inf``/``nan``/``≤ 0`` or ``≥ max_range`` mean open.
        angles: ``(beams,)`` beam bearings (rad, sensor frame), any order; a scan whose beams
            cover the whole turn is treated as circular.
        max_range: gap horizon (m): returns at least this far count as open space.
        jump: range difference (m) between neighbouring returns that makes a radial gap.
        origin: ``(2,)`` sensor position in the robot frame (m); default the robot's centre.

    Returns:
        The gaps, sorted by their right side's bearing.

    Raises:
        ValueError: ``ranges`` and ``angles`` differ in shape, or a non-positive horizon/jump.
    """
    if not (max_range > 0 and jump > 0):
        raise ValueError(f"max_range ({max_range}) and jump ({jump}) must be > 0")
    o = np.zeros(2) if origin is None else np.asarray(origin, dtype=np.float64).reshape(2)
    r = np.asarray(ranges, dtype=np.float64).reshape(-1)
    a = np.asarray(angles, dtype=np.float64).reshape(-1)
    if r.shape != a.shape:
        raise ValueError(f"ranges {r.shape} and angles {a.shape} differ in shape")
    ok = np.isfinite(a)
    r, a = r[ok], np.angle(np.exp(1j * a[ok]))
    order = np.argsort(a, kind="stable")
    r, a = r[order], a[order]
    n = len(r)
    if n < 2:
        return Gaps.empty(o)
    with np.errstate(invalid="ignore"):
        hit = np.isfinite(r) & (r > 0) & (r < max_range)
    if not hit.any():
        return Gaps.empty(o)  # nothing in sight: no side to pass
    step = float(np.median(np.diff(a)))
    circular = step > 0 and (a[-1] - a[0]) + 1.5 * step >= TWO_PI
    rc = np.where(hit, r, max_range)
    if circular:
        # Start the scan at a return so that no run of open beams wraps past the end; the
        # angles of the beams moved to the back gain a turn, so they keep increasing.
        k = int(np.argmax(hit))
        rc, hit = np.roll(rc, -k), np.roll(hit, -k)
        a = np.concatenate([a[k:], a[:k] + TWO_PI])
    pts = np.stack([rc * np.cos(a), rc * np.sin(a)], axis=-1)

    sides: list[tuple[int, int, bool]] = []  # (right index, left index, swept); n = wrapped 0
    # -- swept: runs of open beams ---------------------------------------------------------------
    edges = np.diff(np.concatenate([[0], (~hit).astype(np.int8), [0]]))
    for s, e in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1, strict=True):
        right = s - 1 if s > 0 else s
        # past the scan's end: circular, the first beam a turn later; else the run's own end
        left = e + 1 if e < n - 1 else (n if circular else e)
        sides.append((int(right), int(left), True))
    # -- radial: jumps between neighbouring returns ----------------------------------------------
    half = max(1, round(math.pi / step)) if step > 0 else n
    last = n if circular else n - 1
    idx = np.arange(n)
    for i in range(last):
        j = (i + 1) % n
        if not (hit[i] and hit[j]) or abs(rc[j] - rc[i]) <= jump:
            continue
        if rc[j] > rc[i]:  # rising: the near return i is the right side
            cand = idx[i + 1:i + 1 + half] if not circular else (i + 1 + idx[:half]) % n
            near, is_right = i, True
        else:  # falling: the near return j is the left side
            lo = i + 1 - half
            cand = idx[max(lo, 0):i + 1] if not circular else (idx[:half] + lo) % n
            near, is_right = j, False
        cand = cand[hit[cand] & (cand != near)]
        if len(cand) == 0:
            continue
        d = np.hypot(*(pts[cand] - pts[near]).T)
        other = int(cand[int(np.argmin(d))])
        # unwrap: the right side's index must come first counter-clockwise
        if is_right:
            sides.append((near, other if other > near else other + n, False))
        else:
            near_u = near if near >= other else near + n  # j wrapped to 0 (i = n - 1)
            sides.append((other, near_u, False))

    seen: set[tuple[int, int]] = set()
    rows = []
    for right, left, swept in sorted(sides):
        if (right, left) in seen or left <= right:
            continue
        seen.add((right, left))
        rows.append((right, left, swept))
    if not rows:
        return Gaps.empty(o)
    ri = np.array([x[0] for x in rows])
    li = np.array([x[1] for x in rows])
    turns = np.where(li >= n, TWO_PI, 0.0)
    return Gaps(
        right_angle=a[ri % n], right_range=rc[ri % n],
        left_angle=a[li % n] + turns, left_range=rc[li % n],
        swept=np.array([x[2] for x in rows], dtype=bool), origin=o,
    )
