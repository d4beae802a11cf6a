"""The 3-D world compiled by MuJoCo: obstacle models, robots, people, stepping and rendering."""

from __future__ import annotations

import numpy as np
import pytest

from arena.core.errors import ConfigError
from arena.maps.grid import OccupancyGrid
from arena.maps.obstacles import CircleFootprint, make_obstacle, obstacle_models
from arena.robots.presets import load_robot
from arena.scene.episode import AgentSpawn
from arena.sim.mujoco.figures import pose_figures
from arena.sim.mujoco.mjcf import compile_model, person_ids_by_geom
from arena.sim.mujoco.world import build_world, robot_body
from tests.mujoco_kit import require_mujoco, unavailable

mujoco = require_mujoco()

GEOM_BOX = {"box": lambda s: s, "cylinder": lambda s: (s[0], s[0], s[1]),
            "sphere": lambda s: (s[0],) * 3, "ellipsoid": lambda s: s}


def geom_bounds(model, data, prefix: str) -> tuple[np.ndarray, np.ndarray]:
    """World-frame bounding box of the geoms named ``prefix...`` (axis-aligned bodies)."""
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    for g in range(model.ngeom):
        if not model.geom(g).name.startswith(prefix):
            continue
        kind = mujoco.mjtGeom(model.geom_type[g]).name.removeprefix("mjGEOM_").lower()
        half = np.array(GEOM_BOX[kind](model.geom_size[g]))
        lo = np.minimum(lo, data.geom_xpos[g] - half)
        hi = np.maximum(hi, data.geom_xpos[g] + half)
    return lo, hi


def small_grid() -> OccupancyGrid:
    return OccupancyGrid.empty(8.0, 6.0, 0.1)


@pytest.mark.parametrize("name", sorted(obstacle_models()))
def test_obstacle_model_fills_its_footprint_and_height(name: str) -> None:
    m = obstacle_models()[name]
    scene = build_world(small_grid(), [make_obstacle("o", name, [4.0, 3.0, 0.0])])
    model = compile_model(scene)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    lo, hi = geom_bounds(model, data, "obstacle/o/")
    assert model.body("obstacle/o").id > 0
    fp = m.polygon()
    if isinstance(m.footprint, CircleFootprint):
        ext = np.array([[-m.footprint.radius] * 2, [m.footprint.radius] * 2])
    else:
        ext = np.array([fp.min(axis=0), fp.max(axis=0)])
    if m.shape3d.kind == "tree":  # the crown spreads above the trunk's footprint
        t_lo, t_hi = geom_bounds(model, data, "obstacle/o/trunk")
        np.testing.assert_allclose([t_lo[:2], t_hi[:2]], ext + np.array([4.0, 3.0]), atol=1e-3)
        ext = np.array([[-m.shape3d.crown_radius] * 2, [m.shape3d.crown_radius] * 2])
    np.testing.assert_allclose([lo[:2], hi[:2]], ext + np.array([4.0, 3.0]), atol=1e-3)
    assert lo[2] == pytest.approx(0.0, abs=1e-3)
    assert hi[2] == pytest.approx(m.height, abs=1e-3)
    assert len(scene.static[1].geoms) >= (1 if m.shape3d.kind in ("box", "cylinder") else 2)


def test_random_box_obstacle_takes_its_own_footprint_and_yaw() -> None:
    from arena.core.geometry import rectangle
    from arena.scene.state import Obstacle

    ob = Obstacle("b", "cuboid", np.array([4.0, 3.0, np.pi / 2]), rectangle(1.2, 0.4), height=0.7)
    model = compile_model(build_world(small_grid(), [ob]))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    g = model.geom("obstacle/b/body").id
    np.testing.assert_allclose(model.geom_size[g], (0.6, 0.2, 0.35))
    np.testing.assert_allclose(data.geom_xmat[g].reshape(3, 3)[:, 0], (0, 1, 0), atol=1e-9)


