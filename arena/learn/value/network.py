"""CADRL and SARL value networks in numpy, and their ``.npz`` policy files.

Networks (Chen et al. 2019; layer sizes of CrowdNav's defaults; ReLU between layers):

- **CADRL** (:class:`CadrlNetwork`): an MLP ``13 → 150 → 100 → 100 → 1`` on each rotated
  (robot, human) pair; the value is the minimum over humans (CrowdNav's multi-human CADRL).
- **SARL** (:class:`SarlNetwork`): ``e_i = ψ_e(pair_i)`` (``13 → 150 → 100``, ReLU on the
  output too), ``h_i = ψ_h(e_i)`` (``100 → 100 → 50``); attention scores
  ``α_i = ψ_α([e_i, mean_j e_j])`` (``200 → 100 → 100 → 1``), softmax over humans; crowd
  feature ``c = Σ_i softmax(α)_i h_i``; value ``f_v([self_i, c])`` (``6 + 50 → 150 → 100 →
  100 → 1``) with ``self`` the first 6 numbers of a pair.

Both accept a padded batch ``(B, n, 13)`` with a mask ``(B, n)`` of the real humans (padding
is left out of the minimum, the mean and the softmax), so the torch training networks of
:mod:`.train` and these give the same numbers.

File layout (``np.savez``, no pickles): one ``(in, out)`` weight and one ``(out,)`` bias per
linear layer, named ``<module>.<k>.weight`` / ``<module>.<k>.bias`` (modules ``value`` for
CADRL; ``embed``, ``feature``, ``attention``, ``value`` for SARL), and ``meta``: a JSON string
with ``format`` (:data:`FORMAT`), ``version``, ``policy`` (``cadrl``/``sarl``), ``layout``
(module → layer widths), ``gamma``, ``time_step`` (s), ``v_pref`` (m/s), ``kinematics``
(``unicycle``/``holonomic``), ``human_radius`` (m), the ``action_set`` options and a
``training`` summary.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar, Protocol

import numpy as np
from numpy.typing import NDArray

from arena.core.errors import ConfigError
from arena.learn.value.state import PAIR_DIM, SELF_DIM

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

FORMAT = "arena-value-policy"
"""``meta["format"]`` of a value-policy file."""
VERSION = 1
"""Version of the file layout."""

CADRL_LAYOUT: dict[str, list[int]] = {"value": [150, 100, 100, 1]}
"""CrowdNav's ``cadrl`` ``mlp_dims``."""
SARL_LAYOUT: dict[str, list[int]] = {
    "embed": [150, 100], "feature": [100, 50], "attention": [100, 100, 1],
    "value": [150, 100, 100, 1],
}
"""CrowdNav's ``sarl`` ``mlp1_dims``, ``mlp2_dims``, ``attention_dims``, ``mlp3_dims``."""


@dataclass(frozen=True, eq=False)
class Mlp:
    """Linear layers with ReLU between them (and after the last when ``last_relu``).

    Attributes:
        weights: ``(in, out)`` matrices, first layer first.
        biases: ``(out,)`` vectors.
        last_relu: whether the output passes a ReLU too.
    """

    weights: tuple[NDArray[np.floating[Any]], ...]
    biases: tuple[NDArray[np.floating[Any]], ...]
    last_relu: bool = False

    def __call__(self, x: FloatArray) -> FloatArray:
        """``(..., in)`` → ``(..., out)``, computed in the weights' precision.

        Loaded files keep their float32 weights: inference in float32 is twice as fast and
        the stored weights hold no more digits anyway.
        """
        n = len(self.weights)
        x = np.asarray(x, dtype=self.weights[0].dtype)
        for k, (w, b) in enumerate(zip(self.weights, self.biases, strict=True)):
            x = x @ w + b
            if k < n - 1 or self.last_relu:
                x = np.maximum(x, 0.0)
        return x

    @property
    def in_dim(self) -> int:
        """Input width."""
        return int(self.weights[0].shape[0])

    @staticmethod
    def dims_of(in_dim: int, widths: list[int]) -> list[tuple[int, int]]:
        """``(in, out)`` of each layer of an MLP with input ``in_dim`` and ``widths``."""
        dims = [in_dim, *widths]
        return [(dims[k], dims[k + 1]) for k in range(len(widths))]

    @classmethod
    def random(cls, in_dim: int, widths: list[int], rng: np.random.Generator,
               last_relu: bool = False) -> Mlp:
        """He-initialised layers (tests and untrained networks)."""
        ws, bs = [], []
        for i, o in cls.dims_of(in_dim, widths):
            ws.append(rng.normal(0.0, np.sqrt(2.0 / i), (i, o)))
            bs.append(np.zeros(o))
        return cls(tuple(ws), tuple(bs), last_relu)


