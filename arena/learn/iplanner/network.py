"""The iPlanner network in numpy, and its ``.npz`` file.

Architecture (iPlanner's PlannerNet, shrunk for a CPU: its ResNet encoder on 360 × 640 images
becomes four strided convolutions on 48 × 80)::

    depth (1, 48, 80) ─ conv 16 ─ conv 32 ─ conv 32 ─ conv 48 ─ flatten (720) ─┐
        (3 × 3, stride 2, ReLU each: 24 × 40, 12 × 20, 6 × 10, 3 × 5)          ├─ fc 256 ─ h
    goal features (4) ─ fc 32 (ReLU) ───────────────────────────────────────────┘
    h ─ fc 128 ─ fc 2K ─ offsets;  waypoint_k = (k / K) · goal + WAYPOINT_SCALE · offset_k
    h ─ fc 64 ─ fc 1 ─ sigmoid ─ collision probability ("fear")

ReLU after every layer but the two heads' last. The waypoints are offsets from the straight
line to the goal (iPlanner predicts them outright; offsets start a CPU-sized training run from a
sensible plan). Convolutions use :func:`arena.perception.convnet.conv2d`, the dense layers
:func:`arena.learn.mlp_file.mlp_forward`. The file holds ``<layer>_w``/``<layer>_b`` (torch's
layout, float32) and ``meta`` (JSON: ``format``, ``policy: iplanner``, the camera, the cost and
how it was trained); every problem with it is one :class:`ConfigError`.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from arena.core.errors import ConfigError
from arena.learn.iplanner.geometry import INPUT_SHAPE, WAYPOINTS, goal_features
from arena.learn.mlp_file import FORMAT, WEIGHTS_KEY, mlp_forward
from arena.perception.convnet import conv2d

F32 = NDArray[np.float32]
F64 = NDArray[np.float64]

CONVS: tuple[tuple[str, int, int], ...] = (("c1", 1, 16), ("c2", 16, 32), ("c3", 32, 32),
                                           ("c4", 32, 48))
"""``(name, in, out)`` channels of the 3 × 3 stride-2 convolutions."""
GOAL_UNITS = 32
HIDDEN = 256
PLAN_UNITS = 128
FEAR_UNITS = 64
WAYPOINT_SCALE = 1.0
"""m per unit of the waypoint head's output."""

POLICY = "iplanner"
TRAIN_COMMAND = "python -m arena.learn.iplanner.train"


def conv_output(shape: tuple[int, int] = INPUT_SHAPE) -> tuple[int, int, int]:
    """``(channels, rows, cols)`` after the convolutions of an input of ``shape``."""
    h, w = shape
    for _ in CONVS:
        h, w = (h + 1) // 2, (w + 1) // 2
    return CONVS[-1][2], h, w


def layer_shapes(k: int = WAYPOINTS) -> dict[str, tuple[int, ...]]:
    """Every weight's shape by key (``c1_w`` …, ``goal_w``, ``fc_w``, ``plan1_w`` …)."""
    c, h, w = conv_output()
    shapes: dict[str, tuple[int, ...]] = {}
    for name, i, o in CONVS:
        shapes[f"{name}_w"], shapes[f"{name}_b"] = (o, i, 3, 3), (o,)
    dense = {"goal": (GOAL_UNITS, 4), "fc": (HIDDEN, c * h * w + GOAL_UNITS),
             "plan1": (PLAN_UNITS, HIDDEN), "plan2": (2 * k, PLAN_UNITS),
             "fear1": (FEAR_UNITS, HIDDEN), "fear2": (1, FEAR_UNITS)}
    for name, shape in dense.items():
        shapes[f"{name}_w"], shapes[f"{name}_b"] = shape, (shape[0],)
    return shapes


@dataclass(frozen=True, eq=False)
class Plan:
    """One forward pass.

    Attributes:
        waypoints: ``(K, 2)`` m, robot frame (x forward, y left).
        fear: collision probability in [0, 1].
    """

    waypoints: F64
    fear: float


