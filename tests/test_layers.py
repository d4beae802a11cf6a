"""Arena's modules import one way: no import cycle, and the low layers in a fixed order.

Every ``import`` statement under ``arena/`` counts, at module level or inside a function (a
function-level import still ties the two modules together), except those under
``if TYPE_CHECKING:`` (annotations only). The low layers, lowest first::

    core < scene < maps < sensors < robots < crowd < sim < tasks < episode

A module of one of them never imports a module of a higher one. ``scene`` (obstacles, the static
world, snapshots, episodes) sits below ``maps`` because map sources and generators produce placed
obstacles; it holds a grid and robot models without calling them (typed under TYPE_CHECKING).
``sensors`` sits below ``robots`` because a robot model carries its sensors' specs. ``episode``
(the one episode loop) sits on top: experiment, eval and learn run their episodes through it.
The higher
packages (nav, eval, experiment, learn, render, cli, config, plugins ...) need to be free of
cycles, and the pairs of :data:`UPWARD` (nav below learn, eval below experiment, the episode
loop below eval, learn and experiment) never import upward.
"""

from __future__ import annotations

import ast
import graphlib
from pathlib import Path

ARENA = Path(__file__).resolve().parent.parent / "arena"

LAYERS = ("core", "scene", "maps", "sensors", "robots", "crowd", "sim", "tasks", "episode")
"""The low layers, lowest first: ``arena.<layer>`` may import only its own and lower layers."""


def _modules() -> dict[str, Path]:
    out = {}
    for path in ARENA.rglob("*.py"):
        name = ".".join(path.relative_to(ARENA.parent).with_suffix("").parts)
        out[name.removesuffix(".__init__")] = path
    return out


MODULES = _modules()


def _resolve(name: str) -> str | None:
    """The arena module an imported name lives in (``arena.a.b.Name`` -> ``arena.a.b``)."""
    while name and name not in MODULES:
        name = name.rpartition(".")[0]
    return name or None


class _Imports(ast.NodeVisitor):
    """Imports of one module: ``(imported module, line)``, TYPE_CHECKING blocks left out."""

    def __init__(self, package: str) -> None:
        self.package = package
        self.found: list[tuple[str, int]] = []

    def visit_If(self, node: ast.If) -> None:
        if "TYPE_CHECKING" not in ast.unparse(node.test):
            for child in node.body:
                self.visit(child)
        for child in node.orelse:
            self.visit(child)

    def _add(self, names: list[str], line: int) -> None:
        for name in names:
            target = _resolve(name)
            if target is not None:
                self.found.append((target, line))

    def visit_Import(self, node: ast.Import) -> None:
        self._add([a.name for a in node.names], node.lineno)

    def visit_ImportFrom(self, node: ast.ImportFrom) -> None:
        base = node.module or ""
        if node.level:
            parts = self.package.split(".")
            parts = parts[: len(parts) - node.level + 1]
            base = ".".join([*parts, base] if base else parts)
        self._add([f"{base}.{a.name}" for a in node.names], node.lineno)


def _graph() -> dict[str, list[tuple[str, int]]]:
    graph = {}
    for name, path in MODULES.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        visitor = _Imports(package)
        visitor.visit(ast.parse(path.read_text(encoding="utf-8")))
        graph[name] = [(t, line) for t, line in visitor.found if t != name]
    return graph


GRAPH = _graph()


def _layer(module: str) -> int | None:
    parts = module.split(".")
    return LAYERS.index(parts[1]) if len(parts) > 1 and parts[1] in LAYERS else None


def test_the_import_graph_is_read():
    # a reader that found nothing would pass the tests below vacuously
    assert any(t == "arena.scene.state" for t, _ in GRAPH["arena.scene.episode"])
    assert any(t == "arena.crowd.walls" for t, _ in GRAPH["arena.crowd.simulator"])
    assert len(GRAPH) > 150


def test_no_import_cycle_among_arena_modules():
    sorter = graphlib.TopologicalSorter({m: {t for t, _ in deps} for m, deps in GRAPH.items()})
    try:
        sorter.prepare()
    except graphlib.CycleError as e:
        cycle = e.args[1]
        raise AssertionError("import cycle: " + " -> ".join(cycle)) from None


def test_low_layers_never_import_a_higher_layer():
    wrong = []
    for module, deps in GRAPH.items():
        own = _layer(module)
        if own is None:
            continue
        for target, line in deps:
            other = _layer(target)
            if other is not None and other > own:
                wrong.append(f"{module}:{line} imports {target}")
    assert wrong == []


def test_the_checks_catch_a_cycle_and_an_upward_import():
    # the same readers on a made-up pair of modules
    visitor = _Imports("arena.maps")
    visitor.visit(ast.parse(
        "from typing import TYPE_CHECKING\n"
        "if TYPE_CHECKING:\n    from arena.sim.backend import BACKENDS\n"
        "def f():\n    from arena.crowd.base import CROWD_MODELS\n"
        "from .grid import OccupancyGrid\n"
    ))
    assert visitor.found == [("arena.crowd.base", 5), ("arena.maps.grid", 6)]
    assert _layer("arena.crowd.base") > _layer("arena.maps.grid")
    sorter = graphlib.TopologicalSorter({"a": {"b"}, "b": {"a"}})
    try:
        sorter.prepare()
    except graphlib.CycleError:
        pass
    else:
        raise AssertionError("graphlib did not report a cycle")


UPWARD = {
    ("nav", "learn"),  # the learned planners live in arena.learn.planners
    ("eval", "experiment"),  # one benchmark episode is arena.eval.episodes
    ("episode", "eval"), ("episode", "learn"), ("episode", "experiment"),  # the loop is below
}
"""Package pairs ``(a, b)``: no module of ``arena.a`` imports one of ``arena.b``."""


def test_the_loop_and_navigation_sit_below_learn_eval_and_experiment():
    def package(module: str) -> str:
        parts = module.split(".")
        return parts[1] if len(parts) > 1 else parts[0]

    wrong = [
        f"{module}:{line} imports {target}"
        for module, deps in GRAPH.items()
        for target, line in deps
        if (package(module), package(target)) in UPWARD
    ]
    assert wrong == []
    # the pairs are read: each upper package does import the lower one
    assert any(package(t) == "nav" for m, d in GRAPH.items() if package(m) == "learn" for t, _ in d)
    assert any(package(t) == "episode" for m, d in GRAPH.items() if package(m) == "eval"
               for t, _ in d)
