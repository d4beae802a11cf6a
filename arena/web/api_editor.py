"""The scenario editor's REST API (part of the app's OpenAPI schema at ``/docs``).

===========================================  ===================================================
``GET  /api/worlds``                         packaged worlds and their scenario names
``GET  /api/worlds/{world}``                 its map (PNG base64, resolution, origin), scenario
                                             names and zones
``GET  /api/worlds/{world}/scenarios/{name}``  a packaged scenario's JSON, to start from
``GET  /api/generators``                     the map generators with their parameters' JSON
                                             schema
``POST /api/maps/generate``                  ``{generator, params, seed, name}``: build a map,
                                             save it as ``_maps/<name>``
``POST /api/maps/upload``                    multipart ``yaml``, ``image``, ``name``: a ROS
                                             map_server map, saved as ``_maps/<name>``
``GET  /api/maps``, ``GET /api/maps/{name}``  the saved maps; one map
``GET  /api/obstacles``                      the obstacle library: footprints (m), heights
``GET  /api/scenario_fields``                pedestrian fields (name → description), types and
                                             startup modes of the scenario format
``POST /api/scenarios/validate``             ``{scenario, map, zones, robot}`` → ``{ok,
                                             problems, warnings}``
``GET  /api/scenarios``                      the saved scenarios' names
``GET  /api/scenarios/{name}``               a saved scenario, its map reference and zones
``PUT  /api/scenarios/{name}``               save (refused while it has problems)
===========================================  ===================================================

A map reference is ``{"kind": "world" | "saved", "name": ...}``. Errors are JSON ``{"detail":
"one line"}``: 404 an unknown world, map, scenario or generator; 413 an upload over the limits
(:mod:`arena.web.editor_maps`); 422 bad content (a bad name, parameters, map or scenario),
naming the file or field.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Literal, TypeVar

from fastapi import APIRouter, Body, File, Form, HTTPException, UploadFile
from pydantic import BaseModel, ConfigDict, Field, StrictInt, ValidationError

from arena.core.errors import ArenaError, from_validation_error
from arena.maps.generators import MAP_GENERATORS
from arena.maps.obstacles import obstacle_models
from arena.maps.sources import WORLDS_DIR, packaged_worlds
from arena.tasks.scenario import KIND_CODES, STARTUP_CODES, Pedestrian, parse_scenario
from arena.web import editor_maps
from arena.web.editor_checks import default_robot, robot_model, validate
from arena.web.editor_store import EditorWorkspace, MapRef, check_name
from arena.web.store import NotFound, RunStore

T = TypeVar("T")


class MapRefBody(BaseModel):
    """A map reference in a request: a packaged world or a saved map."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    kind: Literal["world", "saved"] = Field(description="'world' (packaged) or 'saved'")
    name: str = Field(description="the world's or saved map's name")


class ScenarioBody(BaseModel):
    """A scenario as the editor sends it (validated, then saved)."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    scenario: dict[str, Any] = Field(description="Arena scenario JSON")
    map: MapRefBody
    zones: list[Any] = Field(default_factory=list, description="zones.yaml entries")
    robot: str | None = Field(None, description="robot preset (default: arena run's)")


class GenerateBody(BaseModel):
    """A map generation request."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    generator: str = Field(description="a map generator's name")
    params: dict[str, Any] = Field(default_factory=dict, description="its parameters")
    seed: StrictInt = Field(0, ge=0, description="master seed")
    name: str | None = Field(None, description="saved map name (default <generator>_<seed>)")


def _body(model: type[T], data: Any, what: str) -> T:
    """``data`` validated as ``model`` (a one-line 422 naming the field otherwise)."""
    try:
        return model.model_validate(data)  # type: ignore[attr-defined, no-any-return]
    except ValidationError as e:
        raise HTTPException(422, str(from_validation_error(e, source=what))) from None


def _answer(call: Callable[..., T], *args: Any) -> T:
    """``call(*args)`` with the app's errors as HTTP answers (see the module doc)."""
    try:
        return call(*args)
    except NotFound as e:
        raise HTTPException(404, str(e)) from None
    except editor_maps.TooLarge as e:
        raise HTTPException(413, str(e)) from None
    except ArenaError as e:
        raise HTTPException(422, str(e)) from None


