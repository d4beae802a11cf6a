"""The ``learning.env`` block: defaults, validation, key paths of errors."""

import pytest

from arena.config.loader import load_config
from arena.config.schema import ExperimentConfig
from arena.core.errors import ConfigError
from arena.learn.config import EnvConfig
from arena.learn.driver import substeps


def test_defaults_follow_arena_training_config():
    env = ExperimentConfig().learning.env
    assert env.max_steps == 500
    assert env.safety_distance == 0.5
    assert env.reward == "default"
    assert env.action.type == "discrete"
    assert env.action_period is None


def test_misspelt_key_in_yaml_names_the_key_path(tmp_path):
    path = tmp_path / "exp.yaml"
    path.write_text("learning:\n  env:\n    observaton: {lidar: true}\n")
    with pytest.raises(ConfigError) as e:
        load_config(path)
    assert e.value.path == "learning.env.observaton"
    assert "unknown key" in str(e.value)


def test_misspelt_nested_key_override():
    with pytest.raises(ConfigError) as e:
        load_config(None, ["learning.env.observation.pedestrians.kk=3"])
    assert e.value.path == "learning.env.observation.pedestrians.kk"


def test_unknown_reward_term_suggests_a_close_name():
    with pytest.raises(ConfigError) as e:
        EnvConfig(reward={"goal_reachd": {"reward": 1.0}})
    assert e.value.path == "learning.env.reward.goal_reachd"
    assert "goal_reached" in str(e.value)


def test_misspelt_reward_param_names_the_key_path():
    with pytest.raises(ConfigError) as e:
        EnvConfig(reward={"collision": {"rewrd": -1.0}})
    assert e.value.path == "learning.env.reward.collision.rewrd"


def test_ped_type_terms_take_arenas_type_key():
    env = EnvConfig(reward={"ped_type_collision": {"type": 1, "reward": -5}})
    assert env.reward == {"ped_type_collision": {"type": 1, "reward": -5}}


def test_unknown_reward_file():
    with pytest.raises(ConfigError, match="default"):
        EnvConfig(reward="no_such_file")


def test_inline_reward_and_semantic_channels_validate():
    env = EnvConfig.model_validate(
        {
            "reward": {"goal_reached": {"reward": 3}, "collision": {"_on_safe_dist_violation": 1}},
            "observation": {"semantic": {"enabled": True, "channels": ["pedestrian_type"]}},
        }
    )
    assert env.observation.semantic.channels == ("pedestrian_type",)
    with pytest.raises(ConfigError):
        load_config(None, ["learning.env.observation.semantic.channels=[pedestrian_speed]"])


def test_action_period_must_be_a_multiple_of_dt():
    assert substeps(EnvConfig(), 0.1) == 1
    assert substeps(EnvConfig(action_period=0.2), 0.1) == 2
    with pytest.raises(ConfigError) as e:
        substeps(EnvConfig(action_period=0.25), 0.1)
    assert e.value.path == "learning.env.action_period"