class IPlannerNet:
    """The network with its weights (keys of :func:`layer_shapes`) and the file's ``meta``."""

    def __init__(self, weights: dict[str, NDArray[Any]], meta: dict[str, Any]) -> None:
        self.meta = meta
        self.k = int(meta.get("waypoints", WAYPOINTS))
        self.w = {key: np.ascontiguousarray(v, dtype=np.float32) for key, v in weights.items()}

    def _dense(self, names: tuple[str, ...], x: F32) -> F64:
        return mlp_forward([self.w[f"{n}_w"] for n in names], [self.w[f"{n}_b"] for n in names],
                           x)

    def plan(self, depth: F32, goal: ArrayLike) -> Plan:
        """Waypoints and fear for a network input ``(1, 48, 80)`` and a goal ``(2,)`` (m)."""
        x = np.asarray(depth, dtype=np.float32)
        for name, *_ in CONVS:
            x = conv2d(x, self.w[f"{name}_w"], self.w[f"{name}_b"], stride=2)
            np.maximum(x, 0.0, out=x)
        g = np.asarray(goal, dtype=np.float64).reshape(2)
        gf = np.maximum(self._dense(("goal",), goal_features(g)), 0.0).astype(np.float32)
        h = np.maximum(self._dense(("fc",), np.concatenate([x.reshape(-1), gf])), 0.0)
        h32 = h.astype(np.float32)
        out = self._dense(("plan1", "plan2"), h32).reshape(self.k, 2)
        line = np.arange(1, self.k + 1)[:, None] / self.k * g[None, :]
        logit = float(self._dense(("fear1", "fear2"), h32)[0])
        fear = 1.0 / (1.0 + np.exp(-logit)) if logit > -50 else 0.0
        return Plan(line + WAYPOINT_SCALE * out, float(fear))


def save_net(path: str | Path, weights: dict[str, NDArray[Any]], meta: dict[str, Any]) -> Path:
    """Write ``weights`` (float32) and ``meta`` (plus ``format``, ``policy``) to ``path``."""
    arrays = {k: np.asarray(v, dtype=np.float32) for k, v in weights.items()}
    arrays["meta"] = np.array(json.dumps({**meta, "format": FORMAT, "policy": POLICY}))
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    with out.open("wb") as f:  # np.savez would append .npz to a name without it
        np.savez(f, allow_pickle=False, **arrays)
    return out


def load_net(path: str | Path) -> IPlannerNet:
    """The network in ``path``.

    Raises:
        ConfigError: missing, unreadable, another policy's file, or weights of other shapes.
    """
    p = Path(path)
    if not p.is_file():
        raise ConfigError(f"no iPlanner policy file {str(p)!r}: train one with `{TRAIN_COMMAND} "
                          "-o RUN` and pass weights: RUN/policy.npz", path=WEIGHTS_KEY)
    try:
        with np.load(p, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
        meta = json.loads(str(arrays.pop("meta")))
    except (OSError, ValueError, KeyError) as e:
        raise ConfigError(f"{p}: not an iPlanner policy file ({e})", path=WEIGHTS_KEY) from None
    if not isinstance(meta, dict) or meta.get("policy") != POLICY or meta.get("format") != FORMAT:
        got = meta if isinstance(meta, dict) else {}
        raise ConfigError(f"{p}: not an iPlanner policy file of format {FORMAT} (policy "
                          f"{got.get('policy')!r}, format {got.get('format')!r})",
                          path=WEIGHTS_KEY)
    want = layer_shapes(int(meta.get("waypoints", WAYPOINTS)))
    bad = sorted(k for k, s in want.items() if k not in arrays or arrays[k].shape != s)
    if bad:
        raise ConfigError(f"{p}: weights {bad[:3]} missing or of the wrong shape for this "
                          "network", path=WEIGHTS_KEY)
    return IPlannerNet({k: arrays[k] for k in want}, meta)
