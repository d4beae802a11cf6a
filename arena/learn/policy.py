"""Trained PPO policies as small ``.npz`` files, run with numpy alone.

:func:`export_policy` (needs torch and Stable-Baselines3) writes the actor of an SB3
``ActorCriticPolicy`` whose feature extractor only flattens (``MlpPolicy``'s
``FlattenExtractor``, ``MultiInputPolicy``'s ``CombinedExtractor`` over non-image boxes):

============================ ===============================================================
``w{i}``, ``b{i}``            Linear layers of the policy MLP then the action head,
                              ``y = x @ w.T + b`` (torch's layout), the activation between
``mean/<key>``, ``var/<key>`` VecNormalize running statistics per observation key (``obs``
                              for a flat Box)
``low/<key>``, ``high/<key>`` observation space bounds per key
``action_low``, ``action_high`` Box action bounds (SB3 clips predictions to them)
``command_table``             ``(k, 3)`` ``[vx, vy, ω]`` of each discrete action (optional)
``command_low/high``,         continuous decoding (optional): raw ranges, clip box
``range_low/high``
``fx/...``                     format 2 only: the conv feature extractor's layers
                              (:mod:`arena.learn.policy_conv`)
``meta``                      JSON: activation, observation keys / shapes / flatten order,
                              normalisation clip and epsilon, action type, command decoding,
                              the ``learning.env.observation`` block, and ``laser``:
                              ``{"angles": [rad, robot frame, mount yaw included],
                              "range_max": m}`` of the laser the policy was trained with
============================ ===============================================================

The flatten order is SB3's: each key's array flattened in C order (``nn.Flatten``), keys in the
order of the extractor's ``ModuleDict`` (the Dict space's order).

Format 2 (written only for policies with a conv extractor, ``rlca_conv``
(:class:`~arena.learn.extractors.RLCAConvExtractor`) or ``drlvo_cnn``
(:class:`~arena.learn.extractors.DrlvoExtractor`); MLP policies stay format 1, so readers of
format 1 keep reading them) adds ``meta["extractor"]`` (its ``type`` and layout, see
:mod:`arena.learn.policy_conv`): the features are the extractor's output, and the MLP above
runs on them.

:class:`NumpyPolicy` imports no torch: ``act`` reproduces
``model.predict(obs, deterministic=True)`` (argmax of the logits, or the Gaussian mean clipped to
the action box).
"""

from __future__ import annotations

import itertools
import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from arena.core.errors import ConfigError
from arena.learn.policy_conv import Features, numpy_extractor, to_numpy

FORMAT = 1
"""Version of the ``.npz`` layout of MLP policies."""
FORMAT_CONV = 2
"""Version of the layout with a conv feature extractor (a superset of format 1)."""
_FORMATS = (FORMAT, FORMAT_CONV)
_ACTIVATIONS = {"ReLU": "relu", "Tanh": "tanh", "Identity": "identity"}
_FLAT_KEY = "obs"


def _linear_layers(seq: Any) -> tuple[list[Any], str]:
    """Linear layers of an ``nn.Sequential`` MLP and its (single) activation name."""
    import torch.nn as nn

    layers, acts = [], set()
    for m in seq:
        if isinstance(m, nn.Linear):
            layers.append(m)
        elif type(m).__name__ in _ACTIVATIONS:
            acts.add(_ACTIVATIONS[type(m).__name__])
        else:
            raise ValueError(f"cannot export policy layer {type(m).__name__}")
    if len(acts) > 1:
        raise ValueError(f"mixed activations {sorted(acts)} cannot be exported")
    return layers, next(iter(acts), "identity")


def _command_arrays(decoder: Any, arrays: dict[str, NDArray[Any]]) -> dict[str, Any]:
    """Add the action decoding of ``decoder`` (an ActionDecoder) to ``arrays``; its meta."""
    arrays["command_low"] = np.asarray(decoder.low, np.float64)
    arrays["command_high"] = np.asarray(decoder.high, np.float64)
    if decoder.table is not None:
        arrays["command_table"] = np.asarray(decoder.table, np.float64)
        return {"type": "table"}
    arrays["range_low"] = np.asarray(decoder.range_low, np.float64)
    arrays["range_high"] = np.asarray(decoder.range_high, np.float64)
    return {
        "type": "box",
        "holonomic": bool(decoder.holonomic),
        "normalize": bool(decoder.config.normalize),
    }


