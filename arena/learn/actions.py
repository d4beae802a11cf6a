"""Action spaces and decoding to body-twist commands ``[vx, vy, ω]`` (arena_specs §8.3).

* ``discrete`` + ``robot``: the preset's ``actions.discrete`` list (Jackal: 7 actions).
* ``discrete`` + ``custom``: ``linspace(linear_range, n_linear) × linspace(angular_range,
  n_angular)``, plus ``(0, 0)`` if the grid lacks it; linear-major order.
* ``continuous``: a Box over the preset's ``actions.continuous`` ranges, ``[v, ω]`` for
  non-holonomic robots and ``[vx, vy, ω]`` for holonomic ones (Arena's raw units), or with
  ``normalize`` a ``[−1, 1]`` Box mapped linearly onto those ranges.

Decoded commands are clipped to the robot's velocity limits; non-holonomic robots get
``vy = 0``.
"""

from __future__ import annotations

import numpy as np
from gymnasium import spaces
from numpy.typing import ArrayLike, NDArray

from arena.learn.config import ActionConfig
from arena.robots.model import LinearRangeXY, RobotModel

FloatArray = NDArray[np.float64]


def custom_grid(
    linear: tuple[float, float], angular: tuple[float, float], n_linear: int, n_angular: int
) -> FloatArray:
    """``(k, 2)`` ``[v m/s, ω rad/s]`` grid with ``(0, 0)`` appended when absent."""
    v, w = np.meshgrid(np.linspace(*linear, n_linear), np.linspace(*angular, n_angular),
                       indexing="ij")
    grid = np.column_stack([v.ravel(), w.ravel()])
    if not np.any(np.all(np.isclose(grid, 0.0), axis=1)):
        grid = np.vstack([grid, [0.0, 0.0]])
    return grid


class ActionDecoder:
    """The action space of one robot and the decoding of batches of actions.

    Args:
        config: the ``learning.env.action`` block.
        robot: the robot model.
    """

    def __init__(self, config: ActionConfig, robot: RobotModel) -> None:
        self.config = config
        self.holonomic = robot.holonomic
        lim = robot.limits()
        self.low = np.array([lim.vx_min, lim.vy_min if self.holonomic else 0.0, -lim.omega_max])
        self.high = np.array([lim.vx_max, lim.vy_max if self.holonomic else 0.0, lim.omega_max])
        cont = robot.actions.continuous
        lin = cont.linear_range
        if isinstance(lin, LinearRangeXY):
            xr, yr = lin.x, lin.y
        else:
            xr, yr = (float(lin[0]), float(lin[1])), (0.0, 0.0)
        self.table: FloatArray | None = None
        self.space: spaces.Space[np.ndarray] | spaces.Discrete
        if config.type == "discrete":
            if config.discretization == "robot":
                if not robot.actions.discrete:
                    raise ValueError(f"robot {robot.name!r} has no discrete actions")
                vw = np.array([[a.linear, a.angular] for a in robot.actions.discrete])
            else:
                vw = custom_grid(xr, cont.angular_range, config.n_linear, config.n_angular)
            self.table = np.column_stack([vw[:, 0], np.zeros(len(vw)), vw[:, 1]])
            # clipped once: clipping is elementwise, so clip(table)[idx] == clip(table[idx])
            self._clipped_table = np.clip(self.table, self.low, self.high)
            # its rows as (1, 3) arrays, for one integer action (the single env's case)
            self._clipped_rows = [row[None] for row in self._clipped_table]
            self.space = spaces.Discrete(len(self.table))
        else:
            if self.holonomic:
                lo = [xr[0], yr[0], cont.angular_range[0]]
                hi = [xr[1], yr[1], cont.angular_range[1]]
            else:
                lo = [xr[0], cont.angular_range[0]]
                hi = [xr[1], cont.angular_range[1]]
            self.range_low, self.range_high = np.array(lo), np.array(hi)
            if config.normalize:
                self.space = spaces.Box(-1.0, 1.0, (len(lo),), np.float32)
            else:
                self.space = spaces.Box(np.array(lo, np.float32), np.array(hi, np.float32))

    def decode(self, actions: ArrayLike) -> FloatArray:
        """``(N, 3)`` commands ``[vx, vy, ω]`` for ``N`` actions (``(N,)`` indices or ``(N, d)``).

        Args:
            actions: discrete indices ``(N,)`` or continuous actions ``(N, d)``.
        """
        if self.table is not None:
            if isinstance(actions, int | np.integer):
                # one index: a copy of its row (list indexing wraps negative indices and
                # raises IndexError as numpy's fancy indexing does), one numpy call instead
                # of three
                row: FloatArray = self._clipped_rows[actions].copy()
                return row
            idx = np.asarray(actions, dtype=np.int64).reshape(-1)
            table_cmd: FloatArray = self._clipped_table[idx]  # a fresh array (fancy indexing)
            return table_cmd
        a = np.asarray(actions, dtype=np.float64)
        d = 3 if self.holonomic else 2
        a = a.reshape(-1, d)
        if self.config.normalize:
            a = self.range_low + (np.clip(a, -1.0, 1.0) + 1.0) / 2.0 * (
                self.range_high - self.range_low
            )
        cmd = np.zeros((a.shape[0], 3))
        if self.holonomic:
            cmd[:] = a
        else:
            cmd[:, 0], cmd[:, 2] = a[:, 0], a[:, 1]
        return np.clip(cmd, self.low, self.high)
