"""Every command and snippet of README.md runs (or, in the default suite, is at least checked).

The README is parsed as it stands: every line of a ```` ```bash ```` block that starts with
``arena`` is a command, every ```` ```python ```` block a snippet. All of them run in README
order in one temporary working directory, so a command can use what an earlier one wrote
(``arena maps generate … -o worlds/wh`` then ``arena run --map worlds/wh``). Placeholders are
made real there first: ``my_experiment.yaml`` (a small experiment) and every ``path/to/…`` (a
copy of a packaged world, its ``map.yaml`` or its scenario), see :func:`_materialise`.
Repository-relative paths (``arena/worlds/…``) are not made real: the commands must work
outside a clone.

Default suite (:func:`test_readme_commands_parse_and_validate`):

- every command's options and arguments are parsed by the CLI's own parser (an unknown or
  malformed option fails here);
- ``arena run`` commands run up to the simulation: the CLI resolves the config, the map and the
  task and draws the first episode (``run_experiment`` replaced by :func:`_first_episode`), so a
  config error or a task that cannot be drawn (a 12 m goal in an 8 m room) fails here;
- ``arena bench``, ``arena train`` and ``arena report`` are parsed only (they run in the slow
  test);
- ``arena ros2`` and ``arena ros1`` are parsed only, in both suites (they talk to other ROS
  processes: tests/ros runs them in network namespaces of their own);
- every other command (``robots``, ``plugins``, ``maps``, ``tasks``, ``scenario``) runs in full;
- every Python snippet compiles and its imports resolve.

Slow suite (:func:`test_readme_runs_every_command_and_snippet`, ``pytest -m slow``): every
command and snippet runs in full, with these reductions appended to keep it minutes long:
``arena run`` gets ``-n 1`` (one episode); ``arena bench paper`` gets ``--scale 0.1`` (13 of
160 episodes, every stage kept; ``quick``'s 31 run in full); ``arena train`` gets ``--steps 256
--envs 1``; ``--interactive`` runs get ``reset`` on stdin (the episode
ends at once instead of running for a minute of wall time).
"""

from __future__ import annotations

import ast
import json
import os
import re
import shlex
import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import click
import pytest
import typer.main
from typer.testing import CliRunner

import arena
from arena.cli import app

README = Path(__file__).resolve().parents[1] / "README.md"
WORLDS = Path(arena.__file__).resolve().parent / "worlds"

PARSE_ONLY = ("bench", "train", "report")
"""First words of commands the default suite parses but does not run (minutes each)."""

ISOLATED = ("ros2", "ros1")
"""First words of commands both suites only parse: they talk to other ROS processes, which the
ROS tests (tests/ros) run in network namespaces of their own, never on this machine's network."""

REDUCTIONS: dict[str, list[str]] = {
    "run": ["-n", "1"],
    "train": ["--steps", "256", "--envs", "1"],
}
"""Arguments the slow test appends to keep each command short (the last option wins)."""

BENCH_SCALES = {"paper": "0.1"}
"""``--scale`` the slow test gives ``arena bench SUITE``: the paper suite's 160 episodes become
13, every stage kept; ``quick`` (31 episodes) runs in full."""


def _reduced(args: list[str]) -> list[str]:
    """``args`` with the slow test's reductions appended."""
    extra = list(REDUCTIONS.get(args[0], []))
    if args[0] == "bench" and len(args) > 1 and args[1] in BENCH_SCALES:
        extra += ["--scale", BENCH_SCALES[args[1]]]
    return [*args, *extra]

# The example plugin files of docs/plugins.md (blocks that start ``# NAME.py``), which README
# commands name with ``--plugin``.
GUIDE_FILES = {
    block.splitlines()[0][2:]: block
    for block in re.findall(
        r"```python\n(.*?)```",
        (Path(__file__).resolve().parents[1] / "docs" / "plugins.md").read_text(encoding="utf-8"),
        flags=re.S,
    )
    if re.fullmatch(r"# \w+\.py", block.splitlines()[0])
}
EXPERIMENT = "name: my_experiment\nrobot: burger\nepisodes: 1\noutput: {video: false}\n"
"""The ``my_experiment.yaml`` the README's examples refer to."""