def test_robots_people_compile_step_and_carry_ids() -> None:
    agents = AgentSpawn(np.array([[2.0, 2.0], [5.0, 4.0]]), np.full(2, 0.3), np.array([1.0, 0.8]),
                        np.array([[[6.0, 2.0]], [[5.0, 1.0]]]), np.array([1, 1]),
                        np.array([0, 0]), np.array([0, 1]))
    scene = build_world(small_grid(), robots=[("r1", load_robot("jackal"), [1.0, 1.0, 0.5])],
                        agents=agents)
    model = compile_model(scene)
    data = mujoco.MjData(model)
    assert model.nmocap == 1 + 3 * 2
    body = model.body("robot/r1")
    assert body.mocapid[0] >= 0
    g = model.geom("robot/r1/body").id
    np.testing.assert_allclose(model.geom_size[g], (0.21, 0.165, 0.125))
    ids = person_ids_by_geom(model)
    assert ids[model.geom("person/1/head").id] == 1
    assert ids[model.geom("person/0/leg_r").id] == 0
    assert ids[g] == -1 and (ids >= 0).sum() == 2 * 6
    # the backend's step: move the mocap bodies, then step
    pos, quat = pose_figures(agents.positions + 0.5, [0.0, 1.0], [0.3, 0.3], [1.0, 1.0],
                             agents.kinds)
    for i in range(2):
        for j, suffix in enumerate(("", "/leg_l", "/leg_r")):
            k = model.body(f"person/{i}{suffix}").mocapid[0]
            data.mocap_pos[k], data.mocap_quat[k] = pos[i, j], quat[i, j]
    for _ in range(3):
        mujoco.mj_step(model, data)
    np.testing.assert_allclose(data.xpos[model.body("person/0").id], (2.5, 2.5, 0.0))
    assert np.isfinite(data.qacc).all()


def test_robot_without_height_is_one_line() -> None:
    model = load_robot("dingo")
    assert model.height is None
    with pytest.raises(ConfigError, match=r"^robot model 'dingo': field 'height' is not set, "
                       r"expected the body height in metres"):
        robot_body("r", model, [0, 0, 0])


def test_obstacle_model_without_shape3d_is_one_line(monkeypatch: pytest.MonkeyPatch) -> None:
    import arena.maps.obstacles as lib

    models = dict(lib.obstacle_models())
    models["chair"] = models["chair"].model_copy(update={"shape3d": None})
    monkeypatch.setattr(lib, "obstacle_models", lambda: models)
    with pytest.raises(ConfigError, match=r"obstacle_models.yaml: obstacle model 'chair' has no "
                       r"field 'shape3d'"):
        build_world(small_grid(), [make_obstacle("c", "chair", [1, 1, 0])])


def render(scene) -> np.ndarray:
    model = compile_model(scene)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    with mujoco.Renderer(model, 240, 320) as r:
        cam = mujoco.MjvCamera()
        cam.lookat[:] = (4.0, 3.0, 0.5)
        cam.distance, cam.azimuth, cam.elevation = 9.0, 90.0, -40.0
        r.update_scene(data, cam)
        return r.render().copy()


def test_render_is_deterministic_and_shows_walls() -> None:
    scene = build_world(small_grid(), [make_obstacle("t", "table", [4.0, 3.0, 0.0])])
    try:
        first = render(scene)
    except Exception as e:  # no EGL/OSMesa library: say what is missing
        message = f"offscreen rendering unavailable ({e}); run tools/install_gl.sh"
        unavailable(message)
    second = render(scene)
    assert first.shape == (240, 320, 3)
    np.testing.assert_array_equal(first, second)
    wall = np.array(scene.params.rgba("wall")[:3]) * 255
    # lit wall pixels are greyish-beige: close in hue to the wall colour, far from the black sky
    close = np.abs(first.astype(float) / first.max(axis=-1, keepdims=True).clip(1) * 255
                   - wall / wall.max() * 255).max(axis=-1) < 25
    assert close.mean() > 0.05
    assert (first.sum(axis=-1) > 30).mean() > 0.5  # mostly scene, not background


def test_episode_world_from_a_scenario() -> None:
    from arena.maps.io import load_map
    from arena.maps.sources import resolve_scenario, resolve_world
    from arena.sim.mujoco.world import build_episode_world
    from arena.tasks.scenario import load_scenario
    from arena.tasks.scenario_convert import scenario_episode

    scenario = load_scenario(resolve_scenario("small_office/default"))
    episode = scenario_episode(scenario, load_map(resolve_world("small_office")),
                               [load_robot("burger")], time_limit=60.0)
    scene = build_episode_world(episode)
    model = compile_model(scene)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    robot = episode.robots[0]
    np.testing.assert_allclose(data.xpos[model.body(f"robot/{robot.name}").id][:2],
                               robot.start.as_array()[:2])
    assert model.nmocap == 1 + 3 * len(episode.agents)
    assert len(episode.agents) == 3 and len(scene.actors) == 3
    np.testing.assert_allclose(data.xpos[model.body("person/2").id][:2],
                               episode.agents.positions[2])
    assert model.body("obstacle/shelf_1").id > 0
    assert scene.wall_boxes == 28
