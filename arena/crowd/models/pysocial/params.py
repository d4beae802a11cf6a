"""Parameters of the ``pysocial`` crowd model.

Apart from the model and its numba kernels: a config validates them without compiling.
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field


class PySocialParams(BaseModel):
    """Parameters of :class:`~arena.crowd.models.pysocial.model.PySocialModel`.

    Defaults are PySocialForce 1.1.2's ``default.toml`` as its simulator applies them (see
    the module docstring for the two group factors).
    """

    model_config = ConfigDict(frozen=True, extra="forbid")

    # desired_force
    desired_factor: float = Field(1.0, ge=0, description="dimensionless, desired_force.factor")
    relaxation_time: float = Field(
        0.5, gt=0, description="s, desired_force.relaxation_time (τ)"
    )
    goal_threshold: float = Field(
        0.2,
        ge=0,
        description="m, desired_force.goal_threshold: closer than this the agent brakes",
    )
    # social_force
    social_factor: float = Field(5.1, ge=0, description="m/s², social_force.factor")
    lambda_importance: float = Field(
        2.0,
        ge=0,
        description="s/m, social_force.lambda_importance: weight of the velocity difference",
    )
    gamma: float = Field(0.35, gt=0, description="m, social_force.gamma: B = γ|D|")
    n: float = Field(2.0, ge=0, description="1/m, social_force.n: angular decay (turning)")
    n_prime: float = Field(
        3.0, ge=0, description="1/m, social_force.n_prime: angular decay (braking)"
    )
    # obstacle_force
    obstacle_factor: float = Field(10.0, ge=0, description="m/s², obstacle_force.factor")
    obstacle_sigma: float = Field(
        0.2, gt=0, description="m, obstacle_force.sigma: decay length"
    )
    obstacle_threshold: float = Field(
        3.0,
        ge=0,
        description="m, obstacle_force.threshold (the agent radius is added, as upstream)",
    )
    agent_radius: float | None = Field(
        0.35,
        ge=0,
        description="m, scene.agent_radius; None uses each agent's own radius",
    )
    resolution: float = Field(
        10.0, gt=0, description="1/m, scene.resolution: obstacle sample points per metre"
    )
    # groups
    enable_group: bool = Field(True, description="scene.enable_group: the three group terms")
    group_coherence_factor: float = Field(
        1.0,
        ge=0,
        description="1/s², GroupCoherenceForceAlt factor (toml's 3.0 is never applied)",
    )
    coherence_uses_distance: bool = Field(
        False,
        description="soften the coherence with |c − r_i| as pedsim does; False reproduces "
        "PySocialForce (which always uses 0)",
    )
    group_repulsion_factor: float = Field(
        1.0, ge=0, description="1/s², group_repulsive_force.factor"
    )
    group_repulsion_threshold: float = Field(
        0.55, ge=0, description="m, group_repulsive_force.threshold"
    )
    group_gaze_factor: float = Field(
        1.0,
        ge=0,
        description="m/s², GroupGazeForceAlt factor (toml's 4.0 is never applied)",
    )
    # Arena
    robot_factor: float = Field(
        1.0,
        ge=0,
        description="dimensionless, robots act through the social term × this; "
        "0 reproduces PySocialForce",
    )
    force_scale: float = Field(
        1.0, ge=0, description="dimensionless, scale on the total (Arena used 0.3)"
    )
    wrap_theta: bool = Field(
        False,
        description="wrap the social angle θ into (−π, π] as Moussaïd intends; False "
        "reproduces PySocialForce's raw atan2 difference",
    )
    cutoff: float = Field(
        10.0,
        gt=0,
        description="m, social/robot interaction range; inf = all pairs (exact PySocialForce)",
    )
