"""``ros2`` and ``ros1`` local planners: an external ROS node drives the robot.

Each tick the episode's topics go out (:class:`~arena.ros.link.RosLink`: ``/clock``, ``/tf``,
``/odom``, ``/scan``, ``/map``, the people, ``/plan``, ``/goal_pose``; the same as
``arena export rosbag2``) and the node's ``cmd_vel`` comes back as the planner's command, so
``arena bench`` benchmarks a ROS planner (a Nav2 controller, a move_base, a learned policy's
node) with every metric and the report::

    contestants:
      - name: my_ros_planner
        local_planner: ros2
        params: {launch: [python, -m, my_pkg.my_node], namespace: auto}

``launch`` starts the node with the first episode and stops it when the process ends (one node
per benchmark worker, re-used by its episodes; ``python`` means this interpreter). The node
gets ``--ros-args -r __ns:=<namespace>`` (ROS 1: ``__ns:=<namespace>``) when a namespace is set,
and its ``/clock``, ``/tf`` and ``/tf_static`` remapped into the namespace, where Arena sends them;
``namespace: auto`` gives each worker process its own (``/arena_<pid>``), so parallel workers
do not hear each other. A node started by hand uses the default ``""``.

The planner takes its frames from the episode runner: the navigation controller forwards its
hooks to it (:class:`~arena.episode.runner.EpisodeHooks`). The command is clipped to the robot's
velocity box and one tick of acceleration, ``vy = 0`` for a non-holonomic robot and a car's
curvature (the local-planner contract); the node's own limits should make that a no-op.
Goals sent on ``goal_pose`` and the ``arena/reset`` service reach the task's interactive module
when the run has one (``arena ros2 run``); a benchmark takes neither (they are noted as events
and ignored).
"""

from __future__ import annotations

import atexit
import json
import os
import signal
import subprocess
import sys
from typing import TYPE_CHECKING, Any, ClassVar, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, field_validator

from arena.core.errors import ConfigError
from arena.episode.runner import EpisodeHooks, EpisodeRunner
from arena.live.hook import LiveHook
from arena.nav.local_planners.base import KINEMATICS, LOCAL_PLANNERS, LocalObservation
from arena.nav.local_planners.path_tracking import finish_command
from arena.ros.link import LinkOptions, RosLink, Transport, check_namespace, check_topic

if TYPE_CHECKING:
    from collections.abc import Callable

FloatArray = NDArray[np.float64]
#: s to wait for a launched node to stop after SIGTERM before it is killed.
STOP_WAIT_S = 3.0
#: Absolute topics a node reads outside its namespace (sim time, tf): a launched node in a
#: namespace gets them remapped into it, where Arena sends them.
ABSOLUTE = ("/clock", "/tf", "/tf_static")


class RosPlannerParams(BaseModel):
    """Parameters of the ``ros2`` / ``ros1`` local planners.

    Attributes:
        mode: ``lockstep`` (the simulation waits for each command: reproducible benchmarks)
            or ``realtime`` (the latest command; pace the run to wall-clock time).
        namespace: topic and service prefix (``""``, ``/name`` or ``auto``: ``/arena_<pid>``).
        timeout: s of wall time to wait for each lock-step command before the episode ends
            as ``error``.
        startup_timeout: s to wait for an episode's first command (the node discovering).
        command_timeout: s (wall) after which a real-time command counts as a stop.
        cmd_vel_stamped: the node sends ``geometry_msgs/TwistStamped`` (Nav2's
            ``enable_stamped_cmd_vel``).
        clock: publish ``/clock`` (simulated time for nodes with ``use_sim_time``).
        launch: the node's command line, started once per process (``None``: started by hand).
    """

    model_config = ConfigDict(frozen=True, extra="forbid")
    mode: Literal["lockstep", "realtime"] = "lockstep"
    namespace: str = ""
    timeout: float = Field(5.0, gt=0)
    startup_timeout: float = Field(30.0, gt=0)
    command_timeout: float = Field(0.5, gt=0)
    cmd_vel_stamped: bool = False
    clock: bool = True
    launch: list[str] | None = None
    remap: dict[str, str] = Field(default_factory=dict)

    @field_validator("remap")
    @classmethod
    def _remap(cls, v: dict[str, str]) -> dict[str, str]:
        try:
            for source, target in v.items():
                check_topic(source, field_name=f"key {source!r}")
                check_topic(target, field_name=f"[{source!r}]")
        except ConfigError as e:  # pydantic names the field
            raise ValueError(str(e)) from None
        return v

    @field_validator("namespace")
    @classmethod
    def _namespace(cls, v: str) -> str:
        try:
            return v if v == "auto" else check_namespace(v, field_name="namespace")
        except ConfigError as e:  # pydantic names the field
            raise ValueError(str(e).split(": ", 1)[1]) from None

    @field_validator("launch")
    @classmethod
    def _launch(cls, v: list[str] | None) -> list[str] | None:
        if v is not None and (not v or not all(isinstance(a, str) and a for a in v)):
            raise ValueError("expected a non-empty list of command-line words")
        return v

    def link_options(self) -> LinkOptions:
        """The link's options (``auto`` namespace resolved for this process)."""
        ns = f"/arena_{os.getpid()}" if self.namespace == "auto" else self.namespace
        return LinkOptions(mode=self.mode, namespace=ns, timeout=self.timeout,
                           startup_timeout=self.startup_timeout,
                           command_timeout=self.command_timeout,
                           cmd_vel_stamped=self.cmd_vel_stamped, clock=self.clock,
                           remap=tuple(sorted(self.remap.items())))


