"""Multi-object tracking of detected people: constant-velocity Kalman filters, optimal assignment.

:class:`Tracker` turns per-frame detections (``(n, 2)`` positions, m, world frame) into tracks
with a stable id, position, velocity and covariance. Per :meth:`Tracker.update`:

1. **Predict** every track to the frame's time with the constant-velocity model: state
   ``[x, y, vx, vy]``, white-noise acceleration of standard deviation ``accel_std`` (m/s²),
   ``Q = G G^T σ_a²`` with ``G = [[dt²/2, 0], [0, dt²/2], [dt, 0], [0, dt]]``.
2. **Associate** detections to tracks by minimising the summed squared Mahalanobis distance
   (``scipy.optimize.linear_sum_assignment``); a pair is only accepted inside the gate
   ``d² ≤ gate`` (default 9.21: the 99 % point of χ² with 2 degrees of freedom), so a detection
   far from every track starts a new one instead of stealing an old one.
3. **Update** each associated track with its detection (measurement noise ``meas_std``, m).
4. **Birth**: an unassociated detection starts a *tentative* track; it is *confirmed* after
   ``confirm_hits`` associated frames (default 2), and reported only then (a single false
   detection never becomes a track). A tentative track missed once is dropped.
5. **Death**: a confirmed track not associated for more than ``max_coast`` s (default 1.0 s) is
   dropped; until then it coasts on its prediction (a person hidden behind another for a
   moment keeps their id).

New tracks start at the detection with zero velocity and a velocity variance of
``(init_speed_std)²`` (a walking person's speed is unknown until the second detection). Ids
count up from 0 per tracker and are never reused. Everything is deterministic: no random draw.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import BaseModel, ConfigDict, Field
from scipy.optimize import linear_sum_assignment

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]

_H = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]])
_BIG = 1e12  # cost of a pair outside the gate (never accepted)


class TrackerParams(BaseModel):
    """Parameters of :class:`Tracker` (SI units)."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    accel_std: float = Field(1.0, gt=0, description="m/s², white-noise acceleration std")
    meas_std: float = Field(0.1, gt=0, description="m, detection position noise std")
    init_speed_std: float = Field(1.5, gt=0, description="m/s, velocity std of a new track")
    gate: float = Field(9.21, gt=0, description="largest squared Mahalanobis distance of a pair")
    confirm_hits: int = Field(2, ge=1, description="associated frames that confirm a track")
    max_coast: float = Field(1.0, ge=0, description="s a confirmed track lives undetected")


@dataclass(frozen=True, eq=False)
class Tracks:
    """The confirmed tracks after an update (``k`` tracks, in id order).

    Attributes:
        ids: ``(k,)`` track ids.
        positions: ``(k, 2)`` m.
        velocities: ``(k, 2)`` m/s.
        covariances: ``(k, 4, 4)`` of ``[x, y, vx, vy]``.
        detected: ``(k,)`` bool, associated with a detection in this frame (else coasting).
    """

    ids: I64
    positions: F64
    velocities: F64
    covariances: F64
    detected: NDArray[np.bool_]

    def __len__(self) -> int:
        return int(self.ids.shape[0])


