r"""Train the APPLR policy with Stable-Baselines3's TD3 and export its actor (torch).

Usage (the ``train`` extra; one CPU thread)::

    OMP_NUM_THREADS=1 python -m arena.learn.applr.train -o RUN [--steps 30000] [--seed 0] \\
        [--config FILE] [--eval-every 5000] [--eval-episodes 30]

writes ``RUN/policy.npz`` (the actor of the best validation checkpoint; copy it to
``arena/learn/data/policies/applr.npz`` to ship it), ``RUN/checkpoints/policy_<step>.npz``,
``RUN/log.csv`` (one row per validation) and ``RUN/summary.json``.

Training (APPLR, Xu et al. 2021): TD3 on :class:`~arena.learn.applr.env.ApplrEnv` (one step =
one 1-s period of DWA driving with the chosen parameters; the packaged config's generated barn
maps), actor and critics MLPs of 256-256 ReLU units, Gaussian exploration noise on the action.
Our addition: the actor's output layer starts at zero, so the first policy answers ``a = 0``
(DWA's defaults) everywhere and TD3 learns departures from DWA rather than from random
parameters; the first ``learning_starts`` steps still draw uniform random parameters (SB3's
warm-up), which fills the replay buffer with what other parameters do.

Episodes: the training config's, drawn under the seed ``seed`` (it replaces the config's own:
SB3 seeds the env with it); validation episodes under ``seed + VALIDATION_OFFSET``.

Validation: every ``eval_every`` steps the deterministic actor (exported, run with numpy as the
planner runs it) drives ``eval_episodes`` episodes of the training config under the seed
``seed + VALIDATION_OFFSET`` (neither training nor held-out episodes); the checkpoint with the
most successes (then the shortest mean time) becomes ``RUN/policy.npz``. DWA with its
defaults (``a = 0``) on the same episodes is the first row of the log.

Determinism: ``torch.manual_seed`` through SB3's ``seed``, one torch thread, seeded envs.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import platform
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from arena.learn.applr.actor import ApplrActor, save_actor
from arena.learn.applr.env import TRAIN_CONFIG, ApplrEnv, ApplrReward
from arena.learn.applr.space import PARAMETERS, parameter_ranges

VALIDATION_OFFSET = 1000
"""Validation episodes come from ``seed + VALIDATION_OFFSET`` of the training config."""


@dataclass
class ApplrTrainSettings:
    """Everything a training run depends on (saved in the policy file's meta)."""

    config: str = str(TRAIN_CONFIG)
    seed: int = 0
    steps: int = 30_000
    period: float = 1.0
    beams: int = 72
    hidden: tuple[int, ...] = (256, 256)
    learning_rate: float = 3e-4
    buffer_size: int = 100_000
    batch_size: int = 256
    gamma: float = 0.99
    tau: float = 0.005
    learning_starts: int = 1_000
    noise_std: float = 0.3
    time_penalty: float = ApplrReward.model_fields["time"].default
    policy_delay: int = 2
    eval_every: int = 5_000
    eval_episodes: int = 30


@dataclass
class Validation:
    """One validation of a policy: successes, collisions and mean time to goal (s)."""

    step: int
    success: float
    collision: float
    time_to_goal: float
    mean_return: float


def validate(env: ApplrEnv, act: Callable[[NDArray[np.float32]], NDArray[np.float64]],
             seed: int, episodes: int, step: int) -> Validation:
    """Drive ``episodes`` episodes of ``seed`` with the deterministic policy ``act``."""
    outcomes: list[str | None] = []
    times: list[float] = []
    returns: list[float] = []
    for k in range(episodes):
        obs, _ = env.reset(seed=seed) if k == 0 else env.reset()
        total, done = 0.0, False
        info: dict[str, Any] = {}
        while not done:
            obs, r, term, trunc, info = env.step(act(obs))
            total += float(r)
            done = term or trunc
        outcomes.append(info["outcome"])
        returns.append(total)
        if info["outcome"] == "success":
            times.append(info["time"])
    n = max(episodes, 1)
    return Validation(
        step=step,
        success=outcomes.count("success") / n,
        collision=outcomes.count("collision") / n,
        time_to_goal=float(np.mean(times)) if times else float("nan"),
        mean_return=float(np.mean(returns)) if returns else 0.0,
    )


def actor_layers(model: Any) -> tuple[list[NDArray[np.float32]], list[NDArray[np.float32]]]:
    """Weights ``(out, in)`` and biases of the linear layers of an SB3 TD3 actor."""
    import torch.nn as nn

    ws, bs = [], []
    for m in model.actor.mu:
        if isinstance(m, nn.Linear):
            ws.append(m.weight.detach().cpu().numpy().astype(np.float32))
            bs.append(m.bias.detach().cpu().numpy().astype(np.float32))
        elif not isinstance(m, nn.ReLU | nn.Tanh):
            raise ValueError(f"cannot export actor layer {type(m).__name__}")
    return ws, bs


def export(model: Any, env: ApplrEnv, path: Path, meta: dict[str, Any]) -> ApplrActor:
    """Write the actor of ``model`` as an APPLR policy file; the loaded file."""
    ws, bs = actor_layers(model)
    save_actor(path, ws, bs, {
        "features": env.features.to_json(),
        "parameters": parameter_ranges(PARAMETERS),
        "period": env.period,
        **meta,
    })
    return ApplrActor.load(path)


def train(s: ApplrTrainSettings, out: Path, log: Callable[[str], None] = print) -> Validation:
    """Run TD3 as the module docstring says; the validation of the shipped checkpoint."""
    import torch
    from stable_baselines3 import TD3
    from stable_baselines3.common.callbacks import BaseCallback
    from stable_baselines3.common.noise import NormalActionNoise

    torch.set_num_threads(1)
    out.mkdir(parents=True, exist_ok=True)
    (out / "checkpoints").mkdir(exist_ok=True)
    reward = ApplrReward(time=s.time_penalty)
    env = ApplrEnv(s.config, period=s.period, beams=s.beams, reward=reward)
    val_env = ApplrEnv(s.config, period=s.period, beams=s.beams, reward=reward)
    env.reset(seed=s.seed)
    k = len(PARAMETERS)
    model = TD3(
        "MlpPolicy", env, learning_rate=s.learning_rate, buffer_size=s.buffer_size,
        learning_starts=s.learning_starts, batch_size=s.batch_size, tau=s.tau, gamma=s.gamma,
        train_freq=1, gradient_steps=1, policy_delay=s.policy_delay,
        action_noise=NormalActionNoise(np.zeros(k), s.noise_std * np.ones(k)),
        policy_kwargs={"net_arch": list(s.hidden)}, seed=s.seed, device="cpu", verbose=0,
    )
    with torch.no_grad():  # the first policy is DWA's defaults (module docstring)
        for actor in (model.actor, model.actor_target):
            head = [m for m in actor.mu if isinstance(m, torch.nn.Linear)][-1]
            head.weight.zero_()
            head.bias.zero_()
    t0 = time.perf_counter()
    settings = {**asdict(s), "hidden": list(s.hidden), "config": _portable(s.config)}
    meta_base: dict[str, Any] = {"training": {"settings": settings,
                              "reward": reward.model_dump(), "command": _command(s, out)}}
    vseed = s.seed + VALIDATION_OFFSET
    rows: list[Validation] = []
    best: tuple[float, float, int] | None = None
    base = validate(val_env, lambda o: np.zeros(k), vseed, s.eval_episodes, -1)
    log(f"DWA defaults: {base}")
    rows.append(base)

    def checkpoint(step: int) -> None:
        nonlocal best
        path = out / "checkpoints" / f"policy_{step}.npz"
        actor = export(model, env, path, meta_base)
        v = validate(val_env, actor.act, vseed, s.eval_episodes, step)
        rows.append(v)
        log(f"step {step}: {v} ({(time.perf_counter() - t0) / 60:.1f} min)")
        key = (v.success, -v.time_to_goal if np.isfinite(v.time_to_goal) else -1e9, step)
        if best is None or key[:2] > best[:2]:
            best = key
        _write_log(out / "log.csv", rows)

    class _Validate(BaseCallback):
        def _on_step(self) -> bool:
            if self.num_timesteps % s.eval_every == 0:
                checkpoint(self.num_timesteps)
            return True

    model.learn(s.steps, callback=_Validate())
    wall = time.perf_counter() - t0
    if s.steps % s.eval_every:
        checkpoint(s.steps)
    assert best is not None
    chosen = next(v for v in rows if v.step == best[2])
    meta: dict[str, Any] = {**meta_base}
    meta["training"] = {
        **meta_base["training"], "steps": s.steps, "wall_time_s": round(wall, 1),
        "hardware": f"{platform.processor() or platform.machine()}, {os.cpu_count()} CPUs "
                    f"visible, torch threads {torch.get_num_threads()}, no GPU",
        "chosen_step": chosen.step, "validation": asdict(chosen),
        "validation_dwa_defaults": asdict(base),
    }
    src = ApplrActor.load(out / "checkpoints" / f"policy_{chosen.step}.npz")
    save_actor(out / "policy.npz", src.weights, src.biases,
               {**{k2: v2 for k2, v2 in src.meta.items() if k2 not in ("format", "policy")},
                **meta})
    (out / "summary.json").write_text(json.dumps(meta["training"], indent=2))
    log(f"done in {wall / 60:.1f} min; shipped step {chosen.step}: {chosen}")
    return chosen


def _portable(path: str) -> str:
    """``path`` relative to the repository when inside it (no machine's folders in files)."""
    root = Path(__file__).resolve().parents[3]
    try:
        return Path(path).resolve().relative_to(root).as_posix()
    except ValueError:
        return path


def _write_log(path: Path, rows: list[Validation]) -> None:
    with path.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(asdict(rows[0])))
        w.writeheader()
        for r in rows:
            w.writerow(asdict(r))


