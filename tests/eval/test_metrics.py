"""Metric values on hand-built records, computed by hand."""

import math

import numpy as np
import pytest

from arena.eval.metrics import MetricParams, compute_metrics, get_metric
from tests.eval._records import make_record, straight


def m(name, rec, **params):
    return get_metric(name)(rec, MetricParams(**params))


def test_straight_line_constant_speed():
    rec = straight(n=11, v=1.0, dt=0.1)
    assert m("path_length", rec) == pytest.approx(1.0)
    assert m("velocity", rec) == pytest.approx(1.0)
    for name in ("acceleration", "jerk", "curvature", "normalized_curvature", "roughness"):
        assert m(name, rec) == pytest.approx(0.0, abs=1e-12), name
    assert m("angle_over_length", rec) == 0.0
    assert m("success", rec) == 1.0
    assert m("time_to_goal", rec) == pytest.approx(1.0)
    assert m("spl", rec) == pytest.approx(1.0)
    assert m("spl", rec, shortest_path=0.5) == pytest.approx(0.5)
    assert m("path_length_ratio", rec) == pytest.approx(1.0)


def test_success_needs_goal_reached():
    rec = straight(goal=[5.0, 0.0, 0.0])
    assert m("success", rec) == 0.0
    assert math.isnan(m("time_to_goal", rec))
    assert m("spl", rec) == 0.0
    assert m("success", straight(outcome="timeout")) == 0.0
    assert m("timeout", straight(outcome="timeout")) == 1.0


def test_circle_arc_curvature():
    r, n, phi = 2.0, 20, 0.1
    a = np.arange(n) * phi
    pose = np.stack([r * np.cos(a), r * np.sin(a), a + np.pi / 2], 1)
    rec = make_record(pose)
    assert m("curvature", rec) == pytest.approx(1 / r)
    chord = 2 * r * math.sin(phi / 2)
    assert m("normalized_curvature", rec) == pytest.approx(2 * chord / r)
    assert m("angle_over_length", rec) == pytest.approx((n - 1) * phi / ((n - 1) * chord))
    # roughness: 2·Area / |p0 p2|², area of the chord triangle
    area = 0.5 * chord * chord * math.sin(phi)
    assert m("roughness", rec) == pytest.approx(2 * area / (2 * r * math.sin(phi)) ** 2)


def test_stop_and_go_acceleration_and_jerk():
    speeds = [0.0, 0.0, 1.0, 1.0, 0.0]
    dt = 0.5
    vel = np.array([[s, 0.0, 0.0] for s in speeds])
    x = np.concatenate([[0.0], np.cumsum(speeds[1:])]) * dt
    rec = make_record(np.stack([x, 0 * x, 0 * x], 1), vel, dt=dt)
    # a = [0, 2, 0, 2] m/s², jerk = |Δa|/Δt = [4, 4, 4]
    assert m("acceleration", rec) == pytest.approx(1.0)
    assert m("acceleration_max", rec) == pytest.approx(2.0)
    assert m("jerk", rec) == pytest.approx(4.0)
    assert m("velocity_min", rec) == 0.0 and m("velocity_max", rec) == 1.0
    assert m("stalled_time", rec, stall_speed=0.05) == pytest.approx(0.5)  # row 1; row 4 at goal


def test_pedestrian_in_private_zone_and_compliance():
    rec0 = straight(n=11, v=1.0, dt=0.1)
    # pedestrian at y=0.4 above x=0.5 for rows 3..6; distance to robot at row j: hypot(0.1j-0.5, .4)
    peds = [(j, 1, 0.5, 0.4, 0, 0, 0, 0.2) for j in range(11)]
    rec = make_record(rec0.pose, rec0.velocity, peds=peds)
    d = np.hypot(np.arange(11) * 0.1 - 0.5, 0.4)
    # body gap d − 0.2 − 0.2 < 0.15 m: rows 2..8 (d ≤ 0.5), Δt = 0.1; < 0.5 m: rows 1..10
    inside = d - 0.4 < 0.15
    assert m("time_in_private_zone", rec, private_zone_radius=0.15) == pytest.approx(
        0.1 * inside.sum()
    )
    assert inside.sum() == 7
    assert m("time_in_private_zone", rec) == pytest.approx(1.0)
    assert m("personal_space_compliance", rec) == pytest.approx(1 - (d - 0.4 < 1.2).mean())
    assert m("intimate_space_compliance", rec) == pytest.approx(1 - (d - 0.4 < 0.45).mean())
    assert m("min_distance_to_person", rec) == pytest.approx(0.4 - 0.4)
    assert m("time_in_private_zone", rec0) == 0.0


def test_private_zone_first_row_has_zero_dt():
    peds = [(0, 1, 0.1, 0.0, 0, 0, 0, 0.2)]
    assert m("time_in_private_zone", make_record(straight().pose, peds=peds)) == 0.0


