"""What the ``arena`` commands share: the consoles and the ``--plugin`` option."""

from __future__ import annotations

from typing import Annotated

import typer
from rich.console import Console

console = Console()
err_console = Console(stderr=True)

PluginOption = Annotated[
    list[str] | None,
    typer.Option(
        "--plugin",
        help="a plugin .py file or module to import first (it registers itself, e.g. a local "
        "planner); repeatable; worker processes import it too",
    ),
]


def load_plugin_options(specs: list[str] | None) -> None:
    """Import the ``--plugin`` files/modules (one-line error naming a bad one)."""
    if specs:
        from arena.plugins import load_plugins

        load_plugins(specs)
