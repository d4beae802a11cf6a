"""arena.learn.train.check_resume: runs made before a config option existed still resume."""

from __future__ import annotations

import json

import pytest

from arena.core.errors import ArenaError
from arena.learn.train import MANIFEST, check_resume
from arena.learn.train_config import TrainSettings
from tests.learn.helpers import small_cfg

SETTINGS = {"ppo": {"batch_size": 32, "minibatch_size": 16},
            "train": {"total_steps": 64, "n_envs": 2, "vec_env": "dummy"}}


def _run(tmp_path, config, settings):
    (tmp_path / MANIFEST).write_text(json.dumps(
        {"kind": "train", "config": config, "settings": settings, "steps_done": 32,
         "checkpoint": "checkpoints/step_32"}))
    return tmp_path


def test_missing_defaulted_keys_resume_but_changed_values_do_not(tmp_path):
    cfg = small_cfg()
    settings = TrainSettings.model_validate(SETTINGS)
    old_cfg = cfg.model_dump(mode="json")
    old_settings = settings.model_dump(mode="json")
    # an older manifest: written before these (defaulted) options existed
    del old_cfg["learning"]["env"]["observation"]["laser_stack"]
    del old_settings["ppo"]["vf_coef"]
    run = _run(tmp_path, old_cfg, old_settings)
    assert check_resume(run, cfg, settings)["steps_done"] == 32

    changed = cfg.model_copy(update={"seed": cfg.seed + 1})
    with pytest.raises(ArenaError, match=r"config key 'seed' differs"):
        check_resume(run, changed, settings)
    other = TrainSettings.model_validate({**SETTINGS, "ppo": {**SETTINGS["ppo"], "n_epochs": 7}})
    with pytest.raises(ArenaError, match=r"settings key 'ppo\.n_epochs' differs"):
        check_resume(run, cfg, other)
