"""The command line as a user meets it: outputs, tables and one-line errors."""

import csv
import json

import pytest

from arena import cli
from tests.cli_kit import run_cli


def test_run_writes_trajectory_summary_and_video(monkeypatch, capsys, tmp_path):
    out = tmp_path / "run"
    code, stdout, _ = run_cli(
        monkeypatch,
        capsys,
        "run",
        "task.obstacles.dynamic=4",
        "task.timeout=8",
        "--out",
        str(out),
        "--robot",
        "burger",
        "output.width_px=320",
        "output.video_format=gif",
    )
    assert code == 0, stdout
    ep = out / "episode_000"
    assert (ep / "trajectory.csv").is_file()
    assert (ep / "agents.csv").is_file()
    assert (ep / "video.gif").is_file()
    assert (out / "config.yaml").is_file()
    rows = list(csv.DictReader((ep / "trajectory.csv").open()))
    assert len(rows) > 10
    assert float(rows[0]["time"]) == 0.0
    info = json.loads((ep / "episode.json").read_text())
    assert info["robot"] == "burger"
    assert "video" in stdout and "trajectory" in stdout


def test_robots_and_plugins_tables(monkeypatch, capsys):
    code, out, _ = run_cli(monkeypatch, capsys, "robots")
    assert code == 0
    for name in ("burger", "jackal", "go1", "f1tenth"):
        assert name in out
    code, out, _ = run_cli(monkeypatch, capsys, "plugins")
    assert code == 0
    for name in ("native2d", "astar", "pure_pursuit", "waypoint_walker", "diff_drive", "ackermann"):
        assert name in out


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        (["run", "robot=burgr"], "did you mean 'burger'"),
        (["run", "task.obstacles.agnets=3"], "task.obstacles.agnets: unknown key"),
        (["run", "--map", "/nonexistent/map.yaml"], "map.yaml"),
        (["run", "/nonexistent/exp.yaml"], "file not found"),
    ],
)
def test_bad_input_gives_one_line_error(monkeypatch, capsys, args, expected):
    code, out, err = run_cli(monkeypatch, capsys, *args)
    assert code == 2
    assert "Traceback" not in err + out
    assert expected in " ".join(err.split())
    assert err.strip().startswith("error:")


