import re
import xml.etree.ElementTree as ET

import numpy as np

from arena.eval import report
from arena.eval.io import save_record
from arena.maps.grid import OccupancyGrid
from tests.eval._records import make_record
from tests.eval._table import CONTESTANTS, STAGES, build_table


def _write_records(run):
    recs = []
    for c in CONTESTANTS:
        for s in STAGES:
            for i in range(5):
                rel = f"episodes/{c}/{s}/{i}.parquet"
                n = 10
                pose = np.stack([np.linspace(0, 4, n), np.full(n, 0.3 * i + 1), np.zeros(n)], 1)
                coll = np.zeros(n, bool)
                coll[5] = i == 3
                save_record(make_record(pose, collision=coll), run / rel)
                recs.append(rel)
    return recs


def test_write_report_self_contained(tmp_path):
    run = tmp_path / "run"
    recs = _write_records(run)
    video = tmp_path / "ep.mp4"
    video.write_bytes(b"\x00\x00\x00\x18ftypmp42fake")
    grid = OccupancyGrid(np.zeros((30, 30), np.int8), 0.2)
    out = report.write_report(build_table(recs), run, tmp_path / "r" / "report.html",
                              grids={"m": grid}, videos=[video], kinds=("bar", "box"))
    text = out.read_text()
    assert text.startswith("<!DOCTYPE html>")
    assert 'src="http' not in text and "href=\"http" not in text and "<link" not in text
    srcs = re.findall(r'src="([^"]*)"', text)
    assert srcs and all(s.startswith("data:") for s in srcs)
    n_png = sum(s.startswith("data:image/png;base64,") for s in srcs)
    # 7 metrics: 5 headline (a bar figure each), 2 others (one figure each: bar and box
    # panels), radar, one trajectory figure per stage, one thumbnail per (stage, episode)
    assert n_png == 5 + 2 + 1 + 2 + 2 * 5
    assert any(s.startswith("data:video/mp4;base64,") for s in srcs)
    for c in CONTESTANTS:
        assert c in text
    # the headline table leads: collisions (an integer column) with its interval and n
    results = text[text.index("<h2>Results</h2>"):text.index("<h2>All metrics</h2>")]
    assert "<th>Collisions</th>" in results and "<th>Time to goal [s]</th>" in results
    assert "<h3>all stages</h3>" in results and "<h3>easy</h3>" in results
    assert "<td>alpha</td><td>5</td>" in results  # n per planner and stage
    assert "personal-space radius 1.2 m" in results
    assert re.search(r"<td>12\.0 <span class=\"iv\">\[1\d\.\d, 1\d\.\d\]</span></td>",
                     results)
    # every figure also as PDF and SVG, stable names
    figs = out.parent / "figures"
    for stem in ("headline_success", "headline_collisions", "metric_min_distance_to_person",
                 "radar", "trajectories_easy"):
        assert (figs / f"{stem}.pdf").read_bytes().startswith(b"%PDF")
        assert ET.parse(figs / f"{stem}.svg").getroot().tag.endswith("svg")
    assert len(list(figs.glob("*.pdf"))) == len(list(figs.glob("*.svg"))) == 5 + 2 + 1 + 2
    # the episode table: one row per episode and contestant, each linking to its trajectory
    links = re.findall(r'<a href="#(ep-[^"]+)">trajectory</a>', text)
    assert len(links) == 20 and set(links) == {f"ep-{s}-{i}" for s in ("easy", "hard")
                                               for i in range(5)}
    for a in set(links):
        assert f'<figure id="{a}">' in text
    assert "openTarget" in text  # following a link opens the collapsed section


def test_episode_thumbnails_are_capped(tmp_path):
    run = tmp_path / "run"
    recs = _write_records(run)
    out = report.write_report(build_table(recs), run, tmp_path / "report.html",
                              kinds=("bar",), episode_figures=3, figures=False)
    text = out.read_text()
    assert len(re.findall(r"<figure id=", text)) == 3
    assert "for the first 3 of 10 (stage, episode) pairs" in text
    assert not (tmp_path / "figures").exists()


