"""The body of ``arena run``, shared by ``arena ros2 run`` / ``arena ros1 run``.

:func:`run_episodes` builds the run's config from the command line's config file, overrides
and options, runs it (:func:`arena.experiment.run_experiment`) and prints each episode and the
table; :mod:`arena.cli` and :mod:`arena.cli_ros` call it.
"""

from __future__ import annotations

import sys
from pathlib import Path

from rich.table import Table

from arena.cli_common import console, err_console, load_plugin_options
from arena.core.errors import ConfigError


def run_episodes(config, overrides, episodes, robot, map_, seed, out, video, scenario, interactive,
         plugin, session, *, resume: bool = False, realtime: bool = False) -> None:
    """The body of ``arena run`` (its options as arguments, ``session`` its live setup).

    ``realtime`` paces the run to wall-clock time without ``--interactive``'s stdin commands
    (``arena ros2 run``).
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
    extra_modules = list(session.modules)  # a live view's goals and teleports
    if interactive:
        from arena.tasks.modules.interactive import InteractiveModule

        if not extra_modules:
            extra_modules.append(InteractiveModule(
                on_error=lambda msg: err_console.print(f"error: {msg}", highlight=False)))
        _read_commands(extra_modules[0])

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
            cfg, out, on_episode=show, modules=extra_modules,
            realtime=(interactive or realtime) and not session.hooks,  # a live view paces itself
            on_step=on_step, hooks=session.hooks, on_start=session.on_start, resume=resume,
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
