import numpy as np
import pytest
from PIL import Image

from arena.eval import plots, trajectory_plots
from arena.eval.stats import MIN_N
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


def test_radar_uses_fixed_ranges_not_min_max():
    names = ["time_in_private_zone", "personal_space_compliance", "min_distance_to_person"]
    contestants, metrics, v = plots.radar_values(build_table(), names)
    assert contestants == ["alpha", "beta"] and metrics == names
    # Means over both stages: e-mean = 2.
    # time_in_private_zone (lower better, [0, 20] s): alpha 1.2, beta 3.2 -> 0.94, 0.84
    # personal_space_compliance (higher better, [0, 1]): alpha 0.86, beta 0.66
    # min_distance_to_person (higher better, [0, 2] m): alpha 1.1, beta 0.8 -> 0.55, 0.4
    np.testing.assert_allclose(v, [[0.94, 0.86, 0.55], [0.84, 0.66, 0.4]])


def test_radar_close_values_stay_close_and_out_of_range_clips():
    cols = {
        "contestant": np.array(["a", "b", "c", "a", "b", "c"]),
        "stage": np.array(["s"] * 6),
        "personal_space_compliance": np.array([0.963, 0.975, 0.5, 0.963, 0.975, np.nan]),
        "min_distance_to_person": np.array([-0.2, 1.0, 5.0, -0.2, 1.0, 5.0]),
        "induced_force": np.array([3.0] * 6),
    }
    _, _, v = plots.radar_values(cols, list(cols)[2:])
    # 0.963 vs 0.975 are no longer 0 vs 1 (min-max scaling did that); overlaps (negative
    # gaps) clip to 0 and gaps past 2 m to 1; induced force 3 > 2 m/s^2 (lower better) -> 0
    np.testing.assert_allclose(v, [[0.963, 0, 0], [0.975, 0.5, 0], [0.5, 1, 0]])
    with pytest.raises(ValueError, match="RADAR_RANGES"):
        plots.radar_values(cols | {"jerk": np.ones(6)}, ["jerk"])


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
    fig = trajectory_plots.plot_trajectories(recs, grid, path=tmp_path / "traj.png")
    _check_png(tmp_path / "traj.png")
    texts = [t.get_text() for t in fig.legends[0].get_texts()]
    assert "collision" in texts and "pedestrians" in texts
    trajectory_plots.plot_trajectories(recs, None, path=tmp_path / "blank.png")
    _check_png(tmp_path / "blank.png")


def test_metric_columns_keep_integer_counts():
    cols = build_columns()
    assert cols["collisions"].dtype.kind == "i"
    cols["flag"] = np.zeros(20, bool)
    cols["map"] = np.array(["m"] * 20)
    names = plots.metric_columns(cols)
    assert "collisions" in names and "flag" in names and "map" not in names


def test_bar_intervals_stay_in_range_and_low_n_is_hatched_without_interval():
    n = 8
    cols = {
        "contestant": np.array(["a"] * n + ["b"] * 2),
        "stage": np.array(["s"] * (n + 2)),
        # a: one collision in 8 episodes; b: 2 episodes, far apart
        "collisions": np.array([0] * (n - 1) + [1] + [0, 9], np.int64),
    }
    fig = plots.plot_metric(cols, "collisions", "bar")
    ax = fig.axes[0]
    assert ax.get_ylim()[0] == 0.0
    (bars,) = [c for c in ax.containers if c.__class__.__name__ == "ErrorbarContainer"]
    segs = bars.lines[2][0].get_segments()
    assert len(segs) == 1  # only contestant a has an interval
    lo, hi = segs[0][:, 1]
    assert 0.0 <= lo <= 1 / n <= hi <= 1.0
    hatched = [p for p in ax.patches if p.get_hatch() == plots.LOW_N_HATCH]
    assert len(hatched) == 1 and hatched[0].get_height() == pytest.approx(4.5)
    texts = [t.get_text() for t in ax.texts]
    assert "n=2" in texts and "8" in texts  # n differs: shown above every bar
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert f"n < {MIN_N}: no interval" in legend


def test_save_formats_writes_valid_pdf_and_svg(tmp_path):
    import xml.etree.ElementTree as ET

    fig = plots.plot_metric(build_table(), "success", "bar", by_stage=True)
    pdf, svg = plots.save_formats(fig, tmp_path / "figs" / "success")
    assert pdf.read_bytes().startswith(b"%PDF")
    root = ET.parse(svg).getroot()
    assert root.tag.endswith("svg")
    assert b"<dc:date>" not in svg.read_bytes()  # no date: a rerun differs only where it must
    assert b"CreationDate" not in pdf.read_bytes()


# -- trajectory small multiples --------------------------------------------------------------------
def _grid_with_block(col):
    """A 20 x 20 grid (0.5 m cells, origin (0, 0)) with one occupied cell in row 10."""
    data = np.zeros((20, 20), np.int8)
    data[10, col] = 100
    return OccupancyGrid(data, 0.5)


