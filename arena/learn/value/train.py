r"""Train the ``crowdnav`` (CADRL) and ``sarl`` value policies in our simulator (torch).

Usage (the ``train`` extra; one CPU thread is plenty)::

    OMP_NUM_THREADS=1 python -m arena.learn.value.train --policy sarl -o /tmp/sarl \\
        [--config FILE] [--il-episodes 300] [--rl-episodes 600] [--seed 0]

writes ``OUT/policy.npz`` (copy it to ``arena/learn/data/policies/sarl.npz`` to ship it),
``OUT/log.csv`` (one row per RL episode), ``OUT/summary.json``, and checkpoints
``OUT/policy_il.npz`` (after imitation) and ``OUT/policy_rlNNNN.npz`` (every
``checkpoint_every`` RL episodes).

Episodes are those ``arena run`` draws for the training config (default
``arena/learn/data/train/value_policy.yaml``: Jackal, generated indoor maps, 0–4 shelves,
0–10 pedestrians, a new map every episode), simulated by the config's backend with the real
crowd and the navigation stack (A* global path, replanning); only the local planner is ours.
Episode ``k`` of the run is generator episode ``k`` (imitation episodes first, then RL).

CrowdNav's two phases (Chen et al. 2019), adapted to local goals:

1. **Imitation.** The registered ``orca`` planner drives ``il_episodes`` episodes; every tick
   is a sample: the joint state toward that tick's local goal ``g`` (SARL*, ``subgoal_horizon``
   m along the path), with value target
   ``Σ_j γ^((t_j − t_i) v_pref) r_j`` over the ticks until the robot reaches ``g`` (its
   centre within its radius of ``g``, or its closest pass within :data:`PASS_DISTANCE` m once
   it has gone by), ``+1`` there; ``r_j`` are CrowdNav's rewards (``-0.25`` on a collision,
   which ends the episode; discomfort ``(d - 0.2) · 0.5 · dt`` within 0.2 m of a pedestrian).
   Measuring the value toward a *fixed* local goal is what the planner's one-step lookahead
   assumes. Each tick is recorded once per horizon of ``(subgoal_horizon, *extra_horizons)``
   (3 m and 6 m): trained on 3 m goals alone, the networks extrapolated the value of farther
   goals upward and a SARL robot drove away from its goal. The network regresses these
   targets (Adam, ``il_epochs`` epochs).
2. **Reinforcement.** The value planner itself drives ``rl_episodes`` episodes, ε-greedy
   with ε falling linearly from 0.5 to 0.1 over ``eps_decay`` episodes; each tick's target is
   the ``n_step``-step return toward its fixed local goal, bootstrapped from a target network
   (``V_target`` of the state ``n_step`` ticks later, toward the same goal) when the goal is
   not reached by then; samples enter a replay memory (with the imitation ones), and after
   each episode ``train_batches`` minibatches are fitted; the target network is refreshed
   every ``target_update`` episodes.

Determinism: every draw comes from ``derive_rng(seed, ...)`` or ``torch.manual_seed(seed)``;
torch runs on one CPU thread, so one seed gives one policy file.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import platform
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import torch
from numpy.typing import NDArray
from torch import nn

import arena.plugins  # noqa: F401  (fills the registries)
from arena.config.loader import load_config
from arena.config.schema import ExperimentConfig
from arena.core.errors import ArenaError
from arena.core.rng import derive_rng
from arena.core.types import Outcome
from arena.crowd.driver import build_driver
from arena.episode.navigation import NavigationController, build_stack
from arena.episode.runner import EpisodeHooks, EpisodeRunner
from arena.learn.planners.crowdnav import (
    CrowdNavPlanner,
    SarlPlanner,
    ValuePlanner,
    ValuePlannerParams,
    observe,
)
from arena.learn.value.network import (
    CADRL_LAYOUT,
    SARL_LAYOUT,
    CadrlNetwork,
    Mlp,
    SarlNetwork,
    ValuePolicyFile,
    save_value_policy,
)
from arena.learn.value.state import PAIR_DIM, SELF_DIM, rotate
from arena.nav.local_planners.base import KINEMATICS, LOCAL_PLANNERS, LocalObservation, LocalPlanner
from arena.robots.presets import load_robot
from arena.sim.backend import BACKENDS, SimulatorBackend
from arena.tasks.generator import TaskGenerator

FloatArray = NDArray[np.float64]

DEFAULT_CONFIG = Path(__file__).resolve().parents[1] / "data" / "train" / "value_policy.yaml"
"""The packaged training config (``arena/learn/data/train/value_policy.yaml``)."""


def _portable(path: str) -> str:
    """``path`` relative to the repository when it lies inside it, else as given.

    Shipped policy files should not carry the folders of the machine that trained them.
    """
    root = Path(__file__).resolve().parents[3]
    try:
        return Path(path).resolve().relative_to(root).as_posix()
    except ValueError:
        return path
PASS_DISTANCE = 1.0
"""m: a robot that never comes within its radius of a local goal reaches it at its closest pass
when that pass is this close (the demonstrator cuts path corners)."""
POLICIES = {"crowdnav": "cadrl", "sarl": "sarl"}
"""Planner name → network kind."""


@dataclass
class TrainSettings:
    """Everything a training run depends on (saved in the policy file's meta)."""

    policy: str = "sarl"
    config: str = str(DEFAULT_CONFIG)
    seed: int = 0
    il_episodes: int = 300
    il_epochs: int = 15
    il_lr: float = 1e-3
    rl_episodes: int = 600
    rl_lr: float = 2e-4
    eps_start: float = 0.5
    eps_end: float = 0.1
    eps_decay: int = 300
    n_step: int = 25
    train_batches: int = 40
    batch_size: int = 128
    target_update: int = 10
    capacity: int = 150_000
    gamma: float = 0.9
    time_step: float = 0.25
    max_humans: int = 10
    subgoal_horizon: float = 3.0
    extra_horizons: tuple[float, ...] = (6.0,)
    checkpoint_every: int = 50


# -- torch networks (the same maths as arena.learn.value.network) -------------------------------
def _mlp(in_dim: int, widths: list[int], last_relu: bool) -> nn.Sequential:
    layers: list[nn.Module] = []
    dims = [in_dim, *widths]
    for k in range(len(widths)):
        layers.append(nn.Linear(dims[k], dims[k + 1]))
        if k < len(widths) - 1 or last_relu:
            layers.append(nn.ReLU())
    return nn.Sequential(*layers)


class TorchCadrl(nn.Module):
    """CADRL value network: per-pair MLP, minimum over the real humans."""

    kind = "cadrl"

    def __init__(self) -> None:
        super().__init__()
        self.value = _mlp(PAIR_DIM, CADRL_LAYOUT["value"], False)

    def forward(self, features: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
        """``(B, n, 13)``, ``(B, n)`` bool → ``(B,)``."""
        v = self.value(features)[..., 0]
        return torch.where(mask, v, torch.full_like(v, math.inf)).min(dim=1).values


class TorchSarl(nn.Module):
    """SARL value network: embedding, attention over the real humans, value MLP."""

    kind = "sarl"

    def __init__(self) -> None:
        super().__init__()
        e = SARL_LAYOUT["embed"][-1]
        self.embed = _mlp(PAIR_DIM, SARL_LAYOUT["embed"], True)
        self.feature = _mlp(e, SARL_LAYOUT["feature"], False)
        self.attention = _mlp(2 * e, SARL_LAYOUT["attention"], False)
        self.value = _mlp(SELF_DIM + SARL_LAYOUT["feature"][-1], SARL_LAYOUT["value"], False)

    def forward(self, features: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
        """``(B, n, 13)``, ``(B, n)`` bool → ``(B,)``."""
        mf = mask[..., None].to(features.dtype)
        e = self.embed(features)
        mean = (e * mf).sum(dim=1) / mf.sum(dim=1).clamp(min=1.0)
        scores = self.attention(torch.cat([e, mean[:, None, :].expand_as(e)], dim=-1))[..., 0]
        scores = scores.masked_fill(~mask, -math.inf)
        w = torch.softmax(scores, dim=1)
        crowd = torch.einsum("bn,bnk->bk", w, self.feature(e))
        out: torch.Tensor = self.value(torch.cat([features[:, 0, :SELF_DIM], crowd], dim=-1))
        return out[:, 0]


def torch_network(kind: str) -> TorchCadrl | TorchSarl:
    """A fresh torch network of ``kind`` (``cadrl``/``sarl``)."""
    return TorchCadrl() if kind == "cadrl" else TorchSarl()


def to_numpy(model: TorchCadrl | TorchSarl) -> CadrlNetwork | SarlNetwork:
    """The numpy network with ``model``'s weights."""
    cls = CadrlNetwork if model.kind == "cadrl" else SarlNetwork
    modules: dict[str, Mlp] = {}
    for name in cls.layout:
        seq = getattr(model, name)
        lin = [m for m in seq if isinstance(m, nn.Linear)]
        modules[name] = Mlp(
            tuple(m.weight.detach().numpy().T.copy() for m in lin),  # float32, as loaded
            tuple(m.bias.detach().numpy().copy() for m in lin),
            cls.last_relu[name],
        )
    return cls(modules)


# -- episodes ------------------------------------------------------------------------------------
@dataclass
class EpisodeLog:
    """One episode's decision ticks.

    Attributes:
        robots: ``(T, 9)`` robot full states, goal = that tick's local goal.
        humans: ``T`` arrays ``(n_t, 5)`` (the phantom human when none was in range).
        times: ``(T,)`` s.
        rewards: ``(T,)`` reward of the transition after each tick (collision, discomfort).
        outcome: ``success``, ``collision``, ``timeout`` or ``stuck``.
    """

    robots: list[FloatArray] = field(default_factory=list)
    humans: list[FloatArray] = field(default_factory=list)
    times: list[float] = field(default_factory=list)
    rewards: list[float] = field(default_factory=list)
    outcome: str = "timeout"
    sim_time: float = 0.0


class RecordingPlanner:
    """Wraps the driving planner and logs each tick's joint state, once per local-goal horizon.

    The planner drives toward a local goal ``subgoal_horizon`` m ahead, so its states have
    goals at most that far; recording the same ticks toward farther local goals too
    (``horizons``) teaches the network the values of the farther goals a lookahead step or a
    detour produces, instead of leaving it to extrapolate.
    """

    supports: ClassVar[frozenset[str]] = KINEMATICS

    def __init__(self, inner: LocalPlanner, params: ValuePlannerParams,
                 horizons: tuple[float, ...]) -> None:
        self.inner = inner
        self.params = params
        self.horizons = horizons
        self.logs = [EpisodeLog() for _ in horizons]

    def reset(self) -> None:
        """Reset the driving planner (the logs are replaced per episode by the caller)."""
        self.inner.reset()

    def compute(self, obs: LocalObservation) -> FloatArray:
        """Log the joint states, then drive with the wrapped planner."""
        for h, log in zip(self.horizons, self.logs, strict=True):
            s = observe(obs, self.params, obs.limits.vx_max, h)
            log.robots.append(s.robot)
            log.humans.append(s.humans)
            log.times.append(float(obs.time))
            log.rewards.append(0.0)
        return np.asarray(self.inner.compute(obs), dtype=np.float64)


class _CrowdNavRewards(EpisodeHooks):
    """CrowdNav's rewards of each tick, added to the logs; the first collision ends the episode.

    ``-0.25`` on a contact; discomfort ``(d - 0.2) · 0.5 · dt`` when the nearest gap ``d`` to a
    pedestrian is under 0.2 m. A step's reward goes to the last logged tick (none before it).
    """

    def __init__(self, logs: list[EpisodeLog], robot_radius: float) -> None:
        self.logs = logs
        self.robot_radius = float(robot_radius)
        self._people = 0

    def before_step(self, runner: EpisodeRunner) -> None:
        assert runner.state is not None
        self._people = len(runner.state.agents)  # the crowd the command was computed for

    def after_step(self, runner: EpisodeRunner) -> None:
        state = runner.state
        assert state is not None
        if not self.logs[0].rewards:
            return
        reward = 0.0
        if bool(state.collisions.any[0]):
            reward = -0.25
            runner.end(Outcome.COLLISION)
        elif self._people:
            gap = (np.hypot(*(state.agents.positions - state.robots.poses[0, :2]).T)
                   - state.agents.radii - self.robot_radius)
            d = float(np.min(gap))
            if d < 0.2:
                reward = (d - 0.2) * 0.5 * runner.dt
        for lg in self.logs:
            lg.rewards[-1] += reward


# How a training episode's log names each way an episode ends (CrowdNav's four, and "error").
_LOG_OUTCOME = {
    Outcome.SUCCESS: "success", Outcome.COLLISION: "collision", Outcome.STUCK: "stuck",
    Outcome.TIMEOUT: "timeout", Outcome.ABORTED: "timeout",
    Outcome.PLANNER_FAILURE: "error", Outcome.ERROR: "error",
}


def run_training_episode(cfg: ExperimentConfig, generator: TaskGenerator,
                         backend: SimulatorBackend, index: int,
                         planner: RecordingPlanner) -> list[EpisodeLog]:
    """Simulate episode ``index`` as ``arena run`` would, with ``planner`` as local planner.

    The same :class:`~arena.episode.runner.EpisodeRunner`, navigation stack and task runtime
    as a benchmark episode; unlike one it ends at the first collision (CrowdNav's episodes
    do), and the rewards of each tick are added to the log. An exception other than an
    :class:`~arena.core.errors.ArenaError` (a bug) is raised again.
    """
    episode = generator.episode(index)
    robot = episode.robots[0].model
    planner.logs = logs = [EpisodeLog() for _ in planner.horizons]
    stack = build_stack(cfg.navigation, robot, episode, local_planner=planner)
    nav = NavigationController(
        stack, generator.runtime(episode), robot, cfg.navigation.scan_sensor
    )
    runner = EpisodeRunner(backend, cfg.sim.dt, [nav, _CrowdNavRewards(logs, robot.radius)], nav)
    crowd = build_driver(cfg.crowd, cfg.pedestrians)
    runner.reset(episode, crowd, cfg.seed)
    outcome = runner.run()
    if runner.exception is not None and not isinstance(runner.exception, ArenaError):
        raise runner.exception
    assert runner.state is not None
    for lg in logs:
        lg.outcome, lg.sim_time = _LOG_OUTCOME[outcome], float(runner.state.time)
    return logs


def pad(features: list[FloatArray], width: int) -> tuple[NDArray[np.float32], NDArray[np.bool_]]:
    """Stack ``(n_i, 13)`` pair arrays into ``(B, width, 13)`` with a mask ``(B, width)``."""
    out = np.zeros((len(features), width, PAIR_DIM), dtype=np.float32)
    mask = np.zeros((len(features), width), dtype=bool)
    for b, f in enumerate(features):
        n = min(len(f), width)
        out[b, :n] = f[:n]
        mask[b, :n] = True
    return out, mask


def targets(log: EpisodeLog, gamma: float, holonomic: bool, n_step: int | None,
            value_fn: Callable[[list[FloatArray]], FloatArray] | None
            ) -> tuple[list[FloatArray], FloatArray]:
    """Rotated states and value targets of every tick of ``log`` (see the module docstring).

    Args:
        log: the episode.
        gamma: discount per m at ``v_pref`` (CrowdNav's ``γ^(Δt · v_pref)`` per step).
        holonomic: the robot's action model (``theta'`` of the rotation).
        n_step: ticks before bootstrapping from ``value_fn``; ``None``: Monte Carlo.
        value_fn: value of rotated states (needed with ``n_step``).

    Returns:
        ``T`` arrays ``(n_t, 13)`` and ``(T,)`` targets.
    """
    robots = np.asarray(log.robots)
    n = len(robots)
    times = np.asarray(log.times)
    rewards = np.asarray(log.rewards)
    feats = [rotate(robots[i], log.humans[i], holonomic) for i in range(n)]
    out = np.zeros(n)
    boot: list[tuple[int, int, float]] = []  # (sample, state index, discount)
    horizon = n if n_step is None else n_step
    for i in range(n):
        g, r_i, vp = robots[i, 5:7], robots[i, 4], robots[i, 7]
        disc = gamma ** ((times - times[i]) * vp)  # (T,) discount of tick j's reward
        d = np.hypot(robots[i + 1:, 0] - g[0], robots[i + 1:, 1] - g[1])
        hit = np.flatnonzero(d < r_i)
        reach = i + 1 + int(hit[0]) if hit.size else None
        if reach is None and d.size:
            k = int(np.argmin(d))
            if d[k] < PASS_DISTANCE and k < d.size - 1:  # went past the goal, not just stopped
                reach = i + 1 + k
        if reach is None and log.outcome == "success":
            reach = n  # the episode's goal was reached after the last tick
        end = min(i + horizon, n) if reach is None else min(reach, i + horizon, n)
        out[i] = float(np.sum(rewards[i:end] * disc[i:end]))
        if reach is not None and reach <= min(i + horizon, n):
            out[i] += float(disc[reach - 1])
        elif end < n and value_fn is not None:
            boot.append((i, end, float(disc[end])))
    if boot and value_fn is not None:
        states = []
        for i, j, _ in boot:
            r = robots[j].copy()
            r[5:7] = robots[i, 5:7]  # the sample's own (fixed) local goal
            states.append(rotate(r, log.humans[j], holonomic))
        v = value_fn(states)
        for (i, _, w), vi in zip(boot, v, strict=True):
            out[i] += w * float(vi)
    return feats, out


class Memory:
    """Replay memory of rotated states and value targets (oldest dropped first)."""

    def __init__(self, capacity: int, width: int) -> None:
        self.capacity, self.width = capacity, width
        self.x = np.zeros((capacity, width, PAIR_DIM), dtype=np.float32)
        self.m = np.zeros((capacity, width), dtype=bool)
        self.y = np.zeros(capacity, dtype=np.float32)
        self.size = 0
        self.head = 0

    def push(self, feats: list[FloatArray], y: FloatArray) -> None:
        """Add samples."""
        x, m = pad(feats, self.width)
        for k in range(len(y)):
            self.x[self.head], self.m[self.head], self.y[self.head] = x[k], m[k], y[k]
            self.head = (self.head + 1) % self.capacity
            self.size = min(self.size + 1, self.capacity)

    def batch(self, idx: NDArray[np.int64]) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """Tensors of the samples ``idx``."""
        return (torch.from_numpy(self.x[idx]), torch.from_numpy(self.m[idx]),
                torch.from_numpy(self.y[idx]))


def fit(model: nn.Module, opt: torch.optim.Optimizer, memory: Memory, batches: int,
        batch_size: int, rng: np.random.Generator) -> float:
    """``batches`` minibatch steps of MSE regression; the mean loss."""
    total = 0.0
    for _ in range(batches):
        idx = rng.integers(0, memory.size, batch_size)
        x, m, y = memory.batch(idx)
        loss = nn.functional.mse_loss(model(x, m), y)
        opt.zero_grad()
        loss.backward()  # type: ignore[no-untyped-call]
        opt.step()
        total += float(loss.detach())
    return total / max(batches, 1)


def train(settings: TrainSettings, out: Path, *,
          log: Callable[[str], None] = print) -> Path:
    """Run both phases; write ``out/policy.npz``, ``out/log.csv``, ``out/summary.json``."""
    s = settings
    if s.policy not in POLICIES:
        raise ValueError(f"unknown policy {s.policy!r}; known: {sorted(POLICIES)}")
    kind = POLICIES[s.policy]
    torch.manual_seed(s.seed)
    torch.set_num_threads(1)
    rng = derive_rng(s.seed, "value_train", "batches")
    explore = derive_rng(s.seed, "value_train", "explore")
    cfg = load_config(s.config, [f"seed={s.seed}", "output.video=false"])
    robot = load_robot(cfg.robot)
    holonomic = robot.kinematics_type == "omni"
    backend = BACKENDS.build(cfg.sim.backend, path="sim.backend")
    generator = TaskGenerator.from_config(cfg, [robot])
    params = ValuePlannerParams(subgoal_horizon=s.subgoal_horizon, max_humans=s.max_humans)
    model = torch_network(kind)
    memory = Memory(s.capacity, s.max_humans)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    v_pref = float(robot.limits().vx_max)

    # Phase 1: imitation of ORCA.
    horizons = (s.subgoal_horizon, *s.extra_horizons)
    demo = RecordingPlanner(LOCAL_PLANNERS.build({"type": "orca"}), params, horizons)
    outcomes: dict[str, int] = {}
    ticks = 0
    for k in range(s.il_episodes):
        logs = run_training_episode(cfg, generator, backend, k, demo)
        outcomes[logs[0].outcome] = outcomes.get(logs[0].outcome, 0) + 1
        for ep in logs:
            if ep.robots:
                feats, y = targets(ep, s.gamma, holonomic, None, None)
                memory.push(feats, y)
                ticks += len(y)
    il_demo_s = time.perf_counter() - t0
    opt = torch.optim.Adam(model.parameters(), lr=s.il_lr)
    il_steps = max(1, s.il_epochs * memory.size // s.batch_size) if memory.size else 0
    il_loss = fit(model, opt, memory, il_steps, s.batch_size, rng) if il_steps else math.nan
    log(f"imitation: {s.il_episodes} episodes {outcomes}, {ticks} samples, {il_steps} steps, "
        f"loss {il_loss:.4f}, {time.perf_counter() - t0:.0f} s")

    # Phase 2: ε-greedy RL with a target network.
    meta = _meta(s, kind, v_pref, holonomic, {})
    save_value_policy(out / "policy_il.npz", to_numpy(model), meta)
    planner_cls: type[ValuePlanner] = CrowdNavPlanner if kind == "cadrl" else SarlPlanner
    target_net = to_numpy(model)

    def target_value(states: list[FloatArray]) -> FloatArray:
        x, m = pad(states, max(s.max_humans, max(len(f) for f in states)))
        return target_net.value(x.astype(np.float64), m)

    opt = torch.optim.Adam(model.parameters(), lr=s.rl_lr)
    rows = []
    rl_outcomes: dict[str, int] = {}
    rl_ticks = 0
    t1 = time.perf_counter()
    for e in range(s.rl_episodes):
        frac = min(e / max(s.eps_decay, 1), 1.0)
        eps = s.eps_start + (s.eps_end - s.eps_start) * frac
        value = planner_cls(params, policy=ValuePolicyFile(to_numpy(model), meta))
        value.epsilon, value.rng = eps, explore
        rec = RecordingPlanner(value, params, horizons)
        logs = run_training_episode(cfg, generator, backend, s.il_episodes + e, rec)
        ep = logs[0]
        rl_outcomes[ep.outcome] = rl_outcomes.get(ep.outcome, 0) + 1
        loss = math.nan
        if ep.robots:
            for lg in logs:
                feats, y = targets(lg, s.gamma, holonomic, s.n_step, target_value)
                memory.push(feats, y)
                rl_ticks += len(y)
            loss = fit(model, opt, memory, s.train_batches, s.batch_size, rng)
        if (e + 1) % s.target_update == 0:
            target_net = to_numpy(model)
        rows.append({"episode": e, "epsilon": round(eps, 4), "outcome": ep.outcome,
                     "time": round(ep.sim_time, 2), "ticks": len(ep.robots),
                     "loss": round(loss, 6)})
        if (e + 1) % s.checkpoint_every == 0:
            save_value_policy(out / f"policy_rl{e + 1:04d}.npz", to_numpy(model), meta)
        if (e + 1) % 50 == 0:
            recent = [r["outcome"] for r in rows[-50:]]
            log(f"rl {e + 1}/{s.rl_episodes}: eps {eps:.2f}, last 50: "
                f"{recent.count('success')} success, {recent.count('collision')} collision, "
                f"{time.perf_counter() - t0:.0f} s")
    wall = time.perf_counter() - t0
    with (out / "log.csv").open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["episode", "epsilon", "outcome", "time", "ticks",
                                          "loss"])
        w.writeheader()
        w.writerows(rows)
    recorded = asdict(s)
    recorded["config"] = _portable(s.config)
    summary = {
        "settings": recorded,
        "il": {"episodes": s.il_episodes, "outcomes": outcomes, "samples": ticks,
               "gradient_steps": il_steps, "final_loss": il_loss,
               "demo_wall_s": round(il_demo_s, 1)},
        "rl": {"episodes": s.rl_episodes, "outcomes": rl_outcomes, "samples": rl_ticks,
               "gradient_steps": s.rl_episodes * s.train_batches,
               "wall_s": round(time.perf_counter() - t1, 1)},
        "wall_s": round(wall, 1),
        "hardware": f"{platform.processor() or platform.machine()}, "
                    f"{os.cpu_count()} CPUs visible, torch threads {torch.get_num_threads()}",
        "torch": torch.__version__,
    }
    (out / "summary.json").write_text(json.dumps(summary, indent=2))
    path = save_value_policy(out / "policy.npz", to_numpy(model),
                             _meta(s, kind, v_pref, holonomic, summary))
    log(f"wrote {path} ({wall:.0f} s)")
    return path


def _meta(s: TrainSettings, kind: str, v_pref: float, holonomic: bool,
          summary: dict[str, Any]) -> dict[str, Any]:
    return {
        "gamma": s.gamma, "time_step": s.time_step, "v_pref": v_pref,
        "kinematics": "holonomic" if holonomic else "unicycle", "human_radius": 0.3,
        "subgoal_horizon": s.subgoal_horizon,
        "training_horizons": [s.subgoal_horizon, *s.extra_horizons],
        "max_humans": s.max_humans,
        "action_set": {"speed_samples": 5, "rotation_samples": 16,
                       "max_rotation": math.pi / 4, "turn_in_place": not holonomic},
        "rewards": {"goal": 1.0, "collision": -0.25, "discomfort_dist": 0.2,
                    "discomfort_factor": 0.5},
        "training": summary,
    }


def main(argv: list[str] | None = None) -> None:
    """Command line: see the module docstring."""
    ap = argparse.ArgumentParser(prog="python -m arena.learn.value.train",
                                 description="Train the crowdnav / sarl value policy.")
    ap.add_argument("--policy", choices=sorted(POLICIES), default="sarl")
    ap.add_argument("-o", "--out", type=Path, required=True, help="output folder")
    ap.add_argument("--config", default=str(DEFAULT_CONFIG), help="experiment YAML")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--il-episodes", type=int, default=TrainSettings.il_episodes)
    ap.add_argument("--rl-episodes", type=int, default=TrainSettings.rl_episodes)
    ap.add_argument("--il-epochs", type=int, default=TrainSettings.il_epochs)
    ap.add_argument("--train-batches", type=int, default=TrainSettings.train_batches)
    ap.add_argument("--eps-decay", type=int, default=TrainSettings.eps_decay,
                    help="RL episodes over which ε falls from 0.5 to 0.1")
    a = ap.parse_args(argv)
    train(TrainSettings(policy=a.policy, config=a.config, seed=a.seed,
                        il_episodes=a.il_episodes, rl_episodes=a.rl_episodes,
                        il_epochs=a.il_epochs, train_batches=a.train_batches,
                        eps_decay=a.eps_decay), a.out)


if __name__ == "__main__":
    main()
