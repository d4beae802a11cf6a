"""RL environment throughput: env steps/s for one SocialNavEnv and the batched vector env.

    python benchmarks/env_throughput.py [--steps 10000] [--worlds 16 64] [--threads 2]
        [--crowds fast_social_force pysocial]

The issue-7 setup: a jackal (720 beams, 30 m) among 20 pedestrians on the packaged
``small_office`` world with 4 static obstacles; default observation (lidar + goal + last
action), the robot's discrete actions, random actions, one simulation step (0.1 s) per env step,
resets included (an episode ends on arrival, contact, the 60 s timeout or 500 steps).

* ``single``: one :class:`~arena.learn.env.SocialNavEnv` (native2d, the full crowd with social
  states, the reference simulator), one core.
* ``batched N, crowd C``: :class:`~arena.learn.batched.BatchedSocialNavEnv` with ``N`` worlds
  of the one engine (the simulation of ``single``, batched), ``--threads`` numba threads, the
  next episode of each world drawn ahead by one helper process (``--prefetch 1``, as training
  does; ``--prefetch 0`` draws in-process); the figure is the sum over worlds (N env steps per
  call). ``--crowds`` names the crowds measured: ``none`` (no people), ``pysocial`` (the full
  crowd: social states and groups on, as ``single``), or any other crowd model (social states
  off); the default measures ``fast_social_force`` (the fast crowd training used before the
  one engine, now a registered crowd model) and ``pysocial``.

Each setup is measured ``--repeat`` times (default 3) and the median printed, with the range:
on a shared 2-core host the same code varies by a third from one minute to the next.

Targets (issues 7 and 18, 2 cores): >= 3,000 steps/s single; batched N = 64 >= 20,000 steps/s
with a fast crowd, and (aim) >= 10,000 with the full pysocial crowd.
"""

from __future__ import annotations

import os

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(var, "1")
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")  # see arena/sim/engine: spinning threads

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


def crowd_overrides(crowd: str) -> list[str]:
    """The config overrides of a ``--crowds`` entry."""
    if crowd == "none":
        return ["task.obstacles.dynamic=0"]
    if crowd == "pysocial":
        return ["crowd={type: pysocial}", "pedestrians.social_states=true"]
    return [f"crowd={{type: {crowd}}}", "pedestrians.social_states=false"]


def batched(n: int, steps: int, prefetch: int, repeat: int, crowd: str) -> list[float]:
    """``repeat`` measurements of ``steps`` env steps each, one after the other on one env."""
    from arena.learn.batched import BatchedSocialNavEnv

    env = BatchedSocialNavEnv(
        None, [*OVERRIDES, *crowd_overrides(crowd)], num_envs=n, prefetch=prefetch
    )
    try:
        env.reset(seed=0)
        env.action_space.seed(0)
        # The helper's start-up (imports, cached kernels: a few seconds) is not drawing time;
        # a training run lasts hours. Warm-up steps then compile this process's kernels.
        if not env.wait_prefetch(timeout=300.0):
            print("warning: the prefetch helper did not deliver within 300 s", file=sys.stderr)
        for _ in range(20):
            env.step(env.action_space.sample())
        calls = max(1, steps // n)
        rates = []
        for _ in range(repeat):
            t0 = time.perf_counter()
            for _ in range(calls):
                env.step(env.action_space.sample())
            rates.append(calls * n / (time.perf_counter() - t0))
        return rates
    finally:
        env.close()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=10_000,
                    help="env steps per measurement (resets included: ~40 episodes single)")
    ap.add_argument("--worlds", type=int, nargs="+", default=[16, 64])
    ap.add_argument("--threads", type=int, default=2, help="numba threads (batched)")
    ap.add_argument("--repeat", type=int, default=3,
                    help="measurements per setup; the median is the figure (shared hosts vary)")
    ap.add_argument("--skip-single", action="store_true")
    ap.add_argument("--crowds", nargs="+", default=["fast_social_force", "pysocial"],
                    help="batched: crowds measured (none, pysocial = full, or a model name)")
    ap.add_argument("--prefetch", type=int, default=1,
                    help="batched: episodes per world drawn ahead by a helper process "
                    "(learning.train.prefetch_episodes; 0: drawn in-process)")
    args = ap.parse_args()
    import numba

    def show(label: str, rates: list[float], target: str) -> None:
        spread = ""
        if len(rates) > 1:
            spread = f"  ({min(rates):,.0f}-{max(rates):,.0f} over {len(rates)})"
        print(f"{label:<46s} {float(np.median(rates)):8,.0f} steps/s{spread}  (target {target})")

    if not args.skip_single:
        numba.set_num_threads(1)
        rates = [single(args.steps) for _ in range(args.repeat)]
        show("single SocialNavEnv (native2d, 1 core):", rates, "3,000")
    numba.set_num_threads(min(args.threads, numba.config.NUMBA_NUM_THREADS))
    for crowd in args.crowds:
        for n in args.worlds:
            rates = batched(n, max(args.steps, 20 * n), args.prefetch, args.repeat, crowd)
            target = "10,000" if crowd == "pysocial" else "20,000"
            show(f"Batched N={n} {crowd} ({numba.get_num_threads()} thr, prefetch "
                 f"{args.prefetch}):", rates, target)
    sys.stdout.flush()


if __name__ == "__main__":
    main()