class Tracker:
    """Tracks people from their detections, one :meth:`update` per frame (see the module doc)."""

    def __init__(self, params: TrackerParams | None = None) -> None:
        self.params = params or TrackerParams()
        self.reset()

    def reset(self) -> None:
        """Forget every track (ids start again at 0)."""
        self._x = np.zeros((0, 4))
        self._p = np.zeros((0, 4, 4))
        self._id = np.zeros(0, dtype=np.int64)
        self._hits = np.zeros(0, dtype=np.int64)
        self._last = np.zeros(0)  # time of the last association
        self._time: float | None = None
        self._next_id = 0

    # -- the steps ------------------------------------------------------------------------------
    def _predict(self, dt: float) -> None:
        if dt <= 0.0 or self._x.shape[0] == 0:
            return
        f = np.eye(4)
        f[0, 2] = f[1, 3] = dt
        g = np.array([[0.5 * dt * dt, 0.0], [0.0, 0.5 * dt * dt], [dt, 0.0], [0.0, dt]])
        q = g @ g.T * self.params.accel_std**2
        self._x = self._x @ f.T
        self._p = f @ self._p @ f.T + q

    def _associate(self, z: F64) -> tuple[I64, I64, F64]:
        """``(track rows, detection rows)`` of the accepted pairs and the innovations' ``S``."""
        k, n = self._x.shape[0], z.shape[0]
        r = self.params.meas_std**2 * np.eye(2)
        s = _H @ self._p @ _H.T + r  # (k, 2, 2)
        if k == 0 or n == 0:
            return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64), s
        y = z[None, :, :] - self._x[:, None, :2]  # (k, n, 2)
        s_inv = np.linalg.inv(s)
        d2 = np.einsum("kni,kij,knj->kn", y, s_inv, y)
        cost = np.where(d2 <= self.params.gate, d2, _BIG)
        rows, cols = linear_sum_assignment(cost)
        ok = cost[rows, cols] < _BIG
        return rows[ok].astype(np.int64), cols[ok].astype(np.int64), s

    def _correct(self, rows: I64, z: F64, s: F64) -> None:
        if rows.shape[0] == 0:
            return
        p = self._p[rows]
        gain = p @ _H.T @ np.linalg.inv(s[rows])  # (m, 4, 2)
        innov = z - self._x[rows, :2]
        self._x[rows] = self._x[rows] + np.einsum("mij,mj->mi", gain, innov)
        self._p[rows] = (np.eye(4) - gain @ _H) @ p

    def update(self, time: float, detections: ArrayLike) -> Tracks:
        """Advance to ``time`` (s) with this frame's ``(n, 2)`` detections (m); the tracks.

        Raises:
            ValueError: ``time`` earlier than the previous frame's, or detections not ``(n, 2)``
                finite.
        """
        z = np.asarray(detections, dtype=np.float64).reshape(-1, 2)
        if not np.all(np.isfinite(z)):
            raise ValueError("detections must be finite (n, 2) positions in metres")
        time = float(time)
        if self._time is not None and time < self._time:
            raise ValueError(f"time went back: {time} s after {self._time} s")
        dt = 0.0 if self._time is None else time - self._time
        self._time = time
        self._predict(dt)
        rows, cols, s = self._associate(z)
        self._correct(rows, z[cols], s)
        p = self.params
        hit = np.zeros(self._x.shape[0], dtype=bool)
        hit[rows] = True
        self._hits[rows] += 1
        self._last[rows] = time
        confirmed = self._hits >= p.confirm_hits
        # tentative tracks die at their first miss; confirmed ones after max_coast s unseen
        keep = np.where(confirmed, time - self._last <= p.max_coast + 1e-9, hit)
        self._drop(~keep)
        hit = hit[keep]
        self._birth(np.setdiff1d(np.arange(z.shape[0]), cols), z, time)
        hit = np.concatenate([hit, np.ones(self._x.shape[0] - hit.shape[0], dtype=bool)])
        return self._report(hit)

    def _drop(self, gone: NDArray[np.bool_]) -> None:
        if not gone.any():
            return
        keep = ~gone
        self._x, self._p, self._id = self._x[keep], self._p[keep], self._id[keep]
        self._hits, self._last = self._hits[keep], self._last[keep]

    def _birth(self, new: I64, z: F64, time: float) -> None:
        m = new.shape[0]
        if m == 0:
            return
        x = np.zeros((m, 4))
        x[:, :2] = z[new]
        p0 = np.diag([self.params.meas_std**2] * 2 + [self.params.init_speed_std**2] * 2)
        self._x = np.concatenate([self._x, x])
        self._p = np.concatenate([self._p, np.broadcast_to(p0, (m, 4, 4))])
        self._id = np.concatenate([self._id, self._next_id + np.arange(m, dtype=np.int64)])
        self._next_id += m
        self._hits = np.concatenate([self._hits, np.ones(m, dtype=np.int64)])
        self._last = np.concatenate([self._last, np.full(m, time)])

    def _report(self, detected: NDArray[np.bool_]) -> Tracks:
        ok = self._hits >= self.params.confirm_hits
        order = np.argsort(self._id[ok], kind="stable")
        return Tracks(
            self._id[ok][order].copy(), self._x[ok][order, :2].copy(),
            self._x[ok][order, 2:].copy(), self._p[ok][order].copy(), detected[ok][order].copy(),
        )
