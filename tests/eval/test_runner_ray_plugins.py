"""``arena bench --backend ray --plugin FILE``: the ray workers import the plugin too."""

from __future__ import annotations

import sys
import textwrap

import pytest
import ray  # a test extra: its absence must fail, not skip

from arena import cli

PLANNER = '''
"""A user's planner for the ray test."""
import math

import numpy as np

from arena.nav import LOCAL_PLANNERS
from arena.nav.local_planners.base import limit_command


@LOCAL_PLANNERS.register("beeline_ray_e")
class Beeline:
    """Turn to the goal, then drive straight at it."""

    supports = frozenset({"diff_drive"})

    def reset(self):
        pass

    def compute(self, obs):
        x, y, th = obs.pose
        g = obs.goal_pose
        err = math.atan2(math.sin(math.atan2(g.y - y, g.x - x) - th),
                         math.cos(math.atan2(g.y - y, g.x - x) - th))
        v = 0.8 * max(math.cos(err), 0.0)
        return limit_command(np.array([v, 0.0, 2.0 * err]), obs.twist, obs.limits, obs.dt)
'''


def test_bench_on_ray_with_a_plugin_planner(monkeypatch, capsys, tmp_path):
    import arena.plugins as plugins
    from arena.eval.store import load_results
    from arena.nav import LOCAL_PLANNERS

    if ray.is_initialized():  # a Ray another test left up lacks the plugin: the bench starts
        ray.shutdown()        # its own, which passes ARENA_PLUGINS on to the workers
    monkeypatch.delenv(plugins.PLUGINS_ENV, raising=False)
    monkeypatch.setenv("RAY_USAGE_STATS_ENABLED", "0")
    path = tmp_path / "ray_planner.py"
    path.write_text(PLANNER)
    suite = tmp_path / "suite.yaml"
    suite.write_text(textwrap.dedent("""
        stages:
          - name: room
            episodes: 2
            robot: jackal
            map: {type: empty, width: 8, height: 6}
            timeout: 30
            config:
              RANDOM:
                static: {min: 0, max: 0}
                dynamic: {min: 1, max: 1}
    """))
    contest = tmp_path / "contest.yaml"
    contest.write_text("contestants:\n  - {name: mine, local_planner: beeline_ray_e}\n")
    monkeypatch.setattr(sys, "argv", [
        "arena", "bench", str(suite), "--contest", str(contest), "-j", "2", "--backend", "ray",
        "--plugin", str(path), "--no-progress", "-o", str(tmp_path / "run"),
    ])
    try:
        with pytest.raises(SystemExit) as done:
            cli.main()
    finally:
        LOCAL_PLANNERS._entries.pop("beeline_ray_e", None)
    assert done.value.code in (0, None), capsys.readouterr().err
    rows = load_results(tmp_path / "run").to_pylist()
    assert [r["outcome"] for r in rows] == ["success", "success"], [r["error"] for r in rows]