def test_main_reads_store(tmp_path, monkeypatch):
    run = tmp_path / "run"
    recs = _write_records(run)
    import arena.eval.store as store

    monkeypatch.setattr(store, "load_results", lambda r: build_table(recs))
    paths = report.main(run)
    assert paths["html"] == run / "report" / "report.html"
    assert paths["html"].is_file() and paths["csv"].is_file() and paths["tex"].is_file()
    assert (paths["figures"] / "headline_success.pdf").is_file()


def test_trajectory_maps_are_rebuilt_from_the_records(tmp_path):
    from arena.config.loader import load_config
    from arena.eval.io import load_record
    from arena.eval.report_trajectories import episode_grid, stage_trajectories
    from arena.experiment import run_experiment
    from arena.maps.raster import planning_grid
    from arena.tasks.generator import TaskGenerator

    def records(extra, name):
        cfg = load_config(None, ["output.video=false", "episodes=2", "task.timeout=2",
                                 "task.obstacles.dynamic=1", *extra])
        out, _ = run_experiment(cfg, tmp_path / name)
        recs = [load_record(out / f"episode_{i:03d}" / "episode.parquet") for i in range(2)]
        cols = {"contestant": np.array(["x", "x"]), "stage": np.array(["s", "s"]),
                "episode": np.array([0, 1]),
                "record": np.array([f"{name}/episode_{i:03d}/episode.parquet" for i in range(2)])}
        return cfg, recs, cols

    cfg, recs, _ = records([], "office")  # one world map, random obstacles per episode
    expected = planning_grid(TaskGenerator.from_config(cfg).episode(1))
    assert episode_grid(recs[1]) == expected
    assert episode_grid(recs[0]) != expected  # the placed obstacles are part of the map drawn
    _, recs, cols = records(["task.obstacles.static=0"], "bare")  # the same map twice
    panels, note = stage_trajectories(cols, tmp_path, "s")
    assert len(panels) == 1 and len(panels[0].paths) == 2 and "one map" in note
    assert panels[0].grid == episode_grid(recs[0])
    _, recs, cols = records(["map.type=barn", "map.width=12", "map.height=10",
                             "task.robots.min_goal_distance=3",
                             "task.modules=[{type: dynamic_map, episodes_per_map: 1}]"], "barn")
    panels, note = stage_trajectories(cols, tmp_path, "s")  # a new map per episode
    assert [p.grid for p in panels] == [episode_grid(r) for r in recs]
    assert panels[0].grid != panels[1].grid and "per episode" in note
    panels, note = stage_trajectories(cols, tmp_path, "s", max_episodes=1)
    assert len(panels) == 1 and note == "episodes 0 of 2 shown, one map"


def test_summary_html_n_is_episodes_and_cells_with_fewer_values_say_so():
    from arena.eval.tables import episode_counts, summary_table

    cols = {"contestant": np.array(["a"] * 6), "stage": np.array(["s"] * 6),
            "time_to_goal": np.array([5.0, 6.0, np.nan, 7.0, 5.5, 6.5]),  # 1 failure
            "success": np.array([1.0, 1.0, 0.0, 1.0, 1.0, 1.0])}
    counts = episode_counts(cols)
    assert counts == {("a", "s"): 6, ("a", "(all)"): 6}
    text = report.summary_html(summary_table(cols), ["time_to_goal", "success"], counts)
    assert "<td>a</td><td>6</td>" in text
    assert re.search(r'<td>6\.00 <span class="iv">\[[\d.]+, [\d.]+\]</span> '
                     r'<span class="iv">n=5</span></td>', text)


def test_run_info_lists_the_manifest_without_unset_fields(tmp_path):
    import json

    (tmp_path / "run.json").write_text(json.dumps(
        {"suite": "quick.yaml", "seed": 3, "worlds": None, "scale": 0.5}))
    cols = {"contestant": np.array(["a", "b"]), "outcome": np.array(["success", "timeout"])}
    page = report._run_info(tmp_path, cols, ["a", "b"], ["s"])
    assert ">seed<" in page and ">3<" in page and ">0.5<" in page
    assert "worlds" not in page and "null" not in page  # no worlds folder given: not listed
    assert "success: 1, timeout: 1" in page