class _Shared:
    """The process's links and launched nodes, one per planner configuration.

    A benchmark builds a new stack (and planner) per episode; the node and the publishers stay,
    so discovery happens once per worker.
    """

    links: ClassVar[dict[str, RosLink]] = {}
    nodes: ClassVar[dict[str, subprocess.Popen[bytes]]] = {}

    @classmethod
    def link(cls, key: str, make: Callable[[], RosLink]) -> RosLink:
        if key not in cls.links:
            if not cls.links:
                atexit.register(cls.close_all)
            cls.links[key] = make()
        return cls.links[key]

    @classmethod
    def launch(cls, key: str, argv: list[str]) -> None:
        proc = cls.nodes.get(key)
        if proc is not None and proc.poll() is None:
            return
        try:
            cls.nodes[key] = subprocess.Popen(argv, start_new_session=True,
                                              preexec_fn=_die_with_parent)
        except OSError as e:
            raise ConfigError(f"local_planner.launch: cannot start {argv[0]!r}: {e}") from None

    @classmethod
    def close_all(cls) -> None:
        for proc in cls.nodes.values():
            stop_process(proc)
        for link in cls.links.values():
            link.close()
        cls.nodes.clear()
        cls.links.clear()


def _die_with_parent() -> None:
    """In the launched node: SIGTERM it when its launcher dies.

    Linux's ``PR_SET_PDEATHSIG``: a killed benchmark worker leaves no node behind.
    """
    if sys.platform.startswith("linux"):
        import ctypes

        ctypes.CDLL(None).prctl(1, signal.SIGTERM)  # 1 = PR_SET_PDEATHSIG


def stop_process(proc: subprocess.Popen[Any], wait: float = STOP_WAIT_S) -> None:
    """SIGTERM ``proc``'s process group, then SIGKILL after ``wait`` s."""
    if proc.poll() is not None:
        return
    try:
        os.killpg(proc.pid, signal.SIGTERM)
        proc.wait(wait)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait(wait)
    except ProcessLookupError:
        pass


