"""The shipped rlca policy: numpy-only inference, and it drives to a goal in an open room."""

from __future__ import annotations

import subprocess
import sys

import numpy as np

from arena.config import load_config
from arena.experiment import run_experiment
from arena.learn.planners.learned import PolicyPlanner
from arena.learn.planners.rlca import RLCA_WEIGHTS, RLCAPlanner
from arena.learn.policy import NumpyPolicy
from arena.nav.local_planners import LOCAL_PLANNERS


def test_shipped_weights_are_small_conv_policies():
    assert RLCA_WEIGHTS.stat().st_size < 2_000_000
    pol = NumpyPolicy.load(RLCA_WEIGHTS)
    assert pol.meta["extractor"]["type"] == "rlca_conv"
    assert pol.shapes["lidar"][0] == 3 and set(pol.keys) == {"lidar", "goal", "velocity"}
    planner = LOCAL_PLANNERS.build({"type": "rlca"})
    assert isinstance(planner, RLCAPlanner) and isinstance(planner, PolicyPlanner)
    assert "learned" in LOCAL_PLANNERS.entry("rlca").tags


def test_shipped_policy_reaches_the_goal_in_an_open_room(tmp_path):
    cfg = load_config(None, [
        "navigation.local_planner={type: rlca}",
        "map={type: empty, width: 10, height: 10}",
        "task.obstacles.static=0", "task.obstacles.dynamic=0",
        "task.robots.min_goal_distance=5", "task.goal_tolerance_angle=null",
        "task.timeout=30", "episodes=2", "output.video=false",
    ])
    _, results = run_experiment(cfg, tmp_path)
    assert all(r.error == "" for r in results)
    assert [r.outcome for r in results].count("success") >= 1, [r.outcome for r in results]


def test_rlca_runs_without_torch_or_gymnasium():
    code = (
        "import sys\n"
        "for m in ('gymnasium', 'pettingzoo', 'torch', 'stable_baselines3'):\n"
        "    sys.modules[m] = None\n"
        "import numpy as np\n"
        "import arena.plugins\n"
        "from arena.nav.local_planners import LOCAL_PLANNERS\n"
        "p = LOCAL_PLANNERS.build({'type': 'rlca'})\n"
        "pol = p.policy\n"
        "obs = {'lidar': np.full((3, 720), 5.0), 'goal': np.array([4.0, 0.3]),\n"
        "       'velocity': np.zeros(3)}\n"
        "print(np.all(np.isfinite(pol.command(pol.act(obs)))))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120, check=False)
    assert out.returncode == 0 and out.stdout.strip() == "True", out.stderr[-2000:]


def test_velocity_part_is_the_measured_twist():
    planner = LOCAL_PLANNERS.build({"type": "rlca"})
    from arena.nav.local_planners.base import LocalObservation
    from arena.robots.presets import load_robot

    robot = load_robot("jackal")
    o = LocalObservation(
        pose=np.zeros(3), twist=np.array([0.4, 0.0, -0.2]), goal=np.array([5.0, 0.0, 0.0]),
        path=np.array([[0.0, 0.0], [5.0, 0.0]]), limits=robot.limits(),
        robot_radius=robot.radius, dt=0.1,
        scan_ranges=np.full(720, 10.0), scan_angles=np.linspace(-2.35, 2.35, 720),
    )
    obs = planner.observation(o)
    np.testing.assert_allclose(obs["velocity"], [0.4, 0.0, -0.2], rtol=1e-6)
    assert obs["lidar"].shape == (3, 720)
    cmd = planner.compute(o)
    assert cmd.shape == (3,) and np.all(np.isfinite(cmd))
