"""``arena ros2`` and ``arena ros1``: Arena as a ROS simulator; ROS 2's one-time setup.

``arena ros2 run CONFIG`` runs the config's episodes like ``arena run``, with robot 0 driven
by a ROS 2 node over Arena's topics (the ``ros2`` local planner, :mod:`arena.ros.planner`):
``/clock``, ``/tf``, ``/tf_static``, ``/odom``, ``/scan``, ``/map``, the people, ``/plan`` and
``/goal_pose`` go out; ``/cmd_vel`` comes in. Goals sent on ``/goal_pose`` (RViz's "2D Goal
Pose") become robot 0's goal; the ``/arena/reset`` service (std_srvs/Trigger) ends the running
episode and starts the next. ``arena ros1 run`` is the same over rospy (Debian's ROS 1; a ROS
master at ``ROS_MASTER_URI``). Registered on the app by :mod:`arena.cli`.
"""

from __future__ import annotations

import json
import shlex
from pathlib import Path
from typing import Annotated, Any

import typer

from arena.cli_common import PluginOption, console, err_console

ros2_app = typer.Typer(help="Arena as a ROS 2 simulator (pip install 'arena\\[ros2]').",
                       no_args_is_help=True)
ros1_app = typer.Typer(help="Arena as a ROS 1 simulator (Debian's ROS 1: "
                            "bash tools/install_ros1.sh).", no_args_is_help=True)


class _Session:
    """What ``arena run``'s body takes from a live session: the ROS run's task module."""

    def __init__(self, modules: list[Any]) -> None:
        self.modules = modules
        self.hooks: list[Any] = []
        self.on_start = None


@ros2_app.command("setup")
def setup_command(
    force: Annotated[bool, typer.Option(help="build tf2_msgs even when one imports")] = False,
) -> None:
    """Build tf2_msgs (TFMessage), the one message package the PyPI ROS 2 wheels lack.

    Installs into this Python environment; needs cmake and a C++ compiler; takes ~5 s.
    """
    from arena.ros.ros2_env import build_tf2_msgs, import_rclpy, tf2_msgs_available

    if tf2_msgs_available() and not force:
        console.print("tf2_msgs is already installed", highlight=False)
    else:
        where = build_tf2_msgs()
        console.print(f"tf2_msgs built and installed: {where}", highlight=False,
                      soft_wrap=True)
    import_rclpy()
    console.print("ROS 2 bridge ready", highlight=False)


def _planner_spec(version: str, mode: str, namespace: str, timeout: float,
                  cmd_vel_stamped: bool, launch: str | None,
                  remap: list[str] | None) -> dict[str, Any]:
    """The ``navigation.local_planner`` block of a ROS run (``--remap`` as ``FROM:=TO``)."""
    from arena.core.errors import ConfigError
    from arena.ros.link import check_topic

    spec: dict[str, Any] = {"type": version, "mode": mode, "namespace": namespace,
                            "timeout": timeout, "cmd_vel_stamped": cmd_vel_stamped}
    if launch:
        spec["launch"] = shlex.split(launch)
    pairs = {}
    for item in remap or []:
        source, sep, target = item.partition(":=")
        if not sep:
            raise ConfigError(f"--remap: expected FROM:=TO (e.g. /scan:=/front/scan), got "
                              f"{item!r}")
        check_topic(source, field_name="--remap")
        check_topic(target, field_name="--remap")
        pairs[source] = target
    if pairs:
        spec["remap"] = pairs
    return spec


def _connect(version: str) -> str:
    """Check the client library (and ROS 1's master): where the run's ROS is.

    Checked once before the run: a missing package is one line, not an error per episode.
    """
    if version == "ros2":
        from arena.ros.ros2_env import import_rclpy

        import_rclpy()
        return "ROS 2"
    from arena.ros.ros1_env import check_master, import_rospy, master_uri

    import_rospy()
    check_master()
    return f"ROS 1 ({master_uri()})"


def _run_command(version: str) -> Any:
    """The ``run`` command of ``arena <version>`` (the same options for ROS 1 and ROS 2)."""

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
            str, typer.Option(help="realtime (paced to the wall clock, as a simulator) or "
                                   "lockstep (each step waits for the node's /cmd_vel: "
                                   "reproducible)")
        ] = "realtime",
        namespace: Annotated[str, typer.Option(help="prefix of every topic and service")] = "",
        remap: Annotated[
            list[str] | None,
            typer.Option(help="FROM:=TO, one of Arena's topics under another absolute name, "
                              "e.g. /scan:=/front/scan (repeatable)"),
        ] = None,
        timeout: Annotated[
            float, typer.Option(help="lockstep: s to wait for each /cmd_vel before the episode "
                                     "ends as error")
        ] = 5.0,
        cmd_vel_stamped: Annotated[
            bool, typer.Option("--cmd-vel-stamped", help="/cmd_vel is "
                               "geometry_msgs/TwistStamped (Nav2's enable_stamped_cmd_vel)")
        ] = False,
        launch: Annotated[
            str | None, typer.Option(help="start this node with the run, e.g. 'python -m "
                                          "arena.ros.nodes.local_planner' (ROS 1: "
                                          "local_planner_ros1)")
        ] = None,
        episodes: Annotated[
            int | None, typer.Option("--episodes", "-n", help="number of episodes")
        ] = None,
        seed: Annotated[int | None, typer.Option(help="master seed")] = None,
        out: Annotated[Path | None, typer.Option("--out", "-o", help="output folder")] = None,
        plugin: PluginOption = None,
    ) -> None:
        from arena.cli_run import run_episodes
        from arena.core.errors import ConfigError
        from arena.ros.link import check_namespace
        from arena.tasks.modules.interactive import InteractiveModule

        if mode not in ("realtime", "lockstep"):
            raise ConfigError(f"--mode: expected realtime or lockstep, got {mode!r}")
        check_namespace(namespace, field_name="--namespace")
        spec = _planner_spec(version, mode, namespace, timeout, cmd_vel_stamped, launch, remap)
        where = _connect(version)
        items = ([config] if config else []) + list(overrides or [])
        items.append(f"navigation.local_planner={json.dumps(spec)}")
        ui = InteractiveModule(
            on_error=lambda msg: err_console.print(f"error: {msg}", highlight=False))
        console.print(f"{where}: {mode}, topics under '{namespace or '/'}'; goals on "
                      f"{namespace}/goal_pose, reset: {namespace}/arena/reset", highlight=False)
        run_episodes(items[0] if items else None, items[1:], episodes, None, None, seed, out,
                     False, None, False, plugin, _Session([ui]), realtime=mode == "realtime")

    name = "ROS 2" if version == "ros2" else "ROS 1"
    run_command.__doc__ = f"""Run episodes with robot 0 driven by a {name} node (docs/ros.md).

    Writes the same results as ``arena run`` (trajectories, metrics, summary.csv).
    """
    return run_command


ros2_app.command("run")(_run_command("ros2"))
ros1_app.command("run")(_run_command("ros1"))
