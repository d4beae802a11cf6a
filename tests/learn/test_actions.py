"""Action spaces and decoding."""

import numpy as np
import pytest
from gymnasium import spaces

from arena.learn.actions import ActionDecoder, custom_grid
from arena.learn.config import ActionConfig
from arena.robots.presets import load_robot


def test_robot_discretization_uses_the_presets_list():
    dec = ActionDecoder(ActionConfig(type="discrete", discretization="robot"), load_robot("jackal"))
    assert dec.space == spaces.Discrete(7)
    np.testing.assert_allclose(dec.decode([0, 2]), [[0.30, 0, 0], [0.15, 0, 0.35]])


def test_one_integer_action_decodes_as_a_batch_of_one():
    """The integer shortcut of ``decode``: the batched rows, fresh arrays, the same errors."""
    dec = ActionDecoder(ActionConfig(type="discrete", discretization="robot"), load_robot("jackal"))
    n = dec.space.n
    for i in [*range(-n, n), *(np.int64(k) for k in range(n)), True]:
        one = dec.decode(i)
        batch = dec.decode(np.asarray(i)[None])
        assert one.shape == (1, 3) and one.dtype == np.float64
        assert one.tobytes() == batch.tobytes()
        one[:] = 99.0  # callers write into the command (inactive robots): must not leak
        assert dec.decode(i).tobytes() == batch.tobytes()
    for bad in (n, -n - 1):
        with pytest.raises(IndexError):
            dec.decode(bad)
        with pytest.raises(IndexError):
            dec.decode([bad])


def test_custom_grid_includes_stop():
    grid = custom_grid((-1.0, 2.0), (-1.0, 1.0), 2, 2)  # no (0, 0) in the 2 x 2 corners
    assert len(grid) == 5 and np.all(grid[-1] == 0)
    assert len(custom_grid((-1.0, 1.0), (-1.0, 1.0), 3, 3)) == 9  # has (0, 0) already
    dec = ActionDecoder(
        ActionConfig(type="discrete", discretization="custom", n_linear=3, n_angular=5),
        load_robot("jackal"),
    )
    assert dec.space.n == 15
    np.testing.assert_allclose(dec.decode(0), [[-2.0, 0.0, -4.0]])


def test_continuous_is_clipped_and_nonholonomic_has_no_vy():
    dec = ActionDecoder(ActionConfig(type="continuous"), load_robot("jackal"))
    assert dec.space.shape == (2,)
    cmd = dec.decode([[5.0, -9.0], [0.5, 0.25]])
    np.testing.assert_allclose(cmd, [[2.0, 0.0, -4.0], [0.5, 0.0, 0.25]])


def test_holonomic_continuous_has_three_components():
    robot = load_robot("ridgeback")
    assert robot.holonomic
    dec = ActionDecoder(ActionConfig(type="continuous"), robot)
    assert dec.space.shape == (3,)
    lim = robot.limits()
    cmd = dec.decode([[100.0, -100.0, 100.0]])
    np.testing.assert_allclose(cmd, [[lim.vx_max, lim.vy_min, lim.omega_max]])


def test_normalized_continuous_maps_onto_the_ranges():
    dec = ActionDecoder(ActionConfig(type="continuous", normalize=True), load_robot("jackal"))
    assert dec.space == spaces.Box(-1.0, 1.0, (2,), np.float32)
    np.testing.assert_allclose(dec.decode([[-1.0, 1.0], [0.5, 0.0]]), [[-2, 0, 4], [1.0, 0, 0]])
