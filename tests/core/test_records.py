"""frozen_record builds the same frozen record as the dataclass's own __init__."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from arena.core.records import frozen_record
from arena.scene.state import Collisions, SimState


def test_record_equals_the_generated_init_and_stays_frozen() -> None:
    wall = np.array([True, False])
    idx = np.array([-1, 3])
    fast = frozen_record(Collisions, wall=wall, obstacle=idx, agent=idx, robot=idx)
    slow = Collisions(wall, idx, idx, idx)
    assert type(fast) is Collisions
    assert repr(fast) == repr(slow)
    for f in dataclasses.fields(Collisions):
        assert getattr(fast, f.name) is getattr(slow, f.name)
    assert fast.any.tolist() == [True, True]
    with pytest.raises(dataclasses.FrozenInstanceError):
        fast.wall = wall  # type: ignore[misc]


def test_every_field_must_be_given() -> None:
    with pytest.raises(TypeError, match=r"SimState: missing fields \['collisions'\]"):
        frozen_record(SimState, time=0.0, step=0, robots=None, agents=None)
    with pytest.raises(TypeError, match=r"unknown fields \['colisions'\]"):
        frozen_record(SimState, time=0.0, step=0, robots=None, agents=None, collisions=None,
                      colisions=None)
