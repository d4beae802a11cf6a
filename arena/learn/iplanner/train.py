"""Train iPlanner: ``python -m arena.learn.iplanner.train -o RUN``.

Renders the dataset (:mod:`.data`; MuJoCo, headless GL), then minimises the self-supervised
trajectory cost (:mod:`.loss`) with Adam (cosine learning-rate schedule) over ``--epochs``
passes, each image with a fresh goal every pass. The images of every tenth map are held out;
the epoch with the lowest held-out loss is kept and written as ``RUN/policy.npz``
(:mod:`.network`, numpy-runnable) with ``RUN/log.json`` (per-epoch terms). Seeded: the same
arguments on the same machine give the same file.
"""

from __future__ import annotations

import argparse
import json
import platform
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import torch

from arena.learn.iplanner.data import DataParams, Dataset, make_dataset, sample_goals
from arena.learn.iplanner.geometry import CAMERA, MAX_DEPTH, WAYPOINTS, CostParams
from arena.learn.iplanner.loss import LossTerms, LossWeights, TrajectoryCost
from arena.learn.iplanner.network import save_net
from arena.learn.iplanner.torch_net import TorchIPlanner

TERMS = ("total", "obstacle", "goal", "motion", "smooth", "fear", "fear_rate")


def _batch(data: Dataset, rows: np.ndarray, goals: np.ndarray) -> tuple[torch.Tensor, ...]:
    return (torch.from_numpy(data.depth[rows].astype(np.float32))[:, None],
            torch.from_numpy(goals.astype(np.float32)),
            torch.from_numpy(data.map_index[rows]),
            torch.from_numpy(data.pose[rows].astype(np.float32)))


def _terms(t: LossTerms) -> dict[str, float]:
    return {k: float(getattr(t, k).detach()) for k in TERMS}


def split(data: Dataset, every: int = 10) -> tuple[np.ndarray, np.ndarray]:
    """``(train rows, held-out rows)``: the images of every ``every``-th map are held out."""
    held = data.map_index % every == every - 1
    val, tr = np.flatnonzero(held), np.flatnonzero(~held)
    return (tr, val) if len(val) and len(tr) else (np.arange(len(data)), np.arange(len(data)))


def fit(data: Dataset, params: DataParams, *, epochs: int, batch: int, lr: float, seed: int,
        cost: CostParams | None = None, weights: LossWeights | None = None,
        log: list[dict[str, Any]] | None = None) -> TorchIPlanner:
    """Train a network on ``data``; returns the one of the best held-out epoch."""
    torch.manual_seed(seed)
    rng = np.random.default_rng(seed)
    net = TorchIPlanner(WAYPOINTS)
    loss = TrajectoryCost(data.maps, cost or CostParams(), weights or LossWeights(), WAYPOINTS)
    opt = torch.optim.Adam(net.parameters(), lr=lr)
    steps_per_epoch = 0
    tr, val = split(data)
    steps_per_epoch = max(1, -(-len(tr) // batch))
    sched = torch.optim.lr_scheduler.CosineAnnealingLR(opt, max(1, epochs * steps_per_epoch))
    val_goals = sample_goals(data, val, params, np.random.default_rng([seed, 1]))
    val_batch = _batch(data, val, val_goals)
    best, best_state = float("inf"), None
    for epoch in range(epochs):
        net.train()
        order = rng.permutation(tr)
        sums = dict.fromkeys(TERMS, 0.0)
        for rows in np.array_split(order, steps_per_epoch):
            depth, goal, maps, pose = _batch(data, rows, sample_goals(data, rows, params, rng))
            wp, logit = net(depth, goal)
            terms = loss(wp, logit, goal, maps, pose)
            opt.zero_grad()
            terms.total.backward()  # type: ignore[no-untyped-call]
            opt.step()
            sched.step()
            for k, v in _terms(terms).items():
                sums[k] += v * len(rows) / len(tr)
        net.eval()
        with torch.no_grad():
            depth, goal, maps, pose = val_batch
            wp, logit = net(depth, goal)
            v_terms = _terms(loss(wp, logit, goal, maps, pose))
        if log is not None:
            log.append({"epoch": epoch, "train": sums, "val": v_terms})
        if v_terms["total"] < best:
            best = v_terms["total"]
            best_state = {k: w.clone() for k, w in net.state_dict().items()}
    assert best_state is not None
    net.load_state_dict(best_state)
    return net


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point."""
    ap = argparse.ArgumentParser(prog="python -m arena.learn.iplanner.train", description=__doc__)
    ap.add_argument("-o", "--out", required=True, help="run folder (gets policy.npz, log.json)")
    ap.add_argument("--barn-maps", type=int, default=DataParams().barn_maps)
    ap.add_argument("--indoor-maps", type=int, default=DataParams().indoor_maps)
    ap.add_argument("--poses-per-map", type=int, default=DataParams().poses_per_map)
    ap.add_argument("--epochs", type=int, default=30)
    ap.add_argument("--batch", type=int, default=128)
    ap.add_argument("--lr", type=float, default=1e-3)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--threads", type=int, default=1, help="torch CPU threads")
    args = ap.parse_args(argv)
    torch.set_num_threads(args.threads)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    params = DataParams(barn_maps=args.barn_maps, indoor_maps=args.indoor_maps,
                        poses_per_map=args.poses_per_map)
    t0 = time.perf_counter()
    data = make_dataset(params, args.seed)
    t_data = time.perf_counter() - t0
    log: list[dict[str, Any]] = []
    cost, weights = CostParams(), LossWeights()
    net = fit(data, params, epochs=args.epochs, batch=args.batch, lr=args.lr, seed=args.seed,
              cost=cost, weights=weights, log=log)
    wall = time.perf_counter() - t0
    best = min(log, key=lambda r: r["val"]["total"])
    meta = {
        "waypoints": WAYPOINTS,
        "camera": CAMERA.model_dump(mode="json"),
        "max_depth": MAX_DEPTH,
        "cost": cost.model_dump(),
        "training": {
            "command": "python -m arena.learn.iplanner.train " + " ".join(argv or sys.argv[1:]),
            "images": len(data), "epochs": args.epochs, "seed": args.seed,
            "data_wall_time_s": round(t_data, 1), "wall_time_s": round(wall, 1),
            "best_epoch": best["epoch"], "val": best["val"],
            "hardware": f"{platform.machine()} CPU, {args.threads} torch thread(s)",
            "data": params.model_dump(mode="json"), "weights": weights.model_dump(),
        },
    }
    path = save_net(out / "policy.npz", net.export(), meta)
    (out / "log.json").write_text(json.dumps({"meta": meta, "epochs": log}, indent=1))
    v = best["val"]
    print(f"wrote {path} ({wall:.0f} s; data {t_data:.0f} s; {len(data)} images; held-out "
          f"loss {v['total']:.3f}, obstacle {v['obstacle']:.3f}, goal {v['goal']:.3f}, "
          f"colliding {v['fear_rate']:.1%})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
