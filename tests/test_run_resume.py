"""``arena run --resume``: a stopped run continues in its folder to the summary an
uninterrupted run writes; options that would change the run are refused in one line."""

from __future__ import annotations

import csv
import shutil

import pytest

from arena.config import load_config
from arena.experiment import run_experiment
from tests.cli_kit import run_cli

#: Columns that measure the computer, not the run.
TIMING = ("wall_time", "control_ms_mean", "control_ms_p95")


def _figures(folder) -> list[dict[str, str]]:
    with (folder / "summary.csv").open(newline="") as f:
        return [{k: v for k, v in row.items() if k not in TIMING} for row in csv.DictReader(f)]


def test_a_resumed_run_has_the_summary_of_an_uninterrupted_one(tmp_path, monkeypatch, capsys):
    cfg = load_config(None, ["episodes=3", "output.video=false", "seed=4"])
    run_experiment(cfg, tmp_path / "whole")
    run_experiment(cfg, tmp_path / "cut")
    # as if stopped during episode 1: its episode.json (written last) and episode 2 missing
    (tmp_path / "cut" / "episode_001" / "episode.json").unlink()
    shutil.rmtree(tmp_path / "cut" / "episode_002")
    (tmp_path / "cut" / "summary.csv").unlink()
    code, _, err = run_cli(monkeypatch, capsys, "run", "--resume", str(tmp_path / "cut"))
    assert code == 0, err
    assert _figures(tmp_path / "cut") == _figures(tmp_path / "whole")
    assert len(_figures(tmp_path / "cut")) == 3
    assert (tmp_path / "cut" / "episode_002" / "episode.json").is_file()


def test_a_kept_episode_is_not_simulated_again(tmp_path):
    cfg = load_config(None, ["episodes=2", "output.video=false"])
    run_experiment(cfg, tmp_path / "run")
    kept = tmp_path / "run" / "episode_000" / "episode.json"
    stamp = kept.stat().st_mtime_ns
    _, results = run_experiment(cfg, tmp_path / "run", resume=True)
    assert kept.stat().st_mtime_ns == stamp
    assert [r.index for r in results] == [0, 1]
    assert results[0].metrics  # recomputed from the kept record


@pytest.mark.parametrize(("args", "words"), [
    (["--seed", "0"], "drop --seed"),
    (["-n", "2"], "drop --episodes"),
    (["robot=burger"], "drop CONFIG/overrides"),
    (["--no-video"], "drop --video/--no-video"),
])
def test_resume_refuses_options_that_change_the_run(tmp_path, monkeypatch, capsys, args, words):
    run_experiment(load_config(None, ["episodes=1", "output.video=false"]), tmp_path / "r")
    code, _, err = run_cli(monkeypatch, capsys, "run", "--resume", str(tmp_path / "r"), *args)
    assert code == 2 and words in err and len(err.strip().splitlines()) == 1


def test_resume_of_a_folder_that_is_no_run(tmp_path, monkeypatch, capsys):
    code, _, err = run_cli(monkeypatch, capsys, "run", "--resume", str(tmp_path))
    assert code == 2 and "not an arena run folder" in err
    (tmp_path / "a").mkdir()
    code, _, err = run_cli(monkeypatch, capsys, "run", "--resume", str(tmp_path),
                           "-o", str(tmp_path / "a"))
    assert code == 2 and "not two different folders" in err
