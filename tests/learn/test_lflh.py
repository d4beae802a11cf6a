"""LfLH: hallucinated obstacles, rendered scans, numpy = torch, the safety check, the planner."""

from __future__ import annotations

import math

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from arena.config import load_config  # noqa: E402
from arena.core.errors import ConfigError  # noqa: E402
from arena.experiment import run_experiment  # noqa: E402
from arena.learn.applr.env import TRAIN_CONFIG  # noqa: E402
from arena.learn.fit_mlp import build_mlp  # noqa: E402
from arena.learn.lflh.actor import LflhActor, save_actor  # noqa: E402
from arena.learn.lflh.dataset import JACKAL_LASER, DataParams, make_dataset  # noqa: E402
from arena.learn.lflh.features import FeatureParams  # noqa: E402
from arena.learn.lflh.hallucinate import HallucinationParams, hallucinate  # noqa: E402
from arena.learn.lflh.motions import MotionParams, sample_motion  # noqa: E402
from arena.learn.lflh.safety import SafetyParams, safe_command, unsafe  # noqa: E402
from arena.learn.planners.lflh import LFLH_WEIGHTS, LflhPlanner  # noqa: E402
from arena.maps.grid import OCCUPIED  # noqa: E402
from arena.nav.local_planners import LOCAL_PLANNERS  # noqa: E402
from arena.sensors.lidar2d import Lidar2D  # noqa: E402


def _occupied_centres(grid) -> np.ndarray:
    rows, cols = np.nonzero(grid.data == OCCUPIED)
    res, (ox, oy) = grid.resolution, grid.origin
    return np.stack([ox + (cols + 0.5) * res, oy + (rows + 0.5) * res], axis=-1)


def _dense_path_distance(points: np.ndarray, poses: np.ndarray) -> np.ndarray:
    # the exact rollout at its own 5 cm steps, not the strided path the hallucination uses
    xy = poses[:, :2]
    return np.min(np.linalg.norm(points[:, None] - xy[None], axis=-1), axis=1)


@pytest.mark.parametrize("seed", range(8))
def test_hallucinated_obstacles_never_touch_the_swept_footprint(seed: int) -> None:
    rng = np.random.default_rng(seed)
    hp = HallucinationParams(open_side_probability=0.0)
    motion = sample_motion(MotionParams(), rng)
    obst = hallucinate(motion.poses, float(np.mean(motion.commands[:, 0])), hp, rng)
    cells = _occupied_centres(obst.grid)
    assert len(cells) > 0
    # a cell's nearest corner is half a diagonal nearer than its centre
    gap = _dense_path_distance(cells, motion.poses) - hp.resolution * math.sqrt(0.5)
    assert gap.min() > hp.robot_radius
    # and the walls hug the motion: some wall is within the sampled clearance + a cell or two
    assert gap.min() < hp.robot_radius + obst.clearance.max() + 3 * hp.resolution


def test_the_rendered_scan_sees_the_hallucinated_walls() -> None:
    rng = np.random.default_rng(3)
    hp = HallucinationParams(gap_probability=0.0, open_side_probability=0.0)
    motion = sample_motion(MotionParams(), rng)
    obst = hallucinate(motion.poses, 0.5, hp, rng)
    lidar = Lidar2D(JACKAL_LASER)
    lidar.bind(obst.grid)
    ranges = lidar.scan(np.zeros(3))
    hit = ranges < JACKAL_LASER.range_max
    assert hit.mean() > 0.3
    angles = np.linspace(JACKAL_LASER.angle_min, JACKAL_LASER.angle_max, JACKAL_LASER.num_beams)
    ends = np.stack([ranges * np.cos(angles), ranges * np.sin(angles)], axis=-1)[hit]
    cells = _occupied_centres(obst.grid)
    # every return lies on the boundary of an occupied cell
    nearest = np.min(np.linalg.norm(ends[:, None] - cells[None], axis=-1), axis=1)
    assert nearest.max() <= hp.resolution * math.sqrt(0.5) + 1e-6
    # and none closer than the walls are to the robot
    assert ranges.min() > hp.robot_radius