def _command(s: ApplrTrainSettings, out: Path) -> str:
    return (f"OMP_NUM_THREADS=1 python -m arena.learn.applr.train -o {out.name} "
            f"--steps {s.steps} --seed {s.seed}")


def main(argv: list[str] | None = None) -> None:
    """The command line (module docstring)."""
    d = ApplrTrainSettings()
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("-o", "--out", required=True, type=Path, help="run folder")
    ap.add_argument("--config", default=d.config, help="training experiment YAML")
    ap.add_argument("--steps", type=int, default=d.steps, help="TD3 env steps (periods)")
    ap.add_argument("--seed", type=int, default=d.seed)
    ap.add_argument("--eval-every", type=int, default=d.eval_every)
    ap.add_argument("--eval-episodes", type=int, default=d.eval_episodes)
    ap.add_argument("--noise", type=float, default=d.noise_std, help="exploration noise std")
    ap.add_argument("--lr", type=float, default=d.learning_rate, help="TD3 learning rate")
    ap.add_argument("--time-penalty", type=float, default=d.time_penalty, help="reward per step")
    a = ap.parse_args(argv)
    s = ApplrTrainSettings(config=str(a.config), seed=a.seed, steps=a.steps,
                           eval_every=a.eval_every, eval_episodes=a.eval_episodes,
                           noise_std=a.noise, learning_rate=a.lr, time_penalty=a.time_penalty)
    train(s, a.out)


if __name__ == "__main__":
    main()
