"""Train the RGB-D people detector on auto-labelled MuJoCo frames; print its held-out AP.

    python tools/train_rgbd_detector.py [--episodes 48] [--steps 160] [--epochs 30]
                                        [-o WEIGHTS.npz] [--figure PR.png] [--example FRAME.png]

Needs the 3-D extra (``arena[3d]``) and torch (``arena[train]``). Training frames: maps of
the generators :data:`TRAIN_MAPS` with 20 walking people (``pysocial``), the camera of
:data:`~arena.perception.rgbd_data.CAMERA` on a jackal at one of four mounts per episode,
every 4th step; held-out frames: maps of the generators :data:`HELD_OUT_MAPS`, never trained on.
The person-id pass labels every pixel. The network (:mod:`arena.perception.convnet`) is
trained with a pixel-wise logistic loss (people weighted 3 ×), Adam, horizontal flips; torch is
seeded, so a run on the same machine gives the same weights. The body-centre offset is fitted
on the training frames afterwards; then the held-out AP at 0.3 m and 0.5 m is printed.
"""

from __future__ import annotations

import argparse
import pickle
import time
from pathlib import Path

import numpy as np

from arena.config import load_config
from arena.perception.classifier import fit_classifier
from arena.perception.convnet import LAYERS, torch_pixelnet
from arena.perception.rgbd_data import RgbdSample, labelled_frames
from arena.perception.rgbd_detector import (
    BLOB_FEATURES,
    CHANNELS,
    CLASSIFIER,
    COLOUR,
    WEIGHTS,
    RgbdPeopleDetector,
    net_input,
)
from arena.perception.scoring import average_precision

TRAIN_MAPS = ("rosnav_indoor", "canteen", "warehouse", "outdoor")
"""Generators of the training maps (corridors, tables and chairs, shelves, trees)."""

HELD_OUT_MAPS = ("office", "rosnav_outdoor")
"""Generators never trained on (desks, separators and office chairs; square blocks)."""


def frames(map_type: str, episodes: int, steps: int, seed: int) -> list[RgbdSample]:
    """Labelled samples of ``episodes`` episodes on ``map_type`` maps."""
    cfg = load_config(None, [f"map={{type: {map_type}}}", "task.obstacles.static=3",
                             "task.obstacles.dynamic=20", "crowd.type=pysocial",
                             f"seed={seed}", "output.video=false", "sim.backend.type=mujoco"])
    return list(labelled_frames(cfg, episodes, steps))


