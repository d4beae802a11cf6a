"""Benchmark throughput: the paper suite (160 episodes) with DWA through ``arena bench``.

Runs every episode of the packaged ``paper`` suite (100 random episodes with shelves and 10-30
people on generated indoor maps, 10 each in generated canteen, warehouse, office, indoor and
outdoor worlds, 10 of the corridor scenario) with one contestant (DWA + bypass) through the
benchmark runner on ``--workers`` processes, exactly as ``arena bench paper`` does (records,
metrics incl. the counterfactual crowd, atomic commits), and prints the wall time, episodes per
minute, the simulated-to-wall time ratio and the per-stage results. Target: the whole suite in
at most 5 minutes on 2 workers.

    python benchmarks/bench_throughput.py [--workers 2] [--scale 1.0] [--planner dwa]
"""

from __future__ import annotations

import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

from arena.config.schema import ExperimentConfig
from arena.eval.runner import run_benchmark
from arena.eval.store import load_results, summarize


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--scale", type=float, default=1.0, help="scale_episodes of the suite")
    ap.add_argument("--planner", default="dwa", help="local planner of the one contestant")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--keep", type=Path, default=None, help="keep the run in this folder")
    args = ap.parse_args()

    with tempfile.TemporaryDirectory() as tmp:
        contest = Path(tmp) / "contest.yaml"
        contest.write_text(
            f"contestants:\n  - {{name: {args.planner}, local_planner: {args.planner}, "
            "inter_planner: bypass}\n"
        )
        run_dir = args.keep or Path(tmp) / "run"
        t0 = time.perf_counter()
        run = run_benchmark("paper", contest, run_dir, base_cfg=ExperimentConfig(seed=args.seed),
                            workers=args.workers, scale=args.scale, progress=False)
        wall = time.perf_counter() - t0
        table = load_results(run)
        n = table.num_rows
        sim_time = float(np.nansum(np.asarray(table.column("time"), dtype=np.float64)))
        worker_wall = float(np.sum(np.asarray(table.column("wall_time"), dtype=np.float64)))
        print(f"paper suite x{args.scale:g}, {args.planner} + bypass, {args.workers} workers, "
              f"seed {args.seed}")
        print(f"{n} episodes in {wall:.1f} s = {60 * n / wall:.1f} episodes/min "
              f"({'meets' if wall <= 300 * args.scale else 'misses'} the 5 min target "
              f"for {160 * args.scale:g} episodes)")
        print(f"simulated {sim_time:.0f} s in {worker_wall:.0f} s of worker time "
              f"({sim_time / worker_wall:.1f}x real time per worker); "
              f"mean {worker_wall / n:.2f} s per episode")
        print(f"{'stage':<18}{'episodes':>9}{'success':>9}{'coll./ep':>9}{'time (s)':>9}")
        for row in summarize(table):
            print(f"{row['stage']:<18}{row['episodes']:>9}{100 * row['success_rate']:>8.0f}%"
                  f"{row['collisions']:>9.2f}{row['time']:>9.1f}")


if __name__ == "__main__":
    main()
