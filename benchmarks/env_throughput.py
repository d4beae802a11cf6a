"""RL environment throughput: env steps/s for one SocialNavEnv and the batched vector env.

    python benchmarks/env_throughput.py [--steps 10000] [--worlds 16 64] [--threads 2]

The issue-7 setup: a jackal (720 beams, 30 m) among 20 pedestrians on the packaged
``small_office`` world with 4 static obstacles; default observation (lidar + goal + last
action), the robot's discrete actions, random actions, one simulation step (0.1 s) per env step,
resets included (an episode ends on arrival, contact, the 60 s timeout or 500 steps).

* ``single``: one :class:`~arena.learn.env.SocialNavEnv` (native2d, the full crowd with social
  states, the reference simulator), one core.
* ``batched N``: :class:`~arena.learn.batched.BatchedSocialNavEnv` with ``N`` worlds stepped
  together (batched lidar/contacts/social-force kernels), ``--threads`` numba threads; the
  figure is the sum over worlds (N env steps per call).

Targets (issue 7, 2 cores): >= 3,000 steps/s single, >= 20,000 steps/s batched (16 and 64).
"""

from __future__ import annotations

import os

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(var, "1")
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")  # see arena/sim/batch: spinning threads

import argparse  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

OVERRIDES = [
    "robot=jackal",
    "map={type: world, name: small_office}",
    "task.obstacles.static=4",
    "task.obstacles.dynamic=20",
    "output.video=false",
    "learning.env.action_period=0.1",
]


def single(steps: int) -> float:
    from arena.learn.env import SocialNavEnv

    env = SocialNavEnv(None, OVERRIDES)
    rng = np.random.default_rng(0)
    env.reset(seed=0)
    for _ in range(50):  # warm-up: numba compilation, caches
        _, _, term, trunc, _ = env.step(env.action_space.sample())
        if term or trunc:
            env.reset()
    env.action_space.seed(int(rng.integers(1 << 31)))
    t0 = time.perf_counter()
    for _ in range(steps):
        _, _, term, trunc, _ = env.step(env.action_space.sample())
        if term or trunc:
            env.reset()
    return steps / (time.perf_counter() - t0)


def batched(n: int, steps: int) -> float:
    from arena.learn.batched import BatchedSocialNavEnv

    env = BatchedSocialNavEnv(None, OVERRIDES, num_envs=n)
    env.reset(seed=0)
    env.action_space.seed(0)
    for _ in range(20):
        env.step(env.action_space.sample())
    calls = max(1, steps // n)
    t0 = time.perf_counter()
    for _ in range(calls):
        env.step(env.action_space.sample())
    return calls * n / (time.perf_counter() - t0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=10_000,
                    help="env steps per measurement (resets included: ~40 episodes single)")
    ap.add_argument("--worlds", type=int, nargs="+", default=[16, 64])
    ap.add_argument("--threads", type=int, default=2, help="numba threads (batched)")
    ap.add_argument("--skip-single", action="store_true")
    args = ap.parse_args()
    import numba

    if not args.skip_single:
        numba.set_num_threads(1)
        rate = single(args.steps)
        print(f"single SocialNavEnv (native2d, 1 core):        {rate:8.0f} steps/s  "
              f"(target 3,000)")
    numba.set_num_threads(min(args.threads, numba.config.NUMBA_NUM_THREADS))
    for n in args.worlds:
        rate = batched(n, max(args.steps, 20 * n))
        print(f"BatchedSocialNavEnv N={n:<3d} ({numba.get_num_threads()} threads):     "
              f"{rate:8.0f} steps/s  (target 20,000)")
    sys.stdout.flush()


if __name__ == "__main__":
    main()
