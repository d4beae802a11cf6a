"""The crowd's state as a struct of arrays, and the integer codes stored in it.

Codes follow Arena's ``pedsim_msgs/AgentState`` where Arena defines them (social states 0-5,
types adult 0 / elder 1) so recorded data maps one to one.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from arena.scene.episode import AgentSpawn

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]


class SocialState(enum.IntEnum):
    """What a pedestrian is doing (Arena's ``AgentState`` constants, plus ``PANIC``)."""

    IDLE = 0
    WALKING = 1
    RUNNING = 2
    INTERACTING = 3
    TALKING = 4
    PHONE = 5
    PANIC = 6


class AgentType(enum.IntEnum):
    """Pedestrian type (Arena: ``human/adult`` 0, ``human/elder`` 1; child reserved)."""

    ADULT = 0
    ELDER = 1
    CHILD = 2


class StartupMode(enum.IntEnum):
    """When a pedestrian starts walking (pedsim ``start_up_mode``)."""

    DEFAULT = 0
    """At once."""
    WAIT_TIMER = 1
    """After ``wait_time`` seconds."""
    TRIGGER_ZONE = 2
    """When a robot comes within ``trigger_radius``."""


@dataclass(eq=False)
class CrowdState:
    """All pedestrians of an episode, index ``i`` everywhere (``n`` agents, ``K`` waypoint slots).

    Owned and mutated only by :class:`arena.crowd.simulator.CrowdSimulator`; crowd models read it.

    Attributes:
        ids: ``(n,)`` stable ids.
        positions: ``(n, 2)`` m.
        velocities: ``(n, 2)`` m/s, world frame.
        headings: ``(n,)`` rad (facing direction; follows the velocity unless a state turns it).
        radii: ``(n,)`` body radius (m).
        vmax: ``(n,)`` preferred (desired) walking speed (m/s).
        vmax_factor: ``(n,)`` multiplier on ``vmax`` set by social states each step.
        waypoints: ``(n, K, 2)`` m; rows past ``num_waypoints`` are NaN.
        num_waypoints: ``(n,)``.
        waypoint_index: ``(n,)`` index of the waypoint being walked to.
        waypoint_mode: ``(n,)`` 0 loop, 1 random.
        destinations: ``(n, 2)`` where each agent heads this step (waypoint, group leader's
            waypoint, or a social state's target).
        startup_mode: ``(n,)`` :class:`StartupMode` codes.
        wait_time: ``(n,)`` s, for ``WAIT_TIMER``.
        trigger_radius: ``(n,)`` m, for ``TRIGGER_ZONE``.
        started: ``(n,)`` bool, whether the agent has started moving.
        group: ``(n,)`` group id, -1 for agents walking alone.
        leader: ``(n,)`` index of the agent's group leader (itself for leaders and loners).
        kinds: ``(n,)`` :class:`AgentType` codes.
        social_state: ``(n,)`` :class:`SocialState` codes.
        stress, energy, social: ``(n,)`` internal levels in [0, 1].
        forces: per-term forces ``name -> (n, 2)`` from the last model step (for inspection,
            recording and the semantic layers).
        time: s since the episode start.
    """

    ids: IntArray
    positions: FloatArray
    velocities: FloatArray
    headings: FloatArray
    radii: FloatArray
    vmax: FloatArray
    vmax_factor: FloatArray
    waypoints: FloatArray
    num_waypoints: IntArray
    waypoint_index: IntArray
    waypoint_mode: IntArray
    destinations: FloatArray
    startup_mode: IntArray
    wait_time: FloatArray
    trigger_radius: FloatArray
    started: BoolArray
    group: IntArray
    leader: IntArray
    kinds: IntArray
    social_state: IntArray
    stress: FloatArray
    energy: FloatArray
    social: FloatArray
    forces: dict[str, FloatArray] = field(default_factory=dict)
    time: float = 0.0

    def __len__(self) -> int:
        return int(self.positions.shape[0])

    @property
    def current_waypoints(self) -> FloatArray:
        """``(n, 2)`` the waypoint each agent walks to."""
        return self.waypoints[np.arange(len(self)), self.waypoint_index]

    @property
    def speeds(self) -> FloatArray:
        """``(n,)`` m/s."""
        return np.hypot(self.velocities[:, 0], self.velocities[:, 1])

    @property
    def max_speeds(self) -> FloatArray:
        """``(n,)`` the speed cap this step: ``vmax · vmax_factor`` (m/s)."""
        return self.vmax * self.vmax_factor

    @classmethod
    def from_spawn(cls, spawn: AgentSpawn) -> CrowdState:
        """Agents at rest at their spawn positions, heading to their first waypoint.

        Groups, start-up modes and timers come from the spawn when given; otherwise every agent
        walks alone and starts at once. Social state WALKING, levels stress 0, energy and
        social 0.5 (Arena's initial values).
        """
        n = len(spawn)
        pos = np.array(spawn.positions, dtype=np.float64).reshape(n, 2)
        wps = np.array(spawn.waypoints, dtype=np.float64)
        first = wps[:, 0, :] if n else np.zeros((0, 2))
        d = first - pos
        headings = np.arctan2(d[:, 1], d[:, 0]) if n else np.zeros(0)

        def ints(v: object, default: int) -> IntArray:
            return np.full(n, default, dtype=np.int64) if v is None else np.array(v, dtype=np.int64)

        def floats(v: object, default: float) -> FloatArray:
            return np.full(n, default) if v is None else np.array(v, dtype=np.float64)

        groups = ints(spawn.groups, -1)
        return cls(
            ids=np.arange(n, dtype=np.int64),
            positions=pos,
            velocities=np.zeros((n, 2)),
            headings=headings,
            radii=np.array(spawn.radii, dtype=np.float64),
            vmax=np.array(spawn.vmax, dtype=np.float64),
            vmax_factor=np.ones(n),
            waypoints=wps,
            num_waypoints=np.array(spawn.num_waypoints, dtype=np.int64),
            waypoint_index=np.zeros(n, dtype=np.int64),
            waypoint_mode=np.array(spawn.waypoint_mode, dtype=np.int64),
            destinations=first.copy(),
            startup_mode=ints(spawn.startup_mode, int(StartupMode.DEFAULT)),
            wait_time=floats(spawn.wait_time, 0.0),
            trigger_radius=floats(spawn.trigger_radius, 0.0),
            started=ints(spawn.startup_mode, int(StartupMode.DEFAULT)) == StartupMode.DEFAULT,
            group=groups,
            leader=leaders_of(groups),
            kinds=np.array(spawn.kinds, dtype=np.int64),
            social_state=np.full(n, int(SocialState.WALKING), dtype=np.int64),
            stress=np.zeros(n),
            energy=np.full(n, 0.5),
            social=np.full(n, 0.5),
        )

    def copy(self) -> CrowdState:
        """A deep copy (for tests and counterfactual replays)."""
        kw: dict[str, Any] = {
            k: (v.copy() if isinstance(v, np.ndarray) else v) for k, v in self.__dict__.items()
        }
        kw["forces"] = {k: v.copy() for k, v in self.forces.items()}
        return CrowdState(**kw)


def leaders_of(groups: IntArray) -> IntArray:
    """Leader index per agent: the lowest index in its group; itself when alone (group -1)."""
    n = groups.shape[0]
    leader = np.arange(n, dtype=np.int64)
    grouped = groups >= 0
    if grouped.any():
        ids, first = np.unique(groups[grouped], return_index=True)
        members = np.flatnonzero(grouped)
        lookup = dict(zip(ids.tolist(), members[first].tolist(), strict=True))
        leader[members] = [lookup[g] for g in groups[members].tolist()]
    return leader
