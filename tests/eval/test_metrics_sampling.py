"""Metrics measure the motion, not the sampling: simulation step and teleport jumps."""

import dataclasses
import math

import numpy as np
import pytest

from arena.eval.metrics import MetricParams, get_metric
from tests.eval._records import make_record


def m(name, rec, **params):
    return get_metric(name)(rec, MetricParams(**params))


def circle_with_speed_changes(dt, duration=10.0, radius=2.0):
    """A circle of ``radius`` m driven at ``v(t) = 1 + 0.5·sin t`` m/s, sampled every dt s."""
    t = np.arange(round(duration / dt) + 1) * dt
    arc = t + 0.5 * (1.0 - np.cos(t))  # ∫ v dt
    a = arc / radius
    pose = np.stack([radius * np.cos(a), radius * np.sin(a), a + np.pi / 2], 1)
    return make_record(pose, dt=dt)


def sine_path(dt, duration=10.0):
    """``y = 0.5·sin(1.5·x)`` driven with ``x(t) = t + 0.3·sin t`` (speed changes), every dt s."""
    t = np.arange(round(duration / dt) + 1) * dt
    x = t + 0.3 * np.sin(t)
    y = 0.5 * np.sin(1.5 * x)
    return make_record(np.stack([x, y, np.zeros_like(x)], 1), dt=dt)


@pytest.mark.parametrize("name", ["normalized_curvature", "roughness"])
@pytest.mark.parametrize("motion", [circle_with_speed_changes, sine_path])
def test_shape_metrics_do_not_depend_on_the_simulation_step(name, motion):
    ref = m(name, motion(0.1))
    assert ref > 0.0
    for dt in (0.05, 0.02, 0.03):  # 0.03: resampled between rows (linear interpolation)
        assert m(name, motion(dt)) == pytest.approx(ref, rel=0.01), dt
    # The recorded rows alone would halve the value at dt 0.05 (what the metric used to do).
    assert m(name, motion(0.05), shape_sample_dt=0.05) < 0.6 * ref


def test_shape_metrics_on_a_circle_match_the_hand_computed_value():
    # Constant 1 m/s on a 2 m circle, resampled every 0.1 s: each resampled triple spans
    # φ = 0.05 rad per side, its Menger curvature is 1/R, its sides a = b = 2R·sin(φ/2) and
    # c = 2R·sin φ, so k·(a+b) = 4·sin(φ/2) and 2·Area/c² = a²/(2R·c) = tan(φ/2)/2.
    radius, phi = 2.0, 0.05
    for dt in (0.1, 0.05, 0.02):
        t = np.arange(round(6.0 / dt) + 1) * dt
        a = t / radius
        rec = make_record(np.stack([radius * np.cos(a), radius * np.sin(a), a], 1), dt=dt)
        assert m("normalized_curvature", rec) == pytest.approx(4 * math.sin(phi / 2), rel=1e-9)
        assert m("roughness", rec) == pytest.approx(math.tan(phi / 2) / 2, rel=1e-9)
    # A coarser spacing is a different (documented) scale: φ = 0.1 rad per side.
    assert m("normalized_curvature", rec, shape_sample_dt=0.2) == pytest.approx(
        4 * math.sin(0.05), rel=1e-9
    )


def teleport_record(with_event=True):
    """Drive (0,0)→(1,0) turning the yaw 0→0.5 rad in 1 s, be teleported at t = 1 s to
    (−1, 1) with yaw 1 rad, then drive 2.9 m along +x (rows 11..40, 0.1 s, 1 m/s)."""
    first = np.stack([np.arange(11) * 0.1, np.zeros(11), np.linspace(0.0, 0.5, 11)], 1)
    x2 = -0.9 + np.arange(30) * 0.1
    second = np.stack([x2, np.ones(30), np.ones(30)], 1)
    rec = make_record(np.concatenate([first, second]), start=[0.0, 0.0, 0.0],
                      goal=[2.0, 1.0, 0.0], goal_radius=0.05)
    events = [(1.0, "teleport", "robot 0 to (-1.00, 1.00, 1.00)")] if with_event else []
    return dataclasses.replace(rec, events=events)


