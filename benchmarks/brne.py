"""BRNE control cycle: median compute time with 10 people and 100 samples per agent, one core.

    python benchmarks/brne.py [--people 10] [--samples 100] [--scenes 200] [--robots go1,jackal]

Scenes (seeded): the robot in a 10 x 6 m room (its walls in a 720-beam, 360° laser scan) moving
along a straight path at cruise speed, ``--people`` pedestrians at random positions 0.8–4.5 m
away (all inside the planner's activation radius, so every one plays) walking at 0.5–1.4 m/s in
random directions. Timed: one ``BrnePlanner.compute`` per scene (nominal, sampling, obstacle
masking, pairwise costs, Nash iteration, command), after a warm-up that compiles the kernels.
Prints the median and 95th percentile per robot preset and the share of the 20 ms budget.
"""

from __future__ import annotations

import os

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(var, "1")

import argparse  # noqa: E402
import math  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from arena.core.types import Pose2D  # noqa: E402
from arena.nav.local_planners.base import LocalObservation  # noqa: E402
from arena.nav.local_planners.brne import BrnePlanner  # noqa: E402
from arena.robots.presets import load_robot  # noqa: E402

BUDGET_MS = 20.0
ROOM = (10.0, 6.0)  # m, walls at x = ±5, y = ±3 around the room centre


def room_scan(pose: np.ndarray, beams: int = 720) -> tuple[np.ndarray, np.ndarray]:
    """Ranges (m) and angles (rad, robot frame) of the room's walls seen from ``pose``."""
    angles = np.linspace(-math.pi, math.pi, beams, endpoint=False)
    world = angles + pose[2]
    c, s = np.cos(world), np.sin(world)
    hx, hy = ROOM[0] / 2, ROOM[1] / 2
    with np.errstate(divide="ignore"):
        tx = np.where(c > 0, (hx - pose[0]) / c, np.where(c < 0, (-hx - pose[0]) / c, np.inf))
        ty = np.where(s > 0, (hy - pose[1]) / s, np.where(s < 0, (-hy - pose[1]) / s, np.inf))
    return np.minimum(tx, ty), angles


def scenes(
    robot: str, people: int, count: int, rng: np.random.Generator
) -> list[LocalObservation]:
    """``count`` observations of ``people`` walking around the robot preset ``robot``."""
    model = load_robot(robot)
    lim = model.limits()
    out = []
    for _ in range(count):
        pose = np.array([rng.uniform(-3.5, -2.5), rng.uniform(-0.5, 0.5), rng.uniform(-0.3, 0.3)])
        r = rng.uniform(0.8, 4.5, people)
        a = rng.uniform(-math.pi, math.pi, people)
        heading = rng.uniform(-math.pi, math.pi, people)
        speed = rng.uniform(0.5, 1.4, people)
        peds = np.stack([pose[0] + r * np.cos(a), pose[1] + r * np.sin(a),
                         speed * np.cos(heading), speed * np.sin(heading)], axis=-1)
        ranges, angles = room_scan(pose)
        out.append(LocalObservation(
            pose=pose, twist=np.array([lim.vx_max, 0.0, 0.0]), goal=Pose2D(4.0, 0.0),
            path=np.array([[pose[0], pose[1]], [4.0, 0.0]]), limits=lim,
            robot_radius=model.radius, dt=0.1, scan_ranges=ranges, scan_angles=angles,
            kinematics=model.kinematics["type"], pedestrians=peds,
        ))
    return out


def main() -> None:
    """Time the control cycle and print one row per robot."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--people", type=int, default=10)
    ap.add_argument("--samples", type=int, default=100)
    ap.add_argument("--scenes", type=int, default=200)
    ap.add_argument("--robots", default="go1,jackal")
    args = ap.parse_args()
    params = BrnePlanner.Params(samples=args.samples, max_people=args.people)
    print(f"BRNE control cycle, {args.people} people, {args.samples} samples per agent, "
          f"{params.steps} steps, {params.iterations} iterations, one core")
    print(f"{'robot':8s} {'median ms':>10s} {'p95 ms':>8s} {'budget':>7s}")
    for robot in args.robots.split(","):
        planner = BrnePlanner(params)
        obs = scenes(robot, args.people, args.scenes, np.random.default_rng(0))
        for o in obs[:3]:  # compile the kernels (cached on disk after the first run)
            planner.compute(o)
        times = []
        for o in obs:
            planner.reset()  # every scene a fresh encounter (no warm start from the last one)
            t0 = time.perf_counter()
            planner.compute(o)
            times.append(time.perf_counter() - t0)
            assert planner.last is not None and len(planner.last.people) == args.people
        ms = 1e3 * np.asarray(times)
        med = float(np.median(ms))
        print(f"{robot:8s} {med:10.2f} {float(np.percentile(ms, 95)):8.2f} "
              f"{100 * med / BUDGET_MS:6.0f}%", flush=True)


if __name__ == "__main__":
    main()
