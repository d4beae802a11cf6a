"""Train the lidar people detector on simulated scans and measure its AP on held-out maps.

    python tools/train_lidar_detector.py [--episodes 60] [--steps 200] [-o WEIGHTS.npz]

The defaults make the shipped weights (``arena/perception/data/lidar_people.npz``).

Training data: ``--episodes`` episodes on generated ``rosnav_indoor`` maps with 20 walking
people (``pysocial``), half with people seen as two legs (``pedestrian_body: legs``), half as
body circles; a jackal driving slow random arcs, a scan every 0.5 s. Held-out evaluation:
other map generators (``canteen``, ``office``) and other seeds, both body models. Prints the
data size, the wall time and AP at 0.3 m and 0.5 m.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from arena.config import load_config
from arena.perception.lidar_data import labelled_frames
from arena.perception.lidar_detector import WEIGHTS, LidarPeopleDetector, train
from arena.perception.scoring import average_precision


def frames(map_type: str, body: str, episodes: int, steps: int, seed: int, offset: int = 0):
    """Labelled scans of ``episodes`` episodes on ``map_type`` maps, people seen as ``body``.

    ``body``: ``legs`` or ``circle`` on the 2-D simulator, ``figure`` on the MuJoCo backend
    (human figures among 3-D furniture: chairs and tables stand on thin legs there).
    """
    sim = (["sim.backend.type=mujoco"] if body == "figure"
           else [f"sim.backend.pedestrian_body={body}"])
    cfg = load_config(None, [f"map={{type: {map_type}}}", "task.obstacles.static=3",
                             "task.obstacles.dynamic=20", *sim,
                             "crowd.type=pysocial", f"seed={seed}", "output.video=false"])
    return list(labelled_frames(cfg, episodes, steps, every=5, episode_offset=offset))


def main() -> None:
    """Draw the data, train, save, and print the held-out AP."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--episodes", type=int, default=60)
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("-o", "--out", type=Path, default=WEIGHTS)
    ap.add_argument("--figures", type=int, default=20,
                    help="episodes on the MuJoCo backend (needs arena[3d]; 0: none)")
    ap.add_argument("--figure", type=Path, default=None,
                    help="also draw the held-out precision-recall curves (PNG)")
    args = ap.parse_args()
    t0 = time.time()
    half = max(args.episodes // 2, 1)
    data = frames("rosnav_indoor", "legs", half, args.steps, 1) + frames(
        "rosnav_indoor", "circle", half, args.steps, 2)
    if args.figures:  # the 3-D world: figures among furniture on legs
        part = max(args.figures // 2, 1)
        data += frames("rosnav_indoor", "figure", part, args.steps, 3) + frames(
            "canteen", "figure", part, args.steps, 4)
    x = np.concatenate([f.segments.features for f in data])
    y = np.concatenate([f.labels for f in data])
    t1 = time.time()
    train(x, y, args.out)
    t2 = time.time()
    print(f"training data: {len(data)} scans, {len(y)} segments ({int(y.sum())} of people); "
          f"drawn in {t1 - t0:.1f} s, fitted in {t2 - t1:.1f} s")
    det = LidarPeopleDetector(args.out)
    curves = {}
    for body in ("legs", "circle", "figure"):
        held = frames("canteen", body, 6, args.steps, 11) + frames("office", body, 6,
                                                                    args.steps, 12)
        found = [det.people(f.segments, det.segment_scores(f.segments)) for f in held]
        people = [f.people for f in held]
        visible = [f.visible for f in held]
        aps = [average_precision(found, people, visible, r)[0] for r in (0.3, 0.5)]
        curves[body] = average_precision(found, people, visible, 0.5)
        n_vis = sum(int(v.sum()) for v in visible)
        print(f"held out ({body}): {len(held)} scans, {n_vis} visible people: "
              f"AP@0.3 m {aps[0]:.3f}, AP@0.5 m {aps[1]:.3f}")
    print(f"wall time {time.time() - t0:.0f} s; weights: {args.out}")
    if args.figure is not None:
        from matplotlib.figure import Figure

        fig = Figure(figsize=(5, 4), dpi=120)
        ax = fig.add_subplot()
        for body, (ap_05, recall, precision) in curves.items():
            name = {"legs": "two legs", "circle": "body circles", "figure": "3-D figures"}[body]
            label = f"people as {name} (AP {ap_05:.2f})"
            ax.plot(recall, precision, label=label)
        ax.set_xlabel("recall (visible people)")
        ax.set_ylabel("precision")
        ax.set_xlim(0, 1)
        ax.set_ylim(0, 1.02)
        ax.grid(alpha=0.3)
        ax.set_title("lidar people detector, held-out maps, 0.5 m", fontsize=10)
        ax.legend(loc="lower left", fontsize=8)
        fig.tight_layout()
        fig.savefig(args.figure)
        print(f"figure: {args.figure}")


if __name__ == "__main__":
    main()