class RosPlanner(EpisodeHooks):
    """Base of the ROS local planners; subclasses name the transport."""

    supports: ClassVar[frozenset[str]] = KINEMATICS
    Params = RosPlannerParams
    #: The transport's module and class (imported on first use: rclpy / rospy are extras).
    transport: ClassVar[tuple[str, str]]
    #: How a launched node takes remaps: ``(args marker, flag before each)``, or ``None`` for
    #: bare ``from:=to`` words.
    remap_flag: ClassVar[tuple[str, str] | None]

    def __init__(self, params: RosPlannerParams | None = None) -> None:
        self.params = params or RosPlannerParams()
        self._hook: LiveHook | None = None
        self.link: RosLink | None = None

    # -- the process's link ---------------------------------------------------------------------
    def _make_transport(self, link: RosLink) -> Transport:
        module, name = self.transport
        cls = getattr(__import__(module, fromlist=[name]), name)
        return cls(link)  # type: ignore[no-any-return]

    def _launch_argv(self, options: LinkOptions) -> list[str]:
        argv = list(self.params.launch or [])
        if argv[0] == "python":
            argv[0] = sys.executable
        ns = options.namespace
        if ns:
            # the node in the namespace; its absolute /clock and /tf follow Arena's there
            argv += self.remap_args([("__ns", ns), *((t, f"{ns}{t}") for t in ABSOLUTE)])
        return argv

    @classmethod
    def remap_args(cls, pairs: list[tuple[str, str]]) -> list[str]:
        """Command-line words that remap ``(from, to)`` names of a launched node.

        ROS 2: ``--ros-args -r from:=to ...``; ROS 1: ``from:=to ...``.
        """
        words = [f"{a}:={b}" for a, b in pairs]
        if cls.remap_flag is None:
            return words
        return [cls.remap_flag[0], *(w for word in words for w in (cls.remap_flag[1], word))]

    def _connect(self) -> RosLink:
        if self.link is None:
            options = self.params.link_options()
            key = json.dumps([self.transport, self.params.model_dump(mode="json"),
                              options.namespace])
            self.link = _Shared.link(key, lambda: RosLink(self._make_transport, options))
            if self.params.launch:
                _Shared.launch(key, self._launch_argv(options))
        return self.link

    # -- hooks (forwarded by the navigation controller) -----------------------------------------
    def initialize_episode(self, runner: EpisodeRunner) -> None:
        """Send the episode's scene and first frame."""
        link = self._connect()
        link.take_goals()  # what came between episodes is not for this one
        link.take_resets()
        self._hook = LiveHook([link])
        self._hook.initialize_episode(runner)

    def before_step(self, runner: EpisodeRunner) -> None:
        """Hand goals and resets from ROS to the task's interactive module, if any."""
        assert self.link is not None
        goals, resets = self.link.take_goals(), self.link.take_resets()
        if not goals and not resets:
            return
        ui = _interactive_module(runner)
        if ui is None:
            runner.event("ros_ignored", f"{len(goals)} goal(s), {resets} reset(s): this run "
                                        "takes no goals or resets (a benchmark)")
            return
        from arena.tasks.modules.interactive import CommandError

        for goal in goals:
            try:
                ui.set_goal(0, goal)
            except CommandError as e:
                runner.event("ros_goal_refused", str(e))
        if resets:
            ui.reset()

    def after_step(self, runner: EpisodeRunner) -> None:
        """Send the step's frame."""
        if self._hook is not None:
            self._hook.after_step(runner)

    def episode_end(self, runner: EpisodeRunner) -> None:
        """Send the last frame (with the outcome)."""
        if self._hook is not None:
            self._hook.episode_end(runner)

    # -- LocalPlanner -----------------------------------------------------------------------------
    def reset(self) -> None:
        """Nothing to forget here (the node keeps its own state)."""

    def compute(self, obs: LocalObservation) -> FloatArray:
        """The node's command for this tick, clipped to the robot's limits.

        Raises:
            ConfigError: called outside an episode runner (no frames to send).
            NodeTimeout: lock-step, and the node did not answer in time.
        """
        if self.link is None:
            raise ConfigError(
                f"the {self.transport[0].rsplit('.', 1)[-1]} local planner needs an episode "
                "runner to send its frames (arena run, arena bench, arena ros2 run)")
        cmd = self.link.command()
        if not np.all(np.isfinite(cmd)):
            cmd = np.zeros(3)
        car = obs.drive == "ackermann" or obs.limits.min_turning_radius > 0
        return finish_command(cmd, obs.twist, obs.limits, obs.dt, car)


def _interactive_module(runner: EpisodeRunner) -> Any:
    runtime = getattr(runner.controller, "runtime", None)
    from arena.tasks.modules.interactive import InteractiveModule

    for module in getattr(runtime, "modules", ()):
        if isinstance(module, InteractiveModule):
            return module
    return None


@LOCAL_PLANNERS.register("ros2", tags=("ros", "external"))
class Ros2Planner(RosPlanner):
    """An external ROS 2 node drives the robot over Arena's ROS 2 topics (``arena[ros2]``)."""

    transport = ("arena.ros.ros2", "Ros2Transport")

    remap_flag = ("--ros-args", "-r")


@LOCAL_PLANNERS.register("ros1", tags=("ros", "external"))
class Ros1Planner(RosPlanner):
    """An external ROS 1 node drives the robot over Arena's ROS 1 topics.

    Needs Debian's ROS 1 (``bash tools/install_ros1.sh``) and a ROS master at
    ``ROS_MASTER_URI``.
    """

    transport = ("arena.ros.ros1", "Ros1Transport")

    remap_flag = None  # rospy reads bare from:=to words
