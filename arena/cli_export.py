"""``arena export``: recorded runs in other tools' formats (MCAP for Foxglove, ROS bags).

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


def _export_bags(flavour: str, run: Path, out: Path | None, only: str | None,
                 clock: bool) -> None:
    """Write the bags of ``run`` and report each like ``arena export mcap``."""
    from arena.export.rosbag import BagFile, export_rosbag

    def done(f: BagFile) -> None:
        warn = "" if f.matches_record else "  [yellow](differs from the record)[/]"
        console.print(f"{f.path}  {f.steps} steps, {f.messages} messages{warn}",
                      highlight=False, soft_wrap=True)

    files = export_rosbag(run, out, flavour=flavour,  # type: ignore[arg-type]
                          only=only, clock=clock, on_file=done)
    differs = sum(not f.matches_record for f in files)
    console.print(f"{len(files)} episode(s) written", highlight=False)
    if differs:
        err_console.print(f"[yellow]warning:[/] {differs} episode(s) did not replay as recorded "
                          "(a non-deterministic plugin?)", highlight=False)


_RUN = Annotated[Path, typer.Argument(help="an arena run or arena bench folder")]
_ONLY = Annotated[
    str | None,
    typer.Option(help="only records whose path in RUN matches this glob, e.g. 'episodes/dwa/*'"),
]
_CLOCK = Annotated[bool, typer.Option("--clock", help="also write /clock at every step")]


@export_app.command("rosbag2")
def export_rosbag2_command(
    run: _RUN,
    out: Annotated[
        Path | None,
        typer.Option("--out", "-o", help="destination folder \\[default: RUN/rosbag2]"),
    ] = None,
    only: _ONLY = None,
    clock: _CLOCK = False,
) -> None:
    r"""Write each recorded episode as a ROS 2 bag (MCAP storage; ros2 bag play, Foxglove).

    Each episode is simulated again from its record's config and checked against the
    recording. One bag folder per episode (episode_000/episode/episode.mcap + metadata.yaml).
    Topics (REP 105 / Nav2 names): /tf, /tf_static, /map, /odom, /scan, /people/markers,
    /people/states, /plan, /local_plan, /goal_pose, /cmd_vel; /robot_<i>/... per robot when
    there are several. Needs pip install 'arena\[rosbag]'.
    """
    _export_bags("ros2", run, out, only, clock)


@export_app.command("rosbag")
def export_rosbag1_command(
    run: _RUN,
    out: Annotated[
        Path | None,
        typer.Option("--out", "-o", help="destination folder \\[default: RUN/rosbag]"),
    ] = None,
    only: _ONLY = None,
    clock: _CLOCK = False,
) -> None:
    r"""Write each recorded episode as a ROS 1 bag (format 2.0; rosbag play, RViz).

    The same topics as `arena export rosbag2`, one .bag file per episode
    (episode_000/episode.bag). Needs pip install 'arena\[rosbag]'.
    """
    _export_bags("ros1", run, out, only, clock)
