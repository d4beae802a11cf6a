"""The ``arena`` command line: a thin front end on the public API.

Errors that users cause (bad config, unknown names, missing files) print as one line and exit
with status 2; no traceback. ``ARENA_DEBUG=1`` shows the traceback anyway.
"""

from __future__ import annotations

import contextlib
import os
import sys
import warnings
from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from arena.cli_bench import bench, report
from arena.cli_common import PluginOption, console, err_console, load_plugin_options
from arena.cli_compare import compare
from arena.cli_export import export_app
from arena.cli_ros import ros1_app, ros2_app
from arena.cli_run import run_episodes
from arena.cli_world import maps_app, scenario_app, tasks_app
from arena.core.errors import ArenaError

app = typer.Typer(
    add_completion=False,
    no_args_is_help=False,
    help="Arena: simulate, develop and benchmark social robot navigation.",
    pretty_exceptions_enable=False,
)


@app.command()
def run(
    config: Annotated[
        str | None,
        typer.Argument(
            help="experiment YAML (default: the packaged demo); or a key=value override"
        ),
    ] = None,
    overrides: Annotated[
        list[str] | None, typer.Argument(help="dotted overrides, e.g. robot=burger seed=3")
    ] = None,
    episodes: Annotated[
        int | None, typer.Option("--episodes", "-n", help="number of episodes")
    ] = None,
    robot: Annotated[str | None, typer.Option(help="robot preset name or YAML path")] = None,
    map_: Annotated[
        str | None, typer.Option("--map", help="map.yaml file, world folder or packaged world name")
    ] = None,
    seed: Annotated[int | None, typer.Option(help="master seed")] = None,
    out: Annotated[Path | None, typer.Option("--out", "-o", help="output folder")] = None,
    video: Annotated[bool | None, typer.Option("--video/--no-video", help="write videos")] = None,
    scenario: Annotated[
        str | None,
        typer.Option(
            "--scenario",
            help="Arena scenario JSON (robots and obstacles from the file), or a packaged one by "
            "name: NAME in the run's world (--map corridor --scenario default) or WORLD/NAME",
        ),
    ] = None,
    interactive: Annotated[
        bool,
        typer.Option(
            "--interactive",
            help="real time; read commands from stdin: goal X Y [TH], teleport X Y [TH], reset, "
            "quit",
        ),
    ] = False,
    live: Annotated[
        bool,
        typer.Option("--live", help="watch and steer it in the browser: the web app's live "
                     "view on 127.0.0.1 (pip install 'arena\\[web]')"),
    ] = False,
    foxglove: Annotated[
        bool,
        typer.Option("--foxglove", help="serve it to Foxglove: WebSocket on 127.0.0.1:8765 "
                     "(pip install 'arena\\[web]')"),
    ] = False,
    port: Annotated[int, typer.Option(help="--live: the web app's port")] = 8080,
    web: Annotated[
        bool, typer.Option("--web/--no-web", help="--live: start the web app, or only serve "
                           "the live channel (a web app on the run's folder shows it)")
    ] = True,
    resume: Annotated[
        Path | None,
        typer.Option("--resume", metavar="RUN_DIR",
                     help="continue the run in this folder with its config.yaml: its finished "
                          "episodes are kept, the others run"),
    ] = None,
    plugin: PluginOption = None,
) -> None:
    """Run episodes: a robot drives to its goals among people; writes videos and trajectories.

    With ``--interactive`` the simulation runs in real time and reads one command per stdin
    line: ``goal X Y [TH]`` (new goal), ``teleport X Y [TH]`` (move the robot), ``reset`` (end
    the episode), ``quit`` (stop reading); ``robot=I`` picks another robot.

    With ``--live`` (or ``--foxglove``) it runs in real time too, shown in the browser (or in
    Foxglove): the live page pauses, steps and changes the pace, and its clicks set goals and
    move the robot.

    ``--resume RUN_DIR`` continues a stopped run: episodes are drawn and seeded by their index,
    so its summary is the one the run would have written uninterrupted.
    """
    from arena.cli_live import live_session

    if resume is not None:
        given = [flag for flag, value in (
            ("CONFIG/overrides", config or overrides), ("--episodes", episodes),
            ("--robot", robot), ("--map", map_), ("--seed", seed), ("--scenario", scenario),
            ("--video/--no-video", video)) if value not in (None, [])]
        if given:
            raise ArenaError(f"--resume continues the run with its own config.yaml; drop "
                             f"{', '.join(given)}")
        if out is not None and out.resolve() != resume.resolve():
            raise ArenaError("give either --resume RUN_DIR or -o RUN_DIR, not two different "
                             "folders")
        if not (resume / "config.yaml").is_file():
            raise ArenaError(f"{resume}: no config.yaml; not an arena run folder")
        config, out = str(resume / "config.yaml"), resume

    # a browser opens only for someone at a terminal (not in scripts and tests)
    with live_session(live=live, foxglove=foxglove, web_port=port, web=web,
                      open_browser=sys.stdout.isatty()) as session:
        run_episodes(config, overrides, episodes, robot, map_, seed, out, video, scenario,
                     interactive, plugin, session, resume=resume is not None)
        if session.url and sys.stdin.isatty():  # someone watches: keep the pages up for them
            import threading

            results = session.url.replace("/live/", "/runs/")
            console.print(f"the run is over; its results stay at {results} until Ctrl+C",
                          highlight=False, soft_wrap=True)
            with contextlib.suppress(KeyboardInterrupt):
                threading.Event().wait()


