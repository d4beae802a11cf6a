"""A kinematic stepping model of a small quadruped: our labels for ArtPlanner's motion cost.

ArtPlanner (Wellhausen & Hutter 2023) learns each edge's traversal time, energy and failure risk
from rollouts of ANYmal's locomotion policy in simulation. We have no such policy, so the labels
come from this model of a Go1-sized quadruped walking straight along the edge, evaluated on the
height map much more densely than the network sees it:

* the feet walk two tracks ``stance_width / 2`` either side of the edge, the body's centre the
  middle one; each track is sampled ``DENSE`` times from ``stance_length / 2`` behind the start to
  as far past the end (the body overhangs both);
* **step**: the largest rise or drop along a foot track within ``step_window`` (one 0.1 m cell):
  above ``max_step`` the leg cannot reach;
* **pitch**: the slope between the hind and front foothold (``stance_length`` apart) at every
  station of the edge; **roll**: between the left and right track. Above ``max_slope`` /
  ``max_roll`` the robot slips or tips;
* **roughness**: the largest deviation of a foot track from its running median over
  ``rough_window`` (a clean step does not count, a bump does): above ``max_roughness`` no
  foothold is reliable.

An edge is feasible when all four stay within their limits over its whole length. Its time
per metre is the mean of ``1 / v`` over the stations, ``v = v_max · f_pitch · f_rough · f_step``:
uphill costs more than downhill (``1 - 0.5 p⁺/p_max - 0.25 p⁻/p_max``), rough ground up to half
the speed, a station within ``step_window`` of a rise above ``slow_step`` 0.6×.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field
from scipy import ndimage

DENSE = 64
"""Samples per track of the labelling model (≤ 2.5 cm apart on a 1 m edge)."""


class SteppingParams(BaseModel):
    """A Go1-sized quadruped's stepping limits (m, rad, m/s); defaults after the Unitree Go1."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    stance_length: float = Field(0.38, gt=0, description="m, hind to front foothold")
    stance_width: float = Field(0.25, gt=0, description="m, left to right foothold")
    max_step: float = Field(0.15, gt=0, description="m, highest rise or drop one leg reaches")
    step_window: float = Field(0.1, gt=0, description="m along a track over which a rise counts")
    max_slope: float = Field(math.radians(25), gt=0, lt=math.pi / 2,
                             description="rad, steepest pitch walked")
    max_roll: float = Field(math.radians(20), gt=0, lt=math.pi / 2,
                            description="rad, steepest roll walked")
    max_roughness: float = Field(0.05, gt=0, description="m, largest foothold deviation")
    rough_window: float = Field(0.3, gt=0, description="m, running-median window of roughness")
    slow_step: float = Field(0.04, gt=0, description="m, rise above which the robot slows")
    v_max: float = Field(0.8, gt=0, description="m/s on level, smooth ground")


def track_points(a: NDArray[np.float64], b: NDArray[np.float64], p: SteppingParams
                 ) -> NDArray[np.float64]:
    """World points ``(n, 3, DENSE, 2)`` of the left, centre and right track of edges ``a→b``.

    ``a``, ``b`` are ``(n, 2)`` (m); each track runs from ``stance_length / 2`` behind ``a`` to
    as far past ``b``.
    """
    d = b - a
    length = np.maximum(np.hypot(d[:, 0], d[:, 1]), 1e-9)
    u = d / length[:, None]
    n = np.stack([-u[:, 1], u[:, 0]], axis=-1)
    half = p.stance_length / 2
    s = -half + np.linspace(0.0, 1.0, DENSE)[None, :] * (length[:, None] + 2 * half)  # (n, D)
    lat = np.array([p.stance_width / 2, 0.0, -p.stance_width / 2])
    return (a[:, None, None, :] + s[:, None, :, None] * u[:, None, None, :]
            + lat[None, :, None, None] * n[:, None, None, :])


def stepping_labels(z: NDArray[np.float64], length: NDArray[np.float64], p: SteppingParams
                    ) -> tuple[NDArray[np.bool_], NDArray[np.float64]]:
    """Feasibility ``(n,)`` and time per metre ``(n,)`` (s/m) of edges from their tracks.

    Args:
        z: ``(n, 3, DENSE)`` ground heights (m) at :func:`track_points`.
        length: ``(n,)`` edge lengths (m).
        p: the robot's limits.
    """
    n = len(length)
    ds = (length + p.stance_length) / (DENSE - 1)  # (n,)
    idx = np.arange(DENSE)
    s = idx[None, :] * ds[:, None] - p.stance_length / 2  # (n, D), 0 at the edge's start
    on_edge = (s >= -1e-9) & (s <= length[:, None] + 1e-9)
    feet = z[:, [0, 2], :]  # (n, 2, D)
    # step: largest |z(s + w) - z(s)| along a foot track, w = step_window (>= one sample)
    k = np.maximum(np.rint(p.step_window / ds).astype(np.int64), 1)
    j = np.minimum(idx[None, :] + k[:, None], DENSE - 1)  # (n, D)
    ahead = np.take_along_axis(feet, np.broadcast_to(j[:, None, :], feet.shape), axis=2)
    rise = np.abs(ahead - feet).max(axis=1)  # (n, D)
    step = rise.max(axis=1)
    # pitch between hind and front footholds (mean of both tracks), at stations on the edge
    m = np.maximum(np.rint(p.stance_length / 2 / ds).astype(np.int64), 1)
    mid = feet.mean(axis=1)  # (n, D)
    front = np.take_along_axis(mid, np.minimum(idx[None, :] + m[:, None], DENSE - 1), axis=1)
    hind = np.take_along_axis(mid, np.maximum(idx[None, :] - m[:, None], 0), axis=1)
    pitch = (front - hind) / (2 * m * ds)[:, None]  # (n, D), > 0 uphill
    roll = (z[:, 0, :] - z[:, 2, :]) / p.stance_width
    # roughness: deviation of each foot track from its running median, which follows a clean
    # step (that is the step limit's business) but not a bump or a hole narrower than half
    # the window
    w = max(round(p.rough_window / float(np.mean(ds))), 3)
    smooth = ndimage.median_filter(feet, size=(1, 1, w), mode="nearest")
    rough = np.abs(feet - smooth).max(axis=1)  # (n, D)

    def worst(v: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.asarray(np.where(on_edge, v, 0.0).max(axis=1), dtype=np.float64)

    tan_slope, tan_roll = math.tan(p.max_slope), math.tan(p.max_roll)
    feasible = (
        (step <= p.max_step) & (worst(np.abs(pitch)) <= tan_slope)
        & (worst(np.abs(roll)) <= tan_roll) & (worst(rough) <= p.max_roughness)
    )
    f_pitch = 1.0 - 0.5 * np.clip(pitch, 0, None) / tan_slope \
        - 0.25 * np.clip(-pitch, 0, None) / tan_slope
    f_rough = 1.0 - 0.5 * np.clip(rough / p.max_roughness, 0, 1)
    near_step = ndimage.maximum_filter1d(rise, size=2 * int(k.max()) + 1, axis=1) > p.slow_step
    f_step = np.where(near_step, 0.6, 1.0)
    v = p.v_max * np.clip(f_pitch * f_rough * f_step, 0.1, 1.0)
    inv = np.where(on_edge, 1.0 / v, 0.0).sum(axis=1) / np.maximum(on_edge.sum(axis=1), 1)
    assert inv.shape == (n,)
    return np.asarray(feasible, dtype=bool), np.asarray(inv, dtype=np.float64)
