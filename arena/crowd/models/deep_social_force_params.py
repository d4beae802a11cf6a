"""The learned potential and the parameters of the ``deep_social_force`` crowd model.

NumPy only, apart from the model's numba kernels: a config validates the parameters (and reads
the weights file it names) without compiling them.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, field_validator

from arena.core import files
from arena.core.errors import ConfigError

FloatArray = NDArray[np.float64]

#: The shipped weights (see the module docstring for what they were trained on).
WEIGHTS = Path(__file__).resolve().parent / "weights" / "deep_social_force.npz"


class MLPPotential:
    """The learned ped-ped potential ``V(b) = softplus(w2·softplus(w1·b + b1) + b2)``.

    Args:
        w1: ``(h,)`` input weights (1/m).
        b1: ``(h,)`` hidden biases.
        w2: ``(h,)`` output weights (m²/s²).
        b2: output bias (m²/s²).
        metadata: training record (architecture, command, loss, data ...).
    """

    def __init__(
        self,
        w1: FloatArray,
        b1: FloatArray,
        w2: FloatArray,
        b2: float,
        metadata: dict[str, Any] | None = None,
    ) -> None:
        self.w1 = np.ascontiguousarray(w1, dtype=np.float64).reshape(-1)
        self.b1 = np.ascontiguousarray(b1, dtype=np.float64).reshape(-1)
        self.w2 = np.ascontiguousarray(w2, dtype=np.float64).reshape(-1)
        self.b2 = float(b2)
        if not self.w1.shape == self.b1.shape == self.w2.shape:
            raise ValueError("w1, b1 and w2 must have the same length (hidden units)")
        self.metadata = metadata or {}

    @classmethod
    def load(cls, path: str | Path = WEIGHTS) -> MLPPotential:
        """Read weights written by ``tools/train_deep_social_force.py``.

        Raises:
            ConfigError: not such a file: no ``.npz``, pickled data, missing arrays ``w1, b1,
                w2, b2``, non-numeric or mismatched shapes, metadata that is not JSON.
        """
        what = "deep_social_force weights file (.npz with w1, b1, w2, b2)"
        z = files.read_npz(path, ("w1", "b1", "w2", "b2"), what=what)
        source = str(path)
        for k in ("w1", "b1", "w2", "b2"):
            if z[k].dtype.kind not in "fiu":
                raise ConfigError(f"array {k!r} is not numeric ({z[k].dtype})", source=source)
        if not (z["w1"].ndim == z["b1"].ndim == z["w2"].ndim == 1
                and z["w1"].shape == z["b1"].shape == z["w2"].shape and z["w1"].size > 0
                and z["b2"].size == 1):
            raise ConfigError(
                f"w1, b1, w2 must be 1-D of one length and b2 one number; got shapes "
                f"{[tuple(z[k].shape) for k in ('w1', 'b1', 'w2', 'b2')]}", source=source,
            )
        meta: Any = {}
        if "metadata" in z:
            try:
                meta = json.loads(str(z["metadata"]))
            except ValueError:
                raise ConfigError("'metadata' is not JSON text", source=source) from None
        return cls(z["w1"], z["b1"], z["w2"], float(z["b2"].reshape(-1)[0]),
                   meta if isinstance(meta, dict) else {})

    @property
    def hidden(self) -> int:
        """Number of hidden units."""
        return int(self.w1.shape[0])

    def value(self, b: FloatArray) -> FloatArray:
        """``V(b)`` (m²/s²) for ``b`` of any shape (m); ``b`` is clamped at 100 m like Kreiss."""
        bb = np.minimum(np.asarray(b, dtype=np.float64), 100.0)[..., None]
        z2 = _softplus(bb * self.w1 + self.b1) @ self.w2 + self.b2
        return _softplus(z2)

    def dvdb(self, b: FloatArray) -> FloatArray:
        """``dV/db`` (m/s²), closed form: ``σ(z2)·Σ_k w2_k·σ(z1_k)·w1_k``; zero beyond 100 m."""
        b_arr = np.asarray(b, dtype=np.float64)
        bb = np.minimum(b_arr, 100.0)[..., None]
        z1 = bb * self.w1 + self.b1
        z2 = _softplus(z1) @ self.w2 + self.b2
        out = _sigmoid(z2) * ((_sigmoid(z1) * self.w1) @ self.w2)
        return np.where(b_arr > 100.0, 0.0, out)


def _softplus(x: FloatArray) -> FloatArray:
    return np.logaddexp(0.0, x)


def _sigmoid(x: FloatArray) -> FloatArray:
    return 0.5 * (1.0 + np.tanh(0.5 * x))  # overflow-free logistic


class DeepSocialForceParams(BaseModel):
    """Parameters of :class:`~arena.crowd.models.deep_social_force.DeepSocialForce`.

    Defaults: Kreiss's ``socialforce`` 0.2.3.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")
    potential: Literal["mlp", "analytic"] = Field(
        "mlp", description="learned MLP V(b), or the analytic v0·exp(−b/σ)"
    )
    weights: str | None = Field(
        None,
        description="path to an .npz from tools/train_deep_social_force.py "
        "(default: the shipped weights); read and checked when the config is loaded",
    )

    @field_validator("weights")
    @classmethod
    def _readable(cls, v: str | None) -> str | None:
        if v is not None:
            try:
                MLPPotential.load(v)
            except ConfigError as e:  # pydantic's location then names crowd.weights
                raise ValueError(str(e)) from None
        return v
    v0: float = Field(
        2.1, ge=0, description="m²/s², analytic potential strength (socialforce default)"
    )
    sigma: float = Field(
        0.3,
        gt=0,
        description="m, analytic potential range (socialforce default; Arena's plugin 1.0)",
    )
    delta_t: float = Field(
        0.4, gt=0, description="s, Δt of the semi-minor axis b (socialforce delta_t_step)"
    )
    tau: float = Field(0.5, gt=0, description="s, relaxation time (socialforce)")
    field_of_view: float = Field(
        200.0, gt=0, le=360, description="deg, full field-of-view angle 2φ (socialforce)"
    )
    out_of_view_factor: float = Field(
        0.5, ge=0, le=1, description="weight of pedestrians outside the view (socialforce)"
    )
    wall_strength: float = Field(
        10.0, ge=0, description="m²/s², u0 of the space potential (socialforce)"
    )
    wall_range: float = Field(
        0.2, gt=0, description="m, r of the space potential (socialforce)"
    )
    robots_as_pedestrians: bool = Field(
        True, description="robots repel like pedestrians walking along their velocity"
    )
    interaction_range: float = Field(
        3.5,
        gt=0,
        description="m, centre distance beyond which pedestrians and robots are ignored "
        "(b ≥ 3.2 m there at 1.5 m/s; analytic force < 1e-4 m/s²)",
    )
    wall_cutoff: float = Field(
        2.0, gt=0, description="m, walls farther away are ignored (force < 3e-3 m/s²)"
    )
    max_substep: float = Field(
        0.1,
        gt=0,
        description="s, longest internal step; 0.1 is stable (module docstring), "
        "socialforce steps 0.04 (0.4 s / 10)",
    )
