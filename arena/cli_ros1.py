"""``arena ros1 run``: Arena as a ROS 1 simulator (rospy, Debian's ROS 1).

The ROS 1 twin of ``arena ros2 run`` (:mod:`arena.cli_ros`): the config's episodes run like
``arena run``, with robot 0 driven by a ROS 1 node over Arena's topics (the ``ros1`` local
planner, :mod:`arena.ros.planner`): ``/clock``, ``/tf``, ``/tf_static``, ``/odom``, ``/scan``,
the latched ``/map``, the people, ``/plan`` and ``/goal_pose`` go out; ``/cmd_vel`` comes in.
Goals on ``/goal_pose`` (RViz's "2D Nav Goal") become robot 0's goal; the ``/arena/reset``
service (std_srvs/Trigger) ends the running episode and starts the next. Needs a ROS master
(``roscore``) at ``ROS_MASTER_URI``. Registered on the app by :mod:`arena.cli`.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer

from arena.cli_common import PluginOption, console, err_console

ros1_app = typer.Typer(help="Arena as a ROS 1 simulator (Debian's ROS 1: "
                            "bash tools/install_ros1.sh).", no_args_is_help=True)


@ros1_app.command("run")
def run_command(
    config: Annotated[
        str | None,
        typer.Argument(help="experiment YAML (default: the packaged demo); or a key=value "
                            "override"),
    ] = None,
    overrides: Annotated[
        list[str] | None, typer.Argument(help="dotted overrides, e.g. robot=burger seed=3")
    ] = None,
    mode: Annotated[
        str, typer.Option(help="realtime (paced to the wall clock, as a simulator) or lockstep "
                               "(each step waits for the node's /cmd_vel: reproducible)")
    ] = "realtime",
    namespace: Annotated[str, typer.Option(help="prefix of every topic and service")] = "",
    timeout: Annotated[
        float, typer.Option(help="lockstep: s to wait for each /cmd_vel before the episode "
                                 "ends as error")
    ] = 5.0,
    cmd_vel_stamped: Annotated[
        bool, typer.Option("--cmd-vel-stamped", help="/cmd_vel is geometry_msgs/TwistStamped")
    ] = False,
    launch: Annotated[
        str | None, typer.Option(help="start this node with the run, e.g. 'python -m "
                                      "arena.ros.nodes.pure_pursuit_ros1'")
    ] = None,
    episodes: Annotated[
        int | None, typer.Option("--episodes", "-n", help="number of episodes")
    ] = None,
    seed: Annotated[int | None, typer.Option(help="master seed")] = None,
    out: Annotated[Path | None, typer.Option("--out", "-o", help="output folder")] = None,
    plugin: PluginOption = None,
) -> None:
    """Run episodes with robot 0 driven by a ROS 1 node (see ``docs/ros.md``).

    Writes the same results as ``arena run`` (trajectories, metrics, summary.csv).
    """
    from arena.cli import _run
    from arena.cli_ros import _planner_spec, _Session
    from arena.core.errors import ConfigError
    from arena.ros.ros1_env import check_master, import_rospy, master_uri
    from arena.tasks.modules.interactive import InteractiveModule

    if mode not in ("realtime", "lockstep"):
        raise ConfigError(f"--mode: expected realtime or lockstep, got {mode!r}")
    import_rospy()  # a missing package or master: one line now, not an error per episode
    check_master()
    spec = {**_planner_spec(mode, namespace, timeout, cmd_vel_stamped, launch), "type": "ros1"}
    items = ([config] if config else []) + list(overrides or [])
    items.append(f"navigation.local_planner={json.dumps(spec)}")
    ui = InteractiveModule(
        on_error=lambda msg: err_console.print(f"error: {msg}", highlight=False))
    console.print(f"ROS 1 ({master_uri()}): {mode}, topics under '{namespace or '/'}'; goals "
                  f"on {namespace}/goal_pose, reset: {namespace}/arena/reset", highlight=False)
    _run(items[0] if items else None, items[1:], episodes, None, None, seed, out, False, None,
         False, plugin, _Session([ui]), realtime=mode == "realtime")
