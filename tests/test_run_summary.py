"""``arena run``'s summary.csv carries every metric ``arena bench`` computes; progress callbacks."""

from __future__ import annotations

import csv
import math
import sys

import pytest

from arena import cli
from arena.cli_views import episode_progress
from arena.config import load_config
from arena.eval.io import load_record
from arena.eval.metrics import METRICS, Metric, compute_metrics
from arena.experiment import run_experiment

FIXED = ["index", "seed", "map", "robot", "stage", "outcome", "time", "steps", "path_length",
         "collisions", "goals_reached", "teleports", "final_goal_distance", "control_ms_mean",
         "control_ms_p95", "wall_time", "error"]
SMALL = ["map.type=empty", "map.width=10", "map.height=8", "task.robots.min_goal_distance=4",
         "task.obstacles.static=0", "task.obstacles.dynamic=3", "task.timeout=8", "episodes=2",
         "output.video=false"]


def _rows(path):
    with path.open() as f:
        return list(csv.DictReader(f))


@pytest.fixture(scope="module")
def small_run(tmp_path_factory):
    steps = []
    out, results = run_experiment(load_config(None, SMALL), tmp_path_factory.mktemp("run"),
                                  on_step=lambda i, t, limit: steps.append((i, t, limit)))
    return out, results, steps


def test_summary_has_every_metric_as_bench_computes_it(small_run):
    out, results, _ = small_run
    with (out / "summary.csv").open() as f:
        header = next(csv.reader(f))
    metric_cols = [m for m in METRICS.names() if m not in FIXED]
    assert header == FIXED + metric_cols
    assert {"min_distance_to_person", "personal_space_compliance", "cf_displacement_mean",
            "time_in_private_zone", "success"} <= set(metric_cols)
    rows = _rows(out / "summary.csv")
    assert len(rows) == 2
    for row, res in zip(rows, results, strict=True):
        expected = compute_metrics(load_record(res.files["record"]))  # the stored record
        assert res.metrics == expected
        for m in metric_cols:
            value = float(row[m])
            if math.isnan(expected[m]):
                assert math.isnan(value), m
            else:
                assert value == pytest.approx(expected[m], rel=1e-5, abs=1e-9), m
        assert float(row["success"]) == (1.0 if row["outcome"] == "success" else 0.0)
        assert row["error"] == ""


def test_on_step_reports_simulated_time_against_the_limit(small_run):
    _, results, steps = small_run
    for res in results:
        mine = [(t, limit) for i, t, limit in steps if i == res.index]
        assert len(mine) == res.steps
        times = [t for t, _ in mine]
        assert times == sorted(times) and times[-1] == pytest.approx(res.time)
        assert {limit for _, limit in mine} == {8.0}


def test_a_faulty_metric_costs_its_figures_not_the_run(tmp_path):
    def broken(record, params):
        raise RuntimeError("divide by zero people")

    METRICS.add("broken_metric_e", Metric("broken_metric_e", broken, "1", "always fails"))
    try:
        out, results = run_experiment(load_config(None, [*SMALL, "episodes=1"]), tmp_path)
    finally:
        METRICS._entries.pop("broken_metric_e")
    (row,) = _rows(out / "summary.csv")
    assert row["outcome"] == results[0].outcome != "error"
    assert row["error"] == "metrics: RuntimeError: divide by zero people"
    assert math.isnan(float(row["broken_metric_e"])) and math.isnan(float(row["success"]))


def test_cli_progress_bar_follows_the_episode(monkeypatch):
    bar, on_step = episode_progress(cli.console, enabled=True)
    with bar:
        on_step(0, 0.1, 30.0)
        on_step(0, 2.5, 30.0)
        (task,) = bar.tasks
        assert (task.completed, task.total, task.fields["episode"]) == (2.5, 30.0, 0)
        on_step(1, 0.1, 45.0)
        (task,) = bar.tasks  # the finished episode's bar is gone
        assert (task.completed, task.total, task.fields["episode"]) == (0.1, 45.0, 1)
    bar, on_step = episode_progress(cli.console, enabled=False)
    assert on_step is None


def test_cli_run_piped_prints_one_line_per_episode(monkeypatch, capsys, tmp_path):
    monkeypatch.setattr(sys, "argv", ["arena", "run", *SMALL, "-o", str(tmp_path / "r")])
    with pytest.raises(SystemExit) as done:
        cli.main()
    assert done.value.code == 0
    out = capsys.readouterr().out
    lines = [line for line in out.splitlines() if line.startswith("  episode ")]
    assert [line.split(":")[0] for line in lines] == ["  episode 0", "  episode 1"]
    assert "simulated" not in out  # no progress bar when not on a terminal