def test_missing_map_image_is_reported(monkeypatch, capsys, tmp_path):
    (tmp_path / "map.yaml").write_text(
        "image: gone.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    code, _, err = run_cli(monkeypatch, capsys, "run", "--map", str(tmp_path / "map.yaml"))
    assert code == 2
    flat = " ".join(err.split())
    assert "map.yaml" in flat and "image" in flat and "gone.pgm" in flat
    assert "Traceback" not in err


def test_malformed_config_yaml(monkeypatch, capsys, tmp_path):
    p = tmp_path / "bad.yaml"
    p.write_text("seed: 1\n  robot: x\n")
    code, _, err = run_cli(monkeypatch, capsys, "run", str(p))
    assert code == 2
    assert "malformed YAML at line" in " ".join(err.split())


def test_maps_list_and_generate(monkeypatch, capsys, tmp_path):
    code, out, _ = run_cli(monkeypatch, capsys, "maps", "list")
    assert code == 0
    for name in (
        "barn",
        "rosnav_indoor",
        "rosnav_outdoor",
        "outdoor",
        "canteen",
        "warehouse",
        "office",
        "small_office",
    ):
        assert name in out
    world = tmp_path / "w"
    code, out, err = run_cli(
        monkeypatch,
        capsys,
        "maps",
        "generate",
        "canteen",
        "chair_chance=1",
        "--seed",
        "3",
        "-o",
        str(world),
        "--width-px",
        "300",
    )
    assert code == 0, err
    assert (world / "map" / "map.yaml").is_file()
    assert (world / "preview.png").is_file()
    data = json.loads((world / "map" / "obstacles.json").read_text())
    models = [o["model"] for o in data["obstacles"]["static"]]
    assert models.count("chair") == 4 * models.count("table") > 0
    # The generated world loads as a map.
    code, out, _ = run_cli(
        monkeypatch,
        capsys,
        "run",
        "--map",
        str(world),
        "--no-video",
        "task.obstacles.dynamic=2",
        "task.timeout=3",
        "task.robots.min_goal_distance=3",
        "--out",
        str(tmp_path / "run"),
    )
    assert code == 0, out


def test_maps_generate_bad_parameter(monkeypatch, capsys, tmp_path):
    code, _, err = run_cli(
        monkeypatch, capsys, "maps", "generate", "barn", "fill_pc=0.2", "-o", str(tmp_path)
    )
    assert code == 2
    assert "fill_pc: unknown key" in " ".join(err.split())
    code, _, err = run_cli(monkeypatch, capsys, "maps", "generate", "warehous", "-o", str(tmp_path))
    assert code == 2
    assert "did you mean 'warehouse'" in " ".join(err.split())


def test_scenario_validate(monkeypatch, capsys, tmp_path):
    good = tmp_path / "ok.json"
    good.write_text(
        json.dumps(
            {
                "robots": [{"start": [1.0, 1.0, 0.0], "goal": [4.0, 4.0, 0.0]}],
                "obstacles": {
                    "static": [{"name": "s1", "model": "shelf", "pos": [2.5, 2.5, 0.0]}],
                    "dynamic": [
                        {
                            "name": "p",
                            "pos": [3.0, 1.0, 0.0],
                            "type": "adult",
                            "waypoints": [[3.0, 4.0, 0.0]],
                            "waypoint_mode": 2,
                        }
                    ],
                    "interactive": [],
                },
            }
        )
    )
    code, out, _ = run_cli(monkeypatch, capsys, "scenario", "validate", str(good))
    assert code == 0
    assert "valid" in out and "waypoint_mode" in out  # mode 2 is accepted with a warning
    bad = tmp_path / "bad.json"
    bad.write_text(
        json.dumps({"obstacles": {"static": [{"name": "s", "model": "shelv", "pos": [1, 1, 0]}]}})
    )
    code, _, err = run_cli(monkeypatch, capsys, "scenario", "validate", str(bad))
    assert code == 2
    flat = " ".join(err.split())
    assert "bad.json" in flat and "obstacles.static[0].model" in flat and "shelf" in flat


def test_scenario_validate_names_keys_arena_ignores_once(monkeypatch, capsys, tmp_path):
    path = tmp_path / "extra.json"
    ped = {"name": "p", "pos": [3.0, 1.0, 0.0], "waypoints": [[3.0, 4.0, 0.0]],
           "yaml_file": "person.yaml", "number_of_peds": 1}
    path.write_text(json.dumps({
        "robots": [{"start": [1.0, 1.0, 0.0], "goal": [4.0, 4.0, 0.0]}],
        "obstacles": {"dynamic": [ped]},
        "format": "arena-rosnav",
    }))
    monkeypatch.setattr(cli.console, "width", 1000)  # a long tmp path is not wrapped mid-name
    code, out, err = run_cli(monkeypatch, capsys, "scenario", "validate", str(path))
    assert code == 0, err
    flat = " ".join(out.split())
    assert flat.count("keys Arena does not read, ignored: format, number_of_peds, yaml_file") == 1
    assert flat.endswith("extra.json: valid (1 warning(s))")
    assert "UserWarning" not in err and "ignored" not in err  # listed once, on stdout


def test_warnings_are_one_line(monkeypatch, capsys):
    import warnings

    monkeypatch.setattr(
        cli, "app", lambda **kw: warnings.warn("scale 0.1 drops stage 's'", stacklevel=1)
    )
    code, _, err = run_cli(monkeypatch, capsys, "run")
    assert code == 0
    assert err == "warning: scale 0.1 drops stage 's'\n"


def test_tasks_list_and_preview(monkeypatch, capsys):
    code, out, _ = run_cli(monkeypatch, capsys, "tasks", "list")
    assert code == 0
    for name in ("random", "scenario", "staged", "benchmark", "dynamic_map"):
        assert name in out
    monkeypatch.setattr(cli.console, "width", 200)
    code, out, _ = run_cli(monkeypatch, capsys, "tasks", "preview", "quick", "--seed", "3",
                           "--contest", "basic")
    assert code == 0, out
    assert "corridor_scenario" in out and "canteen" in out
    assert "total: 31 episodes in 4 stages" in out
    assert "1 contestants x 31 episodes" in out
    code, out2, _ = run_cli(monkeypatch, capsys, "tasks", "preview", "quick", "--seed", "3",
                            "--scale", "0.1")
    assert code == 0 and "total: 3 episodes" in out2


def test_tasks_preview_errors_are_one_line(monkeypatch, capsys, tmp_path):
    code, _, err = run_cli(monkeypatch, capsys, "tasks", "preview", "nosuch")
    assert code == 2 and err.startswith("error:") and "packaged" in err
    bad = tmp_path / "s.yaml"
    bad.write_text("stages:\n  - {name: x, episodes: 1, map: atlantis}\n")
    code, _, err = run_cli(monkeypatch, capsys, "tasks", "preview", str(bad))
    assert code == 2 and "stages[0].map" in err and str(bad) in err.replace("\n", "")
