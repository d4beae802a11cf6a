"""Crowd step time for every registered crowd model at 10, 100 and 1,000 agents, with walls.

    python benchmarks/crowd_step.py [--sizes 10 100 1000] [--steps 50] [--world small_office]

World: a 40 x 40 m hall with outer walls, two interior walls with doors and 12 pillars (or a
packaged world's map with ``--world``). Agents start at random free positions and walk loops
between two random waypoints. Timed: one ``CrowdSimulator.step`` (neighbour search, model,
integrator with the wall guard), social states off so the figure is the model's cost, or one
step of a model's own driver (``fast_social_force``: the whole step is the model); one core.
References in the same run when installed: PyPI ``pysocialforce`` (``Simulator.step``) and
``pyrvo`` (RVO2 C++, ``do_step``; preferred velocities set before the timer, as our figure
includes computing them).
"""

from __future__ import annotations

import os

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(var, "1")

import argparse  # noqa: E402
import logging  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from arena.crowd.base import CROWD_MODELS  # noqa: E402
from arena.crowd.driver import driver_of  # noqa: E402
from arena.crowd.models.rvo2 import world_polygons  # noqa: E402
from arena.crowd.simulator import CrowdSimulator, PedestrianConfig  # noqa: E402
from arena.crowd.walls import world_segments  # noqa: E402
from arena.maps.grid import OccupancyGrid  # noqa: E402
from arena.maps.io import load_map  # noqa: E402
from arena.maps.sources import resolve_world  # noqa: E402
from arena.scene.episode import WAYPOINT_LOOP, AgentSpawn  # noqa: E402
from arena.scene.state import RobotStates, StaticWorld  # noqa: E402

RES = 0.1


def hall() -> StaticWorld:
    """40 x 40 m with walls, two interior walls with 3 m doors, 12 pillars."""
    n = round(40 / RES)
    occ = np.zeros((n, n), dtype=bool)
    occ[:3, :] = occ[-3:, :] = occ[:, :3] = occ[:, -3:] = True
    occ[130:133, :] = True
    occ[130:133, 80:110] = occ[130:133, 290:320] = False
    occ[270:273, :] = True
    occ[270:273, 180:210] = False
    for i in range(4):
        for j in range(3):
            y, x = 60 + 90 * j + 20, 60 + 90 * i
            occ[y : y + 6, x : x + 6] = True
    return StaticWorld.build(OccupancyGrid.from_occupied(occ, RES))


def spawn(world: StaticWorld, n: int, seed: int = 0) -> AgentSpawn:
    """``n`` agents at free positions (0.5 m from walls), two random waypoints each."""
    rng = np.random.default_rng(seed)
    free = np.argwhere(world.grid.distance > 0.5)
    pick = free[rng.choice(len(free), size=3 * n, replace=False)]
    pts = world.grid.cell_to_world(pick).reshape(n, 3, 2)
    return AgentSpawn(
        positions=pts[:, 0],
        radii=np.full(n, 0.3),
        vmax=rng.uniform(0.8, 1.4, n),
        waypoints=pts[:, 1:],
        num_waypoints=np.full(n, 2),
        waypoint_mode=np.full(n, WAYPOINT_LOOP),
        kinds=np.zeros(n, dtype=np.int64),
        groups=np.full(n, -1, dtype=np.int64),
    )


NO_ROBOTS = RobotStates(
    ("r",),
    ("burger",),
    np.array([[-100.0, -100.0, 0.0]]),
    np.zeros((1, 3)),
    np.zeros((1, 3)),
    np.array([0.2]),
    (None,),
    (np.zeros(0),),
)


def time_model(name: str, world: StaticWorld, n: int, steps: int) -> tuple[float, float]:
    """ms per driver step, and ms of it spent in the model's ``compute`` (all for a driver)."""
    sim = driver_of(CROWD_MODELS.build(name), PedestrianConfig(social_states=False))
    sim.reset(spawn(world, n), world, np.random.default_rng(1))
    for _ in range(3):  # warm-up: JIT and caches
        sim.step(NO_ROBOTS, 0.1)
    if not isinstance(sim, CrowdSimulator):  # the model's own driver: all of it is the model
        t0 = time.perf_counter()
        for _ in range(steps):
            sim.step(NO_ROBOTS, 0.1)
        full = 1e3 * (time.perf_counter() - t0) / steps
        return full, full
    inner = sim.model.compute
    spent = [0.0]

    def timed(frame):
        t = time.perf_counter()
        out = inner(frame)
        spent[0] += time.perf_counter() - t
        return out

    sim.model.compute = timed
    t0 = time.perf_counter()
    for _ in range(steps):
        sim.step(NO_ROBOTS, 0.1)
    total = time.perf_counter() - t0
    return 1e3 * total / steps, 1e3 * spent[0] / steps


