"""One conformance test per plugin registry: every registered plugin is run."""

import numpy as np
import pytest

import arena.plugins  # noqa: F401
from arena.core.geometry import polygons_overlap
from arena.core.registry import all_registries
from arena.crowd.base import CROWD_MODELS
from arena.crowd.driver import build_driver
from arena.maps.generators import MAP_GENERATORS
from arena.maps.grid import OccupancyGrid
from arena.maps.sources import MAP_SOURCES
from arena.sim.backend import BACKENDS
from arena.tasks.base import TASK_MODES
from arena.testing import check_backend, check_crowd_model, check_map_source, check_task_mode

# Registry kind -> where its conformance test lives.
COVERED = {
    "simulator backend": "here",
    "crowd model": "here",
    "map source": "here",
    "task mode": "here",
    "kinematics": "tests/robots/test_kinematics.py",
    "global planner": "tests/conformance/test_planners_conformance.py",
    "local planner": "tests/conformance/test_planners_conformance.py",
    "intermediate planner": "tests/conformance/test_intermediate_conformance.py",
    "robot": "tests/robots/test_presets.py",
    "map generator": "here",
    "metric": "tests/conformance/test_metrics_conformance.py",
    "reward term": "tests/learn/test_rewards.py",
    "sensor": "tests/sensors/test_named_sensors.py",
    "people perception": "tests/perception/test_stage.py",
}


def test_every_registry_has_a_conformance_test():
    kinds = {k for k in all_registries() if not k.startswith("test kind")}
    assert kinds <= set(COVERED), f"registries without conformance test: {kinds - set(COVERED)}"


def test_every_alias_is_its_target_plugin():
    # an alias (Arena's `rosnav`) is looked up, built and documented as its target: no copy
    for reg in all_registries().values():
        for alias, target in reg.aliases().items():
            assert alias not in reg.names(), f"{reg.kind} alias {alias!r} is also a plugin"
            assert reg.entry(alias) is reg.entry(target)


@pytest.mark.parametrize("name", BACKENDS.names())
def test_backend(name):
    if name == "mujoco":  # the optional extra arena[3d]
        pytest.importorskip("mujoco")
    check_backend(lambda: BACKENDS.build(name))
    for crowd in CROWD_MODELS.names():
        check_backend(
            lambda: BACKENDS.build(name), lambda c=crowd: build_driver(c), steps=5
        )


@pytest.mark.parametrize("name", CROWD_MODELS.names())
def test_crowd_model(name):
    # Demo models (spinny walks in circles by design) are exempt from reaching waypoints.
    demo = "demo" in CROWD_MODELS.entry(name).tags
    check_crowd_model(lambda: CROWD_MODELS.build(name), reaches_waypoints=not demo)


MAP_PARAMS = {"world": {"name": "small_office"}, "empty": {}}


@pytest.mark.parametrize("name", MAP_SOURCES.names())
def test_map_source(name, tmp_path):
    if name == "file":
        from arena.maps.io import save_map

        path = save_map(OccupancyGrid.empty(6, 5, 0.1), tmp_path / "m" / "map.yaml")
        params = {"path": str(path)}
    else:
        params = MAP_PARAMS.get(name, {})  # generators run on their defaults
    check_map_source(MAP_SOURCES.build({"type": name, **params}))


@pytest.mark.parametrize("name", MAP_GENERATORS.names())
def test_map_generator(name):
    gen = MAP_GENERATORS.build(name)
    check_map_source(gen)
    for seed in range(3):
        result = gen.build(np.random.default_rng(seed))
        xmin, ymin, xmax, ymax = result.grid.bounds
        # Shrunk by 1 mm about their centres: bays of one rack may share an edge.
        polys = [
            o.polygon - 1e-3 * np.sign(o.polygon - o.polygon.mean(axis=0)) for o in result.obstacles
        ]
        for poly in polys:
            assert poly[:, 0].min() >= xmin and poly[:, 0].max() <= xmax
            assert poly[:, 1].min() >= ymin and poly[:, 1].max() <= ymax
        for i, a in enumerate(polys):
            for b in polys[i + 1 :]:
                assert not polygons_overlap(a, b), f"{name}: overlapping obstacles (seed {seed})"


SCENARIO = (
    '{"robots": [{"start": [2, 2, 0], "goal": [13, 9, 0]}], "obstacles": {"static": '
    '[{"name": "b", "model": "cuboid", "pos": [8, 6, 0]}], "dynamic": [{"name": "p", '
    '"pos": [3, 9, 0], "waypoints": [[12, 3, 0]], "waypoint_mode": 0}]}}'
)


def _scenario_file(tmp_path):
    file = tmp_path / "s.json"
    file.write_text(SCENARIO)
    return {"file": str(file)}


# Task modes that need parameters (files, a world with zones ...): name -> factory(tmp_path)
# returning (extra params, map block or None for the default empty room). Every other mode
# must run on its defaults.
MODE_PARAMS = {
    "robots.scenario": lambda tmp: (_scenario_file(tmp), None),
    "obstacles.scenario": lambda tmp: (_scenario_file(tmp), None),
    "modules.benchmark": lambda tmp: ({"suite": "quick"}, None),
    "robots.zones": lambda tmp: ({}, {"type": "world", "name": "hospital_floor"}),
    "obstacles.zones": lambda tmp: ({}, {"type": "world", "name": "hospital_floor"}),
}


@pytest.mark.parametrize("name", TASK_MODES.names())
def test_task_mode(name, tmp_path):
    role, short = name.split(".", 1)
    params, map_spec = MODE_PARAMS.get(name, lambda tmp: ({}, None))(tmp_path)
    check_task_mode(role, {"type": short, **params}, map_spec)
