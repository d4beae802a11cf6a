"""Robot presets against Arena-Rosnav's robot table, the RobotModel API and loader errors."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from arena.core.errors import ConfigError, UnknownNameError
from arena.core.registry import Entry
from arena.robots import RobotModel, describe_robots, load_robot, robot_names
from arena.robots.presets import PRESET_DIR, ROBOTS, PresetFile

# Arena-Rosnav robot table (arena-simulation-setup 9a24fce: model_params.yaml + flatland
# footprint), as published, with the kinematics each robot gets here. Angles are given to the
# table's 3-4 decimals. footprint: ("circle", r) or ("rect", length x, width y).
# laser: (angle_min, angle_max, beams, range m, rate Hz, noise m).
ARENA_TABLE = {
    "burger": dict(kin="diff_drive", radius=0.113, holo=False, vx=0.22, vy=0.0, w=2.84,
                   fp=("circle", 0.105), laser=(0.0, 6.283, 360, 3.5, 10, 0.0)),
    "waffle": dict(kin="diff_drive", radius=0.208, holo=False, vx=0.26, vy=0.0, w=1.82,
                   fp=("circle", 0.208), laser=(0.0, 6.283, 360, 3.5, 10, 0.0)),
    "jackal": dict(kin="diff_drive", radius=0.267, holo=False, vx=2.0, vy=0.0, w=4.0,
                   fp=("rect", 0.42, 0.33), laser=(-2.356, 2.356, 720, 30.0, 10, 0.0)),
    "dingo": dict(kin="diff_drive", radius=0.378, holo=False, vx=1.3, vy=0.0, w=2.356,
                  fp=("rect", 0.551, 0.517), laser=(-2.356, 2.356, 720, 30.0, 10, 0.0)),
    "agvota": dict(kin="diff_drive", radius=0.629, holo=False, vx=0.5, vy=0.0, w=0.4,
                   fp=("rect", 1.026, 0.728), laser=(-1.571, 1.571, 720, 30.0, 10, 0.0)),
    "laikago": dict(kin="legged", radius=0.629, holo=False, vx=0.5, vy=0.0, w=0.4,
                    fp=("rect", 0.58, 0.38), laser=(-1.571, 1.571, 720, 30.0, 10, 0.0)),
    "tiago": dict(kin="diff_drive", radius=0.27, holo=False, vx=1.5, vy=0.0, w=2.0,
                  fp=("circle", 0.27), laser=(-1.920, 1.920, 666, 25.0, 10, 0.0)),
    "ridgeback": dict(kin="omni", radius=0.625, holo=True, vx=1.1, vy=0.5, w=2.0,
                      fp=("rect", 0.96, 0.80), laser=(-2.356, 2.356, 720, 10.0, 10, 0.0)),
    "cob4": dict(kin="omni", radius=0.36, holo=True, vx=1.1, vy=0.2, w=0.8,
                 fp=("circle", 0.36), laser=(-3.1415, 3.1415, 720, 29.5, 10, 0.0)),
    "youbot": dict(kin="omni", radius=0.347, holo=True, vx=0.8, vy=0.8, w=1.2,
                   fp=("rect", 0.38, 0.58), laser=(-1.571, 1.565, 512, 5.6, 10, 0.0)),
    "rto": dict(kin="omni", radius=0.225, holo=True, vx=2.78, vy=2.78, w=1.0,
                fp=("circle", 0.225), laser=(-2.400, 2.400, 552, 50.0, 10, 0.0)),
    "rto_lab": dict(kin="omni", radius=0.225, holo=True, vx=2.78, vy=2.78, w=1.0,
                    fp=("circle", 0.225), laser=(-2.094, 2.094, 683, 5.6, 10, 0.0)),
    "go1": dict(kin="legged", radius=0.347, holo=True, vx=0.8, vy=0.8, w=1.2,
                fp=("rect", 0.58, 0.38), laser=(-1.571, 1.565, 512, 5.6, 10, 0.0)),
    "buddy": dict(kin="omni", radius=0.347, holo=True, vx=0.8, vy=0.8, w=1.2,
                  fp=("rect", 1.10, 0.55), laser=(-3.1416, 3.1416, 1800, 80.0, 10, 0.008)),
}

# Acceleration limits (acc_x m/s², acc_y m/s², acc_omega rad/s²) chosen per robot; the sources
# are cited in each preset's `sources`.
ACCELERATIONS = {
    "burger": (2.5, 0.0, 3.2), "waffle": (2.5, 0.0, 3.2), "jackal": (20.0, 0.0, 25.0),
    "dingo": (1.0, 0.0, 2.0), "agvota": (0.5, 0.0, 0.3), "laikago": (1.25, 0.0, 1.0),
    "tiago": (0.6, 0.0, math.pi / 3), "ridgeback": (2.5, 2.5, 1.0), "cob4": (2.5, 2.5, 3.2),
    "youbot": (1.25, 1.25, 1.0), "rto": (2.5, 2.5, 3.2), "rto_lab": (2.5, 2.5, 3.2),
    "go1": (1.25, 1.25, 1.0), "buddy": (1.0, 0.5, 0.5),
}

# Arena's legacy discrete set: (linear m/s, angular rad/s) per action. move_forward runs at the
# robot's forward limit (jackal: 0.30); dingo has its own set; agvota and laikago turn_strong at
# their 0.4 rad/s limit (Arena lists 0.75, which the base would clip).
ACTION_NAMES = ("move_forward", "move_backward", "turn_left", "turn_right", "turn_strong_left",
                "turn_strong_right", "stop")


def legacy_actions(forward, backward=-0.15, turn_v=0.15, strong=0.75):
    return [(forward, 0.0), (backward, 0.0), (turn_v, 0.35), (turn_v, -0.35), (0.0, strong),
            (0.0, -strong), (0.0, 0.0)]


DISCRETE = {name: legacy_actions(row["vx"]) for name, row in ARENA_TABLE.items()}
DISCRETE["jackal"] = legacy_actions(0.30)
DISCRETE["dingo"] = legacy_actions(1.3, backward=-1.0, turn_v=0.75)
DISCRETE["agvota"] = legacy_actions(0.5, strong=0.4)
DISCRETE["laikago"] = legacy_actions(0.5, strong=0.4)


def rect_extent(poly: np.ndarray) -> tuple[float, float]:
    ext = poly.max(axis=0) - poly.min(axis=0)
    return float(ext[0]), float(ext[1])


# -- the table ---------------------------------------------------------------------------------
def test_every_preset_is_registered():
    assert set(robot_names()) == set(ARENA_TABLE) | {"f1tenth"}
    assert set(robot_names("builtin")) == set(robot_names())


@pytest.mark.parametrize("name", sorted(ARENA_TABLE))
def test_preset_matches_arena_table(name):
    row = ARENA_TABLE[name]
    m = load_robot(name)
    assert m.name == name and m.description and m.sources
    assert m.kinematics_type == row["kin"]
    assert m.radius == row["radius"]
    assert m.holonomic is row["holo"]
    lim = m.limits()
    assert (lim.vx_min, lim.vx_max) == (-row["vx"], row["vx"])
    assert (lim.vy_min, lim.vy_max) == (-row["vy"] if row["vy"] else 0.0, row["vy"])
    assert lim.omega_max == pytest.approx(row["w"], abs=5e-4)
    assert lim.min_turning_radius == 0.0
    np.testing.assert_allclose((lim.acc_x, lim.acc_y, lim.acc_omega), ACCELERATIONS[name])
    kind, *dims = row["fp"]
    if kind == "circle":
        assert m.footprint_polygon() is None
        assert m.circumscribed_radius == dims[0]
    else:
        poly = m.footprint_polygon()
        assert poly.shape == (4, 2)
        np.testing.assert_allclose(rect_extent(poly), dims, atol=1e-9)
        np.testing.assert_allclose(poly.mean(axis=0), [0.0, 0.0], atol=1e-12)  # centred
    a_min, a_max, beams, rng, rate, noise = row["laser"]
    las = m.laser
    assert las.angle_min == pytest.approx(a_min, abs=1e-3)
    assert las.angle_max == pytest.approx(a_max, abs=1e-3)
    got = (las.num_beams, las.range_max, las.update_rate, las.noise_std)
    assert got == (beams, rng, rate, noise)


@pytest.mark.parametrize("name", sorted(ARENA_TABLE))
def test_preset_actions_mirror_arena(name):
    m = load_robot(name)
    acts = m.actions
    assert tuple(a.name for a in acts.discrete) == ACTION_NAMES
    np.testing.assert_allclose([(a.linear, a.angular) for a in acts.discrete], DISCRETE[name])
    # Arena's continuous ranges are the velocity limits
    lim = m.limits()
    lin = acts.continuous.linear_range
    if m.holonomic:
        assert (tuple(lin.x), tuple(lin.y)) == ((lim.vx_min, lim.vx_max), (lim.vy_min, lim.vy_max))
    else:
        assert tuple(lin) == (lim.vx_min, lim.vx_max)
    assert tuple(acts.continuous.angular_range) == (-lim.omega_max, lim.omega_max)


def test_arena_radius_is_the_circumscribed_radius_where_arena_derived_it():
    for name in ("jackal", "dingo", "agvota", "ridgeback", "youbot", "go1"):
        m = load_robot(name)
        assert m.circumscribed_radius == pytest.approx(m.radius, abs=1.5e-3), name
    # documented Arena quirks: radii copied from other robots
    assert load_robot("laikago").circumscribed_radius == pytest.approx(0.3467, abs=1e-4)
    assert load_robot("buddy").circumscribed_radius == pytest.approx(0.6149, abs=1e-4)


def test_full_circle_lasers():
    for name in ("burger", "waffle", "cob4", "buddy"):
        assert load_robot(name).laser.full_circle, name
    assert load_robot("buddy").laser.angle_increment == pytest.approx(2 * math.pi / 1800)


def test_f1tenth_car():
    m = load_robot("f1tenth")
    L, dmax = 0.3302, 0.4189
    assert m.kinematics_type == "ackermann" and not m.holonomic
    p = m.build_kinematics().params
    assert (p.wheelbase, p.max_steering_angle, p.max_steering_rate) == (L, dmax, 3.2)
    assert (p.vx_min, p.vx_max, p.acc_x) == (-5.0, 5.0, 2.5)
    lim = m.limits()
    assert lim.min_turning_radius == pytest.approx(L / math.tan(dmax))
    assert lim.omega_max == pytest.approx(5.0 * math.tan(dmax) / L)
    assert rect_extent(m.footprint_polygon()) == pytest.approx((0.58, 0.31))
    assert m.circumscribed_radius == pytest.approx(0.4868, abs=1e-4)
    assert m.radius >= m.circumscribed_radius
    las = m.laser
    assert math.degrees(las.angle_max - las.angle_min) == pytest.approx(270.0)
    assert (las.num_beams, las.range_max, las.update_rate) == (1081, 10.0, 40.0)
    assert las.angle_increment == pytest.approx(math.radians(0.25))
    # every discrete action is an arc the car can drive (steering below full lock)
    for a in m.actions.discrete:
        if a.linear != 0:
            assert abs(math.atan(L * a.angular / a.linear)) < dmax, a.name


# -- limits and the kinematics model -----------------------------------------------------------
@pytest.mark.parametrize("name", [*sorted(ARENA_TABLE), "f1tenth"])
def test_limits_consistent_with_kinematics_params(name):
    m = load_robot(name)
    kin = m.build_kinematics()
    assert kin is m.build_kinematics()  # built once
    assert kin.name == m.kinematics_type
    assert m.limits() == kin.limits()
    assert m.holonomic == kin.holonomic == m.limits().holonomic
    p = kin.params
    lim = m.limits()
    assert (lim.vx_min, lim.vx_max) == (p.vx_min, p.vx_max)
    assert lim.acc_x == p.acc_x
    if hasattr(p, "omega_max"):
        assert (lim.omega_max, lim.acc_omega) == (p.omega_max, p.acc_omega)
    if m.holonomic:
        assert lim.vy_max == p.vy_max and lim.acc_y == p.acc_y
    # the stored spec is complete: it rebuilds the same model
    assert m.kinematics == {"type": kin.name, **p.model_dump()}


def test_footprint_polygon_is_counter_clockwise_copy():
    m = load_robot("youbot")  # stored clockwise in the file
    poly = m.footprint_polygon()
    x, y = poly[:, 0], poly[:, 1]
    assert 0.5 * (np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))) > 0
    poly[0] = 99.0
    assert m.footprint_polygon()[0, 0] != 99.0


def test_json_round_trip_keeps_infinite_accelerations():
    data = yaml.safe_load((PRESET_DIR / "burger.yaml").read_text())
    del data["kinematics"]["acc_x"]  # the default: unlimited
    m = RobotModel.model_validate(data)
    assert math.isinf(m.limits().acc_x)
    again = RobotModel.model_validate_json(m.model_dump_json())
    assert again == m and math.isinf(again.limits().acc_x)
    assert json.loads(m.model_dump_json(), parse_constant=float)["kinematics"]["acc_x"] == math.inf


def test_describe_robots_rows():
    rows = {r["name"]: r for r in describe_robots()}
    assert set(rows) == set(robot_names())
    keys = ["name", "kinematics", "radius", "footprint", "velocity", "acc", "laser"]
    assert all(list(r) == keys for r in rows.values())
    assert rows["jackal"] == {
        "name": "jackal", "kinematics": "diff_drive", "radius": "0.267",
        "footprint": "0.42 × 0.33", "velocity": "vx -2 … 2, vy 0, ω ±4",
        "acc": "20 / 0 / 25", "laser": "720 × 270°, 30 m, 10 Hz",
    }
    assert rows["burger"]["footprint"] == "circle r 0.105"
    assert rows["burger"]["laser"] == "360 × 360°, 3.5 m, 10 Hz"
    assert rows["ridgeback"]["velocity"] == "vx -1.1 … 1.1, vy -0.5 … 0.5, ω ±2"
    assert rows["f1tenth"]["kinematics"] == "ackermann (R 0.742)"
    assert describe_robots(["go1"])[0]["kinematics"] == "legged"


# -- loading -----------------------------------------------------------------------------------
def test_load_by_path_equals_load_by_name(tmp_path):
    path = PRESET_DIR / "rto.yaml"
    assert load_robot(path) == load_robot("rto")
    assert load_robot(str(path)) == load_robot("rto")
    copy = tmp_path / "my_robot.yml"
    copy.write_text(path.read_text())
    assert load_robot(str(copy)) == load_robot("rto")


def test_unknown_robot_name_suggests_close_match():
    with pytest.raises(UnknownNameError, match="did you mean 'burger'") as err:
        load_robot("burgr")
    assert "known: agvota" in str(err.value)


def test_third_party_entries(monkeypatch, tmp_path):
    path = tmp_path / "bot.yaml"
    data = yaml.safe_load((PRESET_DIR / "burger.yaml").read_text()) | {"name": "bot"}
    path.write_text(yaml.safe_dump(data))
    model = load_robot(path)
    for obj in (str(path), path, model, lambda: path, lambda: model):
        monkeypatch.setitem(ROBOTS._entries, "bot", Entry("bot", obj, ("third_party",)))
        assert load_robot("bot") == model
    monkeypatch.setitem(ROBOTS._entries, "bot", Entry("bot", lambda: 42, ("third_party",)))
    with pytest.raises(ConfigError, match="returned int"):
        load_robot("bot")


def write_variant(tmp_path: Path, edit, base: str = "burger") -> Path:
    data = yaml.safe_load((PRESET_DIR / f"{base}.yaml").read_text())
    edit(data)
    path = tmp_path / "robot.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def set_in(keys, value):
    def edit(data):
        d = data
        for k in keys[:-1]:
            d = d[k]
        d[keys[-1]] = value
    return edit


@pytest.mark.parametrize(
    ("edit", "path", "match"),
    [
        (set_in(["kinematics", "vx_max"], -1.0), "kinematics.vx_max", "greater than 0"),
        (set_in(["kinematics", "acc_xx"], 1.0), "kinematics.acc_xx", "unknown key"),
        (set_in(["kinematics", "type"], "omnii"), "kinematics.type", "did you mean 'omni'"),
        (set_in(["radiuss"], 0.2), "radiuss", "unknown key"),
        (set_in(["radius"], 0.0), "radius", "greater than 0"),
        (set_in(["laser", "num_beams"], 0), "laser.num_beams", "greater than 0"),
        (set_in(["footprint"], {"type": "polygon", "points": [[0, 0], [1, 1]]}),
         "footprint.polygon.points", "at least 3"),
        (set_in(["footprint"], {"type": "square", "side": 1}), "footprint", "square"),
        (set_in(["actions", "discrete", 0, "linear"], 0.5), "actions.discrete[0].linear",
         "outside the robot's range"),
        (set_in(["actions", "discrete", 4, "angular"], 3.0), "actions.discrete[4].angular",
         "outside the robot's range"),
        (set_in(["actions", "continuous", "linear_range"], [0.3, -0.3]),
         "actions.continuous.linear_range", "min <= max"),
        (set_in(["actions", "continuous", "angular_range"], [-9.0, 9.0]),
         "actions.continuous.angular_range", "exceeds the kinematics limits"),
        (set_in(["actions", "continuous", "linear_range"], {"x": [-0.2, 0.2], "y": [0, 0]}),
         "actions.continuous.linear_range", "cannot move sideways"),
        (set_in(["actions", "discrete", 1, "name"], "move_forward"), "actions.discrete",
         "duplicate discrete action names"),
    ],
)
def test_bad_preset_names_file_and_key_path(tmp_path, edit, path, match):
    bad = write_variant(tmp_path, edit)
    with pytest.raises(ConfigError, match=match) as err:
        load_robot(bad)
    assert err.value.source == str(bad)
    assert err.value.path == path
    assert str(err.value).startswith(f"{bad}: {path}: ")


def test_holonomic_robot_needs_xy_linear_range(tmp_path):
    bad = write_variant(
        tmp_path, set_in(["actions", "continuous", "linear_range"], [-1.1, 1.1]), base="ridgeback"
    )
    with pytest.raises(ConfigError, match="robot is holonomic") as err:
        load_robot(bad)
    assert err.value.path == "actions.continuous.linear_range"


def test_malformed_yaml_reports_line(tmp_path):
    path = tmp_path / "broken.yaml"
    path.write_text("name: broken\nkinematics:\n  type: diff_drive\n  vx_max: [1.0\nradius: 0.2\n")
    with pytest.raises(ConfigError, match=r"malformed YAML at line \d+, column \d+") as err:
        load_robot(path)
    assert err.value.source == str(path)


def test_duplicate_yaml_key_is_an_error(tmp_path):
    text = (PRESET_DIR / "burger.yaml").read_text()
    text = text.replace("radius: 0.113", "radius: 0.113\nradius: 0.2")
    path = tmp_path / "dup.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError, match=r"line \d+.*duplicate key 'radius'"):
        load_robot(path)


def test_other_file_errors(tmp_path):
    with pytest.raises(ConfigError, match="file not found"):
        load_robot(tmp_path / "nope.yaml")
    listing = tmp_path / "list.yaml"
    listing.write_text("- 1\n- 2\n")
    with pytest.raises(ConfigError, match="expected a mapping"):
        load_robot(listing)
    missing = write_variant(tmp_path, lambda d: d.pop("laser"))
    with pytest.raises(ConfigError, match="required key is missing") as err:
        load_robot(missing)
    assert err.value.path == "laser"


def test_preset_file_name_must_match(tmp_path):
    path = write_variant(tmp_path, set_in(["name"], "other"))
    with pytest.raises(ConfigError, match="differs from its file name") as err:
        PresetFile(path)()
    assert err.value.path == "name"
