r"""Train the MLP pedestrian-pedestrian potential shipped with ``deep_social_force``.

Follows the synthetic experiment of Kreiss, S. (2021) "Deep Social Force" (package
``socialforce`` 0.2.x): trajectories are generated with the analytic Helbing–Molnár potential
``V(b) = v0·exp(−b/σ)`` (``v0 = 2.1 m²/s²``, ``σ = 0.3 m``) in two-pedestrian circle-crossing
and opposing-flow scenes, and a small MLP ``V_θ(b)`` is trained so that the simulator driven by
``−∇V_θ`` predicts each next state (0.4 s later) from the current one, with an L1 loss on the
predicted positions. No real pedestrian data is used (none can be downloaded here).

Simulator used for both data generation and training (our implementation of Kreiss's
``socialforce.Simulator`` semantics): state step ``Δt = 0.4 s`` in 10 sub-steps of 0.04 s;
desired term ``(v_pref·e − v)/τ`` with ``τ = 0.5 s`` and ``v_pref`` the initial speed;
pairwise force ``−V'(b)·∂b/∂r_ab`` with Helbing–Molnár's semi-minor axis ``b`` (``Δt = 0.4 s``)
weighted by a 200° field of view (0.5 outside); speed capped at ``1.3·v_pref``. We integrate
with semi-implicit Euler (Kreiss: a leap-frog variant); the same integrator generates the data
and trains the model, so the fitted potential does not depend on that choice.

Needs ``torch`` (CPU is enough): ``.venv/bin/pip install torch``. Usage::

    .venv/bin/python tools/train_deep_social_force.py \\
        --out arena/crowd/models/weights/deep_social_force.npz

The output ``.npz`` holds ``w1, b1, w2, b2`` (float64; ``V(b) = softplus(w2·softplus(w1·b + b1)
+ b2)``) and ``metadata`` (a JSON string: architecture, command, steps, wall time, final loss,
data description, force error against the analytic potential).
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import shlex
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch

DELTA_T = 0.4  # s, state step of Kreiss's simulator and Δt in b
OVERSAMPLING = 10  # sub-steps per state step
TAU = 0.5  # s, relaxation time
MAX_SPEED_MULTIPLIER = 1.3  # speed cap relative to the preferred speed (Kreiss)
COS_HALF_FOV = math.cos(math.radians(100.0))  # 200° field of view
OUT_OF_VIEW = 0.5  # weight of interactions outside the field of view
V0, SIGMA = 2.1, 0.3  # m²/s², m: the analytic generator potential


@dataclass
class Scenes:
    """A batch of scenes with the same number of pedestrians.

    Attributes:
        pos: ``(S, T, N, 2)`` positions (m) at every state step.
        vel: ``(S, T, N, 2)`` velocities (m/s).
        dest: ``(S, N, 2)`` destinations (m).
        pref: ``(S, N)`` preferred speeds (m/s).
    """

    pos: torch.Tensor
    vel: torch.Tensor
    dest: torch.Tensor
    pref: torch.Tensor


class MLPPotential(torch.nn.Module):
    """``V(b) = softplus(w2·softplus(w1·b + b1) + b2)``, one hidden layer (Kreiss's MLP)."""

    def __init__(self, hidden: int) -> None:
        super().__init__()
        self.lin1 = torch.nn.Linear(1, hidden)
        self.lin2 = torch.nn.Linear(hidden, 1)

    def value(self, b: torch.Tensor) -> torch.Tensor:
        """Potential (m²/s²) at ``b`` (any shape, m)."""
        z1 = b.unsqueeze(-1) * self.lin1.weight[:, 0] + self.lin1.bias
        z2 = torch.nn.functional.softplus(z1) @ self.lin2.weight[0] + self.lin2.bias[0]
        return torch.nn.functional.softplus(z2)

    def dvdb(self, b: torch.Tensor) -> torch.Tensor:
        """``dV/db`` (m/s²) written out, differentiable in the weights (as the numpy runtime)."""
        w1, c1 = self.lin1.weight[:, 0], self.lin1.bias
        w2, c2 = self.lin2.weight[0], self.lin2.bias[0]
        b = torch.clamp(b, max=100.0)
        z1 = b.unsqueeze(-1) * w1 + c1
        z2 = torch.nn.functional.softplus(z1) @ w2 + c2
        return torch.sigmoid(z2) * ((torch.sigmoid(z1) * w1) @ w2)


def analytic_dvdb(b: torch.Tensor) -> torch.Tensor:
    """``dV/db`` of the generator ``V = v0·exp(−b/σ)``."""
    return -V0 / SIGMA * torch.exp(-b / SIGMA)


def pair_forces(pos, vel, dest, dvdb) -> torch.Tensor:
    """Sum over ``b ≠ a`` of ``−V'(b_ab)·∂b/∂r_ab`` with field-of-view weights.

    Args:
        pos: ``(B, N, 2)`` positions (m).
        vel: ``(B, N, 2)`` velocities (m/s).
        dest: ``(B, N, 2)`` destinations (m).
        dvdb: callable ``b -> dV/db``.

    Returns:
        ``(B, N, 2)`` accelerations (m/s²).
    """
    n = pos.shape[1]
    e = desired_directions(pos, dest)
    r = pos[:, :, None, :] - pos[:, None, :, :]  # r_ab = x_a − x_b
    eye = torch.eye(n, dtype=torch.bool)
    # Keep the diagonal away from zero so norms stay differentiable; masked out below.
    r = torch.where(eye[None, :, :, None], torch.ones_like(r), r)
    s = DELTA_T * torch.linalg.norm(vel, dim=-1)[:, None, :]  # (B, 1, N): Δt·|v_b|
    u = r - s[..., None] * e[:, None, :, :]
    rn = torch.linalg.norm(r, dim=-1)
    un = torch.linalg.norm(u, dim=-1).clamp(min=1e-12)
    q = (rn + un) ** 2 - s**2
    ok = q > 1e-8
    b = 0.5 * torch.sqrt(q.clamp(min=1e-8))
    grad = ((rn + un) / (4.0 * b))[..., None] * (r / rn[..., None] + u / un[..., None])
    f = -dvdb(b)[..., None] * grad
    in_view = torch.einsum("zaj,zabj->zab", e, -r) > rn * COS_HALF_FOV
    w = torch.where(in_view, 1.0, OUT_OF_VIEW)
    keep = (~eye)[None] & ok
    f = torch.where(keep[..., None], f * w[..., None], torch.zeros_like(f))
    return f.sum(dim=2)


def desired_directions(pos: torch.Tensor, dest: torch.Tensor) -> torch.Tensor:
    """Unit vectors toward the destinations, zero at the destination."""
    d = dest - pos
    norm = torch.linalg.norm(d, dim=-1, keepdim=True)
    return torch.where(norm > 1e-9, d / norm.clamp(min=1e-9), torch.zeros_like(d))


def state_step(pos, vel, dest, pref, dvdb):
    """One state step (``Δt = 0.4 s``) in ``OVERSAMPLING`` semi-implicit Euler sub-steps."""
    h = DELTA_T / OVERSAMPLING
    vmax = MAX_SPEED_MULTIPLIER * pref
    for _ in range(OVERSAMPLING):
        e = desired_directions(pos, dest)
        acc = (pref[..., None] * e - vel) / TAU + pair_forces(pos, vel, dest, dvdb)
        vel = vel + h * acc
        speed = torch.linalg.norm(vel, dim=-1)
        vel = vel * torch.clamp(vmax / speed.clamp(min=1e-12), max=1.0)[..., None]
        pos = pos + h * vel
    return pos, vel


def rotation(theta: np.ndarray) -> np.ndarray:
    """``(S, 2, 2)`` rotation matrices."""
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)


