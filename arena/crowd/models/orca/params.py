"""Parameters of the ``orca`` and ``rvo2`` crowd models.

Apart from the model and its numba kernels: a config validates them without compiling.
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field


class OrcaParams(BaseModel):
    """Parameters of :class:`~arena.crowd.models.orca.model.OrcaModel`, named as RVO2's.

    The agent radius is ``state.radii`` (plus ``safety_margin``) and the max speed
    ``state.vmax · state.vmax_factor`` (per agent; the simulator's speed cap), so they are not
    parameters here. RVO2 has no library defaults; ours are pedestrian-scale: a 2 s horizon
    (with 4-5 s, CrowdNav's choice, ORCA, RVO2 included, stalls for good when eight people of
    different speeds swap sides of a 4 m circle), and 5 m of neighbour range, beyond which a
    pedestrian cannot constrain the velocity within that horizon at walking speeds.
    ``safety_margin = 0`` and ``pref_perturbation = 0`` give RVO2's results.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")
    neighbor_dist: float = Field(
        5.0, gt=0, description="m, pedestrians farther away are ignored (RVO2 neighborDist)"
    )
    max_neighbors: int = Field(
        10, ge=0, description="nearest pedestrians considered per agent (RVO2 maxNeighbors)"
    )
    time_horizon: float = Field(
        2.0, gt=0, description="s, collisions this far ahead are avoided (RVO2 timeHorizon)"
    )
    safety_margin: float = Field(
        0.05,
        ge=0,
        description="m, added to each agent's radius for avoidance (0 reproduces RVO2; when "
        "RVO2's linear program is infeasible in dense crowds it lets agents overlap by a few cm)",
    )
    pref_speed_factor: float = Field(
        1.0, gt=0, le=1, description="preferred speed as a fraction of the max speed"
    )
    arrival_time: float = Field(
        1.0,
        gt=0,
        description="s, the preferred velocity is (destination − p)/arrival_time on the last "
        "stretch (RVO2's examples: 1 s)",
    )
    pref_perturbation: float = Field(
        1e-4,
        ge=0,
        description="m/s, random nudge of the preferred velocity against deadlocks from "
        "perfect symmetry (RVO2's Blocks example: 1e-4; 0 for none)",
    )
    avoid_robots: bool = Field(
        True, description="avoid robots as non-reciprocating moving obstacles (full share)"
    )


class Rvo2Params(OrcaParams):
    """Parameters of :class:`~arena.crowd.models.rvo2.Rvo2Model`.

    Those of ORCA, plus the obstacle horizon.
    """

    time_horizon_obst: float = Field(
        2.0,
        gt=0,
        description="s, collisions with walls this far ahead are avoided (RVO2 timeHorizonObst)",
    )
