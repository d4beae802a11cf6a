"""Robot presets: YAML files in ``arena/robots/presets/`` plus third-party ones, by name.

Every ``<name>.yaml`` in the presets folder is registered in :data:`ROBOTS` at import. Other
packages add robots through the ``arena.robots`` entry-point group; an entry point may name a YAML
path (``str`` or :class:`~pathlib.Path`), a :class:`RobotModel`, or a callable returning either.

Example::

    from arena.robots.presets import load_robot
    jackal = load_robot("jackal")
    mine = load_robot("configs/my_robot.yaml")
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from arena.core import files
from arena.core.errors import ConfigError, from_validation_error
from arena.core.registry import Registry
from arena.robots.model import CircleFootprint, RobotModel

PRESET_DIR = Path(__file__).with_name("presets")
"""Folder of the built-in robot YAML files."""


@dataclass(frozen=True)
class PresetFile:
    """A built-in robot preset: one YAML file, parsed on first use and then cached."""

    path: Path
    _cache: dict[str, RobotModel] = field(default_factory=dict, compare=False, repr=False)

    def __call__(self) -> RobotModel:
        """The validated robot (shared: :class:`RobotModel` is immutable)."""
        if "model" not in self._cache:
            model = load_robot_file(self.path)
            if model.name != self.path.stem:
                raise ConfigError(
                    f"preset name {model.name!r} differs from its file name {self.path.stem!r}",
                    source=str(self.path), path="name",
                )
            self._cache["model"] = model
        return self._cache["model"]


ROBOTS: Registry[Any] = Registry("robot", entry_points="arena.robots")
"""Robot presets by name; each entry is a loader (see the module docstring)."""

for _path in sorted(PRESET_DIR.glob("*.yaml")):
    ROBOTS.add(_path.stem, PresetFile(_path), tags=("builtin",))


# -- loading ------------------------------------------------------------------------------------
def read_yaml(path: str | Path) -> Any:
    """Parse a YAML file with the shared strict loader (:mod:`arena.core.files`).

    Raises:
        ConfigError: the file is missing, not UTF-8 text or not valid YAML (duplicate keys
            included), naming the file, the line and the column.
    """
    return files.read_yaml(path)


def load_robot_file(path: str | Path) -> RobotModel:
    """Load and validate one robot YAML file.

    Raises:
        ConfigError: naming the file and the key path of the first problem.
    """
    p = Path(path)
    data = read_yaml(p)
    if not isinstance(data, dict):
        raise ConfigError(
            f"expected a mapping of robot fields at the top level, got {type(data).__name__}",
            source=str(p),
        )
    try:
        return RobotModel.model_validate(data)
    except ValidationError as e:
        raise from_validation_error(e, source=str(p)) from None
    except ConfigError as e:  # kinematics and action checks raise these with a key path
        raise e.located(source=str(p)) from None


def _looks_like_path(name: str | Path) -> bool:
    if isinstance(name, Path):
        return True
    return name.endswith((".yaml", ".yml")) or "/" in name or "\\" in name


def load_robot(name_or_path: str | Path) -> RobotModel:
    """A robot by preset name (``"jackal"``) or from a YAML file path.

    Raises:
        UnknownNameError: an unknown preset name (with a close match, "did you mean ...?").
        ConfigError: an invalid or malformed file, naming the file and the key path.
    """
    if _looks_like_path(name_or_path):
        return load_robot_file(Path(name_or_path).expanduser())
    return _resolve(ROBOTS.get(name_or_path), name_or_path)


def _resolve(obj: Any, name: str) -> RobotModel:
    """Turn a registry entry (loader, path, model or factory) into a :class:`RobotModel`."""
    if isinstance(obj, RobotModel):
        return obj
    if isinstance(obj, (str, Path)):
        return load_robot_file(obj)
    if callable(obj):  # a PresetFile or a third-party factory
        result = obj()
        if isinstance(result, (RobotModel, str, Path)):
            return _resolve(result, name)
        raise ConfigError(f"robot {name!r}: its loader returned {type(result).__name__}")
    raise ConfigError(f"robot {name!r}: unsupported registry entry {type(obj).__name__}")


def robot_names(tag: str | None = None) -> list[str]:
    """Sorted names of every registered robot preset (optionally only those with ``tag``)."""
    return ROBOTS.names(tag)


# -- tables -------------------------------------------------------------------------------------
def _num(x: float) -> str:
    """A compact number: 3 significant digits, no trailing zeros (``inf`` for no limit)."""
    return "inf" if math.isinf(x) else f"{x:.3g}"


def _span(lo: float, hi: float) -> str:
    return "0" if lo == hi == 0 else f"{_num(lo)} … {_num(hi)}"


def _footprint_text(model: RobotModel) -> str:
    if isinstance(model.footprint, CircleFootprint):
        return f"circle r {_num(model.footprint.radius)}"
    poly = model.footprint_polygon()
    assert poly is not None
    ext = poly.max(axis=0) - poly.min(axis=0)
    return f"{_num(ext[0])} × {_num(ext[1])}"


def describe_robot(model: RobotModel) -> dict[str, Any]:
    """One table row for a CLI or web listing: short display strings (SI units, rounded).

    Keys: ``name``, ``kinematics`` (with the minimum turning radius R for car-like robots),
    ``radius`` (m), ``footprint`` (circle radius or bounding box length × width, m),
    ``velocity`` (vx and vy ranges in m/s, yaw-rate limit ω in rad/s), ``acc``
    (``acc_x / acc_y / acc_omega``, m/s², m/s², rad/s²) and ``laser`` (beams × field of view,
    range, rate). Values are rounded to 3 significant digits; exact ones are on the
    :class:`RobotModel`. Seven columns keep the table legible on an 80-column terminal.
    """
    lim = model.limits()
    laser = model.laser
    fov = 360.0 if laser.full_circle else math.degrees(laser.angle_max - laser.angle_min)
    kind = model.kinematics_type
    if lim.min_turning_radius > 0:
        kind = f"{kind} (R {_num(lim.min_turning_radius)})"
    return {
        "name": model.name,
        "kinematics": kind,
        "radius": _num(model.radius),
        "footprint": _footprint_text(model),
        "velocity": (
            f"vx {_span(lim.vx_min, lim.vx_max)}, vy {_span(lim.vy_min, lim.vy_max)}, "
            f"ω ±{_num(lim.omega_max)}"
        ),
        "acc": " / ".join(_num(a) for a in (lim.acc_x, lim.acc_y, lim.acc_omega)),
        "laser": (
            f"{laser.num_beams} × {fov:.0f}°, {_num(laser.range_max)} m, "
            f"{_num(laser.update_rate)} Hz"
        ),
    }


def describe_robots(names: list[str] | None = None) -> list[dict[str, Any]]:
    """Table rows (see :func:`describe_robot`) for ``names`` or every registered robot."""
    return [describe_robot(load_robot(n)) for n in (names if names is not None else robot_names())]


__all__ = [
    "PRESET_DIR",
    "ROBOTS",
    "PresetFile",
    "describe_robot",
    "describe_robots",
    "load_robot",
    "load_robot_file",
    "read_yaml",
    "robot_names",
]
