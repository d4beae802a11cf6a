"""Human figures: sizes by type, and the gait pose function (no simulator needed)."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from arena.crowd.state import AgentType
from arena.sim.mujoco.figures import (
    HIP_HALF_WIDTH,
    MAX_SWING,
    figure_bodies,
    figure_size,
    leg_swing,
    pose_figures,
)


def _pitch(quat: np.ndarray, yaw: float) -> np.ndarray:
    """The leg's pitch: the foot direction (body -z) rotated by ``quat``, in the heading frame."""
    w, x, y, z = quat
    foot = -np.array([2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)])
    forward = foot[0] * np.cos(yaw) + foot[1] * np.sin(yaw)
    return np.arctan2(forward, -foot[2])  # > 0: the foot is ahead of the hip


def test_legs_swing_in_antiphase_and_feet_follow_heading() -> None:
    yaw = 0.7
    for d in np.linspace(0.0, 3.0, 13):
        pos, quat = pose_figures([[1.0, 2.0]], [yaw], [d], [1.3], [AgentType.ADULT])
        left, right = _pitch(quat[0, 1], yaw), _pitch(quat[0, 2], yaw)
        assert left == pytest.approx(-right, abs=1e-12)
        assert left == pytest.approx(leg_swing([d], [1.3], [0])[0], abs=1e-12)
    # the hips sit either side of the centre line, left of the heading for the left leg
    np.testing.assert_allclose(pos[0, 1, :2] - pos[0, 0, :2],
                               HIP_HALF_WIDTH * np.array([-np.sin(yaw), np.cos(yaw)]))
    assert pos[0, 1, 2] == pytest.approx(figure_size(AgentType.ADULT).hip)


def test_swing_amplitude_grows_with_speed_and_is_zero_at_rest() -> None:
    d = np.linspace(0.0, 5.0, 400)  # many gait phases
    amplitudes = [np.abs(leg_swing(d, np.full_like(d, v), np.zeros(400))).max()
                  for v in (0.0, 0.3, 0.8, 1.3)]
    assert amplitudes[0] == 0.0
    assert all(a < b for a, b in itertools.pairwise(amplitudes))
    assert np.abs(leg_swing(d, np.full_like(d, 20.0), np.zeros(400))).max() <= MAX_SWING
    # one gait cycle per stride of 0.8 x stature: same pose a stride further on
    stride = 0.8 * figure_size(AgentType.ADULT).height
    np.testing.assert_allclose(leg_swing([0.3], [1.0], [0]), leg_swing([0.3 + stride], [1.0], [0]))


def test_elders_are_smaller_and_geoms_carry_the_person_id() -> None:
    assert figure_size(AgentType.ELDER).height < figure_size(AgentType.ADULT).height
    assert figure_size(99) == figure_size(AgentType.ADULT)
    bodies = figure_bodies(7, AgentType.ELDER, 1.0, 2.0, 0.0)
    assert [b.name for b in bodies] == ["person/7", "person/7/leg_l", "person/7/leg_r"]
    assert all(b.mocap and b.person_id == 7 for b in bodies)
    assert all(g.name.startswith("person/7/") for b in bodies for g in b.geoms)
    head = next(g for g in bodies[0].geoms if g.name.endswith("head"))
    assert head.pos[2] + head.size[0] == pytest.approx(figure_size(AgentType.ELDER).height)
    # at rest the feet touch the floor: hip height - leg capsule reach == 0
    leg = bodies[1].geoms[0]
    assert bodies[1].pos[2] + leg.pos[2] - leg.size[1] - leg.size[0] == pytest.approx(0.0)