@app.command()
def robots() -> None:
    """List the robot presets with their kinematics, limits and lidar."""
    from arena.robots.presets import describe_robots

    rows = describe_robots()
    table = Table(title="Robot presets")
    for col in rows[0]:
        table.add_column(str(col))
    for row in rows:
        table.add_row(*(str(v) for v in row.values()))
    console.print(table)


@app.command()
def plugins(
    kind: Annotated[
        str | None, typer.Argument(help="only this kind, e.g. local_planner, crowd_model")
    ] = None,
    name: Annotated[
        str | None, typer.Argument(help="show this plugin's parameters (defaults, units)")
    ] = None,
    as_json: Annotated[bool, typer.Option("--json", help="print JSON")] = False,
    plugin: PluginOption = None,
) -> None:
    """List every plugin registry and the names registered in it; or one plugin's parameters.

    On a terminal this prints tables; piped, it prints tab-separated lines (kind, name, tags,
    description) that no column width truncates; ``--json`` prints JSON.
    """
    from arena.cli_views import print_plugins

    load_plugin_options(plugin)
    print_plugins(console, kind, name, as_json=as_json)


app.add_typer(maps_app, name="maps")
app.add_typer(scenario_app, name="scenario")
app.add_typer(tasks_app, name="tasks")
app.add_typer(export_app, name="export")
app.add_typer(ros2_app, name="ros2")
app.add_typer(ros1_app, name="ros1")
app.command()(bench)


@app.command()
def train(
    config: Annotated[
        str | None,
        typer.Argument(help="experiment YAML (default: the packaged default; resume: the run's)"),
    ] = None,
    overrides: Annotated[
        list[str] | None,
        typer.Argument(help="dotted overrides, e.g. learning.ppo.n_epochs=5 seed=3"),
    ] = None,
    out: Annotated[Path | None, typer.Option("--out", "-o", help="run folder")] = None,
    resume: Annotated[
        Path | None, typer.Option("--resume", help="continue the run in this folder")
    ] = None,
    steps: Annotated[
        int | None, typer.Option("--steps", min=1, help="total env steps (learning.train)")
    ] = None,
    envs: Annotated[
        int | None, typer.Option("--envs", min=1, help="parallel envs (learning.train.n_envs)")
    ] = None,
    progress: Annotated[
        bool, typer.Option("--progress/--no-progress", help="show a progress bar")
    ] = True,
    export: Annotated[
        Path | None,
        typer.Option("--export", help="only write CHECKPOINT/policy.npz from a checkpoint "
                     "folder (RUN/checkpoints/step_N), or the file -o names"),
    ] = None,
    plugin: PluginOption = None,
) -> None:
    r"""Train a PPO policy on arena/SocialNav-v0 (pip install 'arena\[train]').

    Writes checkpoints, TensorBoard logs, ``run.json`` and the final ``policy.npz`` (for the
    ``rosnav_rl`` local planner) into the run folder; ``--resume RUN_DIR`` continues a run;
    ``--export RUN/checkpoints/step_N`` writes the policy of an earlier checkpoint.
    """
    # before numba/OpenMP start threads: idle workers sleep instead of spinning, so that the
    # batched engine's parallel loops do not steal cores from torch (see arena.sim.engine)
    os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
    from datetime import datetime

    from arena.config.schema import ExperimentConfig
    from arena.learn.train import load_training, read_run, require_sb3, summary
    from arena.learn.train import train as run_training
    from arena.learn.train_config import TrainSettings

    require_sb3()
    load_plugin_options(plugin)
    if export is not None:
        from arena.learn.train import export_checkpoint

        console.print(f"wrote {export_checkpoint(export, out)}")
        return
    items = ([config] if config else []) + list(overrides or [])
    path = None
    if items and "=" not in items[0]:
        path, items = items[0], items[1:]
    if resume is not None and out is not None and resume.resolve() != out.resolve():
        raise ArenaError("give either --resume RUN_DIR or -o RUN_DIR, not two different folders")
    if resume is not None and path is None and not items:
        manifest = read_run(resume)
        cfg = ExperimentConfig.model_validate(manifest["config"])
        settings = TrainSettings.model_validate(manifest["settings"])
    else:
        cfg, settings = load_training(path, items)
    update = {}
    if steps is not None:
        update["total_steps"] = steps
    if envs is not None:
        update["n_envs"] = envs
    if update:
        settings = settings.model_copy(update={"train": settings.train.model_copy(update=update)})
    run_dir = resume or out
    if run_dir is None:
        from arena.experiment import run_name

        stamp = datetime.now().strftime("%y-%m-%d_%H-%M-%S")
        run_dir = Path("runs") / f"train_{run_name(cfg)}_{stamp}"
    console.print(
        f"[bold]train[/] {cfg.robot} · {settings.train.total_steps} steps · "
        f"{settings.train.n_envs} env(s) · seed "
        f"{settings.train.seed if settings.train.seed is not None else cfg.seed} → {run_dir}"
    )
    result = run_training(cfg, settings, run_dir, resume=resume is not None, progress=progress)
    console.print(summary(result))