def _blocks(text: str) -> Iterator[tuple[str, str]]:
    """``(language, body)`` of every fenced code block."""
    for m in re.finditer(r"^```(\w*)[^\n]*\n(.*?)^```", text, flags=re.S | re.M):
        yield m.group(1), m.group(2)


def readme_commands(text: str) -> list[list[str]]:
    """The ``arena`` commands of the bash blocks, as argument lists without ``arena``."""
    out = []
    for lang, body in _blocks(text):
        if lang != "bash":
            continue
        for line in body.splitlines():
            if line.strip().startswith("arena "):
                out.append(shlex.split(line, comments=True)[1:])
    return out


def readme_snippets(text: str) -> list[str]:
    """The Python blocks."""
    return [body for lang, body in _blocks(text) if lang == "python"]


def _materialise(tokens: list[str], root: Path) -> None:
    """Create the files a command's placeholder paths name, under ``root``.

    ``my_experiment.yaml`` gets :data:`EXPERIMENT`; ``path/to/X.yaml`` the packaged
    ``small_office`` map (``map.yaml`` + image beside it; a map the demo's 12 m goals fit);
    ``path/to/X/…/N.json`` a scenario of the packaged ``corridor`` world; ``path/to/X`` (a
    folder) a copy of that world.
    """
    for i, tok in enumerate(tokens):
        value = tok.split("=", 1)[-1]
        if value.endswith("my_experiment.yaml") and not (root / value).exists():
            (root / value).write_text(EXPERIMENT)
        if tok == "--plugin" and i + 1 < len(tokens) and tokens[i + 1] in GUIDE_FILES:
            (root / tokens[i + 1]).write_text(GUIDE_FILES[tokens[i + 1]], encoding="utf-8")
        m = re.match(r"(path/to/[^/]+)(/.*)?$", value)
        if m is None:
            continue
        head = root / m.group(1)
        if head.suffix in (".yaml", ".yml"):
            if not head.exists():
                head.parent.mkdir(parents=True, exist_ok=True)
                for f in (WORLDS / "small_office" / "map").iterdir():
                    shutil.copy(f, head.parent / (head.name if f.suffix == ".yaml" else f.name))
            continue
        if not head.exists():
            shutil.copytree(WORLDS / "corridor", head)
        # `--map path/to/world --scenario NAME`: the world holds scenarios/NAME.json
        if "--scenario" in tokens:
            name = tokens[tokens.index("--scenario") + 1]
            scenario = head / "scenarios" / f"{name}.json"
            if "/" not in name and not name.endswith(".json") and not scenario.exists():
                shutil.copy(WORLDS / "corridor" / "scenarios" / "default.json", scenario)
        full = root / value
        if full.suffix == ".json" and not full.exists():
            full.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy(WORLDS / "corridor" / "scenarios" / "default.json", full)


def _parse(args: list[str]) -> None:
    """Parse ``args`` with the CLI's click commands, down to the leaf (no callback runs)."""
    cmd: click.Command = typer.main.get_command(app)
    ctx = cmd.make_context("arena", list(args), resilient_parsing=False)
    while isinstance(cmd, click.Group):
        rest = [*ctx.protected_args, *ctx.args]
        name, sub, rest = cmd.resolve_command(ctx, rest)
        assert sub is not None, f"unknown command {name!r}"
        ctx = sub.make_context(name, rest, parent=ctx)
        cmd = sub


def _first_episode(cfg: Any, *args: Any, **kwargs: Any) -> tuple[Path, list[Any]]:
    """Stand-in for ``run_experiment``: build everything and draw episode 0, simulate nothing."""
    from arena.robots.presets import load_robot
    from arena.tasks.generator import TaskGenerator

    TaskGenerator.from_config(cfg, [load_robot(cfg.robot)]).episode(0)
    return Path("."), []


