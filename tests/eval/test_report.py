import math
import re

import numpy as np
import pytest
from scipy import stats

from arena.eval import report
from arena.eval.io import save_record
from arena.maps.grid import OccupancyGrid
from tests.eval._records import make_record
from tests.eval._table import CONTESTANTS, STAGES, build_table, values


def _hand_ci(v):
    v = np.asarray(v, float)
    n = v.size
    mean = sum(v) / n
    s = math.sqrt(sum((x - mean) ** 2 for x in v) / (n - 1))
    return mean, stats.t.ppf(0.975, n - 1) * s / math.sqrt(n)


def test_summary_means_and_ci_by_hand():
    rows = report.summary_table(build_table())
    assert len(rows) == 2 * 2 * 7
    by = {(r.contestant, r.stage, r.metric): r for r in rows}
    for c, cn in enumerate(CONTESTANTS):
        for s, sn in enumerate(STAGES):
            for m, v in values(c, s).items():
                r = by[(cn, sn, m)]
                mean, ci = _hand_ci(v)
                assert r.n == 5
                assert r.mean == pytest.approx(mean)
                assert r.ci == pytest.approx(ci)
                assert r.lower == pytest.approx(mean - ci)
    # time_to_goal alpha/easy: 10..14 -> mean 12, s = sqrt(2.5), t(0.975, 4) = 2.7764451
    r = by[("alpha", "easy", "time_to_goal")]
    assert r.mean == pytest.approx(12.0)
    assert r.ci == pytest.approx(2.7764451 * math.sqrt(2.5) / math.sqrt(5), rel=1e-6)
    assert r.unit == "s"


def test_write_tables_csv_and_latex(tmp_path):
    csv_path, tex_path = report.write_tables(build_table(), tmp_path / "out")
    lines = csv_path.read_text().splitlines()
    assert lines[0].startswith("contestant,stage,metric,unit,n,mean,ci95")
    assert len(lines) == 1 + 28
    tex = tex_path.read_text()
    assert r"\toprule" in tex and r"\midrule" in tex and r"\bottomrule" in tex
    ci = 2.7764451 * math.sqrt(2.5) / math.sqrt(5)
    assert rf"time\_to\_goal [s] & alpha & easy & 5 & 12.000 $\pm$ {ci:.3f} \\" in tex
    # beta/hard time_to_goal: 15..19 -> mean 17
    assert rf"time\_to\_goal [s] & beta & hard & 5 & 17.000 $\pm$ {ci:.3f} \\" in tex
    assert tex.count(r"\\") == 28 + 1


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
    # 7 metrics x 2 kinds + radar + one trajectory figure per stage
    assert n_png == 7 * 2 + 1 + 2
    assert any(s.startswith("data:video/mp4;base64,") for s in srcs)
    for c in CONTESTANTS:
        assert c in text
    assert "Time to goal [s]" in text and "12.000 ± " in text


def test_main_reads_store(tmp_path, monkeypatch):
    run = tmp_path / "run"
    recs = _write_records(run)
    import arena.eval.store as store

    monkeypatch.setattr(store, "load_results", lambda r: build_table(recs))
    paths = report.main(run)
    assert paths["html"] == run / "report" / "report.html"
    assert paths["html"].is_file() and paths["csv"].is_file() and paths["tex"].is_file()


def test_trajectory_maps_are_rebuilt_from_the_records(tmp_path):
    from arena.config.loader import load_config
    from arena.eval.io import load_record
    from arena.eval.report import episode_grid, stage_trajectories
    from arena.experiment import planning_grid, run_experiment
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
