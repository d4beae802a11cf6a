"""Every learned planner builds and plans with numpy alone: no torch, SB3 or Gymnasium."""

from __future__ import annotations

import subprocess
import sys

CODE = """
import sys
for name in ("torch", "stable_baselines3", "gymnasium"):
    sys.modules[name] = None  # importing it now fails
import numpy as np
from arena.core.types import Pose2D
from arena.maps.grid import OccupancyGrid
from arena.nav.global_planners import GLOBAL_PLANNERS
from arena.nav.local_planners.base import LOCAL_PLANNERS
learned = [n for n in LOCAL_PLANNERS.names() if "learned" in LOCAL_PLANNERS.entry(n).tags]
for n in learned:
    LOCAL_PLANNERS.build({"type": n})
planner = GLOBAL_PLANNERS.build({"type": "artplanner"})
path = planner.plan(OccupancyGrid.empty(6.0, 4.0, 0.1), Pose2D(1.0, 1.0), Pose2D(5.0, 3.0))
print(sorted(learned), len(path) > 1)
"""


def test_learned_planners_need_no_torch_sb3_or_gymnasium():
    out = subprocess.run([sys.executable, "-c", CODE], capture_output=True, text=True,
                         timeout=300, check=False)
    assert out.returncode == 0, out.stderr[-2000:]
    names, planned = out.stdout.strip().rsplit(" ", 1)
    for n in ("applr", "crowdnav", "iplanner", "lflh", "rlca", "rosnav_rl", "sarl", "trail"):
        assert n in names
    assert planned == "True"
