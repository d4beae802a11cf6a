"""Import every built-in plugin module so that all registries are filled.

Third-party plugins arrive through entry points and are loaded by each registry lazily.
"""

from __future__ import annotations

import arena.crowd
import arena.eval.metrics
import arena.maps.generators
import arena.maps.sources
import arena.nav
import arena.robots
import arena.sim.native2d
import arena.tasks.modules
import arena.tasks.obstacle_modes
import arena.tasks.robot_modes  # noqa: F401
from arena.core.registry import all_registries

__all__ = ["all_registries"]