def _mask(features: FloatArray, mask: BoolArray | None) -> BoolArray:
    if mask is None:
        return np.ones(features.shape[:2], dtype=bool)
    return np.asarray(mask, dtype=bool).reshape(features.shape[:2])


class ValueNetwork(Protocol):
    """``V(joint state)`` from rotated pairs.

    Attributes:
        kind: ``"cadrl"`` or ``"sarl"``.
        modules: the network's MLPs by name (the file's module names).
    """

    kind: ClassVar[str]
    modules: dict[str, Mlp]

    def value(self, features: FloatArray, mask: BoolArray | None = None) -> FloatArray:
        """``(B, n, 13)`` rotated pairs (``mask`` ``(B, n)``: real humans) → ``(B,)`` values."""
        ...


class CadrlNetwork:
    """CADRL's value: the minimum over humans of an MLP on each pair."""

    kind: ClassVar[str] = "cadrl"
    layout: ClassVar[dict[str, list[int]]] = CADRL_LAYOUT
    in_dims: ClassVar[dict[str, int]] = {"value": PAIR_DIM}
    last_relu: ClassVar[dict[str, bool]] = {"value": False}

    def __init__(self, modules: dict[str, Mlp]) -> None:
        self.modules = modules

    def value(self, features: FloatArray, mask: BoolArray | None = None) -> FloatArray:
        """See :class:`ValueNetwork`."""
        m = _mask(features, mask)
        v = self.modules["value"](features)[..., 0]  # (B, n)
        out: FloatArray = np.min(np.where(m, v, np.inf), axis=1).astype(np.float64)
        return out


class SarlNetwork:
    """SARL's value: attention-weighted crowd feature and the self state."""

    kind: ClassVar[str] = "sarl"
    layout: ClassVar[dict[str, list[int]]] = SARL_LAYOUT
    in_dims: ClassVar[dict[str, int]] = {
        "embed": PAIR_DIM, "feature": SARL_LAYOUT["embed"][-1],
        "attention": 2 * SARL_LAYOUT["embed"][-1],
        "value": SELF_DIM + SARL_LAYOUT["feature"][-1],
    }
    last_relu: ClassVar[dict[str, bool]] = {
        "embed": True, "feature": False, "attention": False, "value": False,
    }

    def __init__(self, modules: dict[str, Mlp]) -> None:
        self.modules = modules

    def attention(self, features: FloatArray, mask: BoolArray | None = None) -> FloatArray:
        """``(B, n)`` softmax attention weights of the humans (0 on padding)."""
        return self._forward(features, mask)[1]

    def value(self, features: FloatArray, mask: BoolArray | None = None) -> FloatArray:
        """See :class:`ValueNetwork`."""
        return self._forward(features, mask)[0].astype(np.float64)

    def _forward(self, features: FloatArray,
                 mask: BoolArray | None) -> tuple[FloatArray, FloatArray]:
        m = _mask(features, mask)
        mf = m[..., None].astype(np.float64)
        e = self.modules["embed"](features)  # (B, n, 100)
        mean = (e * mf).sum(axis=1) / np.maximum(mf.sum(axis=1), 1.0)  # (B, 100)
        a_in = np.concatenate([e, np.broadcast_to(mean[:, None, :], e.shape)], axis=-1)
        scores = np.where(m, self.modules["attention"](a_in)[..., 0], -np.inf)
        scores = scores - np.max(scores, axis=1, keepdims=True)
        w = np.exp(scores)
        w = w / np.sum(w, axis=1, keepdims=True)
        crowd = np.einsum("bn,bnk->bk", w, self.modules["feature"](e))
        joint = np.concatenate([features[:, 0, :SELF_DIM], crowd], axis=-1)
        return self.modules["value"](joint)[:, 0], w


NETWORKS: dict[str, type[CadrlNetwork] | type[SarlNetwork]] = {
    "cadrl": CadrlNetwork, "sarl": SarlNetwork,
}
"""Network classes by ``meta["policy"]``."""


def random_network(kind: str, rng: np.random.Generator) -> CadrlNetwork | SarlNetwork:
    """An untrained network of ``kind`` (``cadrl``/``sarl``) with CrowdNav's layout."""
    cls = NETWORKS[kind]
    return cls({name: Mlp.random(cls.in_dims[name], widths, rng, cls.last_relu[name])
                for name, widths in cls.layout.items()})


