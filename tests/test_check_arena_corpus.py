"""``tools/check_arena_corpus.py`` on a tiny synthetic corpus (the real one is not in the repo)."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

import numpy as np
import pytest

TOOL = Path(__file__).resolve().parents[1] / "tools" / "check_arena_corpus.py"


@pytest.fixture(scope="module")
def tool():
    spec = importlib.util.spec_from_file_location("check_arena_corpus", TOOL)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up while it executes
    spec.loader.exec_module(module)
    yield module
    del sys.modules[spec.name]


def _world(folder: Path, size_m: float) -> None:
    n = round(size_m / 0.1)
    img = np.full((n, n), 254, dtype=np.uint8)
    img[[0, -1], :] = img[:, [0, -1]] = 0
    (folder / "map").mkdir(parents=True)
    (folder / "map" / "map.pgm").write_bytes(f"P5 {n} {n} 255\n".encode() + img.tobytes())
    (folder / "map" / "map.yaml").write_text(
        "image: map.pgm\nresolution: 0.1\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n")


SCENARIO = {"robots": [{"start": [2.0, 2.0, 0.0], "goal": [8.0, 8.0, 0.0]}],
            "obstacles": {"dynamic": [{"name": "p", "pos": [2.0, 8.0], "waypoints": [[8, 2]]}]}}


@pytest.fixture(scope="module")
def corpus(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("corpus") / "arena_files"
    (root).mkdir()
    (root / "MANIFEST.tsv").write_text("kind\tstored_as\n")
    _world(root / "worlds" / "setup" / "worlds" / "room", 16.0)
    scen = root / "scenarios" / "setup" / "worlds" / "room" / "scenarios"
    scen.mkdir(parents=True)
    (scen / "default.json").write_text(json.dumps(SCENARIO))
    (scen / "copy.json").write_text(json.dumps(SCENARIO))
    (scen / "legacy.json").write_text(json.dumps({"pedsim_agents": [], "robot_position": [1, 1]}))
    bench = root / "benchmark" / "rosnav" / "configs" / "benchmark"
    (bench / "suites").mkdir(parents=True)
    (bench / "suites" / "s.yaml").write_text(
        "stages:\n  - {name: a, episodes: 2, robot: jackal, map: room, tm_robots: scenario,"
        " tm_obstacles: scenario}\n  - {name: b, episodes: 1, map: hall}\n")
    return root


def test_every_file_gets_one_line_and_expected_failures_are_marked(tool, corpus, capsys,
                                                                  monkeypatch):
    monkeypatch.setattr(tool, "EXPECTED", (
        ("scenarios/*/legacy.json", "none of the keys Arena reads", "pre-2023 format"),
        ("scenarios/*/default.json", "anything", "a stale entry"),
    ))
    code = tool.main([str(corpus), "--shared-worlds", str(corpus / "none"), "-v"])
    out = capsys.readouterr().out
    lines = {line.split()[1]: line.split()[2] for line in out.splitlines()
             if line[:1].strip() and line.split()[0] in tool.KINDS}
    base = "scenarios/setup/worlds/room/scenarios/"
    assert lines == {
        "worlds/setup/worlds/room/map/map.yaml": "OK",
        base + "copy.json": "OK",  # checked first (sorted), default.json is its duplicate
        base + "default.json": "DUP",
        base + "legacy.json": "XFAIL",
        "benchmark/rosnav/configs/benchmark/suites/s.yaml": "FAIL",
    }
    assert "[expected: pre-2023 format]" in out
    # the suite finds 'room' in the worlds folder; 'hall' is nowhere, with the closest names
    suite = next(line for line in out.splitlines() if "suites/s.yaml" in line)
    assert "1/2 stages fail; first: stages[1] b: ConfigError:" in suite
    assert "no world 'hall' in the worlds folder <worlds>" in suite
    assert "  scenario     DUP 1, OK 1, XFAIL 1" in out
    assert code == 1  # a FAIL


def test_a_stale_expected_entry_is_xpass(tool, corpus, capsys, monkeypatch):
    monkeypatch.setattr(tool, "EXPECTED", (("worlds/*/map.yaml", "x", "a stale entry"),
                                           ("gone/*.json", "x", "a file no longer there")))
    tool.main([str(corpus), "--shared-worlds", str(corpus / "none")])
    out = capsys.readouterr().out
    assert "map.yaml  XPASS  " in out and "update EXPECTED" in out
    assert "  EXPECTED entry matching no file (remove it?): gone/*.json\n" in out


def test_missing_corpus_is_one_clear_line(tool, tmp_path, capsys):
    assert tool.main([str(tmp_path / "nope")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: no Arena corpus at ") and "\n" not in err


def test_the_check_leaves_arena_run_as_it_was(tool, corpus, capsys):
    import arena.experiment

    before = arena.experiment.run_experiment
    tool.main([str(corpus), "--shared-worlds", str(corpus / "none")])
    capsys.readouterr()
    assert arena.experiment.run_experiment is before