def export_policy(
    model: Any,
    vecnormalize: Any | None,
    path: str | Path,
    *,
    decoder: Any | None = None,
    observation: Mapping[str, Any] | None = None,
    laser: Any | None = None,
) -> Path:
    """Write the deterministic actor of an SB3 PPO ``model`` to ``path`` (``.npz``).

    Args:
        model: a Stable-Baselines3 on-policy model (PPO/A2C) with an MLP actor.
        vecnormalize: the ``VecNormalize`` wrapper it was trained with, or ``None``.
        path: output file.
        decoder: the env's :class:`~arena.learn.actions.ActionDecoder`, recorded so that a
            planner can turn actions into ``[vx, vy, ω]`` commands.
        observation: the ``learning.env.observation`` block (JSON mapping), recorded for
            planners that rebuild observations.
        laser: the robot's :class:`~arena.sensors.spec.LidarSpec`, recorded (beam angles and
            range) so that a planner can resample another laser onto the policy's beams.

    Returns:
        The written path.
    """
    from gymnasium import spaces
    from stable_baselines3.common.distributions import (
        CategoricalDistribution,
        DiagGaussianDistribution,
    )
    from stable_baselines3.common.torch_layers import CombinedExtractor, FlattenExtractor

    from arena.learn.policy_conv import export_extractor

    policy = model.policy
    if getattr(policy, "squash_output", False):
        raise ValueError("policies with squashed outputs (gSDE) cannot be exported")
    arrays: dict[str, NDArray[Any]] = {}
    obs_space = policy.observation_space
    extractor = policy.pi_features_extractor
    fx_meta: dict[str, Any] | None = None
    if hasattr(extractor, "other_keys"):  # a conv extractor of arena.learn.extractors
        keys = list(obs_space.spaces.keys())
        sub_spaces = {k: obs_space[k] for k in keys}
        obs_type = "dict"
        fx_arrays, fx_meta = export_extractor(extractor)
        arrays.update(fx_arrays)
    elif isinstance(extractor, CombinedExtractor):
        import torch.nn as nn

        keys = list(extractor.extractors.keys())
        for k, sub in extractor.extractors.items():
            if not isinstance(sub, nn.Flatten):
                raise ValueError(f"observation {k!r} uses {type(sub).__name__}; only MLPs export")
        sub_spaces = {k: obs_space[k] for k in keys}
        obs_type = "dict"
    elif isinstance(extractor, FlattenExtractor) and isinstance(obs_space, spaces.Box):
        keys = [_FLAT_KEY]
        sub_spaces = {_FLAT_KEY: obs_space}
        obs_type = "box"
    else:
        raise ValueError(f"feature extractor {type(extractor).__name__} cannot be exported")
    for k, sp in sub_spaces.items():
        arrays[f"low/{k}"] = np.asarray(sp.low, np.float32)
        arrays[f"high/{k}"] = np.asarray(sp.high, np.float32)
    layers, act = _linear_layers(policy.mlp_extractor.policy_net)
    layers.append(policy.action_net)
    for i, lin in enumerate(layers):
        arrays[f"w{i}"] = to_numpy(lin.weight)
        arrays[f"b{i}"] = to_numpy(lin.bias)
    if act == "identity" and len(layers) > 1:
        act = _ACTIVATIONS.get(getattr(policy.activation_fn, "__name__", ""), "identity")

    norm: dict[str, Any] = {"enabled": False}
    if vecnormalize is not None and vecnormalize.norm_obs:
        rms = vecnormalize.obs_rms
        norm_keys = (
            list(vecnormalize.norm_obs_keys) if obs_type == "dict" else [_FLAT_KEY]
        )
        for k in norm_keys:
            r = rms[k] if obs_type == "dict" else rms
            arrays[f"mean/{k}"] = np.asarray(r.mean, np.float64)
            arrays[f"var/{k}"] = np.asarray(r.var, np.float64)
        norm = {
            "enabled": True,
            "keys": norm_keys,
            "clip": float(vecnormalize.clip_obs),
            "epsilon": float(vecnormalize.epsilon),
        }

    dist = policy.action_dist
    action: dict[str, Any]
    if isinstance(dist, CategoricalDistribution):
        action = {"type": "discrete", "n": int(policy.action_space.n)}
    elif isinstance(dist, DiagGaussianDistribution):
        action = {"type": "box", "shape": list(policy.action_space.shape)}
        arrays["action_low"] = np.asarray(policy.action_space.low, np.float64)
        arrays["action_high"] = np.asarray(policy.action_space.high, np.float64)
    else:
        raise ValueError(f"action distribution {type(dist).__name__} cannot be exported")

    command = _command_arrays(decoder, arrays) if decoder is not None else None

    meta = {
        "format": FORMAT if fx_meta is None else FORMAT_CONV,
        "activation": act,
        "n_layers": len(layers),
        "obs": {
            "type": obs_type,
            "keys": keys,
            "shapes": {k: list(sp.shape) for k, sp in sub_spaces.items()},
        },
        "normalize": norm,
        "action": action,
        "command": command,
        "observation": dict(observation) if observation is not None else None,
        "laser": laser_meta(laser) if laser is not None else None,
    }
    if fx_meta is not None:
        meta["extractor"] = fx_meta
    return _write(path, arrays, meta)


