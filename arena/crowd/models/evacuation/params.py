"""Parameters of the ``evacuation`` and ``bonding`` crowd models.

Apart from the model and its numba kernels: a config validates them without compiling.
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field


class EvacuationParams(BaseModel):
    """Parameters of :class:`~arena.crowd.models.evacuation.model.Evacuation`.

    Defaults: Helbing, Farkas & Vicsek 2000.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")
    social_strength: float = Field(
        2000.0, ge=0, description="N, A: strength of the psychological repulsion (paper)"
    )
    social_range: float = Field(
        0.08, gt=0, description="m, B: range of the psychological repulsion (paper)"
    )
    body_stiffness: float = Field(
        1.2e5, ge=0, description="kg/s², k: body compression coefficient (paper)"
    )
    friction: float = Field(
        2.4e5, ge=0, description="kg/(m·s), κ: sliding friction coefficient (paper)"
    )
    mass: float = Field(
        80.0, gt=0, description="kg, m: pedestrian mass (paper; Arena's plugin used 180)"
    )
    tau: float = Field(
        0.5, gt=0, description="s, τ: relaxation time (paper; Arena's plugin used 1.0)"
    )
    robots_as_bodies: bool = Field(
        True, description="robots repel, push and rub pedestrians like another body"
    )
    interaction_range: float = Field(
        2.0,
        gt=0,
        description="m, centre distance beyond which pedestrians, walls and robots are "
        "ignored; the social term there is below 1e-4 N for radii 0.3 m",
    )
    max_substep: float = Field(
        0.005,
        gt=0,
        description="s, longest internal integration step; shortened further while "
        "contacts are stiffer (see module docstring)",
    )
    max_substeps: int = Field(
        400,
        ge=1,
        description="most sub-steps per step (bounds the cost of deep overlaps, e.g. "
        "agents spawned on top of each other; the speed cap keeps the result bounded)",
    )


class BondingParams(EvacuationParams):
    """Parameters of :class:`~arena.crowd.models.bonding.Bonding`.

    The evacuation model's, plus the bonding term.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")
    bond_strength: float = Field(
        200.0,
        ge=0,
        description="N, C: saturated bonding pull (ours: of the order of the 160 N "
        "driving force; Xu & Duh's calibrated value was not retrievable)",
    )
    bond_range: float = Field(
        1.0, gt=0, description="m, D: gap over which the pull saturates (ours)"
    )
    comfort_gap: float = Field(
        0.5,
        ge=0,
        description="m, c: surface-to-surface gap between relatives with no pull (ours)",
    )
