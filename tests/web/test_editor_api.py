"""The scenario editor's API: maps from every generator and from uploads (with their limits),
live validation with the project's own checks, and saved scenarios that ``arena run`` runs."""

from __future__ import annotations

import io
import json
import subprocess
import sys

import numpy as np
import pytest
from fastapi.testclient import TestClient
from PIL import Image

from arena.maps.generators import MAP_GENERATORS
from arena.maps.grid import OccupancyGrid
from arena.maps.io import load_map, save_map
from arena.tasks.scenario import load_scenario
from arena.web import editor_maps
from arena.web.editor_store import EditorWorkspace
from arena.web.server import create_app
from arena.web.store import RunStore

WORLD = {"kind": "world", "name": "small_office"}
# small_office: a free corridor along y = 0 and an office around (-10, 3.5); x = -12 is its wall
START, GOAL = [-10.0, 3.5, 0.0], [-7.0, 3.5, 0.0]


def scenario(start=START, goal=GOAL, peds=None) -> dict:
    peds = peds if peds is not None else [
        {"name": "p1", "pos": [-6.0, 0.0, 0.0], "type": "elder",
         "waypoints": [[0.0, 0.0, 0.0], [-6.0, 0.0, 0.0]], "start_up_mode": "wait_timer",
         "wait_time": 1.0}]
    return {"robots": [{"start": start, "goal": goal}],
            "obstacles": {"static": [], "interactive": [], "dynamic": peds}}


@pytest.fixture
def root(tmp_path):
    return tmp_path / "runs"


@pytest.fixture
def client(root):
    root.mkdir()
    return TestClient(create_app(root, pages=False))


def test_worlds_obstacles_and_fields(client):
    worlds = {w["name"]: w for w in client.get("/api/worlds").json()}
    assert "default" in worlds["small_office"]["scenarios"]
    world = client.get("/api/worlds/small_office").json()
    assert world["map"]["resolution"] > 0 and world["map"]["png"]
    assert client.get("/api/worlds/hospital_floor").json()["zones"], "the hospital has zones"
    assert client.get("/api/worlds/nowhere").status_code == 404
    assert client.get("/api/worlds/small_office/scenarios/nothing").status_code == 404
    start = client.get("/api/worlds/small_office/scenarios/default").json()["scenario"]
    assert start["robots"]
    library = {o["name"]: o for o in client.get("/api/obstacles").json()}
    assert len(library["shelf"]["footprint"]) >= 3
    fields = client.get("/api/scenario_fields").json()
    assert {"vmax", "start_up_mode", "waypoint_mode"} <= fields["pedestrian"].keys()
    assert {"adult", "elder"} <= set(fields["types"])
    assert "trigger_zone" in fields["startup_modes"]


def test_seven_generators_listed_with_their_schema(client):
    listed = {g["name"]: g for g in client.get("/api/generators").json()}
    assert len(listed) == 7 and set(listed) == set(MAP_GENERATORS.names())
    for g in listed.values():
        assert "width" in g["schema"]["properties"], g["name"]


@pytest.mark.parametrize("name", MAP_GENERATORS.names())
def test_each_generator_makes_a_saved_map(client, root, name):
    res = client.post("/api/maps/generate", json={
        "generator": name, "seed": 3, "params": {"width": 16.0, "height": 12.0}})
    assert res.status_code == 200, res.text
    body = res.json()
    assert body["ref"] == {"kind": "saved", "name": f"{name}_3"}
    grid = load_map(root / "_maps" / f"{name}_3" / "map.yaml")
    assert (grid.width, grid.height) == (body["map"]["width"], body["map"]["height"])
    assert grid.free.any() and (~grid.free).any()
    assert client.get(f"/api/maps/{name}_3").status_code == 200
    assert f"{name}_3" in client.get("/api/maps").json()