def _write(path: str | Path, arrays: dict[str, NDArray[Any]], meta: dict[str, Any]) -> Path:
    arrays["meta"] = np.array(json.dumps(meta))
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    with out.open("wb") as f:  # np.savez would append .npz to a name without it
        np.savez(f, **arrays)  # type: ignore[arg-type]
    return out


def laser_meta(laser: Any) -> dict[str, Any]:
    """``{"angles": [...], "range_max": m}`` of a ``LidarSpec`` (angles in the robot frame)."""
    angles = np.asarray(laser.angles(), dtype=np.float64) + float(laser.mount[2])
    return {"angles": [float(a) for a in angles], "range_max": float(laser.range_max)}


def random_policy(
    env_config: Any,
    robot: Any,
    hidden: tuple[int, ...] = (64, 64),
    rng: np.random.Generator | int | None = None,
    activation: str = "tanh",
) -> NumpyPolicy:
    """An untrained policy in the exact :func:`export_policy` layout, without torch.

    The observation and action spaces are those :class:`~arena.learn.env.SocialNavEnv` builds
    from ``env_config`` (a ``learning.env`` :class:`~arena.learn.config.EnvConfig`) and
    ``robot``; weights are random (He-scaled hidden layers), observations are normalised to
    about ``[-1, 1]`` by their space bounds. Useful as a test fixture and an "untrained"
    baseline.
    """
    from gymnasium import spaces

    from arena.learn.actions import ActionDecoder
    from arena.learn.observations import ObservationBuilder

    gen = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
    builder = ObservationBuilder(env_config.observation, robot)
    decoder = ActionDecoder(env_config.action, robot)
    obs_space = builder.space
    act_space = decoder.space
    arrays: dict[str, NDArray[Any]] = {}
    if isinstance(obs_space, spaces.Dict):
        sub = dict(obs_space.spaces.items())
        obs_type = "dict"
    else:
        sub = {_FLAT_KEY: obs_space}
        obs_type = "box"
    dim = 0
    for k, sp in sub.items():
        lo = np.asarray(sp.low, np.float64)
        hi = np.asarray(sp.high, np.float64)
        arrays[f"low/{k}"] = lo.astype(np.float32)
        arrays[f"high/{k}"] = hi.astype(np.float32)
        finite = np.isfinite(lo) & np.isfinite(hi)
        arrays[f"mean/{k}"] = np.where(finite, (lo + hi) / 2, 0.0)
        half = np.where(finite, (hi - lo) / 2, 1.0)
        arrays[f"var/{k}"] = np.maximum(half, 1e-6) ** 2
        dim += int(np.prod(sp.shape))
    if isinstance(act_space, spaces.Discrete):
        n_out = int(act_space.n)
        action: dict[str, Any] = {"type": "discrete", "n": n_out}
    else:
        n_out = int(np.prod(act_space.shape))
        action = {"type": "box", "shape": list(act_space.shape)}
        arrays["action_low"] = np.asarray(act_space.low, np.float64)
        arrays["action_high"] = np.asarray(act_space.high, np.float64)
    widths = [dim, *[int(h) for h in hidden], n_out]
    for i, (a, b) in enumerate(itertools.pairwise(widths)):
        scale = np.sqrt(2.0 / a) if i < len(widths) - 2 else 1.0 / np.sqrt(a)
        arrays[f"w{i}"] = (gen.standard_normal((b, a)) * scale).astype(np.float32)
        arrays[f"b{i}"] = np.zeros(b, np.float32)
    command = _command_arrays(decoder, arrays)
    keys = list(sub)
    meta = {
        "format": FORMAT,
        "activation": activation if len(widths) > 2 else "identity",
        "n_layers": len(widths) - 1,
        "obs": {"type": obs_type, "keys": keys,
                "shapes": {k: list(sp.shape) for k, sp in sub.items()}},
        "normalize": {"enabled": True, "keys": keys, "clip": 10.0, "epsilon": 1e-8},
        "action": action,
        "command": command,
        "observation": env_config.observation.model_dump(mode="json"),
        "laser": laser_meta(robot.lidar(env_config.observation.sensor)),
        "random": True,
    }
    arrays["meta"] = np.array(json.dumps(meta))
    return NumpyPolicy(arrays, source="<random>")


