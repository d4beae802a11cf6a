"""The results page's data and charts: the report's figures from a known table, an ``arena run``
summary as a one-contestant table, and the ``/api/runs/{run}/summary`` endpoint."""

from __future__ import annotations

import numpy as np
import pytest
from fastapi.testclient import TestClient

from arena.config import load_config
from arena.experiment import run_experiment
from arena.web.results import results_view, run_columns
from arena.web.results_page import bar_options, headline_html, outcome_options, radar_options
from arena.web.server import create_app
from tests.eval._table import CONTESTANTS, STAGES, build_columns, values


@pytest.fixture(scope="module")
def view():
    return results_view(build_columns())


def _row(view, contestant, stage, metric):
    (row,) = [r for r in view["summary"]
              if (r["contestant"], r["stage"], r["metric"]) == (contestant, stage, metric)]
    return row


def test_headline_cells_are_the_means_with_intervals(view):
    assert view["contestants"] == list(CONTESTANTS)
    assert view["stages"] == [*STAGES, "(all)"]
    assert [h["metric"] for h in view["headline"]] == [
        "success", "collisions", "time_to_goal", "path_length", "time_in_private_zone"]
    for c, cn in enumerate(CONTESTANTS):
        for s, sn in enumerate(STAGES):
            row = _row(view, cn, sn, "time_to_goal")
            assert row["n"] == 5
            assert row["mean"] == pytest.approx(values(c, s)["time_to_goal"].mean())
            assert row["lower"] <= row["mean"] <= row["upper"]
        pooled = np.concatenate([values(c, s)["time_to_goal"] for s in range(len(STAGES))])
        assert _row(view, cn, "(all)", "time_to_goal")["mean"] == pytest.approx(pooled.mean())
        assert _row(view, cn, "(all)", "time_to_goal")["n"] == 10


def test_other_metrics_outcomes_and_radar(view):
    others = {m["metric"]: m for m in view["metrics"]}
    assert set(others) == {"personal_space_compliance", "min_distance_to_person"}
    beta = {r["contestant"]: r for r in others["min_distance_to_person"]["rows"]}["beta"]
    pooled = np.concatenate([values(1, s)["min_distance_to_person"] for s in range(2)])
    assert beta["mean"] == pytest.approx(pooled.mean()) and beta["n"] == 10
    assert others["min_distance_to_person"]["higher"] is True
    assert view["outcomes"] == {"alpha": {"success": 8, "collision": 2},
                                "beta": {"success": 6, "collision": 4}}
    radar = view["radar"]
    assert radar["contestants"] == list(CONTESTANTS)
    assert set(radar["metrics"]) == {"personal_space_compliance", "min_distance_to_person",
                                     "time_in_private_zone"}
    k = radar["metrics"].index("personal_space_compliance")  # fixed range [0, 1], higher better
    assert radar["values"][0][k] == pytest.approx(values(0, 0)["personal_space_compliance"].mean())
    assert view["episodes"] == 20


def test_bar_chart_follows_the_stage(view):
    metric = next(h for h in view["headline"] if h["metric"] == "path_length")
    for stage in view["stages"]:
        options = bar_options(view, metric, stage)
        bars, errors = options["series"]
        assert [b["value"] for b in bars["data"]] == [
            _row(view, c, stage, "path_length")["mean"] for c in CONTESTANTS]
        assert errors["data"] == [[i, _row(view, c, stage, "path_length")["lower"],
                                   _row(view, c, stage, "path_length")["upper"]]
                                  for i, c in enumerate(CONTESTANTS)]
        assert options["xAxis"]["data"] == list(CONTESTANTS)
    assert "↓" in bar_options(view, metric, "easy")["title"]["text"]  # lower is better
    stacked = outcome_options(view)["series"]
    assert [s["name"] for s in stacked] == ["success", "collision"]
    assert stacked[1]["data"] == [2, 4]
    assert len(radar_options(view["radar"])["radar"]["indicator"]) == 3


def test_headline_table_escapes_names():
    cols = build_columns()
    cols["contestant"] = np.where(cols["contestant"] == "alpha", "<b>a</b>", "beta")
    text = headline_html(results_view(cols))
    assert "<b>a</b>" not in text and "&lt;b&gt;a&lt;/b&gt;" in text
    assert text.count("<tr>") == 1 + 3 * 2  # header, then (2 stages + all) x 2 contestants


def test_an_empty_table():
    view = results_view({"contestant": np.array([], str)})
    assert view["episodes"] == 0 and view["summary"] == [] and view["radar"] is None


def test_a_cli_run_is_one_contestant(tmp_path):
    run_experiment(load_config(None, ["episodes=2", "output.video=false", "seed=3"]),
                   tmp_path / "two")
    client = TestClient(create_app(tmp_path, pages=False))
    view = client.get("/api/runs/two/summary").json()
    assert view["contestants"] == ["two"] and view["episodes"] == 2
    rows = client.get("/api/runs/two").json()["results"]
    expected = np.mean([r["path_length"] for r in rows])
    (row,) = [r for r in view["summary"] if r["metric"] == "path_length"]
    assert row["mean"] == pytest.approx(expected) and row["n"] == 2
    assert sum(view["outcomes"]["two"].values()) == 2
    assert client.get("/api/runs/nope/summary").status_code == 404
    cols = run_columns("two", rows)
    assert list(cols["contestant"]) == ["two", "two"] and "index" not in cols
