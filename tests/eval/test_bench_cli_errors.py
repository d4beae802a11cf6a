"""``arena bench`` on bad options and corrupt run folders: one ``error:`` line, no traceback."""

from __future__ import annotations

import json
import math
import sys
import warnings
from pathlib import Path

import pytest

from arena import cli
from arena.config.schema import ExperimentConfig
from arena.core.errors import ArenaError
from arena.eval.runner import check_scale, run_benchmark
from arena.eval.store import commit_episode, load_results, read_manifest
from arena.tasks.suite import load_suite
from tests.eval._suites import stage

SUITE = "stages:\n" + stage("open", 2, "jackal", timeout=4, static=(0, 1)) + stage(
    "tail", 1, "burger", timeout=4
)
CONTEST = "contestants:\n  - {name: pp, local_planner: pure_pursuit}\n"


@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    d = tmp_path_factory.mktemp("bench_errors")
    (d / "suite.yaml").write_text(SUITE)
    (d / "contest.yaml").write_text(CONTEST)
    return d / "suite.yaml", d / "contest.yaml"


@pytest.fixture(scope="module")
def finished_run(files: tuple[Path, Path], tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A finished run at scale 0.5 (the ``open`` stage's one episode), in this process."""
    suite, contest = files
    run = tmp_path_factory.mktemp("finished") / "run"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the dropped stage, tested below
        run_benchmark(suite, contest, run, base_cfg=ExperimentConfig(seed=0), scale=0.5,
                      workers=0)
    return run


def _bench(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str],
           *args: str) -> tuple[int, str, str]:
    monkeypatch.setattr(sys, "argv", ["arena", "bench", *args])
    monkeypatch.setattr(cli.err_console, "width", 400)
    code = 0
    try:
        cli.main()
    except SystemExit as e:
        code = int(e.code or 0)
    out = capsys.readouterr()
    return code, out.out, out.err


def _one_error_line(code: int, err: str, *fragments: str) -> None:
    assert code == 2, err
    assert "Traceback" not in err
    lines = [x for x in err.strip().splitlines() if not x.startswith("warning: ")]
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    for fragment in fragments:
        assert fragment in lines[0], lines[0]


@pytest.mark.parametrize(("args", "fragments"), [
    (["--seed", "-1"], ["--seed: Input should be greater than or equal to 0 (got -1)"]),
    (["--scale", "nan"], ["--scale: expected a finite number > 0, got nan"]),
    (["--scale", "inf"], ["--scale: expected a finite number > 0, got inf"]),
    (["--scale", "0"], ["--scale: expected a finite number > 0, got 0"]),
    (["--scale", "-2"], ["--scale: expected a finite number > 0, got -2"]),
    (["--scale", "0.4"], ["suite.yaml", "scale 0.4 leaves no episode in any stage",
                          "a scale >= 0.5 keeps one"]),
    (["--episode-timeout", "-1"], ["--episode-timeout: expected seconds >= 0"]),
    (["--episode-timeout", "nan"], ["--episode-timeout: expected seconds >= 0"]),
    (["--workers", "-1"], ["--workers: expected an integer >= 0, got -1"]),
    (["--workers", "0", "--episode-timeout", "5"], ["--episode-timeout: an episode in this "
                                                    "process (--workers 0) cannot be stopped"]),
    (["--workers", "0", "--backend", "ray"], ["--workers: expected an integer >= 1, got 0"]),
])
def test_bad_options(args: list[str], fragments: list[str], files: tuple[Path, Path],
                     tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                     capsys: pytest.CaptureFixture[str]) -> None:
    suite, contest = files
    code, _, err = _bench(monkeypatch, capsys, str(suite), "--contest", str(contest),
                          "-o", str(tmp_path / "run"), "--no-progress", *args)
    _one_error_line(code, err, *fragments)
    assert not (tmp_path / "run").exists()  # nothing written


def test_out_is_a_file(files: tuple[Path, Path], tmp_path: Path,
                       monkeypatch: pytest.MonkeyPatch,
                       capsys: pytest.CaptureFixture[str]) -> None:
    suite, contest = files
    target = tmp_path / "taken"
    target.write_text("mine")
    code, _, err = _bench(monkeypatch, capsys, str(suite), "--contest", str(contest),
                          "-o", str(target), "--no-progress")
    _one_error_line(code, err, "-o/--out", str(target), "is a file")
    assert target.read_text() == "mine"
    with pytest.raises(ArenaError, match="is a file; the run folder must be a folder"):
        run_benchmark(suite, contest, target)
    with pytest.raises(ArenaError, match="cannot create the run folder"):
        run_benchmark(suite, contest, target / "run")


@pytest.mark.parametrize(("edit", "fragments"), [
    ({"seed": "7"}, ["run.json: seed: Input should be a valid integer", "'7'"]),
    ({"seed": -3}, ["run.json: seed: Input should be greater than or equal to 0"]),
    ({"seed": True}, ["run.json: seed: Input should be a valid integer", "True"]),
    ({"seed": 1.5}, ["run.json: seed: Input should be a valid integer", "1.5"]),
    ({"seed": None}, ["run.json: seed: Input should be a valid integer"]),
    ({"scale": math.nan}, ["run.json: scale:", "finite"]),
    ({"scale": 0}, ["run.json: scale: Input should be greater than 0"]),
    ({"scale": "1"}, ["run.json: scale: Input should be a valid number"]),
    ({"contest": 3}, ["run.json: contest: Input should be a valid string"]),
    ({"seed": "DROP"}, ["run.json: seed: required key is missing"]),
])
def test_resume_with_a_bad_manifest_field(edit: dict[str, object], fragments: list[str],
                                          finished_run: Path, tmp_path: Path,
                                          monkeypatch: pytest.MonkeyPatch,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    run = tmp_path / "run"
    _copy_run(finished_run, run)
    data = json.loads((run / "run.json").read_text())
    for key, value in edit.items():
        if value == "DROP":
            del data[key]
        else:
            data[key] = value
    (run / "run.json").write_text(json.dumps(data))
    code, _, err = _bench(monkeypatch, capsys, "quick", "--resume", str(run), "--no-progress")
    _one_error_line(code, err, str(run / "run.json"), *fragments)
    with pytest.raises(ArenaError, match=r"run\.json"):
        read_manifest(run)


@pytest.mark.parametrize(("content", "fragment"), [
    (b"{not json", "unreadable run manifest"),
    (b"\xff\xfe\x00garbage", "unreadable run manifest"),
    (b"[1, 2]", "the run manifest is not a JSON object (got list)"),
    (b"[" * 100_000 + b"]" * 100_000, "unreadable run manifest"),
])
def test_resume_with_a_corrupt_manifest(content: bytes, fragment: str, finished_run: Path,
                                        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    run = tmp_path / "run"
    _copy_run(finished_run, run)
    (run / "run.json").write_bytes(content)
    code, _, err = _bench(monkeypatch, capsys, "quick", "--resume", str(run), "--no-progress")
    _one_error_line(code, err, str(run / "run.json"), fragment)


@pytest.mark.parametrize(("content", "fragment"), [
    ("{truncated", "unreadable episode row"),
    ("[]", "expected an episode row (a JSON object), got list"),
    ('{"contestant": "pp"}', "field 'local_planner': expected string, got None"),
    ("EPISODE_STR", "field 'episode': expected int64, got '0'"),
    ("METRIC_STR", "metric 'success': expected a number or null, got 'yes'"),
    ("OTHER_PLACE", "the row is of other/open/0, not of the episode its file name says"),
    ("UNSAFE_NAME", "contestant name '../x' cannot be a file name"),
])
def test_resume_with_a_corrupt_episode_row(content: str, fragment: str, finished_run: Path,
                                           tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    run = tmp_path / "run"
    _copy_run(finished_run, run)
    row_file = run / "episodes" / "pp" / "open" / "0000.json"
    row = json.loads(row_file.read_text())
    if content == "EPISODE_STR":
        content = json.dumps({**row, "episode": "0"})
    elif content == "METRIC_STR":
        content = json.dumps({**row, "success": "yes"})
    elif content == "OTHER_PLACE":
        content = json.dumps({**row, "contestant": "other"})
    elif content == "UNSAFE_NAME":
        content = json.dumps({**row, "contestant": "../x"})
    row_file.write_text(content)
    suite = json.loads((run / "run.json").read_text())["suite"]
    code, _, err = _bench(monkeypatch, capsys, suite, "--resume", str(run), "--no-progress")
    _one_error_line(code, err, str(row_file), fragment, "delete the file to run that episode")
    with pytest.raises(ArenaError, match="delete the file"):
        load_results(run)


def test_scale_that_drops_a_stage_warns_once_per_stage(files: tuple[Path, Path],
                                                       tmp_path: Path,
                                                       monkeypatch: pytest.MonkeyPatch,
                                                       capsys: pytest.CaptureFixture[str]
                                                       ) -> None:
    suite, contest = files
    with pytest.warns(UserWarning, match=r"scale 0\.5 drops stage 'tail' \(1 episode\(s\)") as w:
        check_scale(load_suite(suite, scale_episodes=0.5), str(suite))
    assert len(w) == 1
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_scale(load_suite(suite, scale_episodes=1.0), str(suite))  # nothing dropped
    run = tmp_path / "run"
    code, _, err = _bench(monkeypatch, capsys, str(suite), "--contest", str(contest),
                          "-o", str(run), "--scale", "0.5", "--no-progress", "-j", "0")
    assert code == 0, err
    assert err.strip().splitlines() == [
        f"warning: {suite.resolve()}: scale 0.5 drops stage 'tail' (1 episode(s) x 0.5 < 1)"]
    assert load_results(run)["stage"].to_pylist() == ["open"]


def _copy_run(src: Path, dst: Path) -> None:
    import shutil

    shutil.copytree(src, dst)


def test_store_rows_are_checked_on_load(tmp_path: Path) -> None:
    row = {"contestant": "c", "local_planner": "x", "inter_planner": "bypass", "stage": "s",
           "episode": 0, "seed": None, "map": "m", "robot": "r", "outcome": "error",
           "time": math.nan, "path_length": math.nan, "collisions": 0, "wall_time": 0.0,
           "error": "worker died (exit code -9: SIGKILL (out of memory?))", "m1": None}
    commit_episode(tmp_path, row, None)  # an error row as the runner writes it loads
    t = load_results(tmp_path)
    assert t["error"].to_pylist() == [row["error"]] and t["seed"].to_pylist() == [None]
    commit_episode(tmp_path, {**row, "episode": 1, "collisions": True}, None)
    with pytest.raises(ArenaError, match=r"0001\.json: field 'collisions': expected int64"):
        load_results(tmp_path)