def test_teleport_jump_is_not_driven_path():
    rec = teleport_record()
    driven = 1.0 + 2.9  # the step after the teleport is dropped with the jump (as EpisodeResult)
    shortest = math.hypot(2.0, 1.0)
    assert m("path_length", rec) == pytest.approx(driven)
    assert m("spl", rec) == pytest.approx(shortest / driven)
    assert m("path_length_ratio", rec) == pytest.approx(driven / shortest)
    assert m("angle_over_length", rec) == pytest.approx(0.5 / driven)  # the jump's 0.5 rad too
    # Both legs are straight: no resampled triple spans the jump.
    assert m("normalized_curvature", rec) == pytest.approx(0.0, abs=1e-12)
    assert m("roughness", rec) == pytest.approx(0.0, abs=1e-12)
    # Without the teleport event the same rows are one path through the jump.
    plain = teleport_record(with_event=False)
    assert m("path_length", plain) == pytest.approx(1.0 + math.hypot(1.9, 1.0) + 2.9)
    assert m("angle_over_length", plain) == pytest.approx(1.0 / m("path_length", plain))
    assert m("normalized_curvature", plain) > 0.0


def test_teleport_of_another_robot_is_driven_path_of_robot_0():
    rec = dataclasses.replace(teleport_record(), events=[(1.0, "teleport", "robot 1 to (0, 0)")])
    assert m("path_length", rec) == pytest.approx(m("path_length", teleport_record(False)))


def test_private_zone_is_measured_between_bodies():
    # A jackal (bounding radius 0.267 m) passes a person (0.3 m) at a 0.4 m body gap
    # (centres 0.967 m apart) for rows 3..7; elsewhere the person is 2 m farther away.
    centre = 0.267 + 0.3 + 0.4
    peds = [(j, 1, centre if 3 <= j <= 7 else centre + 2.0, 0.0, 0, 0, 0, 0.3)
            for j in range(11)]
    rec = make_record(np.zeros((11, 3)), peds=peds, robot_radius=0.267)
    assert m("time_in_private_zone", rec) == pytest.approx(0.5)  # gap 0.4 < 0.5 m, 5 rows
    assert m("time_in_private_zone", rec, private_zone_radius=0.35) == 0.0
    assert m("time_in_private_zone", rec, private_zone_radius=0.45) == pytest.approx(0.5)
    assert m("min_distance_to_person", rec) == pytest.approx(0.4)


def _jackal_passes_person(gap_near, gap_far=3.0):
    """A jackal (0.267 m) and a person (0.3 m): body gap ``gap_near`` at rows 3..7, else far."""
    peds = [(j, 1, 0.567 + (gap_near if 3 <= j <= 7 else gap_far), 0.0, 0, 0, 0, 0.3)
            for j in range(11)]
    return make_record(np.zeros((11, 3)), peds=peds, robot_radius=0.267)


def test_personal_and_intimate_space_are_measured_between_bodies():
    # gap 1.0 m (centres 1.567 m apart): inside Hall's 1.2 m personal space for 5 of 11 rows,
    # outside Francis's 0.5 m and the 0.45 m intimate space; centre to centre it would be outside
    rec = _jackal_passes_person(1.0)
    assert m("personal_space_compliance", rec) == pytest.approx(6 / 11)
    assert m("personal_space_compliance", rec, personal_space_radius=0.5) == 1.0
    assert m("intimate_space_compliance", rec) == 1.0
    # gap 0.4 m (centres 0.967 m): inside the intimate space for the same 5 rows
    rec = _jackal_passes_person(0.4)
    assert m("intimate_space_compliance", rec) == pytest.approx(6 / 11)
    assert m("intimate_space_compliance", rec, intimate_space_radius=0.35) == 1.0
    assert m("personal_space_compliance", rec, personal_space_radius=0.5) == pytest.approx(6 / 11)
    assert m("min_distance_to_person", rec) == pytest.approx(0.4)
    assert m("personal_space_compliance", make_record(np.zeros((11, 3)))) == 1.0