def _invoke(args: list[str], stdin: str = "") -> tuple[int, str]:
    result = CliRunner().invoke(app, args, input=stdin, catch_exceptions=True)
    output = result.output
    if result.exception is not None and not isinstance(result.exception, SystemExit):
        output += f"\n{type(result.exception).__name__}: {result.exception}"
        return 1, output
    return result.exit_code, output


TEXT = README.read_text(encoding="utf-8")
COMMANDS = readme_commands(TEXT)
SNIPPETS = readme_snippets(TEXT)


def test_the_readme_has_commands_and_snippets():
    """The parser finds what the README shows (guards against a silently empty test)."""
    assert len(COMMANDS) >= 20 and {c[0] for c in COMMANDS} >= {"run", "bench", "train"}
    assert len(SNIPPETS) >= 2
    assert ["robots"] in COMMANDS


@pytest.fixture
def _restore_plugins(monkeypatch):
    """Commands with ``--plugin`` register plugins in this process: remove them afterwards."""
    from arena.plugins import PLUGINS_ENV, all_registries

    monkeypatch.setenv(PLUGINS_ENV, os.environ.get(PLUGINS_ENV, ""))
    before = {kind: set(reg.names()) for kind, reg in all_registries().items()}
    yield
    for kind, reg in all_registries().items():
        for name in set(reg.names()) - before.get(kind, set()):
            reg._entries.pop(name)


@pytest.mark.usefixtures("_restore_plugins")
def test_readme_commands_parse_and_validate(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr("arena.experiment.run_experiment", _first_episode)
    failures = []
    for args in COMMANDS:
        _materialise(args, tmp_path)
        line = "arena " + shlex.join(args)
        try:
            _parse(args)
        except (click.UsageError, AssertionError) as e:
            failures.append(f"{line}: does not parse: {e}")
            continue
        if args[0] in PARSE_ONLY or args[0] in ISOLATED:
            continue
        code, output = _invoke(args)
        if code != 0:
            failures.append(f"{line}: exit {code}: {output.strip()[-400:]}")
    assert not failures, "\n".join(failures)


def test_readme_snippets_compile_and_import(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for code in SNIPPETS:
        tree = ast.parse(code)
        imports = [n for n in tree.body if isinstance(n, ast.Import | ast.ImportFrom)]
        exec(compile(ast.Module(body=imports, type_ignores=[]), "README.md", "exec"), {})


@pytest.mark.slow
def test_readme_runs_every_command_and_snippet(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    failures = []
    for args in COMMANDS:
        _materialise(args, tmp_path)
        if args[0] in ISOLATED:
            _parse(args)
            continue
        full = _reduced(args)
        stdin = "reset\nquit\n" if "--interactive" in args else ""
        code, output = _invoke(full, stdin)
        if code != 0:
            failures.append(f"arena {shlex.join(full)}: exit {code}: {output.strip()[-400:]}")
    for code in SNIPPETS:
        (tmp_path / "my_experiment.yaml").write_text(EXPERIMENT)
        try:
            exec(compile(code, "README.md", "exec"), {"__name__": "readme"})
        except Exception as e:  # report every failing snippet, not only the first
            failures.append(f"snippet {code.splitlines()[0]!r}: {type(e).__name__}: {e}")
    assert not failures, "\n".join(failures)


def test_placeholders_are_made_real(tmp_path):
    """The placeholder rules give loadable files: a map, a world folder and its scenario."""
    from arena.maps.io import load_map

    _materialise(["--map", "path/to/map.yaml", "my_experiment.yaml"], tmp_path)
    _materialise(["path/to/w", "--scenario", "path/to/w/scenarios/1.json"], tmp_path)
    assert load_map(tmp_path / "path/to/map.yaml").data.size > 0
    assert (tmp_path / "path/to/w/map/map.yaml").is_file()
    assert json.loads((tmp_path / "path/to/w/scenarios/1.json").read_text())
    assert "robot: burger" in (tmp_path / "my_experiment.yaml").read_text()
