"""Train ArtPlanner's motion-cost network: ``python -m arena.learn.artplanner.train -o RUN``.

Draws ``--samples`` random terrain edges (:mod:`arena.learn.artplanner.dataset`), labels them
with the quadruped stepping model (:mod:`arena.learn.artplanner.stepping`), and fits an MLP
(two hidden ReLU layers) with Adam: binary cross-entropy on feasibility plus the squared error
of the time per metre on the feasible edges. Keeps the epoch with the lowest held-out loss and
writes ``RUN/model.npz`` (:mod:`arena.learn.artplanner.model`) and ``RUN/log.json``. Seeded: the
same arguments on the same machine give the same file.
"""

from __future__ import annotations

import argparse
import json
import platform
import sys
import time
from pathlib import Path

import numpy as np
import torch
from torch import nn

from arena.learn.artplanner.dataset import make_dataset
from arena.learn.artplanner.features import EdgeFeatureParams
from arena.learn.artplanner.model import save_model
from arena.learn.artplanner.stepping import SteppingParams
from arena.learn.fit_mlp import Split, fit_held_out

TIME_SCALE = 2.0
"""s/m per unit of the network's time output (targets run from 1.25 to about 12 s/m)."""


def _loss(out: torch.Tensor, feasible: torch.Tensor, t: torch.Tensor) -> torch.Tensor:
    bce = nn.functional.binary_cross_entropy_with_logits(out[:, 0], feasible)
    mse = ((out[:, 1] - t) ** 2 * feasible).sum() / feasible.sum().clamp(min=1.0)
    return bce + mse


def fit(x: np.ndarray, feasible: np.ndarray, t: np.ndarray, hidden: int, epochs: int, seed: int,
        log: list[dict[str, float]]) -> nn.Sequential:
    """Fit the MLP (``t`` already divided by :data:`TIME_SCALE`); 10 % held out.

    Adam at 2e-3, batches of 512 (:func:`~arena.learn.fit_mlp.fit_held_out`); each epoch's log
    also holds the held-out feasibility accuracy (``val_accuracy``).
    """

    def accuracy(net: nn.Module, train: Split, out: torch.Tensor, val: Split) -> dict[str, float]:
        return {"val_accuracy": float(((out[:, 0] > 0).float() == val[1]).float().mean())}

    return fit_held_out(x, (feasible, t), hidden, _loss, epochs=epochs, batch=512, lr=2e-3,
                        seed=seed, log=log, extra_log=accuracy)


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point."""
    ap = argparse.ArgumentParser(prog="python -m arena.learn.artplanner.train", description=__doc__)
    ap.add_argument("-o", "--out", required=True, help="run folder (gets model.npz, log.json)")
    ap.add_argument("--samples", type=int, default=400_000, help="random terrain edges")
    ap.add_argument("--epochs", type=int, default=60)
    ap.add_argument("--hidden", type=int, default=64, help="units per hidden layer")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--threads", type=int, default=1, help="torch CPU threads")
    args = ap.parse_args(argv)
    if args.samples < 10 or args.epochs < 1 or args.hidden < 1:
        ap.error("--samples >= 10, --epochs >= 1 and --hidden >= 1 are needed")
    torch.set_num_threads(args.threads)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    features, stepping = EdgeFeatureParams(), SteppingParams()
    t0 = time.perf_counter()
    x, feasible, t = make_dataset(args.samples, features, stepping, args.seed)
    t_data = time.perf_counter() - t0
    log: list[dict[str, float]] = []
    net = fit(x, feasible, (t / TIME_SCALE).astype(np.float32), args.hidden, args.epochs,
              args.seed, log)
    wall = time.perf_counter() - t0
    layers = [m for m in net if isinstance(m, nn.Linear)]
    best = min(log, key=lambda r: r["val_loss"])
    meta = {
        "features": features.model_dump(),
        "stepping": stepping.model_dump(),
        "time_scale": TIME_SCALE,
        "training": {
            "command": "python -m arena.learn.artplanner.train " + " ".join(argv or sys.argv[1:]),
            "samples": args.samples, "epochs": args.epochs, "seed": args.seed,
            "feasible_fraction": round(float(feasible.mean()), 4),
            "data_wall_time_s": round(t_data, 1), "wall_time_s": round(wall, 1),
            "val_loss": best["val_loss"], "val_accuracy": best["val_accuracy"],
            "hardware": f"{platform.machine()} CPU, {args.threads} torch threads",
            "labels": "kinematic stepping model (arena.learn.artplanner.stepping), not a "
                      "locomotion policy",
        },
    }
    path = save_model(out / "model.npz", [m.weight.detach().numpy() for m in layers],
                      [m.bias.detach().numpy() for m in layers], meta)
    (out / "log.json").write_text(json.dumps({"meta": meta, "epochs": log}, indent=1))
    print(f"wrote {path} ({wall:.0f} s; data {t_data:.0f} s; held-out accuracy "
          f"{best['val_accuracy']:.3f}, loss {best['val_loss']:.4f})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
