"""Import every built-in plugin module so that all registries are filled; load user plugins.

Third-party plugins arrive two ways:

* installed packages through entry points, loaded by each registry lazily;
* plugin files or modules named on the command line (``arena run --plugin my_planner.py``) or
  in the ``ARENA_PLUGINS`` environment variable (entries separated by ``os.pathsep``). A plugin
  registers itself on import, e.g. with ``@LOCAL_PLANNERS.register("my_planner")``.

:func:`load_plugins` records what it loaded in ``ARENA_PLUGINS``, and importing this module
loads what that variable names: worker processes (``arena bench -j N``, ``arena train``'s env
workers, a local Ray) inherit the environment and so import the same plugins before their first
job, and a class defined in a plugin file pickles by reference under the same module name.
"""

from __future__ import annotations

import difflib
import hashlib
import importlib
import importlib.util
import os
import re
import sys
from collections.abc import Iterable
from pathlib import Path
from types import ModuleType
from typing import Any

import arena.crowd.base
import arena.eval.metrics
import arena.maps.generators
import arena.maps.sources
import arena.nav
import arena.perception.stage
import arena.robots
import arena.sim.native2d
import arena.tasks.base  # noqa: F401  (task modes are declared there, imported when named)
from arena.core.errors import ConfigError, UnknownNameError
from arena.core.params_doc import describe_params
from arena.core.registry import Registry, all_registries

__all__ = ["PLUGINS_ENV", "all_registries", "describe_plugin", "kind_key", "load_plugins",
           "registry_for"]

#: Environment variable naming the plugin files / modules every Arena process imports.
PLUGINS_ENV = "ARENA_PLUGINS"

_MODULE_NAME = re.compile(r"[A-Za-z_]\w*(\.[A-Za-z_]\w*)*")
_loaded: dict[str, ModuleType] = {}  # resolved spec -> module (each plugin imported once)


def _is_path(spec: str) -> bool:
    # a bare name that is a folder (a package in the working folder) is a module name
    return spec.endswith(".py") or "/" in spec or os.sep in spec or Path(spec).is_file()


def _resolve(spec: str) -> str:
    """A plugin spec as loaded: an absolute ``.py`` path, or a dotted module name."""
    if not isinstance(spec, str) or not spec.strip():
        raise ConfigError(f"--plugin: expected a .py file or a module name, got {spec!r}")
    spec = spec.strip()
    if _is_path(spec):
        path = Path(spec).expanduser()
        if not path.is_file():
            raise ConfigError("no such plugin file", source=spec)
        if path.suffix != ".py":
            raise ConfigError("a plugin file must be a Python file ending in .py", source=spec)
        return str(path.resolve())
    if not _MODULE_NAME.fullmatch(spec):
        raise ConfigError(
            f"--plugin: {spec!r} is neither a .py file nor a dotted module name"
        )
    return spec


