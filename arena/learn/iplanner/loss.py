"""iPlanner's self-supervised loss in torch: the cost of the trajectory through the waypoints.

For waypoints ``(N, K, 2)`` (robot frame) and goals ``(N, 2)``, as iPlanner's ``TrajCost``:

- **obstacle**: the spline (:func:`~.geometry.spline_matrix`) from the origin through the
  waypoints is moved into the world by each image's pose, the map's SDF is read bilinearly at
  its points (differentiable in the points: the four cell weights depend on them) and
  :func:`~.geometry.obstacle_cost` is averaged over them;
- **goal**: ``log(1 + |goal - wp_K|)``;
- **motion**: ``Σ_k | |goal| / K - |wp_k - wp_{k-1}| |`` (segments as long as those of the
  straight line to the goal; iPlanner's motion loss), plus a small smoothness term
  ``Σ |wp_{k+1} - 2 wp_k + wp_{k-1}|²`` (ours: it keeps the waypoints in order);
- **fear**: binary cross-entropy of the collision head against the label "the trajectory's cost
  within ``fear_distance`` of arc length exceeds ``fear_threshold``" (no gradient into the
  waypoints).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch
from pydantic import BaseModel, ConfigDict, Field

from arena.learn.iplanner.data import MapStack
from arena.learn.iplanner.geometry import CostParams, spline_matrix


class LossWeights(BaseModel):
    """Weights of the loss terms (iPlanner: obstacle 0.5 on a summed cost, motion 2, goal 5)."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    obstacle: float = Field(5.0, ge=0)
    goal: float = Field(2.0, ge=0)
    motion: float = Field(0.5, ge=0)
    smooth: float = Field(0.5, ge=0)
    fear: float = Field(1.0, ge=0)


@dataclass(frozen=True)
class LossTerms:
    """The batch means of each term (tensors; ``total`` carries the gradient)."""

    total: torch.Tensor
    obstacle: torch.Tensor
    goal: torch.Tensor
    motion: torch.Tensor
    smooth: torch.Tensor
    fear: torch.Tensor
    fear_rate: torch.Tensor
    """share of the batch labelled colliding"""


class TrajectoryCost:
    """The loss on one :class:`~.data.MapStack` (see the module docstring)."""

    def __init__(self, maps: MapStack, cost: CostParams, weights: LossWeights, k: int) -> None:
        self.sdf = torch.from_numpy(maps.sdf)
        self.offset = torch.from_numpy(maps.offset)
        self.shape = torch.from_numpy(maps.shape)
        self.origin = torch.from_numpy(maps.origin).float()
        self.resolution = torch.from_numpy(maps.resolution).float()
        self.cost = cost
        self.weights = weights
        self.spline = torch.from_numpy(np.array(spline_matrix(k), dtype=np.float32))

    def trajectory(self, waypoints: torch.Tensor) -> torch.Tensor:
        """``(N, P, 2)`` spline points from the origin through ``waypoints`` ``(N, K, 2)``."""
        pts = torch.cat([torch.zeros_like(waypoints[:, :1]), waypoints], dim=1)
        return torch.einsum("pk,nkd->npd", self.spline, pts)

    def distance(self, maps: torch.Tensor, pose: torch.Tensor, local: torch.Tensor
                 ) -> torch.Tensor:
        """Bilinear SDF (m) ``(N, P)`` at robot-frame points ``local`` ``(N, P, 2)``."""
        c, s = torch.cos(pose[:, 2:3]), torch.sin(pose[:, 2:3])
        x = pose[:, 0:1] + c * local[..., 0] - s * local[..., 1]
        y = pose[:, 1:2] + s * local[..., 0] + c * local[..., 1]
        res = self.resolution[maps][:, None]
        rows, cols = self.shape[maps, 0][:, None], self.shape[maps, 1][:, None]
        u = ((x - self.origin[maps, 0][:, None]) / res - 0.5)
        v = ((y - self.origin[maps, 1][:, None]) / res - 0.5)
        u = torch.minimum(torch.clamp(u, min=0.0), cols - 1.0)
        v = torch.minimum(torch.clamp(v, min=0.0), rows - 1.0)
        c0 = torch.minimum(torch.floor(u.detach()).long(), cols - 2).clamp(min=0)
        r0 = torch.minimum(torch.floor(v.detach()).long(), rows - 2).clamp(min=0)
        fu, fv = u - c0, v - r0
        base = self.offset[maps][:, None] + r0 * cols + c0
        sdf = self.sdf
        return ((1 - fu) * (1 - fv) * sdf[base] + fu * (1 - fv) * sdf[base + 1]
                + (1 - fu) * fv * sdf[base + cols] + fu * fv * sdf[base + cols + 1])

    def obstacle_cost(self, d: torch.Tensor) -> torch.Tensor:
        """:func:`~.geometry.obstacle_cost` of distances ``d`` (m)."""
        p = self.cost
        return torch.square(torch.relu(p.safe_distance - d) / (p.safe_distance - p.robot_radius))

    def __call__(self, waypoints: torch.Tensor, fear_logit: torch.Tensor, goal: torch.Tensor,
                 maps: torch.Tensor, pose: torch.Tensor) -> LossTerms:
        """The loss of a batch.

        Args: waypoints ``(N, K, 2)``, fear logits ``(N,)``, goals ``(N, 2)``, map indices
        ``(N,)`` and poses ``(N, 3)``.
        """
        w, p = self.weights, self.cost
        traj = self.trajectory(waypoints)
        cost = self.obstacle_cost(self.distance(maps, pose, traj))
        obstacle = cost[:, 1:].mean(dim=1)
        goal_loss = torch.log1p(torch.linalg.norm(goal - waypoints[:, -1], dim=1))
        pts = torch.cat([torch.zeros_like(waypoints[:, :1]), waypoints], dim=1)
        seg = torch.linalg.norm(pts[:, 1:] - pts[:, :-1], dim=2)
        want = torch.linalg.norm(goal, dim=1, keepdim=True) / waypoints.shape[1]
        motion = torch.abs(want - seg).sum(dim=1)
        smooth = torch.square(pts[:, 2:] - 2 * pts[:, 1:-1] + pts[:, :-2]).sum(dim=(1, 2))
        with torch.no_grad():
            step = torch.linalg.norm(traj[:, 1:] - traj[:, :-1], dim=2)
            arc = torch.cumsum(step, dim=1)
            near = torch.where(arc <= p.fear_distance, cost[:, 1:], torch.zeros_like(step))
            label = (near.max(dim=1).values > p.fear_threshold).float()
        fear = torch.nn.functional.binary_cross_entropy_with_logits(fear_logit, label)
        total = (w.obstacle * obstacle.mean() + w.goal * goal_loss.mean()
                 + w.motion * motion.mean() + w.smooth * smooth.mean() + w.fear * fear)
        return LossTerms(total, obstacle.mean(), goal_loss.mean(), motion.mean(), smooth.mean(),
                         fear, label.mean())
