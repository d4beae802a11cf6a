"""The ``arena`` command line: a thin front end on the public API.

Errors that users cause (bad config, unknown names, missing files) print as one line and exit
with status 2; no traceback. ``ARENA_DEBUG=1`` shows the traceback anyway.
"""

from __future__ import annotations

import os
import sys
import warnings
from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from arena.cli_bench import bench, report
from arena.cli_common import PluginOption, console, err_console, load_plugin_options
from arena.core.errors import ArenaError, ConfigError

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
    plugin: PluginOption = None,
) -> None:
    """Run episodes: a robot drives to its goals among people; writes videos and trajectories.

    With ``--interactive`` the simulation runs in real time and reads one command per stdin
    line: ``goal X Y [TH]`` (new goal), ``teleport X Y [TH]`` (move the robot), ``reset`` (end
    the episode), ``quit`` (stop reading); ``robot=I`` picks another robot.
    """
    from rich.markup import escape

    from arena.config import load_config
    from arena.experiment import run_experiment, run_name

    load_plugin_options(plugin)
    items = ([config] if config else []) + list(overrides or [])
    path = None
    if items and "=" not in items[0]:
        path, items = items[0], items[1:]
    if episodes is not None:
        items.append(f"episodes={episodes}")
    if robot is not None:
        items.append(f"robot={robot}")
    if seed is not None:
        items.append(f"seed={seed}")
    if video is not None:
        items.append(f"output.video={'true' if video else 'false'}")
    if map_ is not None:
        p = Path(map_)
        if p.suffix in (".yaml", ".yml"):
            items += ["map.type=file", f"map.path={p.resolve()}"]
        else:
            items += ["map.type=world", f"map.name={p.resolve() if p.is_dir() else map_}"]
    if scenario is not None:
        import json

        from arena.maps.sources import resolve_scenario

        world = _world_of(load_config(path, items).map)
        try:
            file = resolve_scenario(scenario, world)
        except ConfigError as e:
            raise ConfigError(e.message, source="--scenario") from None
        block = json.dumps({"type": "scenario", "file": str(file)})
        items += [f"task.robots={block}", f"task.obstacles={block}"]
    cfg = load_config(path, items)
    extra_modules = []
    if interactive:
        from arena.tasks.modules.interactive import InteractiveModule

        ui = InteractiveModule(
            on_error=lambda msg: err_console.print(f"error: {msg}", highlight=False)
        )
        extra_modules.append(ui)
        _read_commands(ui)

    table = Table(title=f"arena run · {run_name(cfg)}", show_lines=False)
    for col in ("episode", "outcome", "time [s]", "path [m]", "collisions", "wall [s]"):
        table.add_column(col, justify="right")
    where = cfg.map.get("name") or cfg.map.get("path") or cfg.map["type"]
    console.print(
        f"[bold]{cfg.robot}[/] on [bold]{where}[/]"
        f", {cfg.episodes} episode(s), seed {cfg.seed}, planner "
        f"{cfg.navigation.global_planner['type']} + {cfg.navigation.local_planner['type']}"
    )

    def show(res) -> None:
        colour = {"success": "green", "timeout": "yellow"}.get(res.outcome, "red")
        console.print(
            f"  episode {res.index}: [{colour}]{res.outcome}[/] after {res.time:.1f} s, "
            f"{res.path_length:.1f} m, {res.collisions} collision(s) ({res.wall_time:.1f} s wall)"
            + (f": {escape(res.error)}" if res.error else ""),
            highlight=False, soft_wrap=True,  # one line, however long the message
        )
        table.add_row(
            str(res.index),
            res.outcome,
            f"{res.time:.1f}",
            f"{res.path_length:.1f}",
            str(res.collisions),
            f"{res.wall_time:.1f}",
        )

    from arena.cli_views import episode_progress

    bar, on_step = episode_progress(console, enabled=console.is_terminal and not interactive)
    with bar:
        out_dir, results = run_experiment(
            cfg, out, on_episode=show, modules=extra_modules, realtime=interactive,
            on_step=on_step,
        )
    console.print(table)
    console.print(f"results:     {out_dir}/summary.csv", soft_wrap=True)
    for res in results:
        for kind in ("video", "trajectory"):
            if kind in res.files:
                console.print(f"{kind + ':':12} {res.files[kind]}", soft_wrap=True)


