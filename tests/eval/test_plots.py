import numpy as np
import pytest
from PIL import Image

from arena.eval import plots
from arena.maps.grid import OccupancyGrid
from tests.eval._records import make_record
from tests.eval._table import build_columns, build_table


def _check_png(path):
    assert path.stat().st_size > 1000
    img = np.asarray(Image.open(path).convert("L"), float)
    assert img.shape[0] > 200 and img.shape[1] > 200
    assert img.std() > 0


@pytest.mark.parametrize("kind", plots.PLOT_KINDS)
@pytest.mark.parametrize("by_stage", [False, True])
def test_each_kind_renders_png(tmp_path, kind, by_stage):
    path = tmp_path / f"{kind}.png"
    fig = plots.plot_metric(build_table(), "time_to_goal", kind, by_stage=by_stage, path=path)
    _check_png(path)
    ax = fig.axes[0]
    assert ax.get_ylabel() == "Time to goal [s]"
    assert [t.get_text() for t in ax.get_xticklabels()] == ["alpha", "beta"]


def test_accepts_mapping_and_rejects_unknown():
    plots.plot_metric(build_columns(), "collisions", "bar")
    with pytest.raises(ValueError, match="unknown plot kind"):
        plots.plot_metric(build_columns(), "collisions", "swarm")  # type: ignore[arg-type]
    with pytest.raises(KeyError):
        plots.plot_metric(build_columns(), "nope", "bar")


def test_metric_label_units():
    assert plots.metric_label("path_length") == "Path length [m]"
    assert plots.metric_label("collisions") == "Collisions [count]"
    assert plots.metric_label("success") == "Success"
    assert plots.metric_label("custom_thing") == "Custom thing"


def test_metric_columns_excludes_keys():
    cols = build_columns()
    cols["seed"] = np.arange(20)
    cols["wall_time"] = np.ones(20)
    assert "seed" not in plots.metric_columns(cols)
    assert "wall_time" not in plots.metric_columns(cols)
    assert "time_to_goal" in plots.metric_columns(cols)


def test_radar_normalisation_by_hand():
    names = ["time_in_private_zone", "personal_space_compliance", "min_distance_to_person"]
    contestants, metrics, v = plots.radar_values(build_table(), names)
    assert contestants == ["alpha", "beta"] and metrics == names
    # Means over both stages: e-mean = 2.
    # time_in_private_zone (lower better): alpha 1.2, beta 3.2 -> alpha 1, beta 0.
    # personal_space_compliance (higher better): alpha 0.86, beta 0.66 -> alpha 1, beta 0.
    # min_distance_to_person (higher better): alpha 1.1, beta 0.8 -> alpha 1, beta 0.
    np.testing.assert_allclose(v, [[1, 1, 1], [0, 0, 0]])


def test_radar_three_contestants_and_ties():
    cols = {
        "contestant": np.array(["a", "b", "c", "a", "b", "c"]),
        "stage": np.array(["s"] * 6),
        "time_in_private_zone": np.array([1.0, 2.0, 5.0, 1.0, 2.0, 5.0]),
        "personal_space_compliance": np.array([0.2, 0.5, 0.8, 0.4, 0.5, np.nan]),
        "induced_force": np.array([3.0] * 6),
    }
    _, _, v = plots.radar_values(cols, list(cols)[2:])
    # tipz (lower better) means 1, 2, 5 -> (5-x)/4 = 1, .75, 0
    # psc (higher better) means .3, .5, .8 -> (x-.3)/.5 = 0, .4, 1
    # induced_force ties -> 1
    np.testing.assert_allclose(v, [[1, 0, 1], [0.75, 0.4, 1], [0, 1, 1]])


def test_radar_plot(tmp_path):
    plots.plot_radar(build_table(), path=tmp_path / "radar.png")
    _check_png(tmp_path / "radar.png")


def _episode(collide: bool, y: float):
    n = 30
    pose = np.stack([np.linspace(1, 8, n), np.full(n, y), np.zeros(n)], 1)
    coll = np.zeros(n, bool)
    if collide:
        coll[15:17] = True
    peds = [(r, pid, 8 - 0.2 * r, 2 + pid, -1, 0, np.pi, 0.3)
            for pid in range(2) for r in range(n)]
    return make_record(pose, collision=coll, peds=peds, outcome="collision" if collide else "s")


def test_trajectories_over_grid_and_blank(tmp_path):
    data = np.zeros((50, 50), np.int8)
    data[0, :] = data[-1, :] = data[:, 0] = data[:, -1] = 100
    grid = OccupancyGrid(data, 0.2)
    recs = [_episode(False, 3.0), _episode(True, 5.0)]
    fig = plots.plot_trajectories(recs, grid, path=tmp_path / "traj.png")
    _check_png(tmp_path / "traj.png")
    texts = [t.get_text() for t in fig.legends[0].get_texts()]
    assert "collision" in texts and "pedestrians" in texts
    plots.plot_trajectories(recs, None, path=tmp_path / "blank.png")
    _check_png(tmp_path / "blank.png")


def test_mean_ci_edge_cases():
    m, ci, n = plots.mean_ci(np.array([2.0]))
    assert (m, n) == (2.0, 1) and np.isnan(ci)
    m, ci, n = plots.mean_ci(np.array([np.nan, 3.0, 3.0]))
    assert (m, ci, n) == (3.0, 0.0, 2)
    assert plots.mean_ci(np.array([]))[2] == 0