def test_generate_errors_are_one_line(client):
    res = client.post("/api/maps/generate", json={"generator": "bran"})
    assert res.status_code == 404 and "did you mean 'barn'" in res.json()["detail"]
    res = client.post("/api/maps/generate", json={"generator": "barn", "params": {"fill_pct": 5}})
    assert res.status_code == 422 and "fill_pct" in res.json()["detail"]
    res = client.post("/api/maps/generate", json={"generator": "barn", "name": "../x"})
    assert res.status_code == 422 and "not a plain map name" in res.json()["detail"]
    res = client.post("/api/maps/generate", json={"generator": "barn", "seed": "x"})
    assert res.status_code == 422 and "seed" in res.json()["detail"]


def _map_files(tmp_path, size=(40, 30)):
    grid = OccupancyGrid.empty(size[0] * 0.1, size[1] * 0.1, 0.1)
    yaml_path = save_map(grid, tmp_path / "up" / "map.yaml", image_format="png")
    return yaml_path.read_bytes(), (yaml_path.parent / "map.png").read_bytes()


def _upload(client, yaml_bytes, image_bytes, name="room", image_name="map.png"):
    return client.post("/api/maps/upload", data={"name": name},
                       files={"yaml": ("map.yaml", yaml_bytes, "application/yaml"),
                              "image": (image_name, image_bytes, "image/png")})


def test_upload_a_map(client, root, tmp_path):
    yaml_bytes, image_bytes = _map_files(tmp_path)
    res = _upload(client, yaml_bytes, image_bytes)
    assert res.status_code == 200, res.text
    assert res.json()["map"]["width"] == 40
    assert load_map(root / "_maps" / "room" / "map.yaml").height == 30


def _png(width, height) -> bytes:
    buf = io.BytesIO()
    Image.fromarray(np.full((height, width), 254, dtype=np.uint8)).save(buf, format="PNG")
    return buf.getvalue()


def test_upload_limits_are_413(client, tmp_path):
    yaml_bytes, image_bytes = _map_files(tmp_path)
    big_yaml = yaml_bytes + b"#" * editor_maps.MAX_YAML_BYTES
    res = _upload(client, big_yaml, image_bytes)
    assert res.status_code == 413 and "map.yaml" in res.json()["detail"]
    res = _upload(client, yaml_bytes, b"\0" * (editor_maps.MAX_IMAGE_BYTES + 1))
    assert res.status_code == 413 and "map image" in res.json()["detail"]
    res = _upload(client, yaml_bytes, _png(editor_maps.MAX_IMAGE_SIDE + 1, 2))
    assert res.status_code == 413 and "pixels" in res.json()["detail"]


@pytest.mark.parametrize(("yaml_text", "image", "field"), [
    (b"resolution: 0.1\norigin: [0, 0, 0]\n", None, "image"),
    (b"image: ../../etc/map.png\nresolution: 0.1\norigin: [0, 0, 0]\n", None, "image"),
    (b"image: map.png\nresolution: -1\norigin: [0, 0, 0]\n", None, "resolution"),
    (b"image: map.png\nresolution: 0.1\norigni: [0, 0, 0]\n", None, "origni"),
    (b"image: [unclosed\n", None, "map.yaml"),
    (b"image: map.png\nresolution: 0.1\norigin: [0, 0, 0]\n", b"not a png", "image"),
])
def test_bad_uploads_are_422_naming_the_field(client, tmp_path, yaml_text, image, field):
    _, image_bytes = _map_files(tmp_path)
    res = _upload(client, yaml_text, image if image is not None else image_bytes)
    assert res.status_code == 422, res.text
    detail = res.json()["detail"]
    assert field in detail and "\n" not in detail and "Traceback" not in detail
    assert str(tmp_path) not in detail


def test_upload_needs_both_files_and_a_plain_name(client, tmp_path):
    yaml_bytes, image_bytes = _map_files(tmp_path)
    res = client.post("/api/maps/upload", files={"yaml": ("map.yaml", yaml_bytes)})
    assert res.status_code == 422 and "image" in res.json()["detail"]
    assert _upload(client, yaml_bytes, image_bytes, name="/etc/x").status_code == 422