def _world_of(map_spec: dict) -> str | None:
    """The world (packaged name or folder) a ``map`` block loads, if it loads one."""
    if map_spec.get("type") == "world":
        return str(map_spec.get("name"))
    if map_spec.get("type") == "file" and map_spec.get("path"):
        folder = Path(str(map_spec["path"])).parent
        return str(folder.parent if folder.name == "map" else folder)
    return None


def _read_commands(ui) -> None:
    """Feed stdin lines to the interactive module from a daemon thread (errors: one line)."""
    import threading

    from arena.tasks.modules.interactive import CommandError, parse_command

    def loop() -> None:
        ui.ready.wait()  # validate against the first episode's map
        for line in sys.stdin:
            if not line.strip():
                continue
            try:
                cmd = parse_command(line)
                if cmd is None:
                    return
                if cmd.kind == "reset":
                    ui.reset()
                elif cmd.kind == "goal":
                    ui.set_goal(cmd.robot, cmd.pose)
                else:
                    ui.teleport(cmd.robot, cmd.pose)
                err_console.print(f"ok: {line.strip()}", highlight=False)
            except CommandError as e:
                err_console.print(f"error: {e}", highlight=False, soft_wrap=True)

    threading.Thread(target=loop, name="arena-stdin", daemon=True).start()


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


maps_app = typer.Typer(help="Generate, list and export maps.", no_args_is_help=True)
app.add_typer(maps_app, name="maps")


@maps_app.command("list")
def maps_list() -> None:
    """List the map generators (with their parameters) and the packaged worlds."""
    import arena.plugins  # noqa: F401
    from arena.maps.generators import MAP_GENERATORS
    from arena.maps.sources import packaged_worlds

    table = Table(title="Map generators  (arena maps generate TYPE, or map.type=TYPE)")
    table.add_column("type")
    table.add_column("description")
    table.add_column("parameters (defaults)")
    for entry in MAP_GENERATORS.entries():
        model = entry.params_model
        params = (
            ""
            if model is None
            else ", ".join(f"{k}={f.default}" for k, f in model.model_fields.items())
        )
        table.add_row(entry.name, entry.summary, params)
    console.print(table)
    console.print("packaged worlds (map.type=world map.name=NAME): " + ", ".join(packaged_worlds()))


@maps_app.command("generate")
def maps_generate(
    kind: Annotated[str, typer.Argument(help="generator type, e.g. barn, canteen")],
    params: Annotated[
        list[str] | None, typer.Argument(help="generator parameters, e.g. fill_pct=0.2")
    ] = None,
    seed: Annotated[int, typer.Option(help="seed")] = 0,
    out: Annotated[Path, typer.Option("--out", "-o", help="output world folder")] = Path("."),
    width_px: Annotated[int, typer.Option(help="preview width")] = 800,
    burn_obstacles: Annotated[
        bool,
        typer.Option("--burn-obstacles/--no-burn-obstacles",
                     help="draw the placed obstacles into map.png as occupied cells (for ROS "
                     "map_server / RViz, and arena run --map FOLDER, which read only the map)"),
    ] = False,
) -> None:
    """Generate a map: ROS map files, placed obstacles (scenario JSON) and a PNG preview.

    map.png holds the generator's walls; the placed obstacles (tables, shelves ...) are in
    obstacles.json unless ``--burn-obstacles`` draws them into map.png too.
    """
    import arena.plugins  # noqa: F401
    from arena.config.loader import parse_override
    from arena.core.rng import derive_rng
    from arena.maps.generators import MAP_GENERATORS
    from arena.maps.sources import write_world
    from arena.render import render_world, save_png
    from arena.scene.state import StaticWorld

    spec: dict[str, object] = {"type": kind}
    for text in params or []:
        key, value = parse_override(text)
        spec[key] = value
    generator = MAP_GENERATORS.build(spec, source="command line")
    result = generator.build(derive_rng(seed, "map"))
    files = write_world(result, out, burn_obstacles=burn_obstacles)
    world = StaticWorld.build(result.grid, result.obstacles)
    preview = out / "preview.png"
    save_png(render_world(world, width_px=width_px, title=f"{kind} · seed {seed}"), preview)
    w, h = result.grid.size_m
    burnt = " (burnt into map.png)" if burn_obstacles and result.obstacles else ""
    console.print(
        f"{kind}: {w:.1f} × {h:.1f} m, {len(result.obstacles)} obstacles{burnt}, "
        f"{100 * result.grid.occupied.mean():.1f} % occupied by walls"
    )
    for label, path in (*files.items(), ("preview", preview)):
        console.print(f"{label + ':':10} {path}")


