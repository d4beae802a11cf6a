r"""Warm-start a PPO run by behaviour cloning a scripted expert, then train on with PPO.

PPO from scratch on Arena's generated indoor maps learns slowly on a few CPU cores (rosnav_rl:
8 % success after 508 k steps; it learns to avoid collisions by hardly moving). A scripted
expert already reaches most goals, so the actor starts from it:

1. ``arena train CONFIG -o RUN --steps <one update>`` creates the run folder (run.json, the
   PPO model, VecNormalize) exactly as ``arena train`` does, with the config's vector env
   (``dummy``, ``subproc``, ``batched`` or ``multi_robot``) and feature extractor;
2. the expert drives the training env for ``--samples`` steps (all slots together; executed
   actions get Gaussian noise of std ``--noise``, the labels stay the expert's clean actions,
   so the data also covers the states just off the expert's path): the VecNormalize statistics
   are updated on its observations, and the normalised observations, the expert's actions and
   the discounted returns are kept;
3. the actor's mean is fitted to the expert's actions (MSE), the log-std set to ``--log-std``,
   and the critic to the returns (MSE), with Adam;
4. ``--dagger-rounds`` times (DAgger, Ross et al. 2011): the fitted policy drives for
   ``--samples`` more steps while the expert labels the states it visits, and the actor and
   critic are refitted on everything collected so far;
5. the model and statistics are written as the run's checkpoint, so
   ``arena train --resume RUN --steps N`` continues with PPO, and the cloned actor is exported
   to ``RUN/policy.npz`` as ``arena train`` would (the rlca planner's weights).

Experts (``--expert``), both reading the raw observation's ``goal`` (a subgoal with
``observation.subgoal``) and newest ``lidar`` scan:

* ``subgoal``: turn toward the subgoal, slow down in front of obstacles (rosnav_rl's expert);
* ``gap``: steer along the free corridor (robot-wide) closest to the subgoal's bearing
  (rlca's expert).

    python tools/bc_warmstart.py arena/learn/data/train/rlca.yaml -o /work/train_runs/rlca \\
        [--expert gap] [--samples 100000] [--dagger-rounds 1] [--epochs 8] [--log-std -1.0]
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

import argparse
import json
import time
from pathlib import Path
from typing import Any

import numpy as np


def _newest_scan(lidar: np.ndarray) -> np.ndarray:
    """``(B, beams)``: the newest scan of a batched ``lidar`` (``(B, beams)`` or stacked)."""
    return lidar[:, -1, :] if lidar.ndim == 3 else lidar


def _normalised(raw: np.ndarray, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    return (2.0 * (raw - low) / (high - low) - 1.0).astype(np.float32)


def expert(
    obs: dict[str, np.ndarray], low: np.ndarray, high: np.ndarray,
    max_speed: float = 1.0, slow_distance: float = 1.0,
) -> np.ndarray:
    """Normalised ``[v, ω]`` actions of the subgoal follower for raw (unnormalised) obs.

    Turn toward the subgoal (ω = 1.5·θ), drive at up to ``max_speed`` m/s scaled by cos θ, and
    slow down linearly when the closest return within ±11° ahead is nearer than
    ``0.4 + slow_distance`` m. In the batched env (64 episodes, seed 99): 1.0/1.0 reaches 53 goals
    in 19.1 s on average, 1.6/1.6 54 in 11.2 s, 2.0/2.5 53 in 8.6 s with more collisions.
    """
    th = obs["goal"][:, 1]
    lid = _newest_scan(obs["lidar"])
    beams = lid.shape[1]
    c = beams // 2  # the jackal's beams are symmetric about straight ahead
    w = max(1, beams // 24)
    front = lid[:, c - w : c + w].min(axis=1)
    v = np.clip(max_speed * np.cos(th), 0.0, max_speed) * np.clip(
        (front - 0.4) / slow_distance, 0.0, 1.0
    )
    om = np.clip(1.5 * th, -1.0, 1.0)
    return _normalised(np.stack([v, om], axis=1), low, high)


def gap_expert(
    obs: dict[str, np.ndarray], low: np.ndarray, high: np.ndarray, angles: np.ndarray,
    max_speed: float = 1.2, half_width: float = 0.4, look: float = 2.5,
    slow_distance: float = 1.0, k_turn: float = 2.0, omega_max: float = 1.5,
) -> np.ndarray:
    """Normalised ``[v, ω]`` actions of a corridor follower for raw (unnormalised) obs.

    For 41 candidate headings across the laser's field of view, the free length of a corridor
    ``2·half_width`` m wide (the newest scan's returns inside it, nearest along it); the robot
    heads for the subgoal when its corridor is free for ``min(ρ, look)`` m, else for the free
    candidate closest to the subgoal's bearing (none free: the longest). ω = ``k_turn`` · heading
    (clipped to ``omega_max``), v = ``max_speed`` · cos²(heading), slowed linearly when the
    corridor straight ahead is shorter than ``0.45 + slow_distance`` m. Angles ``(beams,)`` rad,
    robot frame. In the rlca training env (3 worlds of 2-4 robots, 600 steps, seed 5) it ended
    31 episodes at the goal and 2 in collisions (the subgoal follower: 10 and 8 in 300 steps).
    """
    rho, th = obs["goal"][:, 0].astype(np.float64), obs["goal"][:, 1].astype(np.float64)
    step = max(1, angles.size // 180)  # a quarter degree per beam is more than needed
    a = angles[::step]
    r = _newest_scan(obs["lidar"])[:, ::step].astype(np.float64)  # (B, P)
    cand = np.linspace(a[0] + 0.2, a[-1] - 0.2, 41)  # (K,) rad
    d = a[None, :] - cand[:, None]  # (K, P)
    along = r[:, None, :] * np.cos(d)[None]
    across = np.abs(r[:, None, :] * np.sin(d)[None])
    free = np.where((across < half_width) & (along > 0), along, np.inf).min(axis=2)  # (B, K)
    need = np.minimum(rho, look)
    dev = np.abs(cand[None, :] - th[:, None])
    score = np.where(free >= need[:, None], dev, 10.0 + look - np.minimum(free, look))
    heading = cand[np.argmin(score, axis=1)]
    toward = free[np.arange(th.size), np.argmin(dev, axis=1)]
    direct = (np.abs(th) < a[-1]) & (toward >= need)
    heading = np.where(direct, th, heading)
    om = np.clip(k_turn * heading, -omega_max, omega_max)
    ahead = free[:, cand.size // 2]
    v = max_speed * np.clip(np.cos(heading), 0.0, 1.0) ** 2 * np.clip(
        (ahead - 0.45) / slow_distance, 0.0, 1.0
    )
    return _normalised(np.stack([v, om], axis=1), low, high)


def people_from_map(
    semantic: np.ndarray, channels: list[str], roi: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """People of a batched ``semantic`` observation ``(B, C, size, size)``, robot frame.

    Returns ``(B, P, 2)`` cell-centre positions (m), ``(B, P, 2)`` velocities (m/s) and the
    ``(B, P)`` mask of occupied cells (a cell with ``pedestrian_location`` set, or a non-zero
    velocity when the map has no location channel).
    """
    b, _, size, _ = semantic.shape
    vx = semantic[:, channels.index("pedestrian_vel_x")]
    vy = semantic[:, channels.index("pedestrian_vel_y")]
    occ = (semantic[:, channels.index("pedestrian_location")] > 0
           if "pedestrian_location" in channels else (vx != 0) | (vy != 0))
    rows, cols = np.meshgrid(np.arange(size), np.arange(size), indexing="ij")
    cell = roi / size
    xy = np.stack([(cols - size // 2 + 0.5) * cell, (rows - size // 2 + 0.5) * cell], axis=-1)
    pos = np.broadcast_to(xy.reshape(1, -1, 2), (b, size * size, 2))
    vel = np.stack([vx.reshape(b, -1), vy.reshape(b, -1)], axis=-1)
    return pos, vel, occ.reshape(b, -1)


def vo_scan(
    scan: np.ndarray, angles: np.ndarray, pos: np.ndarray, vel: np.ndarray, mask: np.ndarray,
    horizons: tuple[float, ...] = (0.5, 1.0, 1.5), radius: float = 0.5,
) -> np.ndarray:
    """``(B, beams)`` scan with each person's predicted positions added as returns.

    Every person is extrapolated at constant velocity to each horizon (s) and drawn as a disc
    of ``radius`` m: the beams it covers read the disc's near side when that is nearer. The
    gap follower then steers around where people will be (DRL-VO's velocity-obstacle idea).
    """
    out = scan.astype(np.float64).copy()
    bi, pi = np.nonzero(mask)
    if bi.size == 0:
        return out
    for t in horizons:
        p = pos[bi, pi] + t * vel[bi, pi]  # (K, 2)
        d = np.hypot(p[:, 0], p[:, 1])
        ok = d > radius
        half = np.arcsin(np.clip(radius / np.maximum(d, 1e-9), 0.0, 1.0))
        bearing = np.arctan2(p[:, 1], p[:, 0])
        diff = np.abs((angles[None, :] - bearing[:, None] + np.pi) % (2 * np.pi) - np.pi)
        hit = (diff <= half[:, None]) & ok[:, None]
        near = np.where(hit, (d - radius)[:, None], np.inf)
        np.minimum.at(out, bi, near)
    return out


def vo_expert(
    obs: dict[str, np.ndarray], low: np.ndarray, high: np.ndarray, angles: np.ndarray,
    channels: list[str], roi: float, **kw: Any,
) -> np.ndarray:
    """:func:`gap_expert` on the newest scan with the people's predicted positions added."""
    pos, vel, occ = people_from_map(obs["semantic"], channels, roi)
    scan = vo_scan(_newest_scan(obs["lidar"]), angles, pos, vel, occ)
    return gap_expert({"goal": obs["goal"], "lidar": scan}, low, high, angles, **kw)


def _collect(
    venv: Any, n: int, steps: int, label: Any, drive: Any, noise: float,
    rng: np.random.Generator, gamma: float,
) -> tuple[dict[str, np.ndarray], np.ndarray, np.ndarray, tuple[int, int, int]]:
    """``steps`` steps of all ``n`` slots: raw obs, expert labels, discounted returns.

    ``drive(normalised obs, raw obs)`` picks the executed action (plus noise); ``label(raw obs)``
    the expert's. Returns the data and (episodes, successes, collisions).
    """
    obs = venv.reset()
    keys = list(obs.keys())
    buf: dict[str, list[np.ndarray]] = {k: [] for k in keys}
    acts, rews, dones = [], [], []
    episodes = successes = collisions = 0
    for _ in range(steps):
        raw = venv.get_original_obs()
        a = label(raw)
        for k in keys:
            buf[k].append(raw[k].copy())
        acts.append(a)
        run = drive(obs, a)
        if noise > 0:
            run = np.clip(run + rng.normal(0.0, noise, run.shape), -1.0, 1.0)
        obs, _, d, infos = venv.step(run.astype(np.float32))
        rews.append(venv.get_original_reward())
        dones.append(d.copy())
        for i in np.flatnonzero(d):
            out = infos[i].get("outcome")
            if out == "cut":  # a multi-robot world restarted under this robot
                continue
            episodes += 1
            successes += out == "success"
            collisions += out == "collision"
    rew = np.stack(rews)  # (T, n)
    don = np.stack(dones)
    ret = np.zeros_like(rew)
    acc = np.zeros(n)
    for t in range(len(rew) - 1, -1, -1):  # discounted returns, cut at episode ends
        acc = rew[t] + gamma * acc * (1.0 - don[t])
        ret[t] = acc
    data = {k: np.concatenate(v) for k, v in buf.items()}
    return data, np.concatenate(acts), ret.reshape(-1), (episodes, successes, collisions)


def _fit(
    pol: Any, obs: dict[str, np.ndarray], act: np.ndarray, ret: np.ndarray, epochs: int,
    lr: float, batch: int = 512,
) -> None:
    """Fit the actor's mean to ``act`` and the critic to ``ret`` (MSE, Adam)."""
    import torch

    pol.set_training_mode(True)
    opt = torch.optim.Adam(pol.parameters(), lr=lr)
    m = act.shape[0]
    rng = np.random.default_rng(0)
    tobs = {k: torch.as_tensor(v) for k, v in obs.items()}
    tact = torch.as_tensor(act)
    tret = torch.as_tensor(ret, dtype=torch.float32)
    for epoch in range(epochs):
        t0 = time.perf_counter()
        order = rng.permutation(m)
        la = lv = 0.0
        for s in range(0, m, batch):
            idx = torch.as_tensor(order[s : s + batch])
            feats = pol.extract_features({k: v[idx] for k, v in tobs.items()})
            # a tuple when actor and critic have their own extractors
            pi_f, vf_f = feats if isinstance(feats, tuple) else (feats, feats)
            mean = pol.action_net(pol.mlp_extractor.forward_actor(pi_f))
            value = pol.value_net(pol.mlp_extractor.forward_critic(vf_f)).squeeze(-1)
            loss_a = ((mean - tact[idx]) ** 2).mean()
            loss_v = ((value - tret[idx]) ** 2).mean()
            loss = loss_a + 0.01 * loss_v
            opt.zero_grad()
            loss.backward()
            opt.step()
            la += float(loss_a.detach()) * len(idx)
            lv += float(loss_v.detach()) * len(idx)
        print(f"  epoch {epoch + 1}: action MSE {la / m:.4f}, value MSE {lv / m:.3f} "
              f"({time.perf_counter() - t0:.0f} s)", flush=True)
    pol.set_training_mode(False)


def main() -> None:
    """Create the run, collect expert data, fit the actor and critic, write the checkpoint."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("config")
    ap.add_argument("-o", "--out", type=Path, required=True)
    ap.add_argument("--expert", choices=["subgoal", "gap", "vo"], default="subgoal")
    ap.add_argument("--samples", type=int, default=200_000, help="steps per collection")
    ap.add_argument("--extra-config", default=None,
                    help="a second experiment config (same robot, observation and action) "
                         "whose world gives as many samples again per round; PPO later "
                         "trains in CONFIG's world only")
    ap.add_argument("--dagger-rounds", type=int, default=0)
    ap.add_argument("--noise", type=float, default=0.0,
                    help="std of the noise on executed (normalised) actions")
    ap.add_argument("--epochs", type=int, default=8)
    ap.add_argument("--log-std", type=float, default=-1.0)
    ap.add_argument("--lr", type=float, default=1e-3)
    ap.add_argument("--batch", type=int, default=512, help="fit minibatch")
    ap.add_argument("--max-speed", type=float, default=None,
                    help="m/s, the expert's top speed (subgoal: 1.0, gap: 1.2)")
    ap.add_argument("--slow-distance", type=float, default=1.0,
                    help="m, the expert slows down over this distance before obstacles")
    args = ap.parse_args()

    import torch
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import VecNormalize

    from arena.learn.actions import ActionDecoder
    from arena.learn.policy import export_policy, laser_meta
    from arena.learn.train import load_training, make_vec_env, train
    from arena.robots.presets import load_robot

    torch.set_num_threads(int(os.environ.get("OMP_NUM_THREADS", "1")))
    cfg, settings = load_training(args.config)
    tr, ppo = settings.train, settings.ppo
    t_start = time.perf_counter()
    first = settings.model_copy(
        update={"train": tr.model_copy(update={"total_steps": ppo.batch_size})}
    )
    train(cfg, first, args.out, progress=False)
    run = json.loads((args.out / "run.json").read_text())
    ckpt = args.out / run["checkpoint"]
    print(f"run created ({time.perf_counter() - t_start:.0f} s): {ckpt}", flush=True)

    robot = load_robot(cfg.robot)
    dec = ActionDecoder(cfg.learning.env.action, robot)
    low, high = dec.range_low[:2], dec.range_high[:2]
    angles = np.asarray(laser_meta(robot.laser)["angles"])

    sem = cfg.learning.env.observation.semantic

    def label(raw: dict[str, np.ndarray]) -> np.ndarray:
        if args.expert == "vo":
            return vo_expert(raw, low, high, angles, list(sem.channels), sem.roi,
                             max_speed=args.max_speed or 1.2, slow_distance=args.slow_distance)
        if args.expert == "gap":
            return gap_expert(raw, low, high, angles,
                              max_speed=args.max_speed or 1.2, slow_distance=args.slow_distance)
        return expert(raw, low, high, args.max_speed or 1.0, args.slow_distance)

    venv = make_vec_env(cfg, tr.n_envs, tr.vec_env, seed=int(run["seed"]) + 7919,
                        robots_per_world=tr.robots_per_world, respawn=tr.respawn,
                        prefetch=tr.prefetch_episodes)
    venv = VecNormalize.load(str(ckpt / "vecnormalize.pkl"), venv)
    venv.training = True
    model = PPO.load(ckpt / "model.zip", env=venv, device="cpu")
    pol = model.policy
    rng = np.random.default_rng(1)
    n = tr.n_envs
    worlds = [venv]
    if args.extra_config is not None:
        cfg2, _ = load_training(args.extra_config)
        if (cfg2.robot != cfg.robot
                or cfg2.learning.env.observation != cfg.learning.env.observation
                or cfg2.learning.env.action != cfg.learning.env.action):
            raise SystemExit(f"{args.extra_config}: robot, learning.env.observation and "
                             f"learning.env.action must equal those of {args.config}")
        venv2 = VecNormalize.load(str(ckpt / "vecnormalize.pkl"), make_vec_env(
            cfg2, tr.n_envs, tr.vec_env, seed=int(run["seed"]) + 2 * 7919,
            robots_per_world=tr.robots_per_world, respawn=tr.respawn))
        # normalised with the first world's statistics, which only the first world updates
        venv2.training = False
        venv2.obs_rms = venv.obs_rms
        worlds.append(venv2)
    data: list[tuple[dict[str, np.ndarray], np.ndarray, np.ndarray]] = []
    for rnd, world in ((r, w) for r in range(args.dagger_rounds + 1) for w in worlds):
        t0 = time.perf_counter()
        if rnd == 0:
            def drive(obs: Any, expert_action: np.ndarray) -> np.ndarray:
                return expert_action
        else:
            venv.training = False  # the statistics the policy was fitted with stay fixed

            def drive(obs: Any, expert_action: np.ndarray) -> np.ndarray:
                act, _ = model.predict(obs, deterministic=True)
                return np.asarray(act, np.float32)
        obs_r, act_r, ret_r, (eps, succ, coll) = _collect(
            world, n, args.samples // n, label, drive, args.noise, rng, ppo.gamma
        )
        who = "expert" if rnd == 0 else f"policy (DAgger round {rnd})"
        who += f" in world {worlds.index(world) + 1}/{len(worlds)}"
        print(f"{who}: {act_r.shape[0]} samples in {time.perf_counter() - t0:.0f} s, "
              f"{eps} episodes: {succ} at the goal, {coll} collisions", flush=True)
        data.append((obs_r, act_r, ret_r))
        if world is not worlds[-1]:
            continue  # fit once per round, on the data of every world
        # raw observations normalised with the statistics as they are now (round 0's moved
        # while it collected), so that every sample sees the normalisation the policy will use
        # only the normalised parts are copied (the scans and maps of a conv policy are large)
        norm_keys = set(venv.norm_obs_keys) if venv.norm_obs else set()
        obs_t = {}
        for k in obs_r:
            part = np.concatenate([d[0][k] for d in data])
            if k in norm_keys:
                part = venv._normalize_obs(part, venv.obs_rms[k])
            obs_t[k] = np.asarray(part, np.float32)
        act_t = np.concatenate([d[1] for d in data])
        ret_t = np.concatenate([d[2] for d in data])
        t0 = time.perf_counter()
        _fit(pol, obs_t, act_t, ret_t, args.epochs, args.lr, args.batch)
        print(f"fit on {act_t.shape[0]} samples: {time.perf_counter() - t0:.0f} s", flush=True)
    with torch.no_grad():
        pol.log_std.fill_(args.log_std)
    model.save(ckpt / "model.zip")
    venv.save(str(ckpt / "vecnormalize.pkl"))
    export_policy(
        model, venv if ppo.normalize.norm_obs else None, args.out / "policy.npz", decoder=dec,
        observation=cfg.learning.env.observation.model_dump(mode="json"), laser=robot.laser,
    )
    venv.close()
    print(f"warm start written to {ckpt} ({time.perf_counter() - t_start:.0f} s in all); "
          f"continue with: arena train --resume {args.out} --steps N", flush=True)


if __name__ == "__main__":
    main()
