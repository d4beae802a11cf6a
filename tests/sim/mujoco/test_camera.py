"""The RGB-D camera: metric depth against known geometry, intrinsics, person ids, determinism."""

from __future__ import annotations

import math

import numpy as np
import pytest

from arena.core.errors import ConfigError
from arena.maps.grid import OccupancyGrid
from arena.scene.episode import AgentSpawn
from arena.sensors.spec3d import RgbdSpec
from arena.sim.mujoco.camera import RgbdCamera, add_depth_noise, camera_pose
from arena.sim.mujoco.mjcf import compile_model
from arena.sim.mujoco.scene import PALETTE
from arena.sim.mujoco.world import build_world
from tests.mujoco_kit import require_mujoco, unavailable

mujoco = require_mujoco()

ROOM = OccupancyGrid.empty(10.0, 6.0, 0.1)  # inner wall faces at x = 0.1, 9.9 and y = 0.1, 5.9


def cam_spec(**kw) -> RgbdSpec:
    base = {"width": 160, "height": 120, "fovy": 60.0, "mount": (0.0, 0.0, 1.0, 0.0, 0.0)}
    return RgbdSpec.model_validate({**base, **kw})


def world(agents: AgentSpawn | None = None):
    model = compile_model(build_world(ROOM, agents=agents))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return model, data


def one_person(x: float, y: float) -> AgentSpawn:
    return AgentSpawn(np.array([[x, y]]), np.full(1, 0.3), np.array([1.0]),
                      np.array([[[x + 1.0, y]]]), np.array([1]), np.array([0]), np.array([0]))


@pytest.fixture(scope="module")
def room():
    model, data = world()
    try:
        RgbdCamera(model, cam_spec(width=8, height=8)).close()
    except ConfigError as e:  # mujoco without a GL library (tools/install_gl.sh installs it)
        unavailable(str(e))
    return model, data


def test_wall_ahead_reads_its_distance_everywhere(room):
    model, data = room
    cam = RgbdCamera(model, cam_spec(mount=(0.3, 0.0, 1.0, 0.0, 0.0)))
    f = cam.render(data, (2.0, 3.0, 0.0))  # optical centre at x = 2.3, the wall at 9.9
    assert f.rgb.shape == (120, 160, 3) and f.rgb.dtype == np.uint8
    assert f.depth.shape == (120, 160) and f.depth.dtype == np.float32
    assert f.person.shape == (120, 160) and f.person.dtype == np.int32
    centre = f.depth[59:61, 79:81]
    np.testing.assert_allclose(centre, 7.6, atol=0.01)
    # a plane facing the camera has one depth along the optical axis (not the ray length)
    wall = np.abs(f.depth - 7.6) < 0.01
    assert wall[48:72, 42:118].all()  # the wall: 2 m tall, y in [0.1, 5.9]
    assert (f.person == -1).all()
    # turned left (robot yaw pi/2, mount yaw 0): the wall at y = 5.9, 2.6 m away
    g = cam.render(data, (5.0, 3.0, math.pi / 2))
    np.testing.assert_allclose(g.depth[59:61, 79:81], 5.9 - 3.3, atol=0.01)


def test_image_order_floor_at_the_bottom_and_nothing_above_the_walls(room):
    model, data = room
    f = RgbdCamera(model, cam_spec()).render(data, (2.0, 3.0, 0.0))
    # the walls are 2 m tall: above them, at the top of the image, nothing (depth 0)
    assert (f.depth[0] == 0).all() and (f.rgb[0] == 0).all()
    assert (f.depth[-1] > 0).all()


def test_floor_depth_follows_the_ray_geometry(room):
    model, data = room
    pitch, h = 0.5, 1.2
    spec = cam_spec(mount=(0.0, 0.0, h, 0.0, pitch), far=20.0)
    f = RgbdCamera(model, spec).render(data, (1.0, 3.0, 0.0))
    _, fy, _, cy = spec.intrinsics()
    rows = np.arange(75, 120)  # below the wall's foot
    yo = (rows - cy) / fy  # optical y (down) of each row's ray, per unit depth
    want = h / (math.sin(pitch) + yo * math.cos(pitch))
    got = f.depth[rows, 80]
    np.testing.assert_allclose(got, want, rtol=2e-3)
    assert got.min() > 1.0  # the floor, not the camera's near field


