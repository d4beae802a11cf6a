"""Train the LfLH policy: ``python -m arena.learn.lflh.train -o RUN``.

Renders ``--samples`` hallucinated samples (:mod:`arena.learn.lflh.dataset`), fits an MLP
(two hidden ReLU layers) to the first command of each motion by mean-squared error with Adam,
keeps the epoch with the lowest held-out error and writes ``RUN/policy.npz``
(:mod:`arena.learn.lflh.actor`) and ``RUN/log.json``. Seeded: the same arguments on the same
machine give the same file.
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

from arena.learn.fit_mlp import Split, fit_held_out
from arena.learn.lflh.actor import save_actor
from arena.learn.lflh.dataset import DataParams, make_dataset


def fit(
    x: np.ndarray, y: np.ndarray, hidden: int, epochs: int, seed: int, log: list[dict[str, float]]
) -> nn.Sequential:
    """Fit an MLP to ``y`` ``(n, 2)`` (already scaled to about [-1, 1]); 10 % held out.

    Mean-squared error, Adam at 1e-3, batches of 256 (:func:`~arena.learn.fit_mlp.fit_held_out`);
    each epoch's log also holds the error over the training samples (``train_mse``).
    """

    def train_mse(net: nn.Module, train: Split, out: torch.Tensor, val: Split) -> dict[str, float]:
        return {"train_mse": float(nn.functional.mse_loss(net(train[0]), train[1]))}

    return fit_held_out(x, (y,), hidden, nn.functional.mse_loss, epochs=epochs, batch=256,
                        lr=1e-3, seed=seed, log=log, extra_log=train_mse)


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point."""
    ap = argparse.ArgumentParser(prog="python -m arena.learn.lflh.train", description=__doc__)
    ap.add_argument("-o", "--out", required=True, help="run folder (gets policy.npz, log.json)")
    ap.add_argument("--samples", type=int, default=24_000, help="hallucinated samples")
    ap.add_argument("--epochs", type=int, default=60)
    ap.add_argument("--hidden", type=int, default=128, help="units per hidden layer")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--clearance-per-speed", type=float, default=None,
                    help="s, wall gap added per m/s of the motion's speed (default: 0.2)")
    ap.add_argument("--threads", type=int, default=2, help="torch CPU threads")
    args = ap.parse_args(argv)
    torch.set_num_threads(args.threads)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    params = DataParams()
    if args.clearance_per_speed is not None:
        params = params.model_copy(update={"hallucination": params.hallucination.model_copy(
            update={"clearance_per_speed": args.clearance_per_speed})})
    t0 = time.perf_counter()
    x, y = make_dataset(args.samples, params, args.seed)
    t_data = time.perf_counter() - t0
    scale = np.array([params.motion.v_max, params.motion.omega_max], dtype=np.float32)
    log: list[dict[str, float]] = []
    net = fit(x, y / scale, args.hidden, args.epochs, args.seed, log)
    wall = time.perf_counter() - t0
    layers = [m for m in net if isinstance(m, nn.Linear)]
    meta = {
        "features": params.features.model_dump(),
        "laser": params.laser.model_dump(),
        "out_scale": scale.tolist(),
        "training": {
            "command": "python -m arena.learn.lflh.train " + " ".join(argv or sys.argv[1:]),
            "samples": args.samples, "epochs": args.epochs, "seed": args.seed,
            "data_wall_time_s": round(t_data, 1), "wall_time_s": round(wall, 1),
            "val_mse": min(r["val_loss"] for r in log),
            "hardware": f"{platform.machine()} CPU, {args.threads} torch threads",
            "data": params.model_dump(mode="json"),
        },
    }
    path = save_actor(out / "policy.npz", [m.weight.detach().numpy() for m in layers],
                      [m.bias.detach().numpy() for m in layers], meta)
    (out / "log.json").write_text(json.dumps({"meta": meta, "epochs": log}, indent=1))
    mse = meta["training"]["val_mse"]
    print(f"wrote {path} ({wall:.0f} s; data {t_data:.0f} s; val mse {mse:.4f})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