def time_pysocialforce(world: StaticWorld, n: int, steps: int) -> float | None:
    """ms per ``pysocialforce.Simulator.step`` on the same scene, or None if not installed."""
    # Importing pysocialforce sets the root logger to DEBUG and opens ./file.log: do it in a
    # scratch folder and restore the logging level.
    level = logging.getLogger().level
    cwd = os.getcwd()
    with tempfile.TemporaryDirectory() as tmp:
        os.chdir(tmp)
        logging.disable(logging.CRITICAL)  # its import logs matplotlib's start-up at DEBUG
        try:
            import pysocialforce as psf
        except ImportError:
            return None
        finally:
            logging.disable(logging.NOTSET)
            os.chdir(cwd)
            logging.getLogger().setLevel(level)
            for h in list(logging.getLogger().handlers):
                if isinstance(h, logging.FileHandler):
                    logging.getLogger().removeHandler(h)
                    h.close()
    sp = spawn(world, n)
    state = np.zeros((n, 6))
    state[:, :2] = sp.positions
    state[:, 4:6] = sp.waypoints[:, 0]
    a, b = world_segments(world)
    obstacles = [(p[0], q[0], p[1], q[1]) for p, q in zip(a, b, strict=True)]
    sim = psf.Simulator(state, obstacles=obstacles)
    sim.step(1)
    t0 = time.perf_counter()
    sim.step(steps)
    return 1e3 * (time.perf_counter() - t0) / steps


def time_pyrvo(world: StaticWorld, n: int, steps: int) -> float | None:
    """ms per RVO2 ``do_step`` (C++) on the same scene, or None if not installed."""
    try:
        import pyrvo
    except ImportError:
        return None
    sp = spawn(world, n)
    sim = pyrvo.RVOSimulator()
    sim.set_time_step(0.1)
    sim.set_agent_defaults(2.0, 10, 5.0, 2.0, 0.3, 1.4, (0.0, 0.0))
    for p in sp.positions:
        sim.add_agent((float(p[0]), float(p[1])))
    for poly in world_polygons(world):  # the obstacles our rvo2 model gets
        sim.add_obstacle([(float(x), float(y)) for x, y in poly])
    sim.process_obstacles()
    total = 0.0
    for _ in range(steps + 1):
        for i in range(n):  # preferred velocities: not timed (a Python loop in the binding)
            pos = np.array(sim.get_agent_position(i).to_tuple())
            d = sp.waypoints[i, 0] - pos
            norm = float(np.hypot(*d))
            v = d / norm * sp.vmax[i] if norm > 1e-9 else d
            sim.set_agent_pref_velocity(i, (float(v[0]), float(v[1])))
        t0 = time.perf_counter()
        sim.do_step()
        total += time.perf_counter() - t0
    return 1e3 * total / (steps + 1)


def main() -> None:
    """Print the table."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--sizes", type=int, nargs="+", default=[10, 100, 1000])
    ap.add_argument("--steps", type=int, default=50)
    ap.add_argument("--models", nargs="*", default=None)
    ap.add_argument("--world", default=None, help="a packaged world's map instead of the hall")
    args = ap.parse_args()
    if args.world:
        world = StaticWorld.build(load_map(resolve_world(args.world)))
        where = f"{args.world} map"
    else:
        world, where = hall(), "40 x 40 m hall with walls"
    names = args.models or CROWD_MODELS.names()
    print(f"crowd step, ms per step (1 core; {where}; {args.steps} steps)")
    print("full = CrowdSimulator.step (neighbour search + model + integrator with wall guard);")
    print("model = the model's compute(), including the neighbour search it triggers (lazy)")
    head = "".join(f"{f'full {n:,d}':>13}{f'model {n:,d}':>13}" for n in args.sizes)
    print(f"{'model':<20}{head}")
    for name in names:
        row = [time_model(name, world, n, args.steps) for n in args.sizes]
        print(f"{name:<20}" + "".join(f"{full:13.3f}{model:13.3f}" for full, model in row))
    if args.world:  # pysocialforce rejects some packaged maps' wall segments
        print("(references run on the hall only)")
        return
    for label, fn in (("ref: pysocialforce", time_pysocialforce), ("ref: pyrvo (C++)", time_pyrvo)):
        vals = [
            fn(world, n, max(3, args.steps // 5) if n >= 1000 else args.steps) for n in args.sizes
        ]
        cells = "".join(
            f"{'(missing)':>13}{'':13}" if v is None else f"{v:13.3f}{'':13}" for v in vals
        )
        print(f"{label:<20}{cells}")


if __name__ == "__main__":
    main()
