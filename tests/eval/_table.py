"""A hand-built results table: 2 contestants x 2 stages x 5 episodes, deterministic values."""

from __future__ import annotations

import numpy as np
import pyarrow as pa

CONTESTANTS = ("alpha", "beta")
STAGES = ("easy", "hard")


def values(c: int, s: int) -> dict[str, np.ndarray]:
    """The 5 episodes of contestant c on stage s."""
    e = np.arange(5, dtype=float)
    return {
        "success": np.array([1, 1, 1, 0, 1], float) if c == 0 else np.array([1, 0, 1, 0, 1.0]),
        "collisions": (e % 2) + c,
        "time_to_goal": 10.0 + 2.0 * c + 3.0 * s + e,
        "path_length": 8.0 + c + 0.5 * e * (s + 1),
        "time_in_private_zone": 1.0 + 2.0 * c + 0.1 * e,
        "personal_space_compliance": 0.9 - 0.2 * c - 0.02 * e,
        "min_distance_to_person": 1.0 - 0.3 * c + 0.05 * e,
    }


def build_columns(records: list[str] | None = None) -> dict[str, np.ndarray]:
    rows: dict[str, list] = {"contestant": [], "stage": [], "episode": [], "outcome": []}
    metrics: dict[str, list] = {}
    for c, cn in enumerate(CONTESTANTS):
        for s, sn in enumerate(STAGES):
            vals = values(c, s)
            for i in range(5):
                rows["contestant"].append(cn)
                rows["stage"].append(sn)
                rows["episode"].append(i)
                rows["outcome"].append("success" if vals["success"][i] else "collision")
                for k, v in vals.items():
                    metrics.setdefault(k, []).append(float(v[i]))
    cols = {k: np.asarray(v) for k, v in rows.items()}
    cols.update({k: np.asarray(v, float) for k, v in metrics.items()})
    cols["collisions"] = cols["collisions"].astype(np.int64)  # an integer count, as in runs
    n = len(cols["episode"])
    cols["record"] = np.asarray(records if records is not None else [""] * n)
    return cols


def build_table(records: list[str] | None = None) -> pa.Table:
    return pa.table(build_columns(records))
