"""Names of runs: what an unnamed experiment is called (folders, video titles)."""

from __future__ import annotations

import re
from pathlib import Path

from arena.config.schema import ExperimentConfig

#: ``ExperimentConfig.name``'s default: a run left unnamed is named after what it runs.
UNNAMED = ExperimentConfig.model_fields["name"].default


def run_name(cfg: ExperimentConfig) -> str:
    """The run's label: ``cfg.name``, or ``<map>_<robot>_<local planner>`` when it is unnamed.

    Unnamed is the schema default (``name: default`` or no ``name`` key): then the map (world
    name, map file's world folder or stem, or generator type), the robot preset (or robot file
    stem) and the local planner name the run, e.g. ``small_office_jackal_pure_pursuit``.
    """
    if cfg.name != UNNAMED:
        return cfg.name
    spec = cfg.map
    if spec.get("type") == "world" and spec.get("name"):
        where = Path(str(spec["name"])).name
    elif spec.get("type") == "file" and spec.get("path"):
        path = Path(str(spec["path"]))
        where = path.parent.parent.name if path.parent.name == "map" else path.stem
    else:
        where = str(spec.get("type", "map"))
    robot = Path(cfg.robot).stem if cfg.robot.endswith((".yaml", ".yml")) else cfg.robot
    local = str(cfg.navigation.local_planner.get("type", "planner"))
    # only characters that are safe in a folder name on every system
    return "_".join(re.sub(r"[^A-Za-z0-9_.-]+", "-", p).strip("-.")[:40] or "x"
                    for p in (where, robot, local))
