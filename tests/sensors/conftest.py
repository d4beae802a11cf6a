"""Fixtures shared by the sensor tests (requested by name; none is autouse)."""

from __future__ import annotations

import pytest

from arena.maps.grid import OccupancyGrid


@pytest.fixture
def box_room() -> OccupancyGrid:
    """40 × 40 cells at 0.25 m with a one-cell border: inner faces at 0.25 m and 9.75 m."""
    return OccupancyGrid.empty(10.0, 10.0, 0.25)