@maps_app.command("export")
def maps_export(
    world: Annotated[str, typer.Argument(
        help="packaged world name, world folder, map.yaml, or a generator type (canteen ...)")],
    params: Annotated[
        list[str] | None, typer.Argument(help="generator parameters, e.g. width=20")
    ] = None,
    fmt: Annotated[str, typer.Option("--format", help="sdf (Gazebo) or mjcf (MuJoCo)")] = "sdf",
    out: Annotated[Path, typer.Option("--out", "-o", help="output folder")] = Path("."),
    seed: Annotated[int, typer.Option(help="seed of a generated map")] = 0,
    scenario: Annotated[str | None, typer.Option(
        help="scenario file or name in the world: adds its obstacles and people")] = None,
    wall_height: Annotated[float, typer.Option(help="wall height (m)")] = 2.0,
) -> None:
    """Export a map as a 3-D world: a Gazebo SDF world or a MuJoCo MJCF model.

    Walls become merged boxes, obstacles 3-D models of the obstacle library; with --scenario
    its pedestrians walk their waypoints (SDF actors; MJCF human figures at their start).
    """
    from pydantic import ValidationError

    from arena.export.world3d import FILE_NAMES, export_scene, load_export_source, write_export
    from arena.sim.mujoco.scene import WorldParams

    if fmt not in FILE_NAMES:  # before building anything
        raise ConfigError(f"--format: expected sdf or mjcf, got {fmt!r}", source="command line")
    try:
        wp = WorldParams(wall_height=wall_height)
    except ValidationError:
        raise ConfigError(f"--wall-height: expected a height in metres in (0, 100], got "
                          f"{wall_height!r}", source="command line") from None
    src = load_export_source(world, params or [], seed=seed, scenario=scenario)
    scene = export_scene(src, wp)
    path = write_export(scene, fmt, out)  # type: ignore[arg-type]
    people = len(scene.actors)
    note = ("" if fmt == "mjcf" or people else
            "; no pedestrians with waypoints (give --scenario): no actors written")
    console.print(
        f"{scene.name}: {scene.wall_boxes} wall boxes, {len(scene.static) - 1} obstacles, "
        f"{people} walking people{note}"
    )
    console.print(f"{fmt + ':':10} {path}")


scenario_app = typer.Typer(help="Arena scenario files.", no_args_is_help=True)
app.add_typer(scenario_app, name="scenario")


@scenario_app.command("validate")
def scenario_validate(
    path: Annotated[Path, typer.Argument(help="scenario JSON file")],
    map_yaml: Annotated[
        str | None, typer.Option("--map", help="map.yaml to check positions against")
    ] = None,
) -> None:
    """Check a scenario file (and, with --map, that its positions lie on the map, not in walls)."""
    from arena.tasks.scenario import validate_file

    with warnings.catch_warnings():
        # the findings below list what loading warned about (ignored keys ...) once
        warnings.simplefilter("ignore", UserWarning)
        findings = validate_file(path, map_yaml)
    for line in findings:
        console.print(f"[yellow]warning:[/] {line}", highlight=False)
    console.print(f"{path}: valid" + (f" ({len(findings)} warning(s))" if findings else ""))


