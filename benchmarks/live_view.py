"""The live view's cost and rate: 100 people, a client reading the live channel.

    python benchmarks/live_view.py [--people 100] [--episodes 6] [--rate 30]

Runs the same episodes (a rosnav_indoor map, ``--people`` people, no video) unwatched and
watched: a :class:`~arena.live.hook.LiveHook` on a :class:`~arena.live.server.LiveServer`
with one client process reading every message, as the web app's proxy does. The run goes as
fast as it can (pace 0), so the channel sends up to ``--rate`` frames per second of wall time.
Prints the steps per second of both, the slowdown, the frames per second the client received,
the frame size, and the cost of one frame (built, encoded) when every step is sent.

Goals (issue 21): the live view updates >= 20 times per second with 100 people and slows the
simulation by < 10 %.
"""

from __future__ import annotations

import os

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(var, "1")

import argparse  # noqa: E402
import multiprocessing as mp  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from arena.config import load_config  # noqa: E402
from arena.experiment import run_experiment  # noqa: E402
from arena.live import LiveClient, LiveControl, LiveHook, LiveServer  # noqa: E402


def _run(cfg, out: Path, hooks=()) -> tuple[int, float]:
    t0 = time.perf_counter()
    _, results = run_experiment(cfg, out, hooks=hooks)
    return sum(r.steps for r in results), time.perf_counter() - t0


def _read(host: str, port: int, token: str, results) -> None:
    """The client (its own process, as the web app is): count frames and bytes until closed."""
    arrivals, size = [], 0
    with LiveClient(host, port, token, timeout=120) as client:
        stream = client._stream
        while line := stream.readline():
            if line.startswith(b'{"type":"frame"'):
                arrivals.append(time.perf_counter())
                size += len(line)
    # the median gap between frames: the rate a viewer sees while an episode runs (the
    # episodes' set-up, when no frame comes, left out)
    gap = float(np.median(np.diff(arrivals))) if len(arrivals) > 2 else float("inf")
    results.put((len(arrivals), gap, size // max(1, len(arrivals))))


def _watched(cfg, out: Path, rate: float) -> tuple[int, float, int, float, int]:
    """Steps, wall s, frames the client got, their median gap (s), mean frame bytes."""
    control = LiveControl(speed=0)
    server = LiveServer(control=control, rate=rate)
    host, port = server.address
    ctx = mp.get_context("spawn")
    results = ctx.Queue()
    reader = ctx.Process(target=_read, args=(host, port, server.token, results), daemon=True)
    reader.start()
    while server.clients == 0:
        time.sleep(0.01)
    steps, wall = _run(cfg, out, [LiveHook([server], control)])
    time.sleep(0.5)  # the client reads what is left
    server.close()
    frames, gap, size = results.get(timeout=60)
    reader.join(10)
    return steps, wall, frames, gap, size


def main() -> None:
    """Run the benchmark and print its figures."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--people", type=int, default=100)
    ap.add_argument("--episodes", type=int, default=6)
    ap.add_argument("--rate", type=float, default=30.0)
    args = ap.parse_args()
    cfg = load_config(None, [
        "map={type: rosnav_indoor, width: 30, height: 30}", "task.obstacles.static=5",
        f"task.obstacles.dynamic={args.people}", f"episodes={args.episodes}",
        "output.video=false", "evaluation.counterfactual=false", "seed=1",
    ])
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        _run(cfg, root / "warm")  # numba compilation, caches
        plain, watched = [], []
        for k in range(2):  # alternated: the host's load drifts
            plain.append(_run(cfg, root / f"plain{k}"))
            watched.append(_watched(cfg, root / f"watched{k}", args.rate))
        every = _watched(cfg, root / "every", 1e9)
    sps_plain = max(s / w for s, w in plain)
    sps_watched = max(s / w for s, w, *_ in watched)
    steps, _, frames, gap, size = max(watched, key=lambda r: r[0] / r[1])
    print(f"live view, {args.people} people, {steps} steps per run, one client, "
          f"rate {args.rate:g} Hz")
    print(f"  unwatched:           {sps_plain:8.0f} steps/s")
    print(f"  watched:             {sps_watched:8.0f} steps/s   "
          f"slowdown {100 * (sps_plain / sps_watched - 1):5.1f} %  (goal < 10 %)")
    print(f"  frames received:     {1 / gap:8.1f} /s      (goal >= 20; median gap "
          f"{1e3 * gap:.0f} ms, {frames} frames)")
    print(f"  frame size:          {size / 1024:8.1f} kB")
    s_all, w_all, f_all, _, _ = every
    per_frame = (w_all / s_all - 1 / sps_plain) * 1e3
    print(f"  every step sent:     {s_all / w_all:8.0f} steps/s   "
          f"{per_frame:.2f} ms per frame (built, encoded, sent); client got {f_all}")


if __name__ == "__main__":
    main()