def _with_contacts(rows):
    coll = np.zeros(11, bool)
    coll[list(rows)] = True
    pose = np.stack([np.arange(11) * 0.1, np.zeros(11), np.zeros(11)], axis=1)
    return make_record(pose, collision=coll)


def test_success_rule_goal_ignores_collisions_arena_needs_fewer_than_two():
    one, two = _with_contacts([2, 3]), _with_contacts([2, 5, 6])  # 1 and 2 rising edges
    assert (m("collisions", one), m("collisions", two)) == (1.0, 2.0)
    assert m("success", two) == 1.0  # default "goal": reaching the goal is enough
    assert m("success", one, success_rule="arena") == 1.0
    assert m("success", two, success_rule="arena") == 0.0
    assert m("spl", two, success_rule="arena") == 0.0
    assert m("spl", two) == pytest.approx(1.0)
    missed = dataclasses.replace(one, meta=dataclasses.replace(one.meta, outcome="timeout"))
    assert m("success", missed, success_rule="arena") == 0.0
    with pytest.raises(ValueError, match="success_rule"):
        MetricParams(success_rule="paper")


def test_minimum_acceleration_jerk_curvature_and_heading_change_by_hand():
    # Along +x with speeds 0, 0.1, 0.3, 0.6, 1.0 m/s at dt 0.1: a = 1, 2, 3, 4 m/s²,
    # jerk = 10 m/s³ throughout; positions a straight line (curvature 0 everywhere).
    v = np.array([0.0, 0.1, 0.3, 0.6, 1.0])
    x = np.concatenate([[0.0], np.cumsum(v[1:] * 0.1)])
    rec = make_record(np.stack([x, 0 * x, 0 * x], axis=1),
                      velocity=np.stack([v, 0 * v, 0 * v], axis=1))
    assert m("acceleration_min", rec) == pytest.approx(1.0)
    assert m("acceleration_max", rec) == pytest.approx(4.0)
    assert m("jerk_min", rec) == pytest.approx(10.0)
    assert m("curvature_min", rec) == 0.0
    assert m("heading_change", rec) == 0.0
    # A square of side 1 driven corner to corner: triples at the corners have curvature
    # 4·0.5/(1·1·√2) = √2 1/m; each step the yaw changes by 90° (3π/2 → 0 too)
    pose = [(0, 0, 0), (1, 0, np.pi / 2), (1, 1, 0), (2, 1, 1.5 * np.pi), (2, 2, 0)]
    rec = make_record(pose)
    assert m("curvature_min", rec) == pytest.approx(math.sqrt(2))
    assert m("heading_change", rec) == pytest.approx(4 * np.pi / 2)
    assert math.isnan(m("jerk_min", make_record(np.zeros((2, 3)))))
    assert math.isnan(m("acceleration_min", make_record(np.zeros((1, 3)))))
    assert math.isnan(m("curvature_min", make_record(np.zeros((2, 3)))))


def test_heading_change_leaves_teleport_jumps_out():
    # the first leg turns 0 → 0.5 rad; the jump's 0.5 → 1 rad counts only without the event
    assert m("heading_change", teleport_record()) == pytest.approx(0.5)
    assert m("heading_change", teleport_record(False)) == pytest.approx(1.0)


def test_collisions_by_kind():
    rec = _with_contacts([2, 3, 4, 8])  # wall contact at rows 2..4 and 8
    obstacle, ped, robot = (np.zeros(11, bool) for _ in range(3))
    obstacle[[4, 5]] = True  # from the wall onto an adjoining obstacle: the same collision
    ped[[1, 6, 7, 9]] = True  # rows 1, 6..7, 9: three contacts
    robot[5] = True
    rec = dataclasses.replace(rec, collision_obstacle=obstacle, collision_pedestrian=ped,
                              collision_robot=robot)
    assert m("collisions_static", rec) == 2.0
    assert m("collisions_pedestrian", rec) == 3.0
    assert m("collisions_robot", rec) == 1.0
    assert m("collisions", rec) == 1.0  # contact of any kind from row 1 to row 9 without a break