app.command()(report)
app.command()(compare)


@app.command()
def web(
    root: Annotated[Path, typer.Option(help="the run store: the folder of the run folders")] = Path(
        "runs"),
    host: Annotated[str, typer.Option(help="interface (anything but loopback needs a token)")
                    ] = "127.0.0.1",
    port: Annotated[int, typer.Option(help="TCP port")] = 8080,
    token: Annotated[
        str | None,
        typer.Option(help="what every request must carry (default: none on 127.0.0.1, a new "
                          "one elsewhere)"),
    ] = None,
) -> None:
    r"""The web app: runs, results, replays and live views (pip install 'arena\[web]')."""
    from arena.web.server import serve

    root.mkdir(parents=True, exist_ok=True)
    serve(root, host=host, port=port, token=token,
          announce=lambda text: console.print(text, highlight=False, soft_wrap=True))


def main() -> None:
    """Console-script entry point: run the app, print user errors as one line.

    Command-line mistakes (an unknown option, ``-n abc``) are click usage errors, which click
    would draw as a multi-line box: they are printed as one line too, naming the option.
    """
    from pydantic import ValidationError
    from rich.markup import escape

    from arena.core.errors import from_validation_error

    # One line per warning (keys an Arena file has that Arena ignores ...), not Python's two
    # with a source line.
    warnings.showwarning = lambda message, *args, **kwargs: err_console.print(
        f"[yellow]warning:[/] {escape(str(message))}", highlight=False, soft_wrap=True)
    try:
        code = app(standalone_mode=False, prog_name="arena")
    except typer.Abort:  # Ctrl-C or end of input at a prompt
        err_console.print("aborted", highlight=False)
        sys.exit(130)
    except typer.TyperException as e:  # typer's (vendored) click errors: usage, bad values
        ctx = getattr(e, "ctx", None)
        if type(e).__name__ == "NoArgsIsHelpError" and ctx is not None:
            console.print(ctx.get_help())  # `arena maps`: the group's help, as click shows it
            sys.exit(0)
        if os.environ.get("ARENA_DEBUG"):
            raise
        text = e.format_message() if hasattr(e, "format_message") else str(e)
        hint = f" (see {ctx.command_path} --help)" if ctx is not None else ""
        err_console.print(f"[bold red]error:[/] {escape(' '.join(text.split()))}{hint}",
                          highlight=False, soft_wrap=True)
        sys.exit(int(getattr(e, "exit_code", 2)))
    except ValidationError as e:  # an option checked by a config model (tasks preview --seed)
        if os.environ.get("ARENA_DEBUG"):
            raise
        err_console.print(f"[bold red]error:[/] {escape(str(from_validation_error(e)))}",
                          highlight=False, soft_wrap=True)
        sys.exit(2)
    except ArenaError as e:
        if os.environ.get("ARENA_DEBUG"):
            raise
        # escape: messages hold key paths like [min, max], which are not rich markup
        err_console.print(f"[bold red]error:[/] {escape(str(e))}", highlight=False,
                          soft_wrap=True)
        sys.exit(2)
    sys.exit(code if isinstance(code, int) else 0)


if __name__ == "__main__":
    main()
