"""``arena maps export``: the SDF and MJCF files it writes, parsed back and checked."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from arena.export.world3d import export_scene, load_export_source
from arena.maps.io import load_map
from arena.maps.obstacles import obstacle_model
from arena.maps.sources import resolve_world
from arena.sim.mujoco.walls import merge_boxes
from tests.cli_kit import run_cli
from tests.mujoco_kit import require_mujoco


def floats(el: ET.Element | None) -> list[float]:
    assert el is not None and el.text is not None
    return [float(v) for v in el.text.split()]


def test_sdf_of_a_world_with_a_scenario(monkeypatch, capsys, tmp_path: Path) -> None:
    code, out, err = run_cli(monkeypatch, capsys, "maps", "export", "small_office",
                             "--scenario", "default", "--format", "sdf", "-o", str(tmp_path),
                             "--wall-height", "2.5")
    assert code == 0, err
    assert "28 wall boxes, 1 obstacles, 3 walking people" in out
    root = ET.parse(tmp_path / "world.sdf").getroot()
    assert root.tag == "sdf" and root.get("version") == "1.6"
    world = root.find("world")
    assert world is not None and world.get("name") == "small_office"
    models = {m.get("name"): m for m in world.findall("model")}
    assert set(models) == {"ground_plane", "walls", "obstacle_shelf_1"}
    # walls: one static model, a collision and a visual box per merged box, 2.5 m tall
    walls = models["walls"]
    assert walls.findtext("static") == "true"
    boxes = walls.findall("link/collision")
    grid = load_map(resolve_world("small_office"))
    assert len(boxes) == len(merge_boxes(grid.occupied)) == 28
    area = 0.0
    for c in boxes:
        sx, sy, sz = floats(c.find("geometry/box/size"))
        assert sz == pytest.approx(2.5) and floats(c.find("pose"))[2] == pytest.approx(1.25)
        area += sx * sy
    assert area == pytest.approx(grid.occupied.sum() * grid.resolution**2)
    assert len(walls.findall("link/visual/material/diffuse")) == 28
    # the shelf: placed at its scenario pose, its parts within its footprint and height
    shelf = models["obstacle_shelf_1"]
    assert floats(shelf.find("pose")) == pytest.approx([2.0, 5.5, 0.0, 0.0, 0.0, 0.0])
    lib = obstacle_model("shelf")
    top = max(floats(c.find("pose"))[2] + floats(c.find("geometry/box/size"))[2] / 2
              for c in shelf.findall("link/collision"))
    assert top == pytest.approx(lib.height)
    # people: actors walking their waypoints at a constant speed, facing where they go
    actors = {a.get("name"): a for a in world.findall("actor")}
    assert sorted(actors) == ["person_0", "person_1", "person_2"]
    wps = actors["person_0"].findall("script/trajectory/waypoint")
    poses = np.array([floats(w.find("pose")) for w in wps])
    times = np.array([floats(w.find("time"))[0] for w in wps])
    np.testing.assert_allclose(poses[:, :2], [[-6.0, 0.0], [8.0, 0.0], [-6.0, 0.0]])
    assert poses[0, 5] == pytest.approx(0.0) and poses[1, 5] == pytest.approx(np.pi)
    speeds = np.hypot(*np.diff(poses[:, :2], axis=0).T) / np.diff(times)
    assert times[0] == 0.0 and speeds == pytest.approx(np.full(2, speeds[0]))
    assert 0.1 < speeds[0] < 3.0
    assert actors["person_0"].findtext("script/loop") == "true"
    assert actors["person_0"].findtext("skin/filename") == "walk.dae"


def test_sdf_without_people_says_so(monkeypatch, capsys, tmp_path: Path) -> None:
    code, out, _ = run_cli(monkeypatch, capsys, "maps", "export", "canteen", "width=12",
                           "height=10", "-o", str(tmp_path))
    assert code == 0
    assert "no pedestrians with waypoints" in " ".join(out.split())
    world = ET.parse(tmp_path / "world.sdf").getroot().find("world")
    assert world is not None and world.findall("actor") == []
    assert len(world.findall("model")) > 10  # ground, walls and the canteen's tables and chairs


def test_mjcf_parses_back_to_the_builders_geoms(monkeypatch, capsys, tmp_path: Path) -> None:
    mujoco = require_mujoco(module=False)
    code, _, err = run_cli(monkeypatch, capsys, "maps", "export", "small_office", "--scenario",
                           "default", "--format", "mjcf", "-o", str(tmp_path))
    assert code == 0, err
    model = mujoco.MjModel.from_xml_path(str(tmp_path / "world.xml"))
    scene = export_scene(load_export_source("small_office", [], scenario="default"))
    geoms = [g for b in scene.bodies for g in b.geoms]
    assert model.ngeom == len(geoms) + 1  # + the floor
    for g in geoms:
        mg = model.geom(g.name)
        np.testing.assert_allclose(mg.size[: len(g.size)], g.size, atol=1e-9)
        np.testing.assert_allclose(mg.pos, g.pos, atol=1e-9)
    assert model.nmocap == 3 * 3  # three people, no robot


@pytest.mark.parametrize(("args", "message"), [
    (["nowhere"], "error: command line: WORLD 'nowhere': not a packaged world, world folder, "
                  "map.yaml or map generator; packaged worlds: campus"),
    (["corridor", "--format", "obj"], "error: command line: --format: expected sdf or mjcf, "
                                      "got 'obj'"),
    (["corridor", "width=3"], "error: command line: corridor: a map takes no parameters"),
    (["corridor", "--wall-height", "0"], "error: command line: --wall-height: expected a height "
                                         "in metres in (0, 100]"),
    (["canteen", "width=1e9"], "at most 50,000,000 cells are allowed"),
    (["corridor", "--scenario", "nope"], "no scenario 'nope' in world 'corridor'"),
])
def test_bad_input_is_one_line(monkeypatch, capsys, tmp_path: Path, args: list[str],
                               message: str) -> None:
    code, _, err = run_cli(monkeypatch, capsys, "maps", "export", *args, "-o",
                           str(tmp_path / "out"))
    assert code != 0
    assert len(err.strip().splitlines()) == 1 and message in err
    assert not (tmp_path / "out").exists()


def test_output_folder_that_is_a_file(monkeypatch, capsys, tmp_path: Path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("x")
    code, _, err = run_cli(monkeypatch, capsys, "maps", "export", "corridor", "-o", str(blocker))
    assert code != 0 and "export folder: exists and is not a folder" in err
    assert len(err.strip().splitlines()) == 1