def generate(n_circle: int, n_opposing: int, steps: int, rng: np.random.Generator) -> Scenes:
    """Two-pedestrian scenes (Kreiss's ``Circle`` and ``ParallelAvoidance``), analytic ``V``.

    Circle crossing: pedestrian 0 walks from (−5, 0) to (6, 0) at 0.7–1.1 m/s; pedestrian 1 is
    the same start and goal rotated by θ ∈ [0.25, 2π − 0.25] rad about the origin, at 0.7–1.1
    times that speed. Opposing flow: pedestrian 0 as above; pedestrian 1 walks from (7, y) to
    (−7, y), y ~ N(0, 0.75²) m, at 1.2–1.4 m/s.
    """
    # Circle crossing.
    sp0 = rng.uniform(0.7, 1.1, n_circle)
    theta = rng.uniform(0.25, 2 * np.pi - 0.25, n_circle)
    rot = rotation(theta)
    p0 = np.array([-5.0, 0.0])
    g0 = np.array([6.0, 0.0])
    sp1 = sp0 * rng.uniform(0.7, 1.1, n_circle)
    pos_c = np.stack([np.broadcast_to(p0, (n_circle, 2)), rot @ p0], axis=1)
    dest_c = np.stack([np.broadcast_to(g0, (n_circle, 2)), rot @ g0], axis=1)
    dir_c = np.stack([np.broadcast_to([1.0, 0.0], (n_circle, 2)), rot @ np.array([1.0, 0.0])], 1)
    vel_c = dir_c * np.stack([sp0, sp1], axis=1)[..., None]
    # Opposing flow.
    sp0 = rng.uniform(0.7, 1.1, n_opposing)
    y = rng.normal(0.0, 0.75, n_opposing)
    sp1 = rng.uniform(1.2, 1.4, n_opposing)
    pos_o = np.stack(
        [np.broadcast_to(p0, (n_opposing, 2)), np.stack([np.full_like(y, 7.0), y], 1)], 1
    )
    dest_o = np.stack(
        [np.broadcast_to(g0, (n_opposing, 2)), np.stack([np.full_like(y, -7.0), y], 1)], 1
    )
    vel_o = np.stack([np.stack([sp0, 0 * sp0], 1), np.stack([-sp1, 0 * sp1], 1)], 1)
    pos = torch.tensor(np.concatenate([pos_c, pos_o]))
    vel = torch.tensor(np.concatenate([vel_c, vel_o]))
    dest = torch.tensor(np.concatenate([dest_c, dest_o]))
    pref = torch.linalg.norm(vel, dim=-1)
    traj_p, traj_v = [pos], [vel]
    with torch.no_grad():
        for _ in range(steps):
            pos, vel = state_step(pos, vel, dest, pref, analytic_dvdb)
            traj_p.append(pos)
            traj_v.append(vel)
    return Scenes(torch.stack(traj_p, 1), torch.stack(traj_v, 1), dest, pref)