def _validate(client, data, ref=WORLD, **extra):
    res = client.post("/api/scenarios/validate", json={"scenario": data, "map": ref, **extra})
    assert res.status_code == 200, res.text
    return res.json()


def test_validation_ok_and_robot_in_a_wall(client):
    ok = _validate(client, scenario())
    assert ok["ok"] and ok["problems"] == [], ok
    assert ok["robot"]["name"] and ok["robot"]["radius"] > 0
    bad = _validate(client, scenario(start=[-12.0, 0.5, 0.0]))
    assert not bad["ok"]
    assert any(p["path"] == "robots[0].start" and "wall" in p["message"] for p in bad["problems"])
    # every position off the map is listed, each with its own key path
    many = _validate(client, scenario(goal=[100.0, 0.0, 0.0], peds=[
        {"name": "a", "pos": [-6.0, 0.0, 0.0], "waypoints": [[0.0, 50.0, 0.0]]}]))
    paths = {p["path"] for p in many["problems"]}
    assert {"robots[0].goal", "obstacles.dynamic[0].waypoints[0]"} <= paths


def test_validation_robot_body_overlaps_an_obstacle(client):
    data = scenario()
    data["obstacles"]["static"] = [{"name": "s", "model": "cuboid", "pos": [-7.0, 3.5, 0.0]}]
    out = _validate(client, data)
    assert any(p["path"] == "robots[0].goal" and "overlaps obstacle" in p["message"]
               for p in out["problems"])


def test_validation_people_on_one_spot_and_bad_fields(client):
    same = [{"name": n, "pos": [-6.0, 0.0, 0.0]} for n in ("a", "b")]
    out = _validate(client, scenario(peds=same))
    assert not out["ok"]
    assert out["problems"][0]["path"] == "obstacles.dynamic[1].pos"
    assert "one spot" in out["problems"][0]["message"]
    bad = scenario()
    bad["obstacles"]["dynamic"][0]["vmax"] = 9.0
    out = _validate(client, bad)
    assert out["problems"][0]["path"] == "obstacles.dynamic[0].vmax"
    typo = scenario()
    typo["obstacles"]["dynamic"][0]["vamx"] = 0.5
    assert "did you mean 'vmax'" in _validate(client, typo)["problems"][0]["message"]
    out = _validate(client, scenario(), zones=[{"label": "z", "category": "a",
                                                "polygon": [[0, 0], [1, 1]]}])
    assert out["problems"][0]["path"].startswith("zones")
    empty = _validate(client, {"robots": [], "obstacles": {}})
    assert empty["problems"][0]["path"] == "robots"


def test_validation_warnings(client):
    data = scenario(peds=[{"name": "still", "pos": [-6.0, 0.0, 0.0]}])
    out = _validate(client, data)
    assert out["ok"]
    assert any(w["path"] == "obstacles.dynamic[0].waypoints" for w in out["warnings"])


def test_bad_requests_are_one_line(client):
    res = client.post("/api/scenarios/validate", json={"scenario": scenario()})
    assert res.status_code == 422
    assert res.json()["detail"] == "request: map: required key is missing"
    res = client.post("/api/scenarios/validate",
                      json={"scenario": scenario(), "map": {"kind": "world", "name": "nowhere"}})
    assert res.status_code == 404
    res = client.post("/api/scenarios/validate",
                      json={"scenario": scenario(), "map": WORLD, "robot": "no_such_robot"})
    assert res.status_code == 422 and "no_such_robot" in res.json()["detail"]


@pytest.mark.parametrize("name", ["..%2Fx", "%2Fetc%2Fpasswd", ".hidden", "a%5Cb", "x.json"])
def test_scenario_names_must_be_plain(client, root, name):
    res = client.put(f"/api/scenarios/{name}", json={"scenario": scenario(), "map": WORLD})
    assert res.status_code in (404, 422)
    assert client.get(f"/api/scenarios/{name}").status_code == 404
    assert not any(p.is_file() for p in root.parent.rglob("*.json"))


