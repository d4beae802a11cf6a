"""The crowd-model plugin API (Arena's "Pedsim Waypoint Plugin", without ROS).

Each simulator step the :class:`~arena.crowd.simulator.CrowdSimulator` hands the configured
model one :class:`CrowdFrame` (agents, robots, destinations, groups, walls as segments, dt) and
gets a :class:`ModelOutput` back: accelerations ``(n, 2)`` that the simulator's one integrator
turns into motion (``v += a·dt``, speed cap, ``p += v·dt``), or, for models that declare
``output = "velocity"`` (ORCA, RVO2), the new velocities directly. Social states run before
(``pre``: destinations, vmax factors) and after (``post``: force overrides) the model.

Writing a model::

    @CROWD_MODELS.register("my_model")
    class MyModel:
        output = "acceleration"

        class Params(BaseModel, frozen=True, extra="forbid"):
            tau: float = Field(0.5, gt=0, description="s, relaxation time")

        def __init__(self, params: Params) -> None: ...
        def neighbor_cutoff(self) -> float: return 5.0      # m, or math.inf for all pairs
        def reset(self, state, world, rng) -> None: ...
        def compute(self, frame) -> ModelOutput: ...

A model that moves its pedestrians itself (``fast_social_force``: one compiled kernel per step)
is a :class:`DriverModel` instead: its ``make_driver`` gives the whole pedestrian driver, and
:func:`arena.crowd.driver.build_driver` picks the one or the other for a config.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, ClassVar, Literal, Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from arena.core.registry import Registry

if TYPE_CHECKING:
    from arena.crowd.neighbors import Neighbors
    from arena.crowd.simulator import PedestrianConfig
    from arena.crowd.state import CrowdState
    from arena.scene.state import StaticWorld
    from arena.sim.backend import PedestrianDriver

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


@dataclass(frozen=True, eq=False)
class RobotView:
    """The robots as pedestrians perceive them (world frame).

    Attributes:
        positions: ``(r, 2)`` m.
        headings: ``(r,)`` rad.
        velocities: ``(r, 2)`` m/s, world frame.
        radii: ``(r,)`` circumscribed radius (m).
    """

    positions: FloatArray
    headings: FloatArray
    velocities: FloatArray
    radii: FloatArray

    def __len__(self) -> int:
        return int(self.positions.shape[0])

    @classmethod
    def empty(cls) -> RobotView:
        """No robots."""
        return cls(np.zeros((0, 2)), np.zeros(0), np.zeros((0, 2)), np.zeros(0))


@dataclass(frozen=True, eq=False)
class CrowdFrame:
    """Everything a crowd model may read for one step. Models must not mutate it.

    Attributes:
        state: the crowd (positions, velocities, radii, vmax, groups, types, social states ...).
        destinations: ``(n, 2)`` where each agent heads this step (after group and social-state
            overrides; use this, not the raw waypoints).
        active: ``(n,)`` bool, agents that move this step (started and not finished); inactive
            agents still repel others but must get zero acceleration.
        robots: the robots.
        walls_a: ``(s, 2)`` start points of the static wall and obstacle segments (m).
        walls_b: ``(s, 2)`` end points.
        neighbors: pedestrian pairs within the model's :meth:`CrowdModel.neighbor_cutoff`.
        dt: step length (s).
        rng: the crowd's generator, for models with random terms.
    """

    state: CrowdState
    destinations: FloatArray
    active: NDArray[np.bool_]
    robots: RobotView
    walls_a: FloatArray
    walls_b: FloatArray
    neighbors: Neighbors
    dt: float
    rng: np.random.Generator


@dataclass
class ModelOutput:
    """What a model returns for one step.

    Attributes:
        accelerations: ``(n, 2)`` m/s² (for ``output = "acceleration"`` models).
        velocities: ``(n, 2)`` m/s, the new velocities (for ``output = "velocity"`` models).
        forces: per-term contributions ``name -> (n, 2)`` summing to the acceleration (optional,
            for recording and semantic layers; e.g. ``desired``, ``social``, ``obstacle``).
    """

    accelerations: FloatArray | None = None
    velocities: FloatArray | None = None
    forces: dict[str, FloatArray] = field(default_factory=dict)


@runtime_checkable
class CrowdModel(Protocol):
    """A pedestrian motion model."""

    output: ClassVar[Literal["acceleration", "velocity"]]

    def neighbor_cutoff(self) -> float:
        """Radius (m) within which other pedestrians influence an agent (``inf``: all pairs)."""
        ...

    def reset(self, state: CrowdState, world: StaticWorld, rng: np.random.Generator) -> None:
        """Prepare for a new episode (precompute wall data, per-agent constants ...)."""
        ...

    def compute(self, frame: CrowdFrame) -> ModelOutput:
        """Accelerations (or velocities) for every agent; zero for inactive agents."""
        ...


@runtime_checkable
class DriverModel(Protocol):
    """A crowd model that moves its pedestrians itself, outside the crowd simulator.

    Registered in :data:`CROWD_MODELS` like any model (``Params``, built by name), it gives a
    whole :class:`~arena.sim.backend.PedestrianDriver` of its own instead of accelerations, so
    none of the simulator's layers (social states, groups, start-up modes, the integrator)
    apply. :func:`arena.crowd.driver.build_driver` returns its :meth:`make_driver`.
    """

    def make_driver(self, pedestrians: PedestrianConfig | None = None) -> PedestrianDriver:
        """A fresh driver; ``pedestrians`` is the config's ``pedestrians:`` block."""
        ...


_BUILTIN_MODELS = {
    "bonding": "bonding", "deep_social_force": "deep_social_force",
    "evacuation": "evacuation.model", "fast_social_force": "fast_social_force.model",
    "orca": "orca.model", "passthrough": "pedsim.model",
    "pedsim": "pedsim.model", "pysocial": "pysocial.model",
    "rvo2": "rvo2", "spinny": "spinny", "waypoint_walker": "walker",
}

CROWD_MODELS: Registry[CrowdModel | DriverModel] = Registry(
    "crowd model",
    entry_points="arena.crowd_models",
    # name -> the module of arena.crowd.models registering it, imported when first named: a
    # config naming one model does not compile the others
    builtins={name: f"arena.crowd.models.{module}" for name, module in _BUILTIN_MODELS.items()},
    # the numba models' parameters, apart from their kernels: validating a config compiles none
    params={
        "evacuation": "arena.crowd.models.evacuation.params:EvacuationParams",
        "fast_social_force": (
            "arena.crowd.models.fast_social_force.params:FastSocialForceParams"
        ),
        "orca": "arena.crowd.models.orca.params:OrcaParams",
        "passthrough": "arena.crowd.models.pedsim.params:PedsimParams",
        "pedsim": "arena.crowd.models.pedsim.params:PedsimParams",
        "pysocial": "arena.crowd.models.pysocial.params:PySocialParams",
        "bonding": "arena.crowd.models.evacuation.params:BondingParams",
        "deep_social_force": "arena.crowd.models.deep_social_force_params:DeepSocialForceParams",
        "rvo2": "arena.crowd.models.orca.params:Rvo2Params",
        "spinny": "arena.crowd.models.pedsim.params:SpinnyParams",
    },
)
