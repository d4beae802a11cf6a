"""Tests of the 2-D lidar: circles and segments against analytic references, and the rest.

Circles and segments against analytic references, clipping, mount, special origins, noise and
the API; the walls are in ``test_lidar2d_walls.py``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from arena.core.errors import SimulationError
from arena.maps.grid import OccupancyGrid
from arena.sensors import Lidar2D, LidarSpec
from tests.sensors.lidar_kit import (
    JACKAL,
    ONE_BEAM,
    circle_ref,
    clip,
    random_spec,
    segment_ref,
    sensor_frame,
    wall_casting,  # noqa: F401  (autouse: every test runs with faces and with the grid walk)
)

# ------------------------------------------------------------------------------------------------
# Circles and segments (empty map): analytic references
# ------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("seed", range(20))
def test_circles_and_segments_match_analytic(seed: int) -> None:
    rng = np.random.default_rng(100 + seed)
    grid = OccupancyGrid.empty(20.0, 20.0, 0.1, walls=False)
    spec = random_spec(rng, range_max=float(rng.uniform(5.0, 25.0)))
    lidar = Lidar2D(spec)
    n_static = int(rng.integers(0, 12))
    sa = rng.uniform(0, 20, size=(n_static, 2))
    sb = sa + rng.normal(0, 1.5, size=(n_static, 2))
    lidar.bind(grid, sa, sb)
    m = int(rng.integers(0, 25))
    cxy = rng.uniform(-2, 22, size=(m, 2))
    cr = rng.uniform(0.1, 1.0, size=m)
    k = int(rng.integers(0, 12))
    da = rng.uniform(0, 20, size=(k, 2))
    db = da + rng.normal(0, 1.0, size=(k, 2))
    for _ in range(5):
        pose = np.array([*rng.uniform(-1, 21, size=2), rng.uniform(-math.pi, math.pi)])
        o, dirs = sensor_frame(spec, pose)
        if np.any(np.linalg.norm(cxy - o, axis=1) <= cr):
            continue
        got = lidar.scan(pose, cxy, cr, da, db)
        ref = np.minimum.reduce([
            circle_ref(o, dirs, cxy, cr), segment_ref(o, dirs, sa, sb), segment_ref(o, dirs, da, db)
        ])
        np.testing.assert_allclose(got, clip(ref, spec), rtol=0, atol=1e-9)


def test_fast_atan2_error_bound() -> None:
    from arena.sensors.lidar2d.kernels import ATAN_ERR, _fast_atan2

    t = np.linspace(-math.pi, math.pi, 20001)
    for rad in (1e-3, 1.0, 1e3):
        y, x = rad * np.sin(t), rad * np.cos(t)
        approx = np.array([_fast_atan2(float(a), float(b)) for a, b in zip(y, x, strict=True)])
        err = np.angle(np.exp(1j * (approx - np.arctan2(y, x))))
        assert np.abs(err).max() < ATAN_ERR


def test_segment_nearly_through_the_origin() -> None:
    # The origin sits 1e-7 m off a long segment: the segment spans almost π as seen from it.
    spec = LidarSpec(angle_min=-math.pi, angle_max=math.pi, num_beams=360, range_max=10.0)
    lidar = Lidar2D(spec)
    lidar.bind(OccupancyGrid.empty(20.0, 20.0, 0.1, walls=False))
    pose = np.array([10.0, 10.0 + 1e-7, 0.05])
    a, b = np.array([[5.0, 10.0]]), np.array([[15.0, 10.0]])
    o, dirs = sensor_frame(spec, pose)
    got = lidar.scan(pose, segments_a=a, segments_b=b)
    np.testing.assert_allclose(got, clip(segment_ref(o, dirs, a, b), spec), atol=1e-9)
    assert np.sum(got < spec.range_max) > 100


def test_circle_behind_the_seam_of_a_full_circle_scan() -> None:
    # A circle straight behind (angle ±π) spans the first and the last beams of a full scan.
    spec = LidarSpec(angle_min=-math.pi, angle_max=math.pi, num_beams=360, range_max=10.0)
    lidar = Lidar2D(spec)
    lidar.bind(OccupancyGrid.empty(20.0, 20.0, 0.1, walls=False))
    pose = np.array([10.0, 10.0, 0.3])
    cxy = np.array([[10.0 - 3.0 * math.cos(0.3), 10.0 - 3.0 * math.sin(0.3)]])
    got = lidar.scan(pose, cxy, np.array([0.5]))
    o, dirs = sensor_frame(spec, pose)
    np.testing.assert_allclose(got, clip(circle_ref(o, dirs, cxy, [0.5]), spec), atol=1e-9)
    assert got[0] < 3.0 and got[-1] < 3.0 and got[180] == spec.range_max


def test_full_circle_has_no_duplicate_beam() -> None:
    spec = LidarSpec(angle_min=-math.pi, angle_max=math.pi, num_beams=8, range_max=20.0)
    lidar = Lidar2D(spec)
    wrapped = np.mod(lidar.angles, 2 * math.pi)
    assert len(np.unique(np.round(wrapped, 12))) == 8
    np.testing.assert_allclose(np.diff(lidar.angles), 2 * math.pi / 8)
    # In an asymmetric scene every beam sees its own direction: beam 0 (−π) and beam 4 (0) differ.
    lidar.bind(OccupancyGrid.empty(10.0, 10.0, 0.25))
    r = lidar.scan(np.array([3.0, 5.0, 0.0]))
    assert r[0] == pytest.approx(3.0 - 0.25) and r[4] == pytest.approx(9.75 - 3.0)


def test_segment_special_cases() -> None:
    spec = ONE_BEAM
    lidar = Lidar2D(spec)
    lidar.bind(OccupancyGrid.empty(10.0, 10.0, 0.1, walls=False))
    pose = np.array([1.0, 1.0, 0.0])
    a, b = np.array([[4.0, 1.0]]), np.array([[6.0, 1.0]])  # collinear, ahead
    assert lidar.scan(pose, segments_a=a, segments_b=b)[0] == pytest.approx(3.0)
    assert lidar.scan(pose, segments_a=b, segments_b=a)[0] == pytest.approx(3.0)
    a, b = np.array([[4.0, 0.0]]), np.array([[4.0, 1.0]])  # beam hits the endpoint
    assert lidar.scan(pose, segments_a=a, segments_b=b)[0] == pytest.approx(3.0)
    a, b = np.array([[-1.0, 1.0]]), np.array([[0.5, 1.0]])  # collinear, behind
    assert lidar.scan(pose, segments_a=a, segments_b=b)[0] == spec.range_max
    # The origin lies on a segment: every beam reports range_min.
    full = LidarSpec(angle_min=-math.pi, angle_max=math.pi, num_beams=16, range_max=5.0,
                     range_min=0.1)
    lid = Lidar2D(full)
    lid.bind(OccupancyGrid.empty(10.0, 10.0, 0.1, walls=False))
    got = lid.scan(pose, segments_a=np.array([[0.0, 0.0]]), segments_b=np.array([[2.0, 2.0]]))
    np.testing.assert_array_equal(got, 0.1)


def test_static_and_dynamic_segments_are_equivalent(box_room) -> None:
    rng = np.random.default_rng(5)
    a = rng.uniform(1, 9, size=(8, 2))
    b = a + rng.normal(0, 1, size=(8, 2))
    l1, l2 = Lidar2D(JACKAL), Lidar2D(JACKAL)
    l1.bind(box_room, a, b)
    l2.bind(box_room)
    pose = np.array([5.0, 5.0, 0.4])
    np.testing.assert_array_equal(l1.scan(pose), l2.scan(pose, segments_a=a, segments_b=b))


# ------------------------------------------------------------------------------------------------
# Clipping, mount, special origins
# ------------------------------------------------------------------------------------------------


def test_range_min_and_range_max_clipping() -> None:
    spec = LidarSpec(angle_min=-0.5, angle_max=0.5, num_beams=11, range_min=0.3, range_max=4.0)
    lidar = Lidar2D(spec)
    lidar.bind(OccupancyGrid.empty(20.0, 20.0, 0.1, walls=False))
    pose = np.array([10.0, 10.0, 0.0])
    assert np.all(lidar.scan(pose) == 4.0)  # nothing in range
    far = lidar.scan(pose, np.array([[14.2, 10.0]]), np.array([0.1]))  # surface at 4.1 m
    assert np.all(far == 4.0)
    near = lidar.scan(pose, np.array([[10.25, 10.0]]), np.array([0.1]))  # surface at 0.15 m
    assert near[5] == 0.3
    mid = lidar.scan(pose, np.array([[12.0, 10.0]]), np.array([0.5]))
    assert mid[5] == pytest.approx(1.5)


def test_mount_offset_equals_scan_from_sensor_pose(box_room) -> None:
    mounted = LidarSpec(angle_min=-2.0, angle_max=2.0, num_beams=200, range_max=15.0,
                        mount=(0.3, -0.1, 0.7))
    plain = LidarSpec(angle_min=-2.0, angle_max=2.0, num_beams=200, range_max=15.0)
    lm, lp = Lidar2D(mounted), Lidar2D(plain)
    a = np.array([[2.0, 2.0], [7.0, 3.0]])
    b = np.array([[2.5, 7.0], [8.0, 8.0]])
    lm.bind(box_room, a, b)
    lp.bind(box_room, a, b)
    cxy, cr = np.array([[6.0, 6.0], [3.0, 7.5]]), np.array([0.4, 0.3])
    pose = np.array([4.0, 4.5, 1.1])
    o, _ = sensor_frame(mounted, pose)
    sensor_pose = np.array([o[0], o[1], pose[2] + 0.7])
    np.testing.assert_allclose(lm.scan(pose, cxy, cr), lp.scan(sensor_pose, cxy, cr), atol=1e-9)
    assert not np.allclose(lm.scan(pose, cxy, cr), lp.scan(pose, cxy, cr))


def test_origin_inside_or_touching_a_wall_reports_range_min(box_room) -> None:
    spec = LidarSpec(angle_min=-math.pi, angle_max=math.pi, num_beams=64, range_max=8.0,
                     range_min=0.05)
    lidar = Lidar2D(spec)
    lidar.bind(box_room)
    np.testing.assert_array_equal(lidar.scan(np.array([0.1, 5.0, 0.0])), 0.05)  # inside
    np.testing.assert_array_equal(lidar.scan(np.array([0.25, 5.1, 0.0])), 0.05)  # on the face
    assert np.all(lidar.scan(np.array([0.4, 5.1, 0.0])) > 0.05)


def test_origin_inside_a_circle_reports_range_min(box_room) -> None:
    spec = LidarSpec(angle_min=-1.0, angle_max=1.0, num_beams=32, range_max=8.0, range_min=0.1)
    lidar = Lidar2D(spec)
    lidar.bind(box_room)
    got = lidar.scan(np.array([5.0, 5.0, 0.0]), np.array([[5.1, 5.0]]), np.array([0.3]))
    np.testing.assert_array_equal(got, 0.1)


def test_off_map_origin_sees_the_map_but_no_walls_outside() -> None:
    grid = OccupancyGrid.empty(5.0, 5.0, 0.25)  # border cells span [0, 0.25] etc.
    lidar = Lidar2D(ONE_BEAM)
    lidar.bind(grid)
    assert lidar.scan(np.array([-1.0, 2.1, 0.0]))[0] == pytest.approx(1.0)  # enters the border
    assert lidar.scan(np.array([-1.0, 2.1, math.pi]))[0] == ONE_BEAM.range_max
    got = lidar.scan(np.array([-1.0, 2.1, math.pi]), np.array([[-4.0, 2.1]]), np.array([0.5]))
    assert got[0] == pytest.approx(2.5)
    # From beyond the far side (y > 5) looking down.
    assert lidar.scan(np.array([2.1, 7.0, -math.pi / 2]))[0] == pytest.approx(2.0)


# ------------------------------------------------------------------------------------------------
# Noise, batching, API hygiene
# ------------------------------------------------------------------------------------------------


def test_noise_statistics_and_determinism(box_room) -> None:
    sigma = 0.02
    spec = LidarSpec(angle_min=-math.pi, angle_max=math.pi, num_beams=720, range_max=30.0,
                     noise_std=sigma)
    lidar = Lidar2D(spec)
    lidar.bind(box_room)
    pose = np.array([4.0, 6.0, 0.2])
    clean = lidar.scan(pose)
    np.testing.assert_array_equal(lidar.scan(pose), clean)  # no rng: deterministic, no noise
    rng = np.random.default_rng(42)
    res = np.stack([lidar.scan(pose, rng=rng) - clean for _ in range(60)])
    n = res.size
    assert abs(res.mean()) < 4 * sigma / math.sqrt(n)
    assert res.std() == pytest.approx(sigma, rel=0.03)
    a = lidar.scan(pose, rng=np.random.default_rng(9))
    b = lidar.scan(pose, rng=np.random.default_rng(9))
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, clean)


def test_noise_spares_max_range_and_stays_within_limits() -> None:
    spec = LidarSpec(angle_min=-1.0, angle_max=1.0, num_beams=101, range_max=2.0, range_min=0.2,
                     noise_std=0.5)
    lidar = Lidar2D(spec)
    lidar.bind(OccupancyGrid.empty(20.0, 20.0, 0.1, walls=False))
    pose = np.array([10.0, 10.0, 0.0])
    cxy, cr = np.array([[10.5, 10.0]]), np.array([0.2])
    clean = lidar.scan(pose, cxy, cr)
    rng = np.random.default_rng(1)
    for _ in range(20):
        noisy = lidar.scan(pose, cxy, cr, rng=rng)
        miss = clean == spec.range_max
        np.testing.assert_array_equal(noisy[miss], spec.range_max)
        assert np.all((noisy >= 0.2) & (noisy <= 2.0))
        assert not np.array_equal(noisy[~miss], clean[~miss])


def test_scan_many_equals_repeated_scan(box_room) -> None:
    rng = np.random.default_rng(11)
    lidar = Lidar2D(JACKAL)
    lidar.bind(box_room, np.array([[3.0, 3.0]]), np.array([[4.0, 6.0]]))
    poses = np.column_stack([rng.uniform(1, 9, size=(5, 2)), rng.uniform(-3, 3, size=5)])
    cxy = rng.uniform(1, 9, size=(6, 2))
    cr = np.full(6, 0.2)
    da = rng.uniform(1, 9, size=(4, 2))
    db = da + 0.5
    many = lidar.scan_many(poses, cxy, cr, da, db)
    for i, p in enumerate(poses):
        np.testing.assert_array_equal(many[i], lidar.scan(p, cxy, cr, da, db))
    # With owners each robot ignores its own circle and segments.
    c_own = np.array([0, 1, 2, 3, 4, -1])
    s_own = np.array([0, 0, 3, -1])
    many = lidar.scan_many(poses, cxy, cr, da, db, circles_owner=c_own, segments_owner=s_own)
    for i, p in enumerate(poses):
        keep_c, keep_s = c_own != i, s_own != i
        one = lidar.scan(p, cxy[keep_c], cr[keep_c], da[keep_s], db[keep_s])
        np.testing.assert_array_equal(many[i], one)


def test_inputs_are_not_mutated_and_read_only_inputs_work(box_room) -> None:
    lidar = Lidar2D(JACKAL)
    sa, sb = np.array([[3.0, 3.0]]), np.array([[4.0, 6.0]])
    lidar.bind(box_room, sa, sb)
    pose = np.array([5.0, 5.0, 0.1])
    cxy, cr = np.array([[7.0, 5.0]]), np.array([0.3])
    da, db = np.array([[2.0, 8.0]]), np.array([[3.0, 8.5]])
    arrays = (pose, cxy, cr, da, db, sa, sb)
    before = [x.copy() for x in arrays]
    first = lidar.scan(pose, cxy, cr, da, db, rng=np.random.default_rng(0))
    for x, y in zip(arrays, before, strict=True):
        np.testing.assert_array_equal(x, y)
    sa[:] = 0.0  # bind copied the static segments
    for x in arrays:
        x.setflags(write=False)
    again = lidar.scan(pose, cxy, cr, da, db)
    np.testing.assert_array_equal(again, lidar.scan(pose.copy(), cxy.copy(), cr.copy(),
                                                    da.copy(), db.copy()))
    assert first.shape == (720,)


def test_usage_errors(box_room) -> None:
    lidar = Lidar2D(JACKAL)
    with pytest.raises(SimulationError):
        lidar.scan(np.zeros(3))
    lidar.bind(box_room)
    with pytest.raises(ValueError, match="pose"):
        lidar.scan(np.zeros(2))
    with pytest.raises(ValueError, match="finite"):
        lidar.scan(np.array([np.nan, 5.0, 0.0]))
    with pytest.raises(ValueError, match="circles_r"):
        lidar.scan(np.array([5.0, 5.0, 0.0]), np.zeros((2, 2)), np.zeros(3))
    with pytest.raises(ValueError, match="segments"):
        lidar.scan(np.array([5.0, 5.0, 0.0]), None, None, np.zeros((2, 2)), np.zeros((1, 2)))


def test_rebinding_switches_worlds() -> None:
    lidar = Lidar2D(ONE_BEAM)
    lidar.bind(OccupancyGrid.empty(10.0, 10.0, 0.25))
    assert lidar.scan(np.array([5.0, 5.1, 0.0]))[0] == pytest.approx(4.75)
    lidar.bind(OccupancyGrid.empty(8.0, 8.0, 0.25))
    assert lidar.scan(np.array([5.0, 5.1, 0.0]))[0] == pytest.approx(2.75)