def test_far_clip_reads_zero_and_near_clip_sees_through(room):
    model, data = room
    far = RgbdCamera(model, cam_spec(far=5.0)).render(data, (2.0, 3.0, 0.0))
    assert (far.depth[55:65, 75:85] == 0).all()  # the wall at 7.9 m is beyond far
    # a wall nearer than near is clipped away: the camera sees the room behind it
    near = RgbdCamera(model, cam_spec(near=0.5)).render(data, (9.6, 3.0, 0.0))
    assert (near.depth[55:65, 75:85] == 0).all()
    back = RgbdCamera(model, cam_spec(near=0.5)).render(data, (9.6, 3.0, math.pi))
    np.testing.assert_allclose(back.depth[59:61, 79:81], 9.5, atol=0.01)


def test_wall_colour_is_its_material(room):
    model, data = room
    f = RgbdCamera(model, cam_spec()).render(data, (2.0, 3.0, 0.0))
    px = f.rgb[50:70, 70:90].reshape(-1, 3).astype(float).mean(axis=0)
    wall = np.array(PALETTE["wall"][:3])
    floor = f.rgb[-5:, 70:90].reshape(-1, 3).astype(float).mean(axis=0)
    # lit, so brighter or darker, but the hue of the wall's material (and not the floor's)
    np.testing.assert_allclose(px / px.sum(), wall / wall.sum(), atol=0.02)
    assert px.sum() > floor.sum()  # beige wall, grey-blue floor
    fl = np.array(PALETTE["floor"][:3])
    np.testing.assert_allclose(floor / floor.sum(), fl / fl.sum(), atol=0.03)


def test_person_ahead_carries_its_id():
    model, data = world(one_person(5.0, 3.0))
    spec = cam_spec()
    f = RgbdCamera(model, spec).render(data, (2.0, 3.0, 0.0))
    assert (f.person[50:60, 77:83] == 0).all()  # the torso just above the image centre
    torso = f.depth[59:61, 79:81]
    assert (torso < 3.0).all() and (torso > 2.7).all()  # in front of the wall, at ~2.9 m
    assert (f.person[:, :20] == -1).all()  # the walls and floor at the side are nobody
    # in front of the far wall (columns 45..114), person pixels are exactly the nearer ones
    band = np.s_[45:72, 45:115]  # rows of the far wall (the floor starts at row 73)
    d = f.depth[band]
    np.testing.assert_array_equal(f.person[band] == 0, (d > 0) & (d < 7.5))
    assert 50 < (f.person[band] == 0).sum() < 1500
    # the person moved away: nobody seen
    k = model.body("person/0").mocapid[0]
    data.mocap_pos[k] = (5.0, 30.0, 0.0)
    for leg in ("leg_l", "leg_r"):
        data.mocap_pos[model.body(f"person/0/{leg}").mocapid[0]] = (5.0, 30.0, 0.9)
    mujoco.mj_forward(model, data)
    assert (RgbdCamera(model, spec).render(data, (2.0, 3.0, 0.0)).person == -1).all()


def test_intrinsics_a_point_lands_where_it_projects():
    """A small sphere at a known point renders around the pixel its pinhole projection gives."""
    spec = RgbdSpec(width=200, height=150, fx=180.0, fy=180.0, cx=70.0, cy=95.0,
                    mount=(0.0, 0.0, 1.0, 0.0, 0.2))
    pose = (0.5, -0.3, 0.4)
    point = np.array([4.0, 1.2, 1.3])
    xml = f"""<mujoco><worldbody>
      <light directional="true" dir="0 0 -1"/>
      <geom name="person/7/head" type="sphere" size="0.1" pos="{point[0]} {point[1]} {point[2]}"/>
    </worldbody></mujoco>"""
    model = compile_model(xml)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    f = RgbdCamera(model, spec).render(data, pose)
    pos, fwd, up = camera_pose(spec, pose)
    right = np.cross(fwd, up)
    rel = point - pos
    z = rel @ fwd
    u = spec.cx + spec.fx * (rel @ right) / z
    v = spec.cy + spec.fy * (rel @ -up) / z
    rows, cols = np.nonzero(f.person == 7)
    assert len(rows) > 40
    assert np.nonzero(f.depth > 0)[0].size == len(rows)  # the sphere alone, nothing else
    assert cols.mean() == pytest.approx(u, abs=0.3)
    assert rows.mean() == pytest.approx(v, abs=0.3)
    # its nearest pixel's depth: the sphere's centre depth less about its radius
    assert f.depth[f.depth > 0].min() == pytest.approx(z - 0.1, abs=0.01)


