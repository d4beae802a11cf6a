"""Supervised fitting of the small MLPs of ``lflh`` and ``artplanner`` (needs torch).

One loop for both trainers: 10 % of the samples held out, Adam with a cosine learning-rate
schedule over the epochs, shuffled minibatches from a seeded generator, and the weights of the
epoch with the lowest held-out loss kept. Seeded: the same data and arguments on the same
machine give the same weights.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import torch
from torch import nn

Loss = Callable[..., torch.Tensor]
"""``loss(output, *targets) -> scalar``: the training objective, also the held-out score."""
EpochLog = Callable[[nn.Module, "Split", torch.Tensor, "Split"], dict[str, Any]]
"""``log(net, training split, held-out output, held-out split) -> entries`` of an epoch's log."""
Split = tuple[torch.Tensor, ...]
"""Inputs then targets of one split."""


def build_mlp(inputs: int, hidden: int, outputs: int = 2) -> nn.Sequential:
    """``inputs → hidden → hidden → outputs`` with ReLU between, no squashing at the end."""
    return nn.Sequential(nn.Linear(inputs, hidden), nn.ReLU(), nn.Linear(hidden, hidden),
                         nn.ReLU(), nn.Linear(hidden, outputs))


def fit_held_out(
    x: np.ndarray,
    targets: tuple[np.ndarray, ...],
    hidden: int,
    loss: Loss,
    *,
    outputs: int = 2,
    epochs: int,
    batch: int,
    lr: float,
    seed: int,
    log: list[dict[str, Any]],
    extra_log: EpochLog | None = None,
) -> nn.Sequential:
    """Fit :func:`build_mlp` to ``(x, targets)``; return it with the best held-out epoch.

    Args:
        x: ``(n, inputs)`` float32 inputs.
        targets: arrays with ``n`` rows each, passed to ``loss`` after the network's output.
        hidden: units per hidden layer.
        outputs: the network's output width.
        loss: the objective; its value on the held-out samples picks the epoch kept.
        epochs: passes over the training samples (the cosine schedule's length).
        batch: minibatch size.
        lr: Adam's initial learning rate.
        seed: seeds the split, the initial weights and the minibatch order.
        log: receives one entry per epoch: ``epoch``, ``val_loss`` and ``extra_log``'s entries.
        extra_log: more entries per epoch from the network, the splits and its held-out output.
    """
    torch.manual_seed(seed)
    order = np.random.default_rng(seed).permutation(len(x))
    n_val = max(1, len(x) // 10)
    val, tr = order[:n_val], order[n_val:]
    x_tr, *t_tr = (torch.from_numpy(a[tr]) for a in (x, *targets))
    x_val, *t_val = (torch.from_numpy(a[val]) for a in (x, *targets))
    net = build_mlp(x.shape[1], hidden, outputs)
    opt = torch.optim.Adam(net.parameters(), lr=lr)
    sched = torch.optim.lr_scheduler.CosineAnnealingLR(opt, epochs)
    best, best_state = float("inf"), None
    g = torch.Generator().manual_seed(seed)
    for epoch in range(epochs):
        net.train()
        for idx in torch.randperm(len(x_tr), generator=g).split(batch):
            step_loss = loss(net(x_tr[idx]), *(t[idx] for t in t_tr))
            opt.zero_grad()
            step_loss.backward()  # type: ignore[no-untyped-call]
            opt.step()
        sched.step()
        net.eval()
        with torch.no_grad():
            out = net(x_val)
            v = float(loss(out, *t_val))
            entry: dict[str, Any] = {"epoch": epoch, "val_loss": v}
            if extra_log is not None:
                entry.update(extra_log(net, (x_tr, *t_tr), out, (x_val, *t_val)))
        log.append(entry)
        if v < best:
            best, best_state = v, {k: w.clone() for k, w in net.state_dict().items()}
    assert best_state is not None
    net.load_state_dict(best_state)
    return net