def test_head_on_ttc():
    rec0 = straight(n=3, v=1.0, dt=0.1)
    # pedestrian 5 m ahead of row 0 walking at 1 m/s toward the robot: gap 5 − 0.4, closing 2 m/s
    peds = [(0, 1, 5.0, 0.0, -1.0, 0.0, math.pi, 0.2)]
    rec = make_record(rec0.pose, rec0.velocity, peds=peds)
    assert m("time_to_collision", rec) == pytest.approx((5.0 - 0.4) / 2.0)
    away = make_record(rec0.pose, rec0.velocity, peds=[(0, 1, 5.0, 0.0, 2.0, 0.0, 0, 0.2)])
    assert math.isnan(m("time_to_collision", away))


@pytest.mark.parametrize(("deg", "looking"), [(4.9, True), (5.1, False)])
def test_gaze_cones(deg, looking):
    n, dt = 5, 0.1
    pose = np.zeros((n, 3))
    a = math.radians(deg)
    # pedestrian at bearing `deg` from the robot (robot faces +x); it faces the robot within `deg`
    ped_heading = a + math.pi
    peds = [(j, 1, 3 * math.cos(a), 3 * math.sin(a), 0, 0, ped_heading + 0.0, 0.2)
            for j in range(n)]
    rec = make_record(pose, dt=dt, peds=peds)
    expect = (n - 1) * dt if looking else 0.0
    assert m("time_looking_at_pedestrians", rec) == pytest.approx(expect)
    # pedestrian heading exactly at the robot: always seen
    assert m("time_seen_by_pedestrians", rec) == pytest.approx((n - 1) * dt)
    off = [(j, 1, 3.0, 0.0, 0, 0, math.pi + a, 0.2) for j in range(n)]
    rec2 = make_record(pose, dt=dt, peds=off)
    assert m("time_seen_by_pedestrians", rec2) == pytest.approx(expect)


def test_collision_rising_edges():
    coll = [0, 1, 1, 0, 1, 0, 0, 1, 1, 1, 0]
    rec = straight(n=11, collision=coll)
    assert m("collisions", rec) == 3.0
    assert m("collisions", straight(n=3, collision=[1, 1, 0])) == 1.0


def test_clearance_and_progress():
    rec = straight(n=11, min_range=np.full(11, 1.0))
    assert m("clearance", rec) == pytest.approx(0.8)
    stuck = make_record(np.zeros((60, 3)), goal=[5.0, 0.0, 0.0], outcome="timeout")
    assert m("failure_to_progress", stuck) == 1.0
    assert m("failure_to_progress", straight(n=60, goal=[100.0, 0, 0], outcome="timeout")) == 0.0


def test_group_space_and_induced_force():
    pose = np.zeros((3, 3))
    group = [(j, i, x, 0.5, 0, 0, 0, 0.2) for j in range(3) for i, x in ((1, -0.5), (2, 0.5))]
    rec = make_record(pose, dt=0.1, peds=group)
    assert m("group_space_intrusion", rec) == pytest.approx(0.2)
    lone = make_record(pose, dt=0.1, peds=[(j, 1, 3.0, 0, 0, 0, 0, 0.2) for j in range(3)])
    assert m("group_space_intrusion", lone) == 0.0
    assert m("induced_force", lone) == pytest.approx(2.1 * math.exp((0.4 - 3.0) / 0.3))


def test_path_irregularity_and_compute_metrics():
    rec = straight()
    assert m("path_irregularity", straight(goal=[5.0, 0, 0])) == pytest.approx(0.0)
    out = compute_metrics(rec, ["path_length", "velocity"], {"private_zone_radius": 1.0})
    assert list(out) == ["path_length", "velocity"]
    assert len(compute_metrics(rec)) >= 30


def test_counterfactual_displacement_by_hand():
    import dataclasses

    rec0 = straight(n=3)
    # ids 1 and 2 at rows 0..2; id 2 is missing from the replay at row 2.
    peds = [(j, i, float(i), 1.0, 0, 0, 0, 0.2) for j in range(3) for i in (1, 2)]
    rec = make_record(rec0.pose, rec0.velocity, peds=peds)
    assert all(math.isnan(m(n, rec)) for n in
               ("cf_displacement_mean", "cf_displacement_max", "cf_people_displaced"))
    cf = rec.ped_position.copy()
    cf[1] += [0.3, 0.4]  # row 0, id 2: 0.5 m
    cf[3] += [0.0, 0.1]  # row 1, id 2: 0.1 m
    cf[5] = np.nan       # row 2, id 2: unknown
    rec = dataclasses.replace(rec, ped_cf_position=cf)
    assert m("cf_displacement_mean", rec) == pytest.approx((0.5 + 0.1) / 5)
    assert m("cf_displacement_max", rec) == pytest.approx(0.5)
    assert m("cf_people_displaced", rec) == pytest.approx(1 / 2)  # id 2 only (0.5 > 0.2 m)
    assert m("cf_people_displaced", rec, cf_displacement_threshold=0.6) == 0.0
