"""Load an experiment config from YAML, apply dotted command-line overrides, validate everything.

``arena run my.yaml robot=burger map.type=empty seed=3`` → :func:`load_config` with the file and
three overrides. Rules:

* The file is merged over the built-in defaults; overrides are merged over that.
* A plugin block (a mapping with ``type``) whose ``type`` changes is replaced, not merged, so
  parameters of the old plugin do not leak into the new one.
* Values are parsed as YAML (``3`` → int, ``[1, 2]`` → list, ``true`` → bool).
* Unknown keys are errors; every error names the file (or the override) and the key path.
"""

from __future__ import annotations

import copy
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import yaml
from pydantic import ValidationError

import arena.plugins  # noqa: F401  (fills the registries, loads ARENA_PLUGINS)
from arena.config.schema import ExperimentConfig, non_finite_key
from arena.core import files
from arena.core.errors import ConfigError, UnknownNameError, from_validation_error, shorten
from arena.crowd.base import CROWD_MODELS
from arena.maps.sources import MAP_SOURCES
from arena.nav.global_planners.base import GLOBAL_PLANNERS
from arena.nav.intermediate.base import INTERMEDIATE_PLANNERS
from arena.nav.local_planners.base import LOCAL_PLANNERS
from arena.perception.stage import check_perception
from arena.robots.presets import load_robot
from arena.sim.backend import BACKENDS
from arena.tasks.base import validate_mode

PRESETS_DIR = Path(__file__).resolve().parent / "presets"
DEFAULT_CONFIG = PRESETS_DIR / "default.yaml"
_KEY = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)*$")


def read_yaml(path: str | Path) -> dict[str, Any]:
    """Read a YAML mapping (rules of :mod:`arena.core.files`: duplicate keys, bombs refused).

    Raises:
        ConfigError: missing or unreadable file, malformed YAML, not a mapping.
    """
    p = Path(path)
    data = files.read_yaml(p)
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise ConfigError(
            f"expected a mapping of keys at the top level, got {type(data).__name__}", source=str(p)
        )
    return data


def merge(base: dict[str, Any], update: dict[str, Any]) -> dict[str, Any]:
    """Deep-merge ``update`` into a copy of ``base``; a plugin block changing type is replaced."""
    out = copy.deepcopy(base)
    for key, value in update.items():
        old = out.get(key)
        if isinstance(old, dict) and isinstance(value, dict):
            if "type" in value and "type" in old and value["type"] != old["type"]:
                out[key] = copy.deepcopy(value)
            else:
                out[key] = merge(old, value)
        else:
            out[key] = copy.deepcopy(value)
    return out


def parse_override(text: str) -> tuple[str, Any]:
    """Split ``"a.b=value"`` into the key path and the YAML-parsed value."""
    if "=" not in text:
        raise ConfigError(
            f"override {shorten(repr(text))} is not of the form key.path=value",
            source="command line",
        )
    key, _, raw = text.partition("=")
    key = key.strip()
    if not _KEY.match(key):
        raise ConfigError(
            f"override {shorten(repr(text))}: {shorten(repr(key))} is not a dotted key path",
            source="command line",
        )
    try:
        value = yaml.load(raw, Loader=files.StrictLoader) if raw.strip() else ""
    except (yaml.composer.ComposerError, yaml.constructor.ConstructorError) as e:
        # Well-formed YAML that the strict loader refuses (duplicate key, nesting, alias bomb).
        raise ConfigError(
            f"override {shorten(repr(text))}: {files.yaml_problem(e)}", source="command line"
        ) from None
    except yaml.YAMLError:
        value = raw  # not YAML: keep the literal string
    return key, value


def _nest(key: str, value: Any) -> dict[str, Any]:
    out: Any = value
    for part in reversed(key.split(".")):
        out = {part: out}
    return out


def load_config(path: str | Path | None = None, overrides: Sequence[str] = ()) -> ExperimentConfig:
    """Load, merge and validate an experiment config (file + overrides).

    Args:
        path: a YAML file; ``None`` uses the packaged ``arena/config/presets/default.yaml``.
        overrides: ``key.path=value`` strings applied in order.

    Raises:
        ConfigError: with the file (or the override) and the key path of the first problem.
    """
    source = str(path) if path is not None else str(DEFAULT_CONFIG)
    data = merge(ExperimentConfig().model_dump(mode="json"), read_yaml(source))
    if path is not None:
        _resolve_relative_paths(data, Path(source).resolve().parent)
    override_paths: list[tuple[str, str]] = []
    for text in overrides:
        key, value = parse_override(text)
        data = _apply(data, key, value, text)
        override_paths.append((key, text))

    def located(err: ConfigError) -> ConfigError:
        # Blame the override that set this key, if one did.
        for key, text in reversed(override_paths):
            if not err.path:
                continue
            same_block = (
                key.endswith(".type") and key.rsplit(".", 1)[0] == err.path.rsplit(".", 1)[0]
            )
            if (
                err.path == key
                or err.path.startswith((key + ".", key + "["))
                or key.startswith(err.path + ".")
                or same_block
            ):
                return type(err)(
                    err.message, source=f"override {shorten(repr(text))}", path=err.path
                )
        return err

    found = non_finite_key(data)
    if found is not None:
        raise located(ConfigError(f"must be a finite number, got {found[1]}", source=source,
                                  path=found[0]))
    try:
        cfg = ExperimentConfig.model_validate(data)
    except ValidationError as e:
        raise located(from_validation_error(e, source=source)) from None
    try:
        validate_plugins(cfg, source=source)
    except ConfigError as e:
        raise located(e) from None
    return cfg


