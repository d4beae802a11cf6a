"""iplanner's control cycle on rendered depth frames: network forward and the whole cycle.

Runs the first ``--episodes`` episodes of the held-out ``barn_rgbd`` suite (the barn maps, a
jackal with iplanner's depth camera) on the mujoco backend in this process, timing every
``IPlannerPlanner.compute`` call (the whole local-planner cycle: depth input, network,
spline, pure-pursuit tracking) and, inside it, the network's forward pass. Prints median,
95th percentile and mean (ms), and the episodes' outcomes. One core: NUMBA and BLAS threads
are pinned to 1 before numpy loads.

    MUJOCO_GL=osmesa python benchmarks/iplanner.py [--episodes 5]
"""

from __future__ import annotations

import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import tempfile
import time
from collections import Counter
from typing import Any

import numpy as np

from arena.config.schema import ExperimentConfig
from arena.eval.runner import run_benchmark
from arena.eval.store import load_results
from arena.learn.iplanner.network import IPlannerNet
from arena.learn.planners import iplanner as module

CONTEST = {"contestants": [{"name": "iplanner", "local_planner": "iplanner",
                            "inter_planner": "bypass"}]}


def main() -> None:
    """Command-line entry point."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--episodes", type=int, default=5)
    args = ap.parse_args()
    cycle: list[float] = []
    forward: list[float] = []
    sources: Counter[str] = Counter()
    compute, plan = module.IPlannerPlanner.compute, IPlannerNet.plan

    def timed_compute(self: Any, obs: Any) -> Any:
        t = time.perf_counter()
        out = compute(self, obs)
        cycle.append(time.perf_counter() - t)
        sources[self.last_source] += 1
        return out

    def timed_plan(self: Any, depth: Any, goal: Any) -> Any:
        t = time.perf_counter()
        out = plan(self, depth, goal)
        forward.append(time.perf_counter() - t)
        return out

    module.IPlannerPlanner.compute = timed_compute  # type: ignore[method-assign]
    IPlannerNet.plan = timed_plan  # type: ignore[method-assign]
    from arena.tasks.suite import ContestFile, load_suite

    suite = load_suite("barn_rgbd", scale_episodes=args.episodes / 50)
    with tempfile.TemporaryDirectory() as run:
        run_benchmark(suite, ContestFile.model_validate(CONTEST), run,
                      base_cfg=ExperimentConfig(sim={"backend": {"type": "mujoco"}}), workers=0,
                      progress=False)
        results = load_results(run)
    for name, xs in (("whole cycle", cycle), ("network forward", forward)):
        ms = 1e3 * np.asarray(xs)
        print(f"{name:16s} median {np.median(ms):6.2f} ms   p95 {np.percentile(ms, 95):6.2f} ms"
              f"   mean {ms.mean():6.2f} ms   ({len(ms)} calls)")
    share = {k: f"{v / max(sum(sources.values()), 1):.0%}" for k, v in sources.most_common()}
    print(f"commands by source: {share}")
    print(f"outcomes: {dict(Counter(results.column('outcome').to_pylist()))}")


if __name__ == "__main__":
    main()
