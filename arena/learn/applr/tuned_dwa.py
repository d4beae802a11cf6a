"""Our DWA with its parameters set from the outside: what an APPLR action acts on.

:class:`TunedDWA` owns a :class:`~arena.nav.local_planners.dwa.DWAPlanner` and applies an
action (:func:`~arena.learn.applr.space.parameter_values`): the DWA fields among the tuned
parameters replace the planner's, the two fractions cap the velocity box the planner sees
(navigation2's ``set_speed_limit``: the planner's limits change, not its code). A cap never
asks for more than the robot can brake in one cycle: the capped ``vx_max`` (``omega_max``) is
at least the current ``vx`` (``|ω|``) minus one cycle of acceleration, so every command stays
within one tick of acceleration of the current twist, as the local-planner contract requires.

It records the last observation it was given (:attr:`TunedDWA.last_obs`): APPLR chooses the next
parameters from it.
"""

from __future__ import annotations

import dataclasses
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from arena.learn.applr.space import CAPS, PARAMETERS, TunedParam, parameter_values
from arena.nav.local_planners.base import KINEMATICS, LocalObservation
from arena.nav.local_planners.dwa import DWAPlanner
from arena.robots.limits import VelocityLimits


def capped_limits(
    limits: VelocityLimits, twist: NDArray[np.float64], dt: float, speed: float, turn: float
) -> VelocityLimits:
    """``limits`` with ``vx_max`` and ``omega_max`` scaled by ``speed`` / ``turn`` (fractions).

    Never below what one cycle of braking reaches from ``twist`` ``(3,)`` (m/s, rad/s) in
    ``dt`` s, never above the robot's own limits.
    """
    vx_floor = float(twist[0]) - limits.acc_x * max(dt, 0.0)
    w_floor = abs(float(twist[2])) - limits.acc_omega * max(dt, 0.0)
    vx_max = min(limits.vx_max, max(speed * limits.vx_max, vx_floor))
    omega_max = min(limits.omega_max, max(turn * limits.omega_max, w_floor))
    return dataclasses.replace(limits, vx_max=max(vx_max, limits.vx_min), omega_max=omega_max)


class TunedDWA:
    """DWA driving with the parameters of the last :meth:`set_action` (defaults after reset).

    Args:
        base: DWA's parameters that APPLR does not tune (defaults if omitted).
        params: the tuned parameters (the policy file's ranges).
    """

    supports: ClassVar[frozenset[str]] = KINEMATICS

    def __init__(self, base: DWAPlanner.Params | None = None,
                 params: tuple[TunedParam, ...] = PARAMETERS) -> None:
        self.base = base if base is not None else DWAPlanner.Params()
        self.tuned = params
        self.dwa = DWAPlanner(self.base)
        self.reset()

    def reset(self) -> None:
        """DWA's defaults (action 0), a fresh DWA, no observation yet."""
        self.dwa.reset()
        self.last_obs: LocalObservation | None = None
        self.set_action(np.zeros(len(self.tuned)))

    def set_action(self, action: NDArray[Any]) -> dict[str, float]:
        """Apply ``action`` ``(k,)``; returns the parameter values it maps to."""
        a = np.clip(np.nan_to_num(np.asarray(action, dtype=np.float64).reshape(-1)), -1.0, 1.0)
        values = parameter_values(a, self.tuned)
        update: dict[str, Any] = {
            k: (int(v) if isinstance(getattr(self.base, k), int) else v)
            for k, v in values.items() if k not in CAPS
        }
        # one validation per period: out-of-range values would be a bug in the ranges
        self.dwa.params = DWAPlanner.Params.model_validate({**self.base.model_dump(), **update})
        self.speed_fraction = values.get("speed_fraction", 1.0)
        self.turn_fraction = values.get("turn_fraction", 1.0)
        self.action = a
        self.values = values
        return values

    def compute(self, obs: LocalObservation) -> NDArray[np.float64]:
        """DWA's command for ``obs`` under the current parameters and caps."""
        self.last_obs = obs
        twist = np.asarray(obs.twist, dtype=np.float64).reshape(3)
        lim = capped_limits(obs.limits, twist, float(obs.dt), self.speed_fraction,
                            self.turn_fraction)
        return self.dwa.compute(dataclasses.replace(obs, limits=lim))
