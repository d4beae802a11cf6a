"""Parameters of the ``fast_social_force`` crowd model.

Apart from the model and its numba kernels: a config validates them without compiling.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

# Indices into the parameter vector the kernel reads (:meth:`FastSocialForceParams.as_array`).
P_TAU, P_GOAL_R, P_A_PED, P_B_PED, P_A_WALL, P_B_WALL, P_A_ROB, P_B_ROB, P_CUTOFF, P_VFAC = range(
    10
)


class FastSocialForceParams(BaseModel):
    """Parameters of :class:`~arena.crowd.models.fast_social_force.model.FastSocialForceModel`.

    Accelerations in m/s²; each repulsion is ``A·exp((r_a + r_b − d)/B)`` (see the model).
    """

    model_config = ConfigDict(frozen=True, extra="forbid")
    relaxation_time: float = Field(0.5, gt=0, description="s, τ of the goal attraction")
    goal_radius: float = Field(0.3, gt=0, description="m, a waypoint counts as reached within")
    ped_factor: float = Field(2.1, ge=0, description="m/s², A of pedestrian repulsion")
    ped_range: float = Field(0.3, gt=0, description="m, B (decay length) of pedestrian repulsion")
    wall_factor: float = Field(
        10.0, ge=0, description="m/s², A of wall and obstacle repulsion (pysocial obstacle_factor)"
    )
    wall_range: float = Field(
        0.2, gt=0, description="m, B of wall repulsion (pysocial obstacle_sigma)"
    )
    robot_factor: float = Field(3.0, ge=0, description="m/s², A of robot repulsion")
    robot_range: float = Field(0.5, gt=0, description="m, B of robot repulsion")
    cutoff: float = Field(3.0, gt=0, description="m, interactions farther than this are ignored")
    max_speed_factor: float = Field(1.3, gt=0, description="speed cap as a multiple of vmax")

    def as_array(self) -> NDArray[np.float64]:
        """``(10,)`` the vector the kernel reads, in the order of the ``P_*`` indices."""
        return np.array([
            self.relaxation_time, self.goal_radius, self.ped_factor, self.ped_range,
            self.wall_factor, self.wall_range, self.robot_factor, self.robot_range,
            self.cutoff, self.max_speed_factor,
        ])