def write_random_policy(
    path: str | Path,
    env_config: Any,
    robot: Any,
    rng: np.random.Generator | int | None = None,
    hidden: tuple[int, ...] = (64, 64),
) -> Path:
    """:func:`random_policy` written to ``path`` (an ``.npz`` that NumpyPolicy.load reads)."""
    pol = random_policy(env_config, robot, hidden, rng)
    arrays = dict(pol.arrays)
    return _write(path, arrays, pol.meta)


class NumpyPolicy:
    """A policy written by :func:`export_policy`, evaluated with numpy.

    Attributes:
        meta: the JSON metadata (see the module docstring).
        keys: observation keys in flatten order (``("obs",)`` for a flat Box).
        shapes: per key, the observation shape (without a batch axis).
    """

    def __init__(self, arrays: Mapping[str, NDArray[Any]], source: str = "<memory>") -> None:
        try:
            self.meta: dict[str, Any] = json.loads(str(arrays["meta"]))
        except KeyError:
            raise ConfigError("not an exported policy (no 'meta' entry)", source=source) from None
        if self.meta.get("format") not in _FORMATS:
            raise ConfigError(
                f"policy format {self.meta.get('format')!r} is not supported "
                f"(expected one of {list(_FORMATS)})",
                source=source,
            )
        self.source = source
        self.arrays = {k: np.asarray(v) for k, v in arrays.items() if k != "meta"}
        self.keys: tuple[str, ...] = tuple(self.meta["obs"]["keys"])
        self.shapes = {k: tuple(s) for k, s in self.meta["obs"]["shapes"].items()}
        self._unstack_single_scan()
        self.is_dict = self.meta["obs"]["type"] == "dict"
        n = int(self.meta["n_layers"])
        self._w = [self.arrays[f"w{i}"].astype(np.float64) for i in range(n)]
        self._b = [self.arrays[f"b{i}"].astype(np.float64) for i in range(n)]
        self.activation = str(self.meta["activation"])
        norm = self.meta["normalize"]
        self._norm_keys = set(norm.get("keys", ())) if norm["enabled"] else set()
        self._clip = float(norm.get("clip", np.inf))
        self._eps = float(norm.get("epsilon", 0.0))
        self.discrete = self.meta["action"]["type"] == "discrete"
        self.extractor: dict[str, Any] | None = self.meta.get("extractor")
        self._features: Features | None = None
        if self.extractor is not None:
            if not self.is_dict:
                raise ConfigError("a conv feature extractor needs a Dict observation",
                                  source=source)
            self._features = numpy_extractor(self.extractor, self.arrays, source)

    def _unstack_single_scan(self) -> None:
        """Read a ``lidar`` of shape ``(1, beams)`` (older files) as ``(beams,)``.

        The environments give one scan as ``(beams,)`` (see
        :func:`~arena.learn.observations.lidar_shape`); the normalisation statistics and space
        bounds of such a file are reshaped once here, so older files keep working unchanged.
        """
        shape = self.shapes.get("lidar")
        if shape is None or len(shape) != 2 or shape[0] != 1:
            return
        self.shapes["lidar"] = (shape[1],)
        for part in ("low", "high", "mean", "var"):
            key = f"{part}/lidar"
            if key in self.arrays and self.arrays[key].shape == shape:
                self.arrays[key] = self.arrays[key].reshape(shape[1])

    @classmethod
    def load(cls, path: str | Path) -> NumpyPolicy:
        """Read an exported ``.npz``.

        Raises:
            ConfigError: no such file, or not an exported policy.
        """
        p = Path(path)
        if not p.is_file():
            raise ConfigError(f"no policy file {str(p)!r}")
        try:
            with np.load(p, allow_pickle=False) as data:
                arrays = {k: data[k] for k in data.files}
        except (OSError, ValueError) as e:
            raise ConfigError(f"unreadable policy file ({e})", source=str(p)) from None
        return cls(arrays, source=str(p))

    # -- evaluation -----------------------------------------------------------------------------
    def _batched(self, obs: Any) -> tuple[dict[str, NDArray[np.float64]], bool]:
        if self.is_dict:
            if not isinstance(obs, Mapping):
                raise ValueError(f"the policy expects a dict observation with keys {self.keys}")
            missing = [k for k in self.keys if k not in obs]
            if missing:
                raise ValueError(f"observation lacks keys {missing}")
            parts = {k: np.asarray(obs[k], dtype=np.float64) for k in self.keys}
        else:
            parts = {_FLAT_KEY: np.asarray(obs, dtype=np.float64)}
        k0 = self.keys[0]
        single = parts[k0].shape == self.shapes[k0]
        out = {}
        for k, a in parts.items():
            a = a[None] if single else a
            if a.shape[1:] != self.shapes[k]:
                raise ValueError(f"observation {k!r} has shape {a.shape[1:]}, "
                                 f"the policy expects {self.shapes[k]}")
            out[k] = a
        return out, single

    def normalised(self, obs: Any) -> dict[str, NDArray[np.float64]]:
        """Per key ``(B, *shape)``: the observation after VecNormalize (float32 precision)."""
        parts, _ = self._batched(obs)
        out = {}
        for k in self.keys:
            a = parts[k]
            if k in self._norm_keys:
                a = np.clip(
                    (a - self.arrays[f"mean/{k}"]) / np.sqrt(self.arrays[f"var/{k}"] + self._eps),
                    -self._clip, self._clip,
                )
            # SB3 feeds float32 tensors; rounding here keeps the numpy path on the same inputs
            out[k] = a.astype(np.float32).astype(np.float64)
        return out

    def features(self, obs: Any) -> NDArray[np.float64]:
        """``(B, D)`` input of the policy MLP: the flattened observation, or the conv features."""
        parts = self.normalised(obs)
        if self._features is None:
            return np.concatenate(
                [parts[k].reshape(parts[k].shape[0], -1) for k in self.keys], axis=1
            )
        assert self._features is not None
        return self._features(parts)

    def logits(self, obs: Any) -> NDArray[np.float64]:
        """``(B, A)`` action logits (discrete) or Gaussian means (continuous), unclipped."""
        x = self.features(obs)
        last = len(self._w) - 1
        for i, (w, b) in enumerate(zip(self._w, self._b, strict=True)):
            x = x @ w.T + b
            if i < last:
                if self.activation == "relu":
                    x = np.maximum(x, 0.0)
                elif self.activation == "tanh":
                    x = np.tanh(x)
        return x

    def act(self, obs: Any) -> Any:
        """Deterministic action for one observation (or a batch, leading axis).

        Returns:
            an ``int`` (discrete) or an ``(A,)`` array, or ``(B,)`` / ``(B, A)`` for a batch.
        """
        _, single = self._batched(obs)
        out = self.logits(obs)
        if self.discrete:
            idx = np.argmax(out, axis=1)
            return int(idx[0]) if single else idx
        shape = tuple(self.meta["action"]["shape"])
        a = np.clip(out.reshape(-1, *shape), self.arrays["action_low"],
                    self.arrays["action_high"])
        return a[0] if single else a

    def command(self, action: ArrayLike) -> NDArray[np.float64]:
        """``(3,)`` ``[vx, vy, ω]`` for one action, as the env's ActionDecoder decodes it.

        Raises:
            ConfigError: the file records no action decoding.
        """
        cmd_meta = self.meta.get("command")
        if cmd_meta is None:
            raise ConfigError("the policy file records no action decoding", source=self.source)
        if cmd_meta["type"] == "table":
            cmd = self.arrays["command_table"][int(np.asarray(action).reshape(-1)[0])]
        else:
            lo, hi = self.arrays["range_low"], self.arrays["range_high"]
            a = np.asarray(action, dtype=np.float64).reshape(-1)
            if cmd_meta["normalize"]:
                a = lo + (np.clip(a, -1.0, 1.0) + 1.0) / 2.0 * (hi - lo)
            cmd = a if cmd_meta["holonomic"] else np.array([a[0], 0.0, a[1]])
        return np.clip(np.asarray(cmd, dtype=np.float64),
                       self.arrays["command_low"], self.arrays["command_high"])
