"""The shipped rosnav_rl policy drives the navigation stack with numpy alone (no torch)."""

from __future__ import annotations

from arena.config import load_config
from arena.experiment import run_experiment


def test_shipped_policy_reaches_goals_among_people(tmp_path):
    cfg = load_config(None, [
        "navigation.local_planner={type: rosnav_rl}",
        "map={type: empty, width: 12, height: 12}",
        "task.obstacles.static=2", "task.obstacles.dynamic=4",
        "task.robots.min_goal_distance=6", "task.goal_tolerance_angle=null",
        "task.timeout=40", "episodes=3", "output.video=false",
    ])
    _, results = run_experiment(cfg, tmp_path)
    assert [r.outcome for r in results].count("success") >= 2, [r.outcome for r in results]
    assert all(r.error == "" for r in results)


def test_core_runs_without_the_learning_extras():
    """``pip install arena`` has no gymnasium/torch: the CLI, configs and rosnav_rl still work."""
    import subprocess
    import sys

    code = (
        "import sys\n"
        "for m in ('gymnasium', 'pettingzoo', 'torch', 'stable_baselines3'):\n"
        "    sys.modules[m] = None\n"
        "import arena.cli, arena.plugins\n"
        "from arena.config import load_config\n"
        "from arena.nav.local_planners import LOCAL_PLANNERS\n"
        "load_config(None, [])\n"
        "LOCAL_PLANNERS.build({'type': 'rosnav_rl'})\n"
        "print('ok')\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0 and out.stdout.strip() == "ok", out.stderr[-2000:]