def test_dataset_is_deterministic_and_labels_are_the_first_command() -> None:
    x1, y1 = make_dataset(6, DataParams(), seed=5)
    x2, y2 = make_dataset(6, DataParams(), seed=5)
    assert np.array_equal(x1, x2) and np.array_equal(y1, y2)
    assert x1.shape == (6, FeatureParams().size) and y1.shape == (6, 2)
    assert np.all((x1[:, :-2] >= 0) & (x1[:, :-2] <= 1))
    assert np.all(y1[:, 0] >= MotionParams().v_min)


def _torch_policy(path, seed: int = 0):
    torch.manual_seed(seed)
    fp = FeatureParams()
    net = build_mlp(fp.size, 32)
    layers = [m for m in net if isinstance(m, torch.nn.Linear)]
    meta = {"features": fp.model_dump(), "laser": JACKAL_LASER.model_dump(),
            "out_scale": [1.5, 2.0], "training": {}}
    save_actor(path, [m.weight.detach().numpy() for m in layers],
               [m.bias.detach().numpy() for m in layers], meta)
    return net


def test_numpy_inference_equals_torch(tmp_path) -> None:
    net = _torch_policy(tmp_path / "p.npz")
    actor = LflhActor.load(tmp_path / "p.npz")
    x = np.random.default_rng(0).random((64, FeatureParams().size)).astype(np.float32)
    with torch.no_grad():
        ref = net(torch.from_numpy(x)).numpy() * np.array([1.5, 2.0])
    np.testing.assert_allclose(actor.act(x), ref, rtol=1e-5, atol=1e-5)


def test_missing_or_foreign_weights_fail_with_one_line(tmp_path) -> None:
    with pytest.raises(ConfigError, match="no LfLH policy file") as e:
        LflhPlanner(LflhPlanner.Params(weights=str(tmp_path / "none.npz")))
    assert "\n" not in str(e.value)
    np.savez(tmp_path / "other.npz", w0=np.zeros((2, 2)))
    with pytest.raises(ConfigError, match="not an LfLH policy file"):
        LflhActor.load(tmp_path / "other.npz")


def _wall_scan(distance: float) -> np.ndarray:
    """Returns of a wall ``distance`` m ahead, 4 m wide, in the robot frame."""
    y = np.linspace(-2.0, 2.0, 161)
    return np.stack([np.full_like(y, distance), y], axis=-1)


def test_safety_check_refuses_a_command_into_a_wall() -> None:
    sp = SafetyParams()
    wall = _wall_scan(0.8)
    assert unsafe(np.array([[1.0, 0.0]]), wall, 0.267, sp)[0]
    assert not unsafe(np.array([[1.0, 0.0]]), _wall_scan(2.0), 0.267, sp)[0]
    cmd, why = safe_command(np.array([1.0, 0.0]), np.array([3.0, 0.0]), wall, 0.267, 1.5, 2.0, sp)
    assert why != "policy"
    assert not unsafe(cmd[None], wall, 0.267, sp)[0]
    # boxed in on all sides: only turning on the spot is left
    ring = 0.35 * np.stack([np.cos(np.linspace(0, 2 * np.pi, 90)),
                            np.sin(np.linspace(0, 2 * np.pi, 90))], axis=-1)
    cmd, why = safe_command(np.array([1.0, 0.0]), np.array([0.0, 2.0]), ring, 0.267, 1.5, 2.0, sp)
    assert why == "turn" and cmd[0] == 0.0 and cmd[1] > 0


def test_shipped_policy_is_small_and_records_its_training() -> None:
    assert LFLH_WEIGHTS.stat().st_size < 5_000_000
    training = LflhActor.load(LFLH_WEIGHTS).meta["training"]
    assert {"samples", "wall_time_s", "hardware", "command"} <= set(training)
    assert "learned" in LOCAL_PLANNERS.entry("lflh").tags


def test_shipped_policy_reaches_the_goal_of_a_seeded_barn_episode(tmp_path) -> None:
    cfg = load_config(TRAIN_CONFIG, ["seed=77", "navigation.local_planner={type: lflh}"])
    _, results = run_experiment(cfg, tmp_path)
    assert results[0].error == ""
    assert results[0].outcome == "success", results[0].outcome