def arrays(samples: list[RgbdSample], colour: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Inputs ``(N, C, h, w)`` and labels ``(N, 1, h, w)`` float32."""
    x = np.stack([net_input(s.depth, s.spec, s.rgb if colour else None) for s in samples])
    y = np.stack([s.mask for s in samples])[:, None].astype(np.float32)
    return x, y


def train(x: np.ndarray, y: np.ndarray, epochs: int, seed: int = 0) -> dict[str, np.ndarray]:
    """Fit the network; its weights as ``w1`` … ``b6`` arrays."""
    import torch

    torch.manual_seed(seed)
    torch.set_num_threads(2)
    net = torch_pixelnet(x.shape[1])
    opt = torch.optim.Adam(net.parameters(), lr=3e-3)
    sched = torch.optim.lr_scheduler.CosineAnnealingLR(opt, epochs)
    loss_fn = torch.nn.BCEWithLogitsLoss(pos_weight=torch.tensor(3.0))
    xt, yt = torch.from_numpy(x), torch.from_numpy(y)
    gen = torch.Generator().manual_seed(seed)
    for epoch in range(epochs):
        order = torch.randperm(len(xt), generator=gen)
        total = 0.0
        for k in range(0, len(order), 32):
            idx = order[k : k + 32]
            xb, yb = xt[idx], yt[idx]
            if epoch % 2:  # horizontal flip: the mounts look straight ahead
                xb, yb = xb.flip(3), yb.flip(3)
            opt.zero_grad()
            loss = loss_fn(net(xb), yb)
            loss.backward()
            opt.step()
            total += float(loss.detach()) * len(idx)
        sched.step()
        print(f"  epoch {epoch + 1:2d}: loss {total / len(xt):.4f}", flush=True)
    out: dict[str, np.ndarray] = {}
    for n, *_ in LAYERS:
        conv = net.convs[n]
        out[f"w{n}"] = conv.weight.detach().numpy().astype(np.float32)
        out[f"b{n}"] = conv.bias.detach().numpy().astype(np.float32)
    return out


def fit_offset(det: RgbdPeopleDetector, samples: list[RgbdSample]) -> float:
    """The body-centre offset (m): from a detection's near surface to its person's centre.

    The median, along the line of sight, over detections within 0.6 m of a visible person.
    """
    det.offset = 0.0
    along = []
    for s in samples:
        xy, _ = det.people(s.depth, det.pixel_scores(s.depth, s.spec, s.rgb), s.spec)
        cam = np.array(s.spec.mount[:2])
        for p in xy:
            d = np.hypot(*(s.people - p).T)
            j = int(np.argmin(d)) if d.size else -1
            if j >= 0 and d[j] < 0.6 and s.visible[j]:
                sight = (p - cam) / max(np.hypot(*(p - cam)), 1e-9)
                along.append(float((s.people[j] - p) @ sight))
    return float(np.median(along)) if along else 0.0


def candidate_labels(
    det: RgbdPeopleDetector, samples: list[RgbdSample]
) -> tuple[np.ndarray, np.ndarray]:
    """Features and 0/1 labels of every candidate person in the samples.

    A candidate (moved by the detector's offset) within 0.5 m of a visible person is one; near
    a hidden person only, it is left out; else it is none.
    """
    feats, labels = [], []
    for s in samples:
        xy, f = det.candidates(s.depth, det.pixel_scores(s.depth, s.spec, s.rgb), s.spec)
        if not len(xy):
            continue
        cam = np.array(s.spec.mount[:2])
        sight = (xy - cam) / np.maximum(np.hypot(*(xy - cam).T), 1e-9)[:, None]
        xy = xy + det.offset * sight
        if len(s.people):
            d = np.hypot(*(xy[:, None, :] - s.people[None, :, :]).transpose(2, 0, 1))
            near = d <= 0.5
            person = (near & s.visible[None, :]).any(axis=1)
            hidden = near.any(axis=1) & ~person
        else:
            person = hidden = np.zeros(len(xy), dtype=bool)
        feats.append(f[~hidden])
        labels.append(person[~hidden].astype(np.int64))
    return np.concatenate(feats), np.concatenate(labels)


def evaluate(det: RgbdPeopleDetector, samples: list[RgbdSample]):  # type: ignore[no-untyped-def]
    """Detections of every sample, and ``(AP@0.3, AP@0.5, curve@0.5)``."""
    found = [det.people(s.depth, det.pixel_scores(s.depth, s.spec, s.rgb), s.spec)
             for s in samples]
    people = [s.people for s in samples]
    visible = [s.visible for s in samples]
    aps = [average_precision(found, people, visible, r)[0] for r in (0.3, 0.5)]
    return found, aps, average_precision(found, people, visible, 0.5)


def main() -> None:
    """Generate, train, fit the offset, save, evaluate."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--episodes", type=int, default=48)
    ap.add_argument("--steps", type=int, default=160)
    ap.add_argument("--epochs", type=int, default=30)
    ap.add_argument("-o", "--out", type=Path, default=WEIGHTS)
    ap.add_argument("--figure", type=Path, default=None,
                    help="also draw the held-out precision-recall curve (PNG)")
    ap.add_argument("--colour", action="store_true",
                    help="add the colour channels (the shipped detector has none)")
    ap.add_argument("--cache", type=Path, default=None,
                    help="keep the generated frames in this pickle file and reuse them")
    args = ap.parse_args()
    t0 = time.time()
    if args.cache is not None and args.cache.exists():
        with args.cache.open("rb") as f:
            data, held = pickle.load(f)
    else:
        each = max(args.episodes // len(TRAIN_MAPS), 1)
        data = [s for k, m in enumerate(TRAIN_MAPS) for s in frames(m, each, args.steps, 1 + k)]
        held = [s for k, m in enumerate(HELD_OUT_MAPS)
                for s in frames(m, max(args.episodes // 4, 1), args.steps, 101 + k)]
        if args.cache is not None:
            with args.cache.open("wb") as f:
                pickle.dump((data, held), f)
    x, y = arrays(data, args.colour)
    t1 = time.time()
    print(f"{len(data)} training frames ({x.shape[2]} x {x.shape[3]}, "
          f"{y.mean():.1%} person pixels), {len(held)} held-out; {t1 - t0:.0f} s")
    weights = train(x, y, args.epochs)
    t2 = time.time()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    channels = CHANNELS + (COLOUR if args.colour else ())
    np.savez(args.out, **weights, offset=np.array(0.0), channels=np.array(channels))
    det = RgbdPeopleDetector(args.out)
    offset = fit_offset(det, data)
    det.offset = offset
    feats, labels = candidate_labels(det, data)
    clf = fit_classifier(feats, labels)
    np.savez(args.out, **weights, offset=np.array(offset), channels=np.array(channels),
             **clf.arrays(CLASSIFIER), blob_features=np.array(BLOB_FEATURES))
    print(f"candidate classifier: {len(labels)} candidates, {labels.sum()} people")
    det = RgbdPeopleDetector(args.out)
    _, aps, curve = evaluate(det, held)
    visible = sum(int(s.visible.sum()) for s in held)
    print(f"trained in {t2 - t1:.0f} s; offset {offset:.3f} m; held-out: {len(held)} frames, "
          f"{visible} visible people, AP@0.3 {aps[0]:.3f}, AP@0.5 {aps[1]:.3f}")
    if args.figure is not None:
        draw(curve, aps[1], args.figure)
    print(f"wrote {args.out} ({time.time() - t0:.0f} s in all)")


def draw(curve, ap: float, path: Path) -> None:  # type: ignore[no-untyped-def]
    """The held-out precision-recall curve at 0.5 m."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    _, recall, precision = curve
    fig, axis = plt.subplots(figsize=(4.5, 3.4), dpi=120)
    axis.plot(recall, precision, label=f"RGB-D, AP@0.5 m = {ap:.3f}")
    axis.set(xlabel="recall", ylabel="precision", xlim=(0, 1), ylim=(0, 1.02),
             title="RGB-D people detector, held-out maps")
    axis.grid(alpha=0.3)
    axis.legend(loc="lower left")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)


if __name__ == "__main__":
    main()
