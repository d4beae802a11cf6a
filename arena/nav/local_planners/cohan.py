"""CoHAN: human-aware Timed Elastic Band (Singamaneni et al. 2021; ROS ``hateb_local_planner``).

Description:
    The :mod:`TEB <arena.nav.local_planners.teb>` band optimisation with CoHAN's human-aware
    costs added on the *predicted* human trajectories (constant velocity from
    :attr:`LocalObservation.pedestrians`, evaluated at the band's time stamps). For every inner
    band pose / segment ``i`` and human ``j`` (within ``ped_range``):

    - **safety** (``human_safety_weight``): hinge ``human_safety_dist − d_ij`` on the distance
      ``d_ij`` (m, centre to centre) between robot and human — a wider berth than the TEB
      dynamic-obstacle clearance;
    - **visibility** (``visibility_weight``): for a walking human (speed above
      ``min_walking_speed``), robot positions outside the human's field of view (``fov``, full
      cone angle around the walking direction) are penalised by ``(|α| − fov/2) / π`` × ``(1 −
      d_ij / visibility_range)⁺`` with ``α`` the bearing of the robot from the human's walking
      direction — approaching from behind, close, costs most; passing in front, in view, is free;
    - **relative velocity / time to collision** (``ttc_weight``): with the closing speed
      ``c = (v_robot,i − v_human,j) · u_ij`` (``u_ij`` the unit vector robot → human) and the gap
      ``g = d_ij − robot_radius − ped_radius`` (at least ``min_gap``), the inverse
      time-to-collision ``c / g`` above ``1 / ttc_threshold`` is penalised.

    Everything else (band, kinematics, obstacles, command) is TEB's.

Arguments:
    See :class:`CohanPlanner.Params` (TEB's parameters plus the human-aware ones).
"""

from __future__ import annotations

import math

import numpy as np
from pydantic import Field

from arena.nav.local_planners.base import LOCAL_PLANNERS
from arena.nav.local_planners.teb import TEBPlanner
from arena.nav.local_planners.teb_band import BandContext, FloatArray, IntArray


@LOCAL_PLANNERS.register("cohan", tags=("classic", "optimisation", "social"))
class CohanPlanner(TEBPlanner):
    """Human-aware TEB (CoHAN / HATEB): TEB plus safety, visibility and TTC costs on humans.

    Args:
        params: validated :class:`CohanPlanner.Params` (defaults if omitted).
    """

    class Params(TEBPlanner.Params):
        """Parameters of :class:`CohanPlanner` (TEB's plus the human-aware terms)."""

        human_safety_dist: float = Field(
            1.2, ge=0, description="m, robot–human centre distance below which safety costs"
        )
        human_safety_weight: float = Field(20.0, ge=0, description="weight of the safety hinge")
        visibility_weight: float = Field(
            30.0, ge=0, description="weight of being close outside a human's field of view"
        )
        fov: float = Field(
            2.0 * math.pi / 3.0, gt=0, le=2 * math.pi,
            description="rad, full angle of a human's field of view around the walking direction",
        )
        visibility_range: float = Field(
            3.0, gt=0, description="m, distance beyond which visibility does not matter"
        )
        min_walking_speed: float = Field(
            0.1, ge=0, description="m/s, humans slower than this have no known facing"
        )
        ttc_weight: float = Field(10.0, ge=0, description="weight of the inverse-TTC hinge")
        ttc_threshold: float = Field(
            3.0, gt=0, description="s, times to collision below this are penalised"
        )
        min_gap: float = Field(0.05, gt=0, description="m, smallest gap used in the TTC term")

    def __init__(self, params: CohanPlanner.Params | None = None) -> None:
        super().__init__(params if params is not None else self.Params())

    @property
    def _c(self) -> CohanPlanner.Params:
        return self.params  # type: ignore[return-value]

    def extra_residuals(
        self, pos: FloatArray, th: FloatArray, dt: FloatArray, ctx: BandContext
    ) -> list[FloatArray]:
        """Safety, visibility and inverse-TTC residuals (rows: poses/segments × humans)."""
        if len(ctx.peds) == 0:
            return []
        p = self._c
        n = ctx.n
        inner = pos[1:n]
        pred = ctx.ped_pred  # (N+1, J, 2)
        rel = inner[:, None, :] - pred[1:n]  # human → robot
        dist = np.sqrt(np.einsum("ijk,ijk->ij", rel, rel))
        safety = math.sqrt(p.human_safety_weight) * np.maximum(p.human_safety_dist - dist, 0.0)
        vel = ctx.peds[:, 2:4]
        speed = np.hypot(vel[:, 0], vel[:, 1])
        walking = speed > p.min_walking_speed
        bearing = np.arctan2(rel[..., 1], rel[..., 0]) - np.arctan2(vel[:, 1], vel[:, 0])
        alpha = np.abs(np.angle(np.exp(1j * bearing)))
        behind = np.maximum(alpha - 0.5 * p.fov, 0.0) / math.pi
        near = np.maximum(1.0 - dist / p.visibility_range, 0.0)
        vis = math.sqrt(p.visibility_weight) * np.where(walking[None, :], behind * near, 0.0)
        # Inverse time to collision per segment (robot velocity of segment i at time t_i).
        v_rob = np.diff(pos, axis=0) / np.maximum(dt, 1e-6)[:, None]  # (N, 2)
        to_h = pred[:n] - pos[:n, None, :]  # robot → human at t_i, (N, J, 2)
        d_seg = np.maximum(np.sqrt(np.einsum("ijk,ijk->ij", to_h, to_h)), 1e-9)
        closing = np.einsum("ijk,ijk->ij", v_rob[:, None, :] - vel[None, :, :], to_h) / d_seg
        gap = np.maximum(d_seg - ctx.radius - p.ped_radius, p.min_gap)
        ttc = math.sqrt(p.ttc_weight) * np.maximum(closing / gap - 1.0 / p.ttc_threshold, 0.0)
        return [safety.ravel(), vis.ravel(), ttc.ravel()]

    def extra_dependencies(self, ctx: BandContext) -> list[IntArray]:
        """Columns of the rows of :meth:`extra_residuals`."""
        j = len(ctx.peds)
        if j == 0:
            return []
        pdeps = np.repeat(ctx.pose_deps(np.arange(1, ctx.n)), j, axis=0)
        sdeps = np.repeat(ctx.segment_deps(np.arange(ctx.n)), j, axis=0)
        return [pdeps, pdeps, sdeps]