def _stage(n_episodes, shared, contestants=("a", "b", "c")):
    episodes = {e: [(c, _episode(collide=(c == "b" and e == 1), y=2.0 + e + 0.3 * k))
                    for k, c in enumerate(contestants)] for e in range(n_episodes)}
    grids = {e: _grid_with_block(3 if shared else e) for e in range(n_episodes)}
    return episodes, grids


def test_shared_map_gives_one_panel_with_every_path():
    episodes, grids = _stage(4, shared=True)
    panels, note = trajectory_plots.trajectory_panels(episodes, grids)
    assert len(panels) == 1 and len(panels[0].paths) == 4 * 3
    assert "one map" in note and "per episode" not in note
    fig = trajectory_plots.plot_stage_trajectories(panels, ["a", "b", "c"], title="T", note=note)
    assert len([ax for ax in fig.axes if ax.get_visible()]) == 1
    assert len(fig.legends) == 1


def test_per_episode_maps_give_one_panel_each_on_its_own_map():
    episodes, grids = _stage(4, shared=False)
    panels, note = trajectory_plots.trajectory_panels(episodes, grids)
    assert [p.title for p in panels] == [f"episode {e}" for e in range(4)]
    assert note == "4 episodes, one map per episode"
    fig = trajectory_plots.plot_stage_trajectories(panels, ["a", "b", "c"])
    axes = [ax for ax in fig.axes if ax.get_visible()]
    assert len(axes) == 4 and len(fig.legends) == 1
    for e, ax in enumerate(axes):
        (img,) = ax.images
        assert img.get_extent() == pytest.approx((0.0, 10.0, 0.0, 10.0))
        dark = np.argwhere(np.asarray(img.get_array()) < 0.5)
        assert dark.tolist() == [[10, e]]  # this episode's occupied cell
        colors = {tuple(np.round(line.get_color(), 3)) if not isinstance(line.get_color(), str)
                  else line.get_color() for line in ax.lines if len(line.get_xdata()) > 1}
        assert colors == set(trajectory_plots.contestant_colors(["a", "b", "c"]).values())


def test_per_episode_panels_are_capped_and_the_note_says_which():
    episodes, grids = _stage(12, shared=False, contestants=("a",))
    panels, note = trajectory_plots.trajectory_panels(episodes, grids, max_panels=9)
    assert len(panels) == 9
    assert note == "episodes 0–8 of 12 shown, one map per episode"
    fig = trajectory_plots.plot_stage_trajectories(panels, ["a"])
    assert sum(ax.get_visible() for ax in fig.axes) == 9
    _, note = trajectory_plots.trajectory_panels({0: episodes[0], 1: episodes[1]}, grids, total=5)
    assert note == "episodes 0–1 of 5 shown, one map per episode"


def test_collision_markers_where_the_record_collides(tmp_path):
    episodes, grids = _stage(2, shared=False)
    panels, _ = trajectory_plots.trajectory_panels(episodes, grids)
    fig = trajectory_plots.plot_stage_trajectories(panels, ["a", "b", "c"], path=tmp_path / "t.png")
    _check_png(tmp_path / "t.png")
    ax0, ax1 = fig.axes[:2]
    assert not [c for c in ax0.collections if c.get_gid() == "collision"]
    (marks,) = [c for c in ax1.collections if c.get_gid() == "collision"]
    rec = dict(episodes[1])["b"]
    hit = rec.pose[rec.collision_wall, :2]
    np.testing.assert_allclose(marks.get_offsets(), hit)
    texts = [t.get_text() for t in fig.legends[0].get_texts()]
    assert texts == ["a", "b", "c", "start", "goal", "collision"]


def test_blank_panels_without_grids_and_ranges():
    episodes, _ = _stage(2, shared=True)
    panels, note = trajectory_plots.trajectory_panels(episodes, {0: None, 1: None})
    assert len(panels) == 1 and panels[0].grid is None and note == "2 episodes, one map"
    fig = trajectory_plots.plot_stage_trajectories(panels, ["a", "b", "c"])
    assert not fig.axes[0].images
    assert trajectory_plots.trajectory_panels({}, {}) == ([], "")
    assert trajectory_plots.episode_ranges([0, 1, 2, 5, 7, 8]) == "0–2, 5, 7–8"


def test_several_kinds_share_one_figure_and_legend():
    fig = plots.plot_metric(build_table(), "path_length", ("bar", "box"), by_stage=True)
    assert [ax.get_title() for ax in fig.axes] == ["mean, 95 % bootstrap interval; n = 5 "
                                                   "episodes per bar", "box, n = 5 episodes "
                                                   "per group"]
    assert fig.get_suptitle() == "Path length" and len(fig.legends) == 1
    with pytest.raises(ValueError, match="unknown plot kind 'pie'"):
        plots.plot_metric(build_table(), "path_length", ("bar", "pie"))  # type: ignore[arg-type]