def editor_router(store: RunStore) -> APIRouter:
    """The editor's API on ``store``'s workspace (see the module doc)."""
    router = APIRouter(prefix="/api", tags=["scenario editor"])
    space = EditorWorkspace(store.root)

    def world_name(world: str) -> str:
        if world not in packaged_worlds():
            raise NotFound(f"no packaged world {world!r}; worlds: {', '.join(packaged_worlds())}")
        return world

    @router.get("/worlds")
    def worlds() -> list[dict[str, Any]]:
        return editor_maps.worlds()

    @router.get("/worlds/{world}")
    def world(world: str) -> dict[str, Any]:
        name = _answer(world_name, world)
        grid = _answer(space.grid, MapRef("world", name))
        return {"name": name, "map": editor_maps.map_json(grid),
                "scenarios": editor_maps.world_scenarios(name),
                "zones": _answer(editor_maps.world_zones, name)}

    @router.get("/worlds/{world}/scenarios/{name}")
    def world_scenario(world: str, name: str) -> dict[str, Any]:
        folder = WORLDS_DIR / _answer(world_name, world) / "scenarios"
        if name not in editor_maps.world_scenarios(world):
            raise HTTPException(404, f"no scenario {name!r} in world {world!r}")
        path = folder / f"{name}.json"
        scenario = _answer(lambda: parse_scenario(path.read_text(encoding="utf-8"),
                                                   source=path.name))
        return {"scenario": scenario.to_json_dict()}

    @router.get("/generators")
    def generators() -> list[dict[str, Any]]:
        return editor_maps.generators()

    @router.post("/maps/generate")
    def generate(body: dict[str, Any] = Body(...)) -> dict[str, Any]:  # noqa: B008 (FastAPI)
        req = _body(GenerateBody, body, "request")
        if req.generator not in MAP_GENERATORS:
            raise HTTPException(404, MAP_GENERATORS.unknown_message(req.generator))
        name = _answer(check_name, req.name or f"{req.generator}_{req.seed}", "map")
        grid = _answer(editor_maps.generate, req.generator, req.params, req.seed)
        _answer(space.save_map, name, grid)
        return {"ref": {"kind": "saved", "name": name}, "map": editor_maps.map_json(grid)}

    @router.post("/maps/upload")
    async def upload(yaml: UploadFile | None = File(None),  # noqa: B008 (FastAPI)
                     image: UploadFile | None = File(None),  # noqa: B008
                     name: str = Form("uploaded")) -> dict[str, Any]:
        if yaml is None or image is None:
            field = "yaml" if yaml is None else "image"
            raise HTTPException(422, f"{field}: missing; send the map.yaml as 'yaml' and its "
                                     "image as 'image' (multipart form)")
        map_name = _answer(check_name, name, "map")
        # read one byte past the limit: enough to refuse, never the whole of a huge file
        data = editor_maps.Upload(
            await yaml.read(editor_maps.MAX_YAML_BYTES + 1),
            image.filename or "image",
            await image.read(editor_maps.MAX_IMAGE_BYTES + 1))
        grid = _answer(editor_maps.read_upload, data)
        _answer(space.save_map, map_name, grid)
        return {"ref": {"kind": "saved", "name": map_name}, "map": editor_maps.map_json(grid)}

    @router.get("/maps")
    def maps() -> list[str]:
        return space.maps()

    @router.get("/maps/{name}")
    def saved_map(name: str) -> dict[str, Any]:
        grid = _answer(space.grid, MapRef("saved", name))
        return {"ref": {"kind": "saved", "name": name}, "map": editor_maps.map_json(grid)}

    @router.get("/obstacles")
    def obstacles() -> list[dict[str, Any]]:
        return [{"name": n, "description": m.description, "height": m.height,
                 "footprint": m.polygon().round(4).tolist()}
                for n, m in obstacle_models().items()]

    @router.get("/scenario_fields")
    def scenario_fields() -> dict[str, Any]:
        return {"pedestrian": {n: f.description or "" for n, f in Pedestrian.model_fields.items()},
                "types": list(KIND_CODES), "startup_modes": list(STARTUP_CODES),
                "robot": default_robot()}

    def check(req: ScenarioBody) -> tuple[MapRef, dict[str, Any], Any]:
        ref = MapRef(req.map.kind, req.map.name)
        grid = space.grid(ref)
        robot = robot_model(req.robot or default_robot())
        data = {**req.scenario, "map": ref.label}
        return ref, data, validate(data, grid, robot, req.zones)

    @router.post("/scenarios/validate")
    def validate_scenario(body: dict[str, Any] = Body(...)) -> dict[str, Any]:  # noqa: B008
        req = _body(ScenarioBody, body, "request")
        _, _, result = _answer(check, req)
        out: dict[str, Any] = result.as_json()
        robot = robot_model(req.robot or default_robot())
        fp = robot.footprint_polygon()
        out["robot"] = {"name": robot.name, "radius": robot.circumscribed_radius,
                        "footprint": None if fp is None else fp.round(4).tolist()}
        return out

    @router.get("/scenarios")
    def scenarios() -> list[str]:
        return space.scenarios()

    @router.get("/scenarios/{name}")
    def load(name: str) -> dict[str, Any]:
        scenario, zones = _answer(space.load, name)
        ref = MapRef.from_label(scenario.map or "")
        return {"name": name, "scenario": scenario.to_json_dict(),
                "map": {"kind": ref.kind, "name": ref.name}, "zones": zones}

    @router.put("/scenarios/{name}")
    def save(name: str, body: dict[str, Any] = Body(...)) -> dict[str, Any]:  # noqa: B008
        _answer(check_name, name, "scenario")
        req = _body(ScenarioBody, body, "request")
        ref, _, result = _answer(check, req)
        if not result.ok or result.scenario is None:
            first = result.problems[0]
            more = f" (and {len(result.problems) - 1} more)" if len(result.problems) > 1 else ""
            raise HTTPException(422, f"not saved: {first.path or 'scenario'}: {first.message}"
                                     + more)
        path = _answer(space.save, name, result.scenario, list(req.zones))
        map_arg = ref.name if ref.kind == "world" else str(space.maps_dir / ref.name)
        return {"name": name, "path": str(path),
                "command": f"arena run --scenario {path} --map {map_arg} -n 1"}

    return router


__all__ = ["editor_router"]
