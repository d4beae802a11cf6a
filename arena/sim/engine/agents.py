"""The pedestrians of an engine's worlds as arrays: padded per world, or standing still."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from arena.scene.episode import Episode
from arena.scene.state import AgentStates

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]
B1 = NDArray[np.bool_]


@dataclass(frozen=True, eq=False)
class PaddedAgents:
    """The pedestrians of all worlds padded to ``P`` slots: ``(W, P, ...)`` arrays.

    Attributes:
        positions: ``(W, P, 2)`` m (padding 0).
        velocities: ``(W, P, 2)`` m/s (padding 0).
        headings: ``(W, P)`` rad (padding 0).
        radii: ``(W, P)`` m (padding 0).
        kinds: ``(W, P)`` type codes (padding -1).
        states: ``(W, P)`` social-state codes (padding -1).
        mask: ``(W, P)`` bool, the slot holds a pedestrian.
    """

    positions: F64
    velocities: F64
    headings: F64
    radii: F64
    kinds: I64
    states: I64
    mask: B1


def pad_agents(agents: Sequence[AgentStates], ag_off: I64, ag_pos: F64, ag_r: F64) -> PaddedAgents:
    """Every world's pedestrians padded to the largest crowd.

    ``ag_off`` ``(W + 1,)`` offsets of the flat ``ag_pos`` ``(A, 2)`` m and ``ag_r`` ``(A,)`` m
    (the engine's gathered arrays of ``agents``).
    """
    w_n = len(agents)
    counts = np.diff(ag_off)
    p = int(counts.max()) if w_n else 0
    world = np.repeat(np.arange(w_n), counts)
    slot = np.arange(int(ag_off[-1])) - ag_off[world]
    ags = agents
    pos = np.zeros((w_n, p, 2))
    vel = np.zeros((w_n, p, 2))
    head = np.zeros((w_n, p))
    rad = np.zeros((w_n, p))
    kinds = np.full((w_n, p), -1, dtype=np.int64)
    states = np.full((w_n, p), -1, dtype=np.int64)
    mask = np.zeros((w_n, p), dtype=bool)
    if world.size:
        pos[world, slot] = ag_pos
        rad[world, slot] = ag_r
        vel[world, slot] = np.concatenate([a.velocities for a in ags])
        head[world, slot] = np.concatenate([a.headings for a in ags])
        kinds[world, slot] = np.concatenate([a.kinds for a in ags])
        states[world, slot] = np.concatenate([a.states for a in ags])
        mask[world, slot] = True
    return PaddedAgents(pos, vel, head, rad, kinds, states, mask)


def standing_agents(episode: Episode) -> AgentStates:
    """The episode's pedestrians standing at their spawn (no driver)."""
    sp = episode.agents
    n = len(sp)
    return AgentStates(
        ids=np.arange(n, dtype=np.int64),
        positions=sp.positions.astype(np.float64, copy=True),
        velocities=np.zeros((n, 2)),
        headings=np.zeros(n),
        radii=sp.radii.astype(np.float64, copy=True),
        kinds=sp.kinds.astype(np.int64, copy=True),
        states=np.zeros(n, dtype=np.int64),
    )