def experiences(scenes: Scenes, radius: float) -> tuple[torch.Tensor, ...]:
    """Consecutive state pairs in which the two pedestrians are within ``radius`` (m)."""
    p, v = scenes.pos, scenes.vel
    s, t = p.shape[0], p.shape[1] - 1
    d0 = torch.linalg.norm(p[:, :-1, 0] - p[:, :-1, 1], dim=-1)
    d1 = torch.linalg.norm(p[:, 1:, 0] - p[:, 1:, 1], dim=-1)
    keep = ((d0 < radius) | (d1 < radius)).reshape(-1)
    flat = lambda x: x.reshape(s * t, *x.shape[2:])[keep]  # noqa: E731
    dest = scenes.dest[:, None].expand(s, t, -1, -1)
    pref = scenes.pref[:, None].expand(s, t, -1)
    return flat(p[:, :-1]), flat(v[:, :-1]), flat(dest), flat(pref), flat(p[:, 1:])


def main(argv: list[str] | None = None) -> None:
    """Generate data, train, report, save."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("deep_social_force.npz"))
    ap.add_argument("--hidden", type=int, default=16, help="hidden units")
    ap.add_argument("--circle", type=int, default=300, help="circle-crossing scenes")
    ap.add_argument("--opposing", type=int, default=300, help="opposing-flow scenes")
    ap.add_argument("--steps-per-scene", type=int, default=21, help="state steps of 0.4 s")
    ap.add_argument("--radius", type=float, default=4.0, help="m, keep interacting pairs")
    ap.add_argument("--train-steps", type=int, default=1500, help="full-batch Adam steps")
    ap.add_argument("--lr", type=float, default=0.02)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)

    torch.manual_seed(args.seed)
    torch.set_default_dtype(torch.float64)
    rng = np.random.default_rng(args.seed)
    t0 = time.perf_counter()
    scenes = generate(args.circle, args.opposing, args.steps_per_scene, rng)
    x_p, x_v, x_d, x_s, y_p = experiences(scenes, args.radius)
    t_data = time.perf_counter() - t0
    print(f"data: {scenes.pos.shape[0]} scenes, {x_p.shape[0]} experiences ({t_data:.1f} s)")

    model = MLPPotential(args.hidden)
    opt = torch.optim.Adam(model.parameters(), lr=args.lr)
    sched = torch.optim.lr_scheduler.CosineAnnealingLR(opt, args.train_steps, eta_min=args.lr / 50)
    t1 = time.perf_counter()
    loss_value = math.nan
    for step in range(args.train_steps):
        pred, _ = state_step(x_p, x_v, x_d, x_s, model.dvdb)
        loss = torch.nn.functional.l1_loss(pred, y_p)
        opt.zero_grad()
        loss.backward()
        opt.step()
        sched.step()
        loss_value = float(loss.item())
        if step % 100 == 0 or step == args.train_steps - 1:
            print(f"step {step:5d}  L1 {loss_value:.3e} m")
    t_train = time.perf_counter() - t1
    with torch.no_grad():
        pred, _ = state_step(x_p, x_v, x_d, x_s, model.dvdb)
        final = float(torch.nn.functional.l1_loss(pred, y_p).item())
        ref, _ = state_step(x_p, x_v, x_d, x_s, analytic_dvdb)
        floor = float(torch.nn.functional.l1_loss(ref, y_p).item())
        grid = torch.linspace(0.1, 3.0, 291)
        err = (model.dvdb(grid) - analytic_dvdb(grid)).abs()
        b_all = _b_values(x_p, x_v, x_d)
    print(f"final L1 {final:.3e} m (analytic potential: {floor:.3e} m); train {t_train:.1f} s")
    fit = {f"{b:.1f}": float(err[round((b - 0.1) * 100)]) for b in (0.3, 0.5, 0.8, 1.0, 1.5, 2.0)}
    print("|ΔF| (m/s²) at b:", fit)

    meta = {
        "model": "Deep Social Force ped-ped potential V(b) (Kreiss 2021), one hidden layer",
        "architecture": f"V(b) = softplus(w2 · softplus(w1·b + b1) + b2), 1-{args.hidden}-1",
        "input": "b: Helbing–Molnár semi-minor axis (m), delta_t = 0.4 s; clamped at 100 m",
        "output": "V in m²/s² (per unit mass); force = −dV/db · ∂b/∂r_ab",
        "command": " ".join(shlex.quote(a) for a in [sys.executable, *sys.argv]),
        "seed": args.seed,
        "train_steps": args.train_steps,
        "optimizer": f"Adam lr {args.lr}, cosine decay to {args.lr / 50}, full batch",
        "loss": "L1 on positions predicted one state step (0.4 s, 10 sub-steps) ahead (m)",
        "final_loss_m": final,
        "analytic_generator_loss_m": floor,
        "wall_time_s": round(t_data + t_train, 2),
        "data": (
            "synthetic only: trajectories simulated with the analytic Helbing–Molnár potential "
            f"V(b) = {V0}·exp(−b/{SIGMA}) (m²/s², m), tau {TAU} s, 200° field of view "
            f"(0.5 outside), speed cap {MAX_SPEED_MULTIPLIER}·v_pref; {args.circle} two-person "
            f"circle-crossing scenes and {args.opposing} two-person opposing-flow scenes "
            f"(Kreiss's Circle and ParallelAvoidance), {args.steps_per_scene} steps of 0.4 s "
            f"each; {x_p.shape[0]} transitions kept with the pair closer than {args.radius} m. "
            "No real pedestrian data."
        ),
        "b_seen_m": {
            "min": float(b_all.min()),
            "p01": float(np.quantile(b_all, 0.01)),
            "median": float(np.median(b_all)),
            "max": float(b_all.max()),
        },
        "force_abs_error_vs_generator_m_s2": fit,
        "force_max_abs_error_b_0.1_3": float(err.max()),
        "torch": torch.__version__,
        "python": platform.python_version(),
        "date": time.strftime("%Y-%m-%d"),
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(
        args.out,
        w1=model.lin1.weight.detach().numpy()[:, 0].astype(np.float64),
        b1=model.lin1.bias.detach().numpy().astype(np.float64),
        w2=model.lin2.weight.detach().numpy()[0].astype(np.float64),
        b2=np.float64(model.lin2.bias.detach().numpy()[0]),
        metadata=np.array(json.dumps(meta, ensure_ascii=False)),
    )
    print(f"wrote {args.out} ({args.out.stat().st_size} bytes)")


def _b_values(pos, vel, dest) -> np.ndarray:
    """Every b_ab (a ≠ b) of the training inputs, for the metadata."""
    e = desired_directions(pos, dest)
    r = pos[:, :, None, :] - pos[:, None, :, :]
    s = DELTA_T * torch.linalg.norm(vel, dim=-1)[:, None, :]
    u = r - s[..., None] * e[:, None, :, :]
    q = (torch.linalg.norm(r, dim=-1) + torch.linalg.norm(u, dim=-1)) ** 2 - s**2
    b = 0.5 * torch.sqrt(q.clamp(min=1e-8))
    off = ~torch.eye(pos.shape[1], dtype=torch.bool)
    return b[:, off].reshape(-1).numpy()


if __name__ == "__main__":
    main()
