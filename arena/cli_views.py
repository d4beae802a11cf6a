"""What the command line prints for plugins and runs: kept out of :mod:`arena.cli`'s commands.

Listings print a table on a terminal and plain tab-separated lines otherwise (pipes, logs, CI),
so that no column width cuts a name; ``--json`` prints JSON.
"""

from __future__ import annotations

import json
import re
from collections.abc import Callable
from contextlib import AbstractContextManager, nullcontext
from typing import Any

from rich.console import Console
from rich.table import Table

#: Columns of one plugin's parameter listing.
PARAM_COLUMNS = ("name", "type", "default", "unit", "constraints", "description")


def print_plugins(
    console: Console, kind: str | None, name: str | None, *, as_json: bool = False
) -> None:
    """``arena plugins [KIND [NAME]]``: every plugin, one kind's, or one plugin's parameters."""
    from arena.plugins import all_registries, describe_plugin, kind_key, registry_for

    if name is not None:
        print_plugin(console, describe_plugin(str(kind), name), as_json=as_json)
        return
    if kind is not None:
        reg = registry_for(kind)
        registries = [(reg.kind, reg)]
    else:
        known = -1
        while len(all_registries()) != known:
            # importing one kind's plugins can create another kind's registry (the learned
            # local planners bring the reward terms): list those made by the imports too
            known = len(all_registries())
            for r in list(all_registries().values()):
                r.entries()
        registries = sorted(all_registries().items())
    rows = []
    for k, reg in registries:
        entries = reg.entries()
        rows += [{"kind": kind_key(k), "name": e.name, "tags": list(e.tags),
                  "description": e.summary} for e in entries]
        # another project's name for a plugin: listed under the kind, pointing at the target
        rows += [{"kind": kind_key(k), "name": alias, "tags": ["alias"],
                  "description": f"alias of {target}", "alias_of": target}
                 for alias, target in sorted(reg.aliases().items())]
    if as_json:
        print(json.dumps(rows, indent=2))
        return
    if not console.is_terminal:
        for r in rows:
            print("\t".join((r["kind"], r["name"], ",".join(r["tags"]), r["description"])))
        return
    table = Table(title="Plugin registries  (arena plugins KIND NAME: parameters)")
    for col in ("kind", "name", "tags", "description"):
        table.add_column(col, no_wrap=col == "name")
    last = None
    for r in rows:
        if last is not None and r["kind"] != last:
            table.add_section()
        table.add_row(r["kind"] if r["kind"] != last else "", r["name"], ", ".join(r["tags"]),
                      r["description"])
        last = r["kind"]
    console.print(table)


def _cells(param: dict[str, Any]) -> list[str]:
    return [", ".join(param[c]) if c == "constraints" else param[c] for c in PARAM_COLUMNS]


def print_plugin(console: Console, info: dict[str, Any], *, as_json: bool = False) -> None:
    """Print :func:`arena.plugins.describe_plugin`'s answer: JSON, a table or plain lines.

    Plain: a ``# kind name: summary  (source)`` line, then a header line and one tab-separated
    line per parameter (name, type, default, unit, constraints, description).
    """
    if as_json:
        print(json.dumps(info, indent=2))
        return
    head = f"{info['kind']} {info['name']}" + (f" [{info['unit']}]" if "unit" in info else "")
    if "alias_of" in info:
        head += f" (alias of {info['alias_of']})"
    if not console.is_terminal:
        print(f"# {head}: {info['summary']}  ({info['source']})")
        if info["parameters"]:
            print("\t".join(PARAM_COLUMNS))
        for p in info["parameters"]:
            print("\t".join(_cells(p)))
        return
    console.print(f"[bold]{head}[/]  ({info['source']})", highlight=False)
    if info["doc"]:  # the prose, without the Args:/Attributes: sections
        console.print(re.split(r"\n\s*(?:Args|Attributes|Returns|Raises|Example)s?:\n",
                               info["doc"])[0], highlight=False)
    if not info["parameters"]:
        console.print("no parameters")
        return
    table = Table(title=f"parameters  ({info['kind']}: {{type: {info['name']}, KEY: VALUE}})")
    for col in PARAM_COLUMNS:
        table.add_column(col, no_wrap=col in ("name", "default"),
                         ratio=3 if col == "description" else None)
    for p in info["parameters"]:
        table.add_row(*_cells(p))
    console.print(table)


def episode_progress(
    console: Console, *, enabled: bool
) -> tuple[AbstractContextManager[Any], Callable[[int, float, float], None] | None]:
    """A progress bar of simulated time against the episode's time limit, and its callback.

    On a terminal the bar shows the running episode (``on_step(episode, time, limit)``, s);
    otherwise (piped, logged) nothing is drawn and the one line per finished episode that
    ``arena run`` prints is the progress.
    """
    if not enabled:
        return nullcontext(), None
    from rich.progress import BarColumn, Progress, TaskID, TextColumn, TimeElapsedColumn

    bar = Progress(
        TextColumn("episode {task.fields[episode]}"),
        BarColumn(),
        TextColumn("{task.completed:5.1f} / {task.total:.0f} s simulated"),
        TimeElapsedColumn(),
        console=console,
        transient=True,
    )
    tasks: dict[int, TaskID] = {}

    def on_step(episode: int, time: float, limit: float) -> None:
        if episode not in tasks:
            for done in tasks.values():  # the previous episode has ended
                bar.remove_task(done)
            tasks.clear()
            tasks[episode] = bar.add_task("", total=limit, episode=episode)
        bar.update(tasks[episode], completed=min(time, limit))

    return bar, on_step
