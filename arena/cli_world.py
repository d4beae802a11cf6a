"""``arena maps``, ``arena scenario`` and ``arena tasks``: maps, scenario files and task suites.

Registered on the app by :mod:`arena.cli`; errors are raised as :class:`ArenaError` and printed
as one line there.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from arena.cli_common import console
from arena.core.errors import ConfigError

maps_app = typer.Typer(help="Generate, list and export maps.", no_args_is_help=True)


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
