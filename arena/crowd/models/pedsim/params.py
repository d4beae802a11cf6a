"""Parameters of the ``pedsim``, ``passthrough`` and ``spinny`` crowd models.

Apart from the model and its numba kernels: a config validates them without compiling.
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field


class PedsimParams(BaseModel):
    """Parameters of :class:`~arena.crowd.models.pedsim.model.PedsimModel`.

    Libpedsim ``Tagent`` defaults unless noted.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")
    relaxation_time: float = Field(
        0.5, gt=0, description="s, τ: the desired force closes the speed gap in τ"
    )
    force_factor_desired: float = Field(1.0, ge=0, description="1, weight of the desired term")
    force_factor_social: float = Field(
        2.1,
        ge=0,
        description="m/s², weight of the social term; libpedsim's per-agent default 2.1 "
        "(Arena's pedsim simulator config sets force_social 5.1, its task generator 5.0)",
    )
    force_factor_obstacle: float = Field(
        10.0, ge=0, description="m/s², weight of the obstacle term (libpedsim and Arena)"
    )
    force_factor_robot: float = Field(
        2.0,
        ge=0,
        description="m/s², weight of the robot term; Arena's task generator uses 0 for plain "
        "pedestrians (they ignore robots) and samples [2, 10] from pedsim.yaml; 2 is that "
        "range's low end and about libpedsim's old use of the social factor 2.1 for robots",
    )
    force_factor_random: float = Field(
        0.1, ge=0, description="m/s², scale of the random term (pedsim force_random)"
    )
    sigma_obstacle: float = Field(
        0.8,
        gt=0,
        description="m, decay length of the obstacle term (libpedsim; Arena's simulator "
        "config sigma_obstacle is 0.2)",
    )
    obstacle_force_range: float = Field(
        2.0, gt=0, description="m, walls farther than this from the centre are ignored"
    )
    lambda_importance: float = Field(
        2.0, ge=0, description="s/m, weight of the velocity difference in t = λ·Δv + ê"
    )
    gamma: float = Field(0.35, gt=0, description="m, B = γ·|t|, the interaction range")
    n: float = Field(2.0, ge=0, description="1/m, angular width of the turning term")
    n_prime: float = Field(3.0, ge=0, description="1/m, angular width of the braking term")
    neighborhood_range: float = Field(
        10.0, gt=0, description="m, pedestrians and robots farther away exert no force"
    )
    subtract_radii: bool = Field(
        True,
        description="social distance edge to edge (Arena's libpedsim); False: centre to "
        "centre (upstream libpedsim)",
    )
    robot_sigma_per_vmax: float = Field(
        0.75, gt=0, description="s, σ_robot = this · vmax (libpedsim 0.3·vmax/0.4)"
    )
    keep_distance: float = Field(
        0.8, ge=0, description="m, rest length of the keep-distance spring"
    )
    keep_distance_gain: float = Field(
        10.0, ge=0, description="1/s², stiffness of the keep-distance spring (libpedsim 10)"
    )
    random_fading_time: float = Field(
        1.0, gt=0, description="s, a new random deviation is drawn this often"
    )


class SpinnyParams(PedsimParams):
    """Parameters of :class:`~arena.crowd.models.spinny.SpinnyModel`.

    Pedsim's, plus the turn per step.
    """

    angle_per_step_deg: float = Field(
        3.0, description="deg, added to the rotation every step (Arena 3°; 0 gives pedsim)"
    )
