"""Seeded random generators, split deterministically by name.

One experiment seed becomes a tree of independent streams: ``derive_rng(seed, "episode", 3,
"crowd")`` always yields the same generator, in any process, whatever else was drawn before.
Names are hashed with CRC32 (stable across runs, unlike Python's ``hash``).
"""

from __future__ import annotations

import zlib
from typing import Annotated

import numpy as np
from pydantic import Field, StrictInt

Key = str | int

MAX_SEED = 2**63 - 1
"""Largest seed a config accepts: seeds are non-negative ints that fit an int64 (the libraries
that take integer seeds, and the stores that keep them, want 64-bit integers)."""

Seed = Annotated[
    StrictInt,
    Field(ge=0, le=MAX_SEED, description="a non-negative integer <= 2**63 - 1 (not a bool)"),
]
"""A pydantic field type for seeds: ``true`` or ``"3"`` is not a seed, nor is ``-1``."""


def _key_to_int(key: Key) -> int:
    if isinstance(key, bool):
        raise TypeError("rng keys must be str or int, not bool")
    if isinstance(key, int | np.integer):
        if key < 0:
            raise ValueError(f"rng keys must be non-negative, got {key}")
        return int(key)
    if isinstance(key, str):
        return zlib.crc32(key.encode("utf-8"))
    raise TypeError(f"rng keys must be str or int, got {type(key).__name__}")


def seed_sequence(seed: int, *path: Key) -> np.random.SeedSequence:
    """The :class:`numpy.random.SeedSequence` for ``seed`` and a key path."""
    if seed < 0:
        raise ValueError(f"seed must be non-negative, got {seed}")
    return np.random.SeedSequence(entropy=int(seed), spawn_key=tuple(_key_to_int(k) for k in path))


def derive_rng(seed: int, *path: Key) -> np.random.Generator:
    """An independent generator for ``seed`` and a key path (e.g. ``"episode", 3, "crowd"``)."""
    return np.random.Generator(np.random.PCG64(seed_sequence(seed, *path)))


def child_seed(seed: int, *path: Key) -> int:
    """A 63-bit integer seed derived from ``seed`` and a key path (for libraries that want ints)."""
    return int(seed_sequence(seed, *path).generate_state(1, dtype=np.uint64)[0] >> np.uint64(1))