@dataclass(frozen=True, eq=False)
class ValuePolicyFile:
    """A loaded policy file: the network and its meta (see the module docstring)."""

    network: CadrlNetwork | SarlNetwork
    meta: dict[str, Any]


def save_value_policy(path: str | Path, network: CadrlNetwork | SarlNetwork,
                      meta: dict[str, Any]) -> Path:
    """Write ``network`` and ``meta`` (format, version, policy and layout filled in) to ``path``.

    Weights are stored as float32 (the files stay well under 1 MB).
    """
    arrays: dict[str, NDArray[Any]] = {}
    for name, mlp in network.modules.items():
        for k, (w, b) in enumerate(zip(mlp.weights, mlp.biases, strict=True)):
            arrays[f"{name}.{k}.weight"] = np.asarray(w, dtype=np.float32)
            arrays[f"{name}.{k}.bias"] = np.asarray(b, dtype=np.float32)
    full = {**meta, "format": FORMAT, "version": VERSION, "policy": network.kind,
            "layout": {n: list(w) for n, w in type(network).layout.items()}}
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    arrays["meta"] = np.array(json.dumps(full))
    with p.open("wb") as f:
        np.savez(f, allow_pickle=False, **arrays)
    return p


REQUIRED_META = ("gamma", "time_step", "v_pref", "kinematics", "human_radius")
"""Meta keys every policy file must have (besides format, version, policy, layout)."""


def load_value_policy(path: str | Path, where: str | None = None) -> ValuePolicyFile:
    """Load a policy file written by :func:`save_value_policy`.

    Args:
        path: the ``.npz`` file.
        where: config key path to name in errors (e.g. ``navigation.local_planner.weights``).

    Raises:
        ConfigError: the file is missing, unreadable, not a value-policy file, or its arrays do
            not match its layout; the message names the file.
    """
    p = Path(path)

    def fail(msg: str) -> ConfigError:
        return ConfigError(f"{p}: {msg}", path=where)

    if not p.is_file():
        raise fail("no such policy file (train one with `python -m arena.learn.value.train`)")
    try:
        with np.load(p, allow_pickle=False) as data:
            arrays = {k: np.asarray(data[k]) for k in data.files}
    except (OSError, ValueError) as e:
        raise fail(f"not a readable .npz policy file ({e})") from None
    if "meta" not in arrays:
        raise fail("no 'meta' entry: not a value-policy file")
    try:
        meta = json.loads(str(arrays.pop("meta")))
    except json.JSONDecodeError as e:
        raise fail(f"'meta' is not JSON ({e})") from None
    if not isinstance(meta, dict) or meta.get("format") != FORMAT:
        raise fail(f"meta.format is not {FORMAT!r}: not a value-policy file")
    if meta.get("version") != VERSION:
        raise fail(f"meta.version {meta.get('version')!r} is not supported (expected {VERSION})")
    kind = meta.get("policy")
    if kind not in NETWORKS:
        raise fail(f"meta.policy {kind!r} is not one of {sorted(NETWORKS)}")
    missing = [k for k in REQUIRED_META if k not in meta]
    if missing:
        raise fail(f"meta lacks {missing}")
    cls = NETWORKS[kind]
    if meta.get("layout") != cls.layout:
        raise fail(f"meta.layout {meta.get('layout')!r} is not {kind}'s {cls.layout!r}")
    modules: dict[str, Mlp] = {}
    for name, widths in cls.layout.items():
        ws, bs = [], []
        for k, (i, o) in enumerate(Mlp.dims_of(cls.in_dims[name], widths)):
            w, b = arrays.get(f"{name}.{k}.weight"), arrays.get(f"{name}.{k}.bias")
            if w is None or b is None or w.shape != (i, o) or b.shape != (o,):
                got = None if w is None or b is None else (w.shape, b.shape)
                raise fail(f"layer {name}.{k} should be ({i}, {o}) + ({o},), found {got}")
            if not (np.all(np.isfinite(w)) and np.all(np.isfinite(b))):
                raise fail(f"layer {name}.{k} holds non-finite numbers")
            ws.append(w.astype(np.float32))
            bs.append(b.astype(np.float32))
        modules[name] = Mlp(tuple(ws), tuple(bs), cls.last_relu[name])
    return ValuePolicyFile(network=cls(modules), meta=meta)
