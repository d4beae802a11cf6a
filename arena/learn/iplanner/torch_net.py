"""The iPlanner network as a torch module (training only; :mod:`.network` runs it in numpy).

The layers and their order are :mod:`.network`'s; :meth:`TorchIPlanner.export` gives the
weights under :func:`~arena.learn.iplanner.network.layer_shapes`' keys.
"""

from __future__ import annotations

import numpy as np
import torch
from numpy.typing import NDArray
from torch import nn

from arena.learn.iplanner.geometry import GOAL_SCALE, WAYPOINTS
from arena.learn.iplanner.network import (
    CONVS,
    FEAR_UNITS,
    GOAL_UNITS,
    HIDDEN,
    PLAN_UNITS,
    WAYPOINT_SCALE,
    conv_output,
)


def goal_features_torch(goal: torch.Tensor) -> torch.Tensor:
    """``(N, 4)`` :func:`~arena.learn.iplanner.geometry.goal_features` of goals ``(N, 2)``."""
    b = torch.atan2(goal[:, 1], goal[:, 0])
    return torch.stack([goal[:, 0] / GOAL_SCALE, goal[:, 1] / GOAL_SCALE, torch.cos(b),
                        torch.sin(b)], dim=1)


class TorchIPlanner(nn.Module):
    """Depth ``(N, 1, 48, 80)``, goal ``(N, 2)`` → waypoints ``(N, K, 2)``, fear logits ``(N,)``."""

    def __init__(self, k: int = WAYPOINTS) -> None:
        super().__init__()
        self.k = k
        self.convs = nn.ModuleDict({n: nn.Conv2d(i, o, 3, stride=2, padding=1)
                                    for n, i, o in CONVS})
        c, h, w = conv_output()
        self.goal = nn.Linear(4, GOAL_UNITS)
        self.fc = nn.Linear(c * h * w + GOAL_UNITS, HIDDEN)
        self.plan1 = nn.Linear(HIDDEN, PLAN_UNITS)
        self.plan2 = nn.Linear(PLAN_UNITS, 2 * k)
        self.fear1 = nn.Linear(HIDDEN, FEAR_UNITS)
        self.fear2 = nn.Linear(FEAR_UNITS, 1)

    def forward(self, depth: torch.Tensor, goal: torch.Tensor
                ) -> tuple[torch.Tensor, torch.Tensor]:
        """``(waypoints (N, K, 2) m, fear logits (N,))``."""
        x = depth
        for name, *_ in CONVS:
            x = torch.relu(self.convs[name](x))
        g = torch.relu(self.goal(goal_features_torch(goal)))
        h = torch.relu(self.fc(torch.cat([x.flatten(1), g], dim=1)))
        out = self.plan2(torch.relu(self.plan1(h))).reshape(-1, self.k, 2)
        steps = torch.arange(1, self.k + 1, dtype=goal.dtype) / self.k
        line = steps[None, :, None] * goal[:, None, :]
        logit = self.fear2(torch.relu(self.fear1(h)))[:, 0]
        return line + WAYPOINT_SCALE * out, logit

    def export(self) -> dict[str, NDArray[np.float32]]:
        """The weights under :func:`~arena.learn.iplanner.network.layer_shapes`' keys."""
        out: dict[str, NDArray[np.float32]] = {}
        layers: dict[str, nn.Module] = {**dict(self.convs.items()), "goal": self.goal,
                                        "fc": self.fc, "plan1": self.plan1, "plan2": self.plan2,
                                        "fear1": self.fear1, "fear2": self.fear2}
        for name, layer in layers.items():
            assert isinstance(layer, nn.Conv2d | nn.Linear)
            out[f"{name}_w"] = layer.weight.detach().numpy().astype(np.float32)
            assert layer.bias is not None
            out[f"{name}_b"] = layer.bias.detach().numpy().astype(np.float32)
        return out
