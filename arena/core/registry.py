"""The one plugin registry used by every plugin kind.

A registry maps stable snake_case names to classes. A class may declare a nested pydantic
``Params`` model; :meth:`Registry.build` validates a flat YAML block ``{type: name, **params}``
against it and constructs ``cls(params)``. Third-party packages add plugins through Python entry
points in the group given at construction (loaded lazily, on first lookup).

Built-in plugins may be declared by name at construction (``builtins={"random":
"arena.tasks.robot_modes.random"}``): the registry knows the name at once and imports the module
(which registers the plugin) only when that name is first looked up. A config is then validated
without importing every implementation, and a registry never imports the modules that register
with it (which import the registry), so the import graph stays one-way. A built-in whose module
is costly to import (numba kernels) may also declare where its ``Params`` live (``params={"orca":
"arena.crowd.models.orca.params:OrcaParams"}``): :meth:`Registry.check` then validates a block
against them without importing the implementation.

A registry may also declare *aliases* of built-ins (``aliases={"rosnav": "rosnav_rl"}``): another
project's name for one of ours, so its files load unchanged. An alias resolves to its target's
:class:`Entry` (same class, same ``Params``, the target's name) in every lookup; it is not a
second plugin, so :meth:`Registry.names` and :meth:`Registry.entries` list the target once and
:meth:`Registry.aliases` lists the aliases.

Example::

    LOCAL_PLANNERS: Registry[LocalPlanner] = Registry(
        "local planner", entry_points="arena.local_planners"
    )

    @LOCAL_PLANNERS.register("pure_pursuit", tags=("classic",))
    class PurePursuitPlanner:
        class Params(BaseModel, frozen=True, extra="forbid"):
            lookahead: float = Field(0.8, gt=0, description="m")
        def __init__(self, params: Params) -> None: ...
"""

from __future__ import annotations

import difflib
import importlib
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from importlib.metadata import entry_points as _entry_points
from typing import Any, Generic, TypeVar

from pydantic import BaseModel, ValidationError

from arena.core.errors import ConfigError, UnknownNameError, from_validation_error

T = TypeVar("T")

_ALL: dict[str, Registry[Any]] = {}


@dataclass(frozen=True)
class Entry(Generic[T]):
    """One registered plugin."""

    name: str
    obj: type[T] | Callable[..., T]
    tags: tuple[str, ...]

    @property
    def params_model(self) -> type[BaseModel] | None:
        """The plugin's nested ``Params`` model, or ``None`` if it takes no parameters."""
        params = getattr(self.obj, "Params", None)
        return params if isinstance(params, type) and issubclass(params, BaseModel) else None

    @property
    def summary(self) -> str:
        """First line of the plugin's docstring."""
        doc = (getattr(self.obj, "__doc__", None) or "").strip()
        return doc.splitlines()[0] if doc else ""


