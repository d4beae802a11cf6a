"""``arena export``: recorded runs in other tools' formats (MCAP for Foxglove).

Registered on the app by :mod:`arena.cli`; errors are raised as :class:`ArenaError` and printed
as one line there.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from arena.cli_common import console, err_console

export_app = typer.Typer(help="Write recorded runs in other tools' formats.",
                         no_args_is_help=True)


@export_app.command("mcap")
def export_mcap_command(
    run: Annotated[Path, typer.Argument(help="an arena run or arena bench folder")],
    out: Annotated[
        Path | None, typer.Option("--out", "-o", help="destination folder \\[default: RUN/mcap]")
    ] = None,
    only: Annotated[
        str | None,
        typer.Option(help="only records whose path in RUN matches this glob, e.g. "
                          "'episodes/dwa/*'"),
    ] = None,
) -> None:
    """Write each recorded episode as an MCAP file that Foxglove opens.

    Each episode is simulated again from its record's config (scans and plans are not
    recorded) and checked against the recording. Topics: /map, /obstacles, /robot, /tf, /scan,
    /people, /plan, /local_plan, /goal in Foxglove's standard schemas.
    """
    from arena.export.mcap import export_mcap

    def done(f) -> None:
        warn = "" if f.matches_record else "  [yellow](differs from the record)[/]"
        console.print(f"{f.path}  {f.steps} steps, {f.messages} messages{warn}",
                      highlight=False, soft_wrap=True)

    files = export_mcap(run, out, only=only, on_file=done)
    differs = sum(not f.matches_record for f in files)
    console.print(f"{len(files)} episode(s) written", highlight=False)
    if differs:
        err_console.print(f"[yellow]warning:[/] {differs} episode(s) did not replay as recorded "
                          "(a non-deterministic plugin?)", highlight=False)
