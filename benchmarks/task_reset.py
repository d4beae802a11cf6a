"""Episode generation time of the task generator (the reset hot path of training and benchmarks).

Prints, per configuration, the mean and max wall time of ``TaskGenerator.episode(i)`` over
``--episodes`` episodes (fewer for the dense cases; map building included only where a new
map is made per episode). A case that cannot be drawn prints how long the error took.

    python benchmarks/task_reset.py [--episodes 50] [--only hospital]
"""

from __future__ import annotations

import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import argparse
import contextlib
import time
from typing import Any

import numpy as np

import arena.plugins  # noqa: F401
from arena.core.errors import SamplingError
from arena.maps.sources import WORLDS_DIR
from arena.robots.presets import load_robot
from arena.tasks.config import TaskConfig
from arena.tasks.generator import TaskGenerator

CORRIDOR = str(WORLDS_DIR / "corridor" / "scenarios" / "default.json")

# (label, map, task[, most episodes]).
CASES: list[tuple[Any, ...]] = [
    (
        "random, small_office, 4 static + 12 people",
        {"type": "world", "name": "small_office"},
        {"obstacles": {"type": "random", "static": 4, "dynamic": 12}},
    ),
    (
        "random, small_office, 20 static + 30 people",
        {"type": "world", "name": "small_office"},
        {"obstacles": {"type": "random", "static": 20, "dynamic": 30}},
    ),
    (
        "random + dynamic_map (new barn map every episode)",
        {"type": "barn", "width": 20.0, "height": 15.0},
        {
            "obstacles": {"type": "random", "static": 0, "dynamic": 10},
            "modules": [{"type": "dynamic_map", "episodes_per_map": 1}],
        },
    ),
    (
        "scenario, corridor world",
        {"type": "world", "name": "corridor"},
        {
            "robots": {"type": "scenario", "file": CORRIDOR},
            "obstacles": {"type": "scenario", "file": CORRIDOR},
        },
    ),
    (
        "random, hospital_floor, 1,000 people",
        {"type": "world", "name": "hospital_floor"},
        {"obstacles": {"type": "random", "static": 0, "dynamic": 1000}},
        10,
    ),
    (
        "random, small_office, 500 static (does not fit)",
        {"type": "world", "name": "small_office"},
        {"obstacles": {"type": "random", "static": 500, "dynamic": 0}},
        3,
    ),
    (
        "random, hospital_floor, 500 static (does not fit)",
        {"type": "world", "name": "hospital_floor"},
        {"obstacles": {"type": "random", "static": 500, "dynamic": 0}},
        3,
    ),
]


def main() -> None:
    """Run every case and print its figures."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--episodes", type=int, default=50)
    ap.add_argument("--only", default="", help="run the cases whose label contains this")
    args = ap.parse_args()
    jackal = load_robot("jackal")
    print("task generator: wall time per episode (1 core)")
    for label, map_spec, task, *most in CASES:
        if args.only not in label:
            continue
        gen = TaskGenerator(
            TaskConfig.model_validate(task), map_spec=map_spec, robots=[jackal], seed=0
        )
        error = ""
        with contextlib.suppress(SamplingError):  # a case that cannot be drawn: timed below
            gen.episode(0)  # builds the shared map and warms caches
        times = []
        for i in range(1, min([args.episodes, *most]) + 1):
            t0 = time.perf_counter()
            try:
                gen.episode(i)
            except SamplingError as e:
                error = str(e)
            times.append(time.perf_counter() - t0)
        ms = 1e3 * np.array(times)
        print(f"  {label:52s} mean {ms.mean():7.1f} ms   max {ms.max():7.1f} ms", flush=True)
        if error:
            print(f"    (fails: {error[:100]}...)")

if __name__ == "__main__":
    main()
