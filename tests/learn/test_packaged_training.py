"""The packaged training configs (arena/learn/data/train/) load and match their shipped policies."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import arena
from arena.learn.train import load_training

DATA = Path(arena.__file__).parent / "learn" / "data"


@pytest.mark.parametrize("name", sorted(p.stem for p in (DATA / "train").glob("*.yaml")))
def test_training_config_validates(name):
    cfg, settings = load_training(DATA / "train" / f"{name}.yaml")
    assert settings.ppo.batch_size % settings.train.n_envs == 0
    assert cfg.robot == "jackal"


@pytest.mark.parametrize("name", ["rosnav_rl", "rlca"])
def test_shipped_policy_was_trained_with_its_config(name):
    """The policy file's recorded observation block is the packaged config's."""
    cfg, _ = load_training(DATA / "train" / f"{name}.yaml")
    with np.load(DATA / "policies" / f"{name}.npz") as f:
        meta = json.loads(str(f["meta"]))
    want = cfg.learning.env.observation.model_dump(mode="json")
    have = meta["observation"]
    assert {k: have[k] for k in have} == {k: want[k] for k in have}


def _strings(x):
    if isinstance(x, dict):
        for v in x.values():
            yield from _strings(v)
    elif isinstance(x, list):
        for v in x:
            yield from _strings(v)
    elif isinstance(x, str):
        yield x


@pytest.mark.parametrize("name", sorted(p.stem for p in (DATA / "policies").glob("*.npz")))
def test_shipped_policy_meta_names_no_local_folders(name):
    """A shipped file records where it came from relative to the repository, not a machine."""
    with np.load(DATA / "policies" / f"{name}.npz") as f:
        meta = json.loads(str(f["meta"]))
    assert not [s for s in _strings(meta) if Path(s).is_absolute()]