tasks_app = typer.Typer(help="Task modes, benchmark suites and curricula.", no_args_is_help=True)
app.add_typer(tasks_app, name="tasks")


@tasks_app.command("list")
def tasks_list() -> None:
    """List the task modes by role (robots, obstacles, modules) with their summaries."""
    import arena.plugins  # noqa: F401
    from arena.tasks.base import ROLES, TASK_MODES, mode_names
    from arena.tasks.datafiles import packaged

    table = Table(title="Task modes  (task.robots / task.obstacles / task.modules)")
    table.add_column("role")
    table.add_column("name")
    table.add_column("description")
    for role in ROLES:
        for i, name in enumerate(mode_names(role)):
            entry = TASK_MODES.entry(f"{role}.{name}")
            table.add_row(role if i == 0 else "", name, entry.summary)
        table.add_section()
    console.print(table)
    console.print("packaged suites: " + ", ".join(packaged("suites")))
    console.print("packaged curricula: " + ", ".join(packaged("curricula")))
    console.print("packaged contests: " + ", ".join(packaged("contests")))


@tasks_app.command("preview")
def tasks_preview(
    suite: Annotated[str, typer.Argument(help="packaged suite name (paper, quick) or YAML path")],
    seed: Annotated[int, typer.Option(help="run seed")] = 0,
    scale: Annotated[float, typer.Option(help="scale_episodes: factor on every stage")] = 1.0,
    contest: Annotated[
        str | None, typer.Option(help="packaged contest name or YAML path")
    ] = None,
    worlds: Annotated[
        Path | None,
        typer.Option("--worlds", metavar="DIR",
                     help="folder of worlds in Arena's layout: the suite's world names are "
                          "looked up there first (as arena bench --worlds)"),
    ] = None,
) -> None:
    """Draw every episode of a suite and print a table (no simulation)."""
    from arena.config.schema import ExperimentConfig
    from arena.robots.presets import load_robot
    from arena.scene.episode import episode_digest
    from arena.tasks.config import TaskConfig
    from arena.tasks.generator import TaskGenerator
    from arena.tasks.suite import contestant_config, load_contest

    base = ExperimentConfig(seed=seed)
    task = TaskConfig.model_validate(
        {"modules": [{"type": "benchmark", "suite": suite, "scale_episodes": scale,
                      "worlds": None if worlds is None else str(worlds)}]}
    )
    gen = TaskGenerator(task, map_spec=base.map, robots=[load_robot(base.robot)], seed=seed)
    contestants = []
    if contest is not None:
        file, source = load_contest(contest)
        for i, c in enumerate(file.contestants):
            contestant_config(base, c, source=source, index=i)  # checks the planner names
            contestants.append(c)
    bench = gen.modules[0]
    table = Table(title=f"suite {suite} · seed {seed} · scale {scale:g}")
    for col in ("stage", "ep", "map", "robot", "start", "goal", "obstacles", "peds", "digest"):
        table.add_column(col, justify="right" if col in ("ep", "obstacles", "peds") else "left")
    total_obs = total_peds = 0
    n = gen.num_episodes or 0
    for ep in gen.episodes(n):
        _, k = bench.stage_of(ep.index)
        r = ep.robots[0]
        total_obs += len(ep.obstacles)
        total_peds += len(ep.agents)
        table.add_row(
            ep.label, str(k), ep.map_name, r.model.name,
            f"({r.start.x:.1f}, {r.start.y:.1f})", f"({r.goal.x:.1f}, {r.goal.y:.1f})",
            str(len(ep.obstacles)), str(len(ep.agents)), episode_digest(ep)[:10],
        )
    console.print(table)
    stages = sum(1 for c in bench.suite.episode_counts if c > 0)
    console.print(
        f"total: {n} episodes in {stages} stages, {total_obs} obstacles, {total_peds} pedestrians"
    )
    if contestants:
        names = ", ".join(f"{c.name} ({c.local_planner} + {c.inter_planner})" for c in contestants)
        console.print(f"contest: {len(contestants)} contestants x {n} episodes = "
                      f"{len(contestants) * n} runs: {names}")


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