def test_byte_identical_renders_and_cameras():
    model, data = world(one_person(5.0, 2.5))
    spec = cam_spec(mount=(0.1, 0.0, 0.8, 0.2, 0.1))
    a = RgbdCamera(model, spec)
    b = RgbdCamera(model, spec)
    fa, fa2, fb = (c.render(data, (1.5, 3.2, -0.1)) for c in (a, a, b))
    for x, y in ((fa, fa2), (fa, fb)):
        assert x.rgb.tobytes() == y.rgb.tobytes()
        assert x.depth.tobytes() == y.depth.tobytes()
        assert x.person.tobytes() == y.person.tobytes()
    assert (fa.person == 0).any()
    assert fa.rgb is not fa2.rgb  # new arrays each frame


def test_images_larger_than_the_model_buffer_leave_the_model_unchanged(room):
    model, data = room
    before = (model.vis.global_.offwidth, model.vis.global_.offheight,
              model.vis.quality.offsamples)
    spec = cam_spec(width=1600, height=1000)
    assert spec.width > before[0] and spec.height > before[1]
    f = RgbdCamera(model, spec).render(data, (2.0, 3.0, 0.0))
    assert f.depth.shape == (1000, 1600)
    np.testing.assert_allclose(f.depth[499:501, 799:801], 7.9, atol=0.01)
    after = (model.vis.global_.offwidth, model.vis.global_.offheight,
             model.vis.quality.offsamples)
    assert after == before


def test_without_segmentation_and_after_close(room):
    model, data = room
    cam = RgbdCamera(model, cam_spec(), segmentation=False)
    f = cam.render(data, (2.0, 3.0, 0.0))
    assert f.person is None
    cam.close()
    cam.close()  # idempotent
    with pytest.raises(RuntimeError, match="after close"):
        cam.render(data, (2.0, 3.0, 0.0))
    # a camera dropped while another's context is current leaves the other's buffers alone
    first = RgbdCamera(model, cam_spec(near=0.2))
    other = RgbdCamera(model, cam_spec())
    del first
    np.testing.assert_allclose(other.render(data, (2.0, 3.0, 0.0)).depth[59:61, 79:81], 7.9,
                               atol=0.01)


def test_camera_without_gl_is_one_line(room, monkeypatch):
    model, _ = room

    def broken(width: int, height: int) -> None:
        raise ImportError("libEGL.so.1: cannot open shared object file")

    monkeypatch.setattr(mujoco, "GLContext", broken)
    with pytest.raises(ConfigError, match=r"^no working OpenGL .*libEGL.so.1: cannot open .*"
                                          r"run tools/install_gl.sh"):
        RgbdCamera(model, cam_spec())


def test_depth_noise_from_the_given_generator(room):
    model, data = room
    spec = cam_spec(depth_noise_std=0.2, far=8.0)
    depth = RgbdCamera(model, spec, segmentation=False).render(data, (2.0, 3.0, 0.0)).depth
    a = add_depth_noise(depth, spec, np.random.default_rng(5))
    b = add_depth_noise(depth, spec, np.random.default_rng(5))
    assert a.dtype == np.float32 and a.tobytes() == b.tobytes()
    valid = depth > 0
    assert valid.any() and (~valid).any()
    assert (a[~valid] == 0).all()  # no return stays no return
    z = np.random.default_rng(5).standard_normal(depth.shape)  # one (H, W) draw
    want = np.clip(depth + 0.2 * z, spec.near, spec.far)
    np.testing.assert_allclose(a[valid], want[valid], rtol=1e-6)
    assert a.max() <= 8.0
    rng = np.random.default_rng(9)
    assert np.array_equal(add_depth_noise(depth, cam_spec(), rng), depth)
    assert rng.standard_normal() == np.random.default_rng(9).standard_normal()  # no draw