def _import_file(path: str) -> ModuleType:
    # One stable module name per file: a spawned worker importing the same file gets the same
    # name, so pickled classes and functions defined in the plugin resolve there too.
    digest = hashlib.sha1(path.encode()).hexdigest()[:10]
    stem = re.sub(r"\W", "_", Path(path).stem)
    name = f"arena_plugin_{stem}_{digest}"
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, path)
    if spec is None or spec.loader is None:
        raise ConfigError("cannot import this file as a Python module", source=path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[name]
        raise
    return module


def _import_module(name: str) -> ModuleType:
    # As ``python -m`` does: a module in the working directory is importable by name.
    cwd = os.getcwd()
    if cwd not in sys.path:
        sys.path.append(cwd)
    return importlib.import_module(name)


def load_plugins(specs: Iterable[str], *, export: bool = True) -> list[ModuleType]:
    """Import plugin files or modules so that they register with Arena's registries.

    Args:
        specs: paths of ``.py`` files, or dotted module names (importable from ``sys.path`` or
            the working directory).
        export: add them to ``ARENA_PLUGINS`` so that child processes load them too.

    Returns:
        The imported modules, in order (a plugin already loaded is not imported again).

    Raises:
        ConfigError: one line naming the plugin, for a missing file, a bad name, or a plugin
            that raises on import (its exception type and message, e.g. a duplicate name).
    """
    modules = []
    for raw in specs:
        spec = _resolve(raw)
        if spec not in _loaded:
            try:
                _loaded[spec] = _import_file(spec) if spec.endswith(".py") else _import_module(
                    spec
                )
            except ConfigError:
                raise
            except ModuleNotFoundError as e:
                if _is_path(spec) or e.name is None or not (
                    spec == e.name or spec.startswith(e.name + ".")
                ):
                    raise ConfigError(
                        f"plugin failed on import: {type(e).__name__}: {e}", source=raw
                    ) from None
                raise ConfigError(
                    "no such plugin module (not a file, not importable)", source=raw
                ) from None
            except (Exception, SystemExit) as e:
                lines = str(e).strip().splitlines()
                msg = f"{type(e).__name__}: {lines[0]}" if lines else type(e).__name__
                raise ConfigError(f"plugin failed on import: {msg}", source=raw) from None
        modules.append(_loaded[spec])
        if export:
            known = [s for s in os.environ.get(PLUGINS_ENV, "").split(os.pathsep) if s]
            if spec not in known:
                os.environ[PLUGINS_ENV] = os.pathsep.join([*known, spec])
    return modules


def kind_key(kind: str) -> str:
    """The command-line spelling of a registry kind: ``"local planner"`` -> ``local_planner``."""
    return kind.replace(" ", "_")


def registry_for(kind: str) -> Registry[Any]:
    """The registry of ``kind``: ``local_planner``, ``local-planner``, ``metrics``, ``crowd``.

    Spaces, dashes, a plural and a unique prefix are accepted; unknown kinds raise with a close
    match and the known kinds.
    """
    registries = {kind_key(k): r for k, r in all_registries().items()}
    key = re.sub(r"[\s-]+", "_", kind.strip().lower())
    for candidate in (key, key[:-1] if key.endswith("s") else key, key.removesuffix("es")):
        if candidate in registries:
            return registries[candidate]
    prefixed = [k for k in registries if k.startswith(key)] if key else []
    if len(prefixed) == 1:  # "crowd" -> crowd_model
        return registries[prefixed[0]]
    known = sorted(registries)
    close = difflib.get_close_matches(key, known, n=1, cutoff=0.4)
    hint = f"did you mean {close[0]!r}? " if close else ""
    raise UnknownNameError(f"unknown plugin kind {kind!r}; {hint}known: {', '.join(known)}")


def describe_plugin(kind: str, name: str) -> dict[str, Any]:
    """What ``arena plugins KIND NAME`` shows: kind, name, tags, docstring, parameters.

    For an alias (``rosnav``) ``name`` is the alias and ``alias_of`` the plugin it stands for,
    whose docstring and parameters are shown. ``parameters`` lists each field of the plugin's
    ``Params`` model as :meth:`~arena.core.params_doc.ParamInfo.as_dict` (name, type, default,
    unit, description, constraints); a metric also reports its ``unit``.
    """
    registry = registry_for(kind)
    entry = registry.entry(name)
    doc = (getattr(entry.obj, "__doc__", None) or "").strip()
    code = getattr(entry.obj, "fn", entry.obj)  # a metric: the function it wraps
    info: dict[str, Any] = {
        "kind": kind_key(registry.kind), "name": entry.name, "tags": list(entry.tags),
        "summary": entry.summary, "doc": doc,
        "source": f"{getattr(code, '__module__', '?')}."
                  f"{getattr(code, '__qualname__', type(code).__name__)}",
        "parameters": [p.as_dict() for p in describe_params(entry.params_model)],
    }
    if entry.name != name:
        info["name"], info["alias_of"] = name, entry.name
    unit = getattr(entry.obj, "unit", None)
    if isinstance(unit, str):
        info["unit"] = unit
    return info


def _from_environment() -> None:
    specs = [s for s in os.environ.get(PLUGINS_ENV, "").split(os.pathsep) if s.strip()]
    if specs:
        try:
            load_plugins(specs, export=False)
        except ConfigError as e:
            raise ConfigError(f"{PLUGINS_ENV}: {e}") from None


_from_environment()