def _apply(data: dict[str, Any], key: str, value: Any, text: str) -> dict[str, Any]:
    node: Any = data
    parts = key.split(".")
    for i, part in enumerate(parts[:-1]):
        # An optional block left unset (None) is opened by setting one of its keys.
        if (
            isinstance(node, dict)
            and part in node
            and node[part] is not None
            and not isinstance(node[part], dict)
        ):
            raise ConfigError(
                f"cannot set {key!r}: {'.'.join(parts[: i + 1])!r} is a value, not a block",
                source=f"override {shorten(repr(text))}",
                path=key,
            )
        node = node.get(part, {}) if isinstance(node, dict) else {}
    return merge(data, _nest(key, value))


TASK_FILE_KEYS = ("file", "zones", "scenario", "suite", "curriculum")
"""Keys of task mode/module blocks that hold file paths (resolved relative to the config)."""


def _resolve_relative_paths(data: dict[str, Any], base: Path) -> None:
    """Make file paths in a config file relative to that file, as users expect."""
    m = data.get("map")
    if isinstance(m, dict) and m.get("type") == "file" and isinstance(m.get("path"), str):
        p = Path(m["path"]).expanduser()
        if not p.is_absolute() and (base / p).exists():
            m["path"] = str(base / p)
    task = data.get("task")
    if isinstance(task, dict):
        blocks = [task.get("robots"), task.get("obstacles")]
        if isinstance(task.get("modules"), list):
            blocks += task["modules"]
        for block in blocks:
            if not isinstance(block, dict):
                continue
            for key in TASK_FILE_KEYS:
                if isinstance(block.get(key), str):
                    p = Path(block[key]).expanduser()
                    if not p.is_absolute() and (base / p).exists():
                        block[key] = str(base / p)
    robot = data.get("robot")
    if isinstance(robot, str) and robot.endswith((".yaml", ".yml")):
        p = Path(robot).expanduser()
        if not p.is_absolute() and (base / p).exists():
            data["robot"] = str(base / p)


def validate_plugins(cfg: ExperimentConfig, *, source: str | None = None) -> None:
    """Check every plugin block and the robot against their registries."""
    MAP_SOURCES.validate(cfg.map, source=source, path="map")
    validate_mode("robots", cfg.task.robots, source=source, path="task.robots")
    validate_mode("obstacles", cfg.task.obstacles, source=source, path="task.obstacles")
    for i, module in enumerate(cfg.task.modules):
        validate_mode("modules", module, source=source, path=f"task.modules[{i}]")
    CROWD_MODELS.check(cfg.crowd, source=source, path="crowd")
    BACKENDS.validate(cfg.sim.backend, source=source, path="sim.backend")
    GLOBAL_PLANNERS.validate(
        cfg.navigation.global_planner, source=source, path="navigation.global_planner"
    )
    INTERMEDIATE_PLANNERS.validate(
        cfg.navigation.intermediate_planner, source=source,
        path="navigation.intermediate_planner",
    )
    local, _ = LOCAL_PLANNERS.validate(
        cfg.navigation.local_planner, source=source, path="navigation.local_planner"
    )
    try:
        robot = load_robot(cfg.robot)
    except UnknownNameError as e:
        raise UnknownNameError(e.message, source=source, path="robot") from None
    try:
        robot.lidar(cfg.navigation.scan_sensor, path="navigation.scan_sensor")
    except ConfigError as e:
        raise e.located(source=source) from None
    check_perception(cfg.navigation.perception, robot, source=source)
    kind = robot.kinematics_type
    supported = getattr(local.obj, "supports", frozenset())
    if kind not in supported:
        raise ConfigError(
            f"local planner {local.name!r} cannot drive {kind!r} robots like {robot.name!r} "
            f"(it supports: {', '.join(sorted(supported))})",
            source=source,
            path="navigation.local_planner.type",
        )
