"""Render the README gallery of every map generator (``docs/images/generators.png``).

    python tools/make_gallery.py [--seed 1]

One tile per registered generator at its default parameters, drawn by :func:`render_world`
(walls dark, placed obstacles brown).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import arena.plugins  # noqa: F401
from arena.core.rng import derive_rng
from arena.maps.generators import MAP_GENERATORS
from arena.render import render_world, save_png
from arena.scene.state import StaticWorld

OUT = Path(__file__).resolve().parent.parent / "docs" / "images" / "generators.png"
TILE = 360
COLS = 4


def tile(name: str, seed: int) -> np.ndarray:
    """One generator's map as a square tile (padded with white)."""
    result = MAP_GENERATORS.build(name).build(derive_rng(seed, "map"))
    img = render_world(StaticWorld.build(result.grid, result.obstacles), width_px=TILE, title=name)
    out = np.full((TILE, TILE, 3), 255, dtype=np.uint8)
    h = min(img.shape[0], TILE)
    out[:h] = img[:h, :TILE]
    return out


def main() -> None:
    """Write the gallery."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    tiles = [tile(n, args.seed) for n in MAP_GENERATORS.names()]
    while len(tiles) % COLS:
        tiles.append(np.full((TILE, TILE, 3), 255, dtype=np.uint8))
    rows = [np.concatenate(tiles[i : i + COLS], axis=1) for i in range(0, len(tiles), COLS)]
    gap = np.full((6, rows[0].shape[1], 3), 255, dtype=np.uint8)
    grid = np.concatenate([r for row in rows for r in (row, gap)][:-1], axis=0)
    OUT.parent.mkdir(parents=True, exist_ok=True)
    save_png(grid, OUT)
    print(f"wrote {OUT} ({len(MAP_GENERATORS.names())} generators)")


if __name__ == "__main__":
    main()
