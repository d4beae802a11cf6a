"""arena compare: two runs of the same episodes, paired by (contestant, stage, episode)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from arena.config.schema import ExperimentConfig
from arena.core.errors import ArenaError
from arena.eval.compare import compare_runs, fmt_estimate, outcome_changes, pair_runs
from arena.eval.runner import run_benchmark
from tests.cli_kit import run_cli
from tests.eval._suites import stage

CONTEST = """contestants:
  - {name: pp, local_planner: pure_pursuit}
  - {name: sf, local_planner: social_force}
"""


@pytest.fixture(scope="module")
def runs(tmp_path_factory) -> tuple[Path, Path]:
    """Run A (6 episodes x 2 contestants) and B: A with three rows of ``sf`` edited."""
    tmp = tmp_path_factory.mktemp("compare")
    (tmp / "suite.yaml").write_text("stages:\n" + stage("open", 6, "jackal", dynamic=(1, 2)))
    (tmp / "contest.yaml").write_text(CONTEST)
    a = run_benchmark(tmp / "suite.yaml", tmp / "contest.yaml", tmp / "a",
                      base_cfg=ExperimentConfig(seed=3), progress=False)
    b = tmp / "b"
    shutil.copytree(a, b)
    for k in (0, 2, 4):  # B: sf failed three episodes and drove 1 m further in them
        row = b / "episodes" / "sf" / "open" / f"{k:04d}.json"
        data = json.loads(row.read_text())
        data.update(outcome="error", success=0.0, path_length=data["path_length"] + 1.0)
        row.write_text(json.dumps(data))
    manifest = json.loads((b / "run.json").read_text())
    manifest["simulator"] = "mujoco"
    (b / "run.json").write_text(json.dumps(manifest))
    return a, b


def test_paired_differences_and_outcome_changes(runs):
    a, b = runs
    pair = pair_runs(a, b)
    assert pair.simulators == ("native2d", "mujoco")
    assert len(pair.keys) == 12
    rows = {(r.contestant, r.metric): r for r in compare_runs(pair)}
    same = rows[("pp", "path_length")]
    assert same.a.mean == same.b.mean and same.diff.mean == 0.0 and not same.significant
    succ = rows[("sf", "success")]
    assert succ.a.n == succ.b.n == succ.diff.n == 6
    a_success = [json.loads((a / "episodes" / "sf" / "open" / f"{k:04d}.json").read_text())
                 ["success"] for k in (0, 2, 4)]
    assert succ.diff.mean == pytest.approx(-sum(a_success) / 6)
    assert succ.b.mean == pytest.approx(succ.a.mean - sum(a_success) / 6)
    path = rows[("sf", "path_length")]
    assert path.diff.mean == pytest.approx(0.5)  # +1 m in 3 of 6 pairs
    assert path.diff.lower > 0.0 and path.significant
    moved = outcome_changes(pair)
    assert [(c.contestant, c.episode, c.b) for c in moved] == [
        ("sf", 0, "error"), ("sf", 2, "error"), ("sf", 4, "error")
    ]
    assert fmt_estimate(path.diff, "{:+.1f}").startswith("+0.5 [")


def test_the_cli_prints_the_table_and_the_changed_episodes(runs, monkeypatch, capsys):
    a, b = runs
    monkeypatch.setenv("COLUMNS", "150")
    code, out, _ = run_cli(monkeypatch, capsys, "compare", str(a), str(b), "-m", "path_length")
    assert code == 0
    assert "(native2d)" in out and "(mujoco)" in out
    assert "+0.5 [" in out and " *" in out
    assert "3 of 12 paired episodes changed outcome (A → B):" in out
    assert "sf · open · episode 2: " in out


def test_runs_of_other_episodes_or_metrics_are_one_line_errors(runs, tmp_path, monkeypatch,
                                                              capsys):
    a, b = runs
    c = tmp_path / "c"
    shutil.copytree(b, c)
    manifest = json.loads((c / "run.json").read_text())
    manifest["seed"] = 4
    (c / "run.json").write_text(json.dumps(manifest))
    with pytest.raises(ArenaError, match=r"run\.json field 'seed' is 4 but .* has 3"):
        pair_runs(a, c)
    with pytest.raises(ArenaError, match=r"no metric 'sucess'"):
        compare_runs(pair_runs(a, b), ["sucess"])
    code, _, err = run_cli(monkeypatch, capsys, "compare", str(a), str(tmp_path / "nothing"))
    assert code != 0 and err.count("\n") == 1 and "nothing" in err
    assert np.isfinite(compare_runs(pair_runs(a, b))[0].a.mean)