@pytest.mark.parametrize("name", ["../x", "/etc/passwd", "a/b", "", ".x"])
def test_workspace_refuses_paths(root, name):
    space = EditorWorkspace(root)
    with pytest.raises(Exception, match="not a plain scenario name"):
        space.scenario_path(name)


def _arena_run(tmp_path, file, map_arg):
    out = tmp_path / "out"
    proc = subprocess.run(
        [sys.executable, "-m", "arena.cli", "run", "--scenario", str(file), "--map", map_arg,
         "-n", "1", "--no-video", "-o", str(out)],
        capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    outcome = (out / "summary.csv").read_text().splitlines()
    assert len(outcome) == 2 and any(o in outcome[1] for o in ("success", "timeout", "collision"))
    return outcome


def test_save_load_and_run_on_a_world(client, root, tmp_path):
    zones = [{"label": "hall", "category": ["public"],
              "polygon": [[-8.0, -0.5], [0.0, -0.5], [0.0, 0.5], [-8.0, 0.5]]}]
    res = client.put("/api/scenarios/demo", json={"scenario": scenario(), "map": WORLD,
                                                  "zones": zones})
    assert res.status_code == 200, res.text
    file = root / "_scenarios" / "demo.json"
    assert res.json()["path"] == str(file)
    loaded = load_scenario(file)
    assert loaded.map == "small_office" and loaded.obstacles.dynamic[0].kind == "elder"
    assert client.get("/api/scenarios").json() == ["demo"]
    back = client.get("/api/scenarios/demo").json()
    assert back["map"] == WORLD and back["zones"] == zones
    assert back["scenario"]["obstacles"]["dynamic"][0]["start_up_mode"] == "wait_timer"
    # the workspace folders are never runs
    assert RunStore(root).runs() == []
    assert client.get("/api/runs").json() == []
    assert "success" in _arena_run(tmp_path, file, "small_office")[1]


def test_save_refuses_problems(client, root):
    res = client.put("/api/scenarios/bad", json={
        "scenario": scenario(start=[-12.0, 0.5, 0.0]), "map": WORLD})
    assert res.status_code == 422 and res.json()["detail"].startswith("not saved: robots[0].start")
    assert not (root / "_scenarios" / "bad.json").exists()
    assert client.get("/api/scenarios/bad").status_code == 404


def test_save_and_run_on_a_generated_map(client, root, tmp_path):
    res = client.post("/api/maps/generate", json={
        "generator": "rosnav_indoor", "seed": 1, "name": "gen", "params": {"width": 12.0,
                                                                          "height": 12.0}})
    assert res.status_code == 200, res.text
    grid = load_map(root / "_maps" / "gen" / "map.yaml")
    # a free start and goal 2 m apart, found on the map itself
    free = np.argwhere(grid.free)
    wall = ~grid.free
    pick = None
    for r, c in free[:: max(1, len(free) // 4000)]:
        win = wall[max(r - 12, 0): r + 13, max(c - 52, 0): c + 13]
        if r >= 12 and c >= 52 and not win.any():
            pick = (r, c)
            break
    assert pick is not None, "the generated map has no free 2.6 m × 1.2 m patch"
    x, y = grid.cell_to_world(np.array([pick]))[0]
    data = scenario(start=[x - 2.0, y, 0.0], goal=[x, y, 0.0], peds=[])
    ref = {"kind": "saved", "name": "gen"}
    res = client.put("/api/scenarios/on_gen", json={"scenario": data, "map": ref})
    assert res.status_code == 200, res.text
    file = root / "_scenarios" / "on_gen.json"
    assert json.loads(file.read_text())["map"] == "_maps/gen"
    assert client.get("/api/scenarios/on_gen").json()["map"] == ref
    _arena_run(tmp_path, file, str(root / "_maps" / "gen"))
