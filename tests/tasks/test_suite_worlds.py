"""Suites that name worlds by folder name (Arena's layout): ``--worlds DIR`` and its config keys."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

from arena import cli
from arena.config.schema import ExperimentConfig
from arena.core.errors import ConfigError
from arena.eval.store import load_results, read_manifest
from arena.maps.sources import WORLDS_DIR
from arena.robots.presets import load_robot
from arena.tasks.generator import TaskGenerator
from arena.tasks.suite import load_benchmark, load_suite

START, GOAL = (1.5, 1.5, 0.0), (4.5, 4.5, 0.0)
SCENARIO = {
    "robots": [{"start": list(START), "goal": list(GOAL)}],
    "obstacles": {
        "static": [], "interactive": [],
        "dynamic": [{"name": "p1", "pos": [1.5, 4.5, 0.0], "type": "adult", "model": "actor1",
                     "waypoints": [[4.5, 1.5, 0.0]], "vmax": 0.3}],
    },
}


def _world(root: Path, name: str, size_m: float) -> Path:
    """``root/name`` in Arena's layout: a walled square room (0.1 m cells) and one scenario."""
    n = round(size_m / 0.1)
    img = np.full((n, n), 254, dtype=np.uint8)
    img[[0, -1], :] = img[:, [0, -1]] = 0
    (root / name / "map").mkdir(parents=True)
    (root / name / "map" / "map.pgm").write_bytes(f"P5 {n} {n} 255\n".encode() + img.tobytes())
    (root / name / "map" / "map.yaml").write_text(
        "image: map.pgm\nresolution: 0.1\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
    (root / name / "scenarios").mkdir()
    (root / name / "scenarios" / "one.json").write_text(json.dumps(SCENARIO))
    return root / name


SUITE = """\
stages:
  - name: scen
    episodes: 1
    robot: jackal
    map: tiny_room
    tm_robots: scenario
    tm_obstacles: scenario
    timeout: 15
    config: {SCENARIO: {file: one.json}}
"""


@pytest.fixture
def layout(tmp_path: Path) -> tuple[Path, Path]:
    """``(worlds folder, suite file)``: the suite lives elsewhere, as in Arena's two repos."""
    worlds = tmp_path / "arena-simulation-setup" / "worlds"
    _world(worlds, "tiny_room", 6.0)
    suites = tmp_path / "arena-rosnav" / "benchmark" / "suites"
    suites.mkdir(parents=True)
    (suites / "s.yaml").write_text(SUITE)
    return worlds, suites / "s.yaml"


def _suite_with_map(path: Path, world: str) -> Path:
    path.write_text(SUITE.replace("map: tiny_room", f"map: {world}"))
    return path


def test_bench_runs_a_suite_on_arena_worlds(layout: tuple[Path, Path], tmp_path: Path,
                                            monkeypatch: pytest.MonkeyPatch,
                                            capsys: pytest.CaptureFixture[str]) -> None:
    worlds, suite = layout
    contest = tmp_path / "contest.yaml"
    contest.write_text("contestants:\n  - {name: pp, local_planner: pure_pursuit}\n")
    run = tmp_path / "run"
    monkeypatch.setattr(sys, "argv", [
        "arena", "bench", str(suite), "--contest", str(contest), "--worlds", str(worlds),
        "--workers", "0", "--no-progress", "-o", str(run)])
    code = 0
    try:
        cli.main()
    except SystemExit as e:
        code = int(e.code or 0)
    err = capsys.readouterr().err
    assert code == 0, err
    rows = load_results(run).to_pylist()
    assert len(rows) == 1
    assert rows[0]["map"] == "tiny_room" and rows[0]["stage"] == "scen"
    assert rows[0]["outcome"] != "error", rows[0]["error"]
    assert read_manifest(run)["worlds"] == str(worlds.resolve())
    # the episode is the scenario file of DIR/tiny_room/scenarios/ (start, goal, one person)
    (_, cfg), = load_suite(suite, worlds=worlds).stage_experiments(ExperimentConfig())
    ep = TaskGenerator.from_config(cfg, [load_robot("jackal")]).episode(0)
    assert (ep.robots[0].start.x, ep.robots[0].start.y) == START[:2]
    assert (ep.robots[0].goal.x, ep.robots[0].goal.y) == GOAL[:2]
    assert len(ep.agents) == 1 and ep.map_name == "tiny_room"


def test_resume_keeps_the_runs_worlds_folder(layout: tuple[Path, Path], tmp_path: Path,
                                             monkeypatch: pytest.MonkeyPatch,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    from arena.eval.runner import run_benchmark

    worlds, suite = layout
    run = tmp_path / "run"
    contest = tmp_path / "c.yaml"
    contest.write_text("contestants:\n  - {name: pp, local_planner: pure_pursuit}\n")
    other = tmp_path / "other_worlds"
    _world(other, "tiny_room", 6.0)
    run_benchmark(suite, contest, run, workers=0, worlds=worlds)
    with pytest.raises(Exception, match="cannot resume: field 'worlds'"):
        run_benchmark(suite, contest, run, workers=0, worlds=other, resume=True)
    # resumed without --worlds: the manifest's folder, nothing left to run
    monkeypatch.setattr(sys, "argv", ["arena", "bench", str(suite), "--resume", str(run),
                                      "--workers", "0", "--no-progress"])
    code = 0
    try:
        cli.main()
    except SystemExit as e:
        code = int(e.code or 0)
    assert code == 0, capsys.readouterr().err
    assert len(load_results(run).to_pylist()) == 1


def test_resolution_order(layout: tuple[Path, Path], tmp_path: Path) -> None:
    worlds, suite = layout
    # DIR wins over a packaged world of the same name ...
    assert (WORLDS_DIR / "empty_room").is_dir()
    _world(worlds, "empty_room", 4.0)
    f = _suite_with_map(suite, "empty_room")
    block = load_suite(f, worlds=worlds).stage_map(0, {})
    assert block == {"type": "world", "name": str(worlds.resolve() / "empty_room")}
    assert load_suite(f).stage_map(0, {}) == {"type": "world", "name": "empty_room"}
    # a packaged world that DIR does not hold is still found
    f = _suite_with_map(suite, "corridor")
    assert load_suite(f, worlds=worlds).stage_map(0, {}) == {"type": "world", "name": "corridor"}
    # ... and over a world next to the suite (<suite dir>/../worlds/<name>)
    _world(suite.parent.parent / "worlds", "tiny_room", 8.0)
    f = _suite_with_map(suite, "tiny_room")
    assert load_suite(f, worlds=worlds).stage_map(0, {})["name"] == str(
        worlds.resolve() / "tiny_room")
    assert load_suite(f).stage_map(0, {})["name"] == str(suite.parent.parent / "worlds"
                                                         / "tiny_room")


def test_config_keys(layout: tuple[Path, Path], tmp_path: Path) -> None:
    worlds, suite = layout
    rel = Path("..", "..", "..", "arena-simulation-setup", "worlds")
    # the suite's own key, relative to the suite file
    suite.write_text(SUITE + f"worlds: {rel.as_posix()}\n")
    s = load_suite(suite)
    assert s.worlds == worlds.resolve()
    assert s.stage_map(0, {})["name"] == str(worlds.resolve() / "tiny_room")
    # a benchmark config.yaml's suite.worlds replaces it; --worlds replaces both
    other = tmp_path / "mine"
    _world(other, "tiny_room", 5.0)
    bench = suite.parent.parent / "config.yaml"
    bench.write_text("suite: {config: s, worlds: ../../mine}\n")
    assert load_benchmark(bench)[0].worlds == other.resolve()
    assert load_benchmark(bench, worlds=worlds)[0].worlds == worlds.resolve()
    bench.write_text("suite: {config: s, worlds: gone}\n")
    with pytest.raises(ConfigError, match=r"config\.yaml: suite\.worlds: no folder .*gone"):
        load_benchmark(bench)
    suite.write_text(SUITE + "worlds: gone\n")
    with pytest.raises(ConfigError, match=r"s\.yaml: worlds: no folder .*gone"):
        load_suite(suite)


def test_errors(layout: tuple[Path, Path], tmp_path: Path) -> None:
    worlds, suite = layout
    with pytest.raises(ConfigError) as e:
        load_suite(suite, worlds=tmp_path / "nope")
    assert str(e.value).startswith("--worlds: no folder ") and "nope" in str(e.value)
    assert "<world>/map/map.yaml" in str(e.value)
    (tmp_path / "file").write_text("x")
    with pytest.raises(ConfigError, match=r"--worlds: .*file.* is a file"):
        load_suite(suite, worlds=tmp_path / "file")

    def stage_error(world: str, folder: Path | None = worlds) -> ConfigError:
        s = load_suite(_suite_with_map(suite, world), worlds=folder)
        with pytest.raises(ConfigError) as e:
            s.stage_experiments(ExperimentConfig())
        assert e.value.source == str(suite) and e.value.path == "stages[0].map"
        assert "\n" not in str(e.value)
        return e.value

    err = stage_error("tiny_rom")
    assert f"no world 'tiny_rom' in the worlds folder {worlds.resolve()} (--worlds; it holds " \
           "1 world)" in err.message and "did you mean 'tiny_room'" in err.message
    err = stage_error("tiny_room", worlds.parent)  # the repository, not its worlds/ folder
    assert f"did you mean {worlds.resolve()}?" in err.message
    for bad in ("..", ".hidden", "a b"):
        err = stage_error(bad)
        assert f"world name {bad!r} cannot be a file name" in err.message
    err = stage_error("arena_hospital_small", None)  # Arena's name, no worlds folder given
    assert "give that folder with --worlds DIR" in err.message


def test_cli_errors_are_one_line(layout: tuple[Path, Path], tmp_path: Path,
                                 monkeypatch: pytest.MonkeyPatch,
                                 capsys: pytest.CaptureFixture[str]) -> None:
    worlds, suite = layout
    monkeypatch.setattr(cli.err_console, "width", 400)
    for folder, fragment in ((tmp_path / "nope", "--worlds: no folder"),
                             (worlds.parent, "no world 'tiny_room' in the worlds folder")):
        monkeypatch.setattr(sys, "argv", ["arena", "bench", str(suite), "--worlds", str(folder),
                                          "--workers", "0", "-o", str(tmp_path / "r")])
        with pytest.raises(SystemExit) as e:
            cli.main()
        err = capsys.readouterr().err
        assert e.value.code == 2 and "Traceback" not in err
        lines = err.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("error: ") and fragment in lines[0], err


def test_tasks_preview_takes_the_worlds_folder(layout: tuple[Path, Path],
                                               monkeypatch: pytest.MonkeyPatch,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    worlds, suite = layout
    monkeypatch.setattr(cli.console, "width", 200)
    monkeypatch.setattr(sys, "argv", ["arena", "tasks", "preview", str(suite), "--worlds",
                                      str(worlds)])
    code = 0
    try:
        cli.main()
    except SystemExit as e:
        code = int(e.code or 0)
    out = capsys.readouterr().out
    assert code == 0, out
    assert "tiny_room" in out and "(1.5, 1.5)" in out and "(4.5, 4.5)" in out
    assert "total: 1 episodes in 1 stages, 0 obstacles, 1 pedestrians" in out
