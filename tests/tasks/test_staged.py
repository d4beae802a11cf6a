"""``modules.staged``: stage settings per episode, stage changes, auto mode."""

import pytest

from arena.core.errors import ConfigError
from arena.robots.presets import load_robot
from arena.tasks.config import TaskConfig
from arena.tasks.generator import TaskGenerator
from arena.tasks.modules.staged import Staged

CURRICULUM = """\
stages:
  - {static: 1, dynamic: 2, goal_radius: 0.8}
  - {static: 0, dynamic: 3, map_generator: {algorithm: barn, algorithm_config: {fill_pct: 0.05}}}
  - {static: 2, dynamic: 1, goal_radius: 0.4,
     map_generator: {algorithm: rosnav, algorithm_config: {map_type: outdoor, obstacle_num: 4}}}
upper_threshold: 0.8
lower_threshold: 0.5
window: 4
"""


@pytest.fixture
def curriculum(tmp_path):
    f = tmp_path / "c.yaml"
    f.write_text(CURRICULUM)
    return str(f)


def _gen(curriculum, **params):
    cfg = TaskConfig.model_validate(
        {"obstacles": {"type": "random", "static": 5, "dynamic": 6},
         "modules": [{"type": "staged", "curriculum": curriculum, **params}]}
    )
    return TaskGenerator(cfg, map_spec={"type": "empty", "width": 16.0, "height": 12.0},
                         robots=[load_robot("jackal")], seed=3)


def test_counts_goal_radius_and_map_per_stage(curriculum):
    gen = _gen(curriculum)
    staged = gen.modules[0]
    ep = gen.episode(0)
    assert (len(ep.obstacles), len(ep.agents), ep.goal_radius) == (1, 2, 0.8)
    assert ep.label == "stage 0" and ep.map_name == "empty"
    staged.promote()
    ep = gen.episode(1)
    assert (len(ep.obstacles), len(ep.agents), ep.goal_radius) == (0, 3, 0.3)
    assert ep.map_name == "barn"
    assert ep.grid.size_m == pytest.approx((16.0, 12.0))  # the run's map size is kept
    staged.promote()
    ep = gen.episode(2)
    assert ep.map_name == "rosnav_outdoor" and len(ep.agents) == 1 and ep.goal_radius == 0.4
    assert len([o for o in ep.obstacles if o.name.startswith("S_")]) == 2


def test_promote_demote_clamp_and_report(curriculum):
    s = Staged(Staged.Params(curriculum=curriculum, index=2))
    assert s.stage == 2 and s.is_last
    assert s.promote() is False and s.stage == 2
    assert s.report(0.5) == -1 and s.stage == 1
    assert s.report(0.7) == 0 and s.stage == 1
    assert s.report(0.8) == 1 and s.stage == 2
    assert s.demote() and s.demote() and not s.demote()
    assert s.stage == 0
    assert s.report(0.1) == 0
    with pytest.raises(ValueError):
        s.report(1.5)


def test_auto_mode_over_window(curriculum):
    s = Staged(Staged.Params(curriculum=curriculum, auto=True))
    for i in range(3):
        s.on_episode_end(i, "success")
    assert s.stage == 0  # window (4) not full yet
    s.on_episode_end(3, "success")
    assert s.stage == 1
    for i, out in enumerate(["success", "collision", "timeout", "success"]):
        s.on_episode_end(4 + i, out)
    assert s.stage == 0  # 2/4 = 0.5 <= lower_threshold 0.5: demoted
    for i, out in enumerate(["success", "success", "timeout", "success"]):
        s.on_episode_end(8 + i, out)
    assert s.stage == 0  # 0.75: between the thresholds, stays


def test_manual_mode_ignores_outcomes_and_threshold_override(curriculum):
    s = Staged(Staged.Params(curriculum=curriculum, window=2, upper_threshold=1.0))
    for i in range(5):
        s.on_episode_end(i, "success")
    assert s.stage == 0
    a = Staged(Staged.Params(curriculum=curriculum, auto=True, window=2, upper_threshold=1.0))
    a.on_episode_end(0, "success")
    a.on_episode_end(1, "timeout")
    assert a.stage == 0
    a.on_episode_end(2, "success")
    a.on_episode_end(3, "success")
    assert a.stage == 1


def test_bad_start_index(curriculum):
    with pytest.raises(ConfigError, match="3 stages"):
        Staged(Staged.Params(curriculum=curriculum, index=5))


def test_default_curriculum_runs():
    gen = _gen("default")
    ep = gen.episode(0)
    assert ep.map_name == "barn" and len(ep.agents) == 12 and ep.goal_radius == 1.0