class Registry(Generic[T]):
    """A named collection of plugins of one kind.

    Args:
        kind: human name of the plugin kind, used in messages ("local planner").
        entry_points: entry-point group scanned for third-party plugins ("arena.local_planners").
        builtins: name -> dotted module that registers that name on import; imported on the
            first lookup of the name (see the module docstring).
        params: built-in name -> ``"module:Class"``, its ``Params`` model in a light module, for
            :meth:`check`; the plugin's ``Params`` must be that class (checked on import).
        aliases: alias -> built-in name it stands for (see the module docstring).
    """

    def __init__(
        self,
        kind: str,
        *,
        entry_points: str | None = None,
        builtins: Mapping[str, str] | None = None,
        params: Mapping[str, str] | None = None,
        aliases: Mapping[str, str] | None = None,
    ) -> None:
        if kind in _ALL:
            raise ValueError(f"a registry for {kind!r} already exists")
        self.kind = kind
        self.entry_point_group = entry_points
        self._entries: dict[str, Entry[T]] = {}
        self._builtins: dict[str, str] = dict(builtins or {})
        self._params: dict[str, str] = dict(params or {})
        if not self._params.keys() <= self._builtins.keys():
            raise ValueError(f"params declared for names that are not built-ins: {self._params}")
        self._aliases: dict[str, str] = dict(aliases or {})
        for alias, target in self._aliases.items():
            # only built-ins: an alias must resolve without loading anything unknown, and may
            # never shadow (or be shadowed by) a plugin of its own
            if alias in self._builtins or target not in self._builtins:
                raise ValueError(
                    f"alias {alias!r} -> {target!r}: an alias must name a built-in "
                    f"and not be one"
                )
        self._entry_points_loaded = entry_points is None
        _ALL[kind] = self

    # -- registration -----------------------------------------------------------------------
    def register(self, name: str, *, tags: tuple[str, ...] = ()) -> Callable[[Any], Any]:
        """Class decorator that registers the class under ``name``."""

        def deco(obj: Any) -> Any:
            self.add(name, obj, tags=tags)
            return obj

        return deco

    def add(self, name: str, obj: Any, *, tags: tuple[str, ...] = ()) -> None:
        """Register ``obj`` under ``name``; a second plugin with the same name is an error."""
        if not name or name != name.strip() or " " in name:
            raise ValueError(f"invalid {self.kind} name {name!r}")
        if name in self._aliases:
            raise ValueError(
                f"duplicate {self.kind} name {name!r}: it is an alias of "
                f"{self._aliases[name]!r}"
            )
        declared = self._builtins.get(name)
        module = str(getattr(obj, "__module__", ""))
        if declared is not None and not (module == declared or module.startswith(declared + ".")):
            self._load_builtin(name)  # a plugin taking a built-in's name meets the check below
        if name in self._entries and self._entries[name].obj is not obj:
            raise ValueError(
                f"duplicate {self.kind} name {name!r}: already registered by "
                f"{_qualname(self._entries[name].obj)}, now {_qualname(obj)}"
            )
        entry = Entry(name=name, obj=obj, tags=tuple(tags))
        if name in self._params and entry.params_model is not self._params_of(name):
            # check() validated configs against the declared model: a twin could drift from it
            raise RuntimeError(
                f"{self.kind} {name!r}: Params is not the declared {self._params[name]}"
            )
        self._entries[name] = entry

    # -- lookup -----------------------------------------------------------------------------
    def _load_entry_points(self) -> None:
        if self._entry_points_loaded:
            return
        self._entry_points_loaded = True
        for ep in _entry_points(group=self.entry_point_group or ""):
            if ep.name in self._entries or ep.name in self._builtins or ep.name in self._aliases:
                continue  # built-in wins; the duplicate guard is for code registrations
            self.add(ep.name, ep.load(), tags=("third_party",))

    @property
    def builtins(self) -> dict[str, str]:
        """The declared built-ins: name -> the module that registers it."""
        return dict(self._builtins)

    def aliases(self) -> dict[str, str]:
        """The declared aliases: alias -> the name it stands for."""
        return dict(self._aliases)

    def resolve(self, name: str) -> str:
        """``name`` with an alias replaced by its target (other names unchanged)."""
        return self._aliases.get(name, name)

    def _load_builtin(self, name: object) -> None:
        module = self._builtins.get(name) if isinstance(name, str) else None
        if module is None or name in self._entries:
            return
        importlib.import_module(module)
        if name not in self._entries:
            raise RuntimeError(f"{module} is declared to register {self.kind} {name!r}, did not")

    def _params_of(self, name: str) -> type[BaseModel]:
        module, _, attr = self._params[name].partition(":")
        model: type[BaseModel] = getattr(importlib.import_module(module), attr)
        return model

    def _load_all_builtins(self) -> None:
        for name in self._builtins:
            self._load_builtin(name)

    def entry(self, name: str) -> Entry[T]:
        """The :class:`Entry` for ``name`` (or for the target of an alias).

        Unknown names raise with a close match.
        """
        self._load_entry_points()
        if isinstance(name, str):
            name = self.resolve(name)
        self._load_builtin(name)
        try:
            return self._entries[name]
        except KeyError:
            raise UnknownNameError(self.unknown_message(name)) from None

    def get(self, name: str) -> Any:
        """The registered class (or factory) for ``name``."""
        return self.entry(name).obj

    def unknown_message(self, name: object) -> str:
        """Message for an unknown name: the close match first, then every known name."""
        known = self.names()
        close = difflib.get_close_matches(str(name), known + sorted(self._aliases), n=1,
                                          cutoff=0.5)
        hint = f"did you mean {close[0]!r}? " if close else ""
        return f"unknown {self.kind} {name!r}; {hint}known: {', '.join(known) or '(none)'}"

    def names(self, tag: str | None = None) -> list[str]:
        """Sorted registered names, optionally only those carrying ``tag``.

        Without ``tag`` no built-in module is imported; tags are known only once imported.
        """
        self._load_entry_points()
        if tag is None:
            return sorted(self._entries.keys() | self._builtins.keys())
        self._load_all_builtins()
        return sorted(n for n, e in self._entries.items() if tag in e.tags)

    def entries(self) -> list[Entry[T]]:
        """All entries, sorted by name (imports every built-in module)."""
        self._load_entry_points()
        self._load_all_builtins()
        return [self._entries[n] for n in sorted(self._entries)]

    def __contains__(self, name: object) -> bool:
        self._load_entry_points()
        return name in self._entries or name in self._builtins or name in self._aliases

    def __iter__(self) -> Iterator[str]:
        return iter(self.names())

    def __len__(self) -> int:
        self._load_entry_points()
        return len(self._entries.keys() | self._builtins.keys())

    # -- construction -----------------------------------------------------------------------
    def validate(
        self, spec: Mapping[str, Any] | str, *, source: str | None = None, path: str | None = None
    ) -> tuple[Entry[T], BaseModel | None]:
        """Check a ``{type: name, **params}`` block; return the entry and its validated params.

        Raises:
            ConfigError: naming ``source`` and the key path when the block is invalid.
        """
        spec = self._spec(spec, source=source, path=path)
        try:
            entry = self.entry(spec["type"])
        except UnknownNameError as e:
            raise UnknownNameError(
                e.message, source=source, path=".".join(p for p in (path, "type") if p)
            ) from None
        return entry, self._params_for(entry.name, entry.params_model, spec, source, path)

    def check(
        self, spec: Mapping[str, Any] | str, *, source: str | None = None, path: str | None = None
    ) -> BaseModel | None:
        """Validate a block as :meth:`validate` does; return only its params.

        A built-in with declared ``params`` is checked against them without importing its
        module (a config is validated without compiling the crowd model's kernels).
        """
        spec = self._spec(spec, source=source, path=path)
        name = spec["type"]
        if isinstance(name, str):
            name = self.resolve(name)
        if isinstance(name, str) and name in self._params and name not in self._entries:
            return self._params_for(name, self._params_of(name), spec, source, path)
        return self.validate(spec, source=source, path=path)[1]

    def _spec(
        self, spec: Mapping[str, Any] | str, *, source: str | None, path: str | None
    ) -> Mapping[str, Any]:
        if isinstance(spec, str):
            spec = {"type": spec}
        if not isinstance(spec, Mapping):
            raise ConfigError(
                f"expected a mapping with a 'type' key or a {self.kind} name, got {spec!r}",
                source=source,
                path=path,
            )
        if "type" not in spec:
            raise ConfigError(
                f"missing 'type' (one of: {', '.join(self.names())})",
                source=source,
                path=path,
            )
        return spec

    def _params_for(
        self,
        name: str,
        model: type[BaseModel] | None,
        spec: Mapping[str, Any],
        source: str | None,
        path: str | None,
    ) -> BaseModel | None:
        raw = {k: v for k, v in spec.items() if k != "type"}
        if model is None:
            if raw:
                raise ConfigError(
                    f"{self.kind} {name!r} takes no parameters, got {sorted(raw)}",
                    source=source,
                    path=path,
                )
            return None
        try:
            return model.model_validate(raw)
        except ValidationError as e:
            raise from_validation_error(e, source=source, prefix=path) from None

    def build(
        self,
        spec: Mapping[str, Any] | str,
        *args: Any,
        source: str | None = None,
        path: str | None = None,
        **kwargs: Any,
    ) -> T:
        """Validate ``spec`` and construct the plugin: ``cls(params, *args, **kwargs)``.

        Plugins without a ``Params`` model are constructed as ``cls(*args, **kwargs)``.
        """
        entry, params = self.validate(spec, source=source, path=path)
        factory: Callable[..., T] = entry.obj
        if params is None:
            return factory(*args, **kwargs)
        return factory(params, *args, **kwargs)

    def __repr__(self) -> str:
        return f"Registry({self.kind!r}, {len(self._entries)} entries)"


def all_registries() -> dict[str, Registry[Any]]:
    """Every registry created so far, by kind (import :mod:`arena.plugins` first to fill them)."""
    return dict(_ALL)


def _qualname(obj: Any) -> str:
    return f"{getattr(obj, '__module__', '?')}.{getattr(obj, '__qualname__', repr(obj))}"
