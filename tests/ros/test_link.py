"""The ROS link and planner over an in-memory node: lock-step, topics, goals, timeouts.

No ROS library and no network: :class:`arena.testing.ros.LoopbackTransport` plays the node.
The same link over rclpy and rospy is tested in test_ros2_bridge.py / test_ros1_bridge.py.
"""

import sys
import time

import numpy as np
import pytest

import arena.plugins  # noqa: F401  (fills the registries)
from arena.config import load_config
from arena.core.errors import ConfigError
from arena.core.types import Outcome, Pose2D
from arena.crowd.driver import build_driver
from arena.episode.navigation import NavigationController, build_stack
from arena.episode.runner import EpisodeRunner
from arena.nav.local_planners.base import LOCAL_PLANNERS
from arena.robots.presets import load_robot
from arena.ros.link import LinkOptions, NodeTimeout, check_namespace
from arena.ros.nodes.planner_node import PlannerNode, as_message, parse_args
from arena.ros.planner import Ros2Planner, RosPlannerParams
from arena.sim.native2d import Native2DBackend
from arena.tasks.generator import TaskRuntime
from arena.tasks.modules.interactive import InteractiveModule
from arena.testing.ros import LoopbackTransport, attach_loopback
from tests.conftest import make_episode


class PlannerNodeReply:
    """The example node (an Arena planner behind ROS) on the messages the link sent so far.

    Each call hands it the plan, scan and goal messages it has not seen yet, in order, then
    answers the latest odom (``None`` before the first one).
    """

    def __init__(self) -> None:
        self.core = PlannerNode(parse_args("test", []))
        self.seen: dict[str, int] = {}

    def __call__(self, sent: dict) -> np.ndarray | None:
        core = self.core
        for topic, handler in (("/plan", core.on_plan), ("/scan", core.on_scan),
                               ("/goal_pose", core.on_goal)):
            messages = sent.get(topic, [])
            for m in messages[self.seen.get(topic, 0):]:
                handler(as_message(m))
            self.seen[topic] = len(messages)
        if not sent.get("/odom"):
            return None
        return core.command(as_message(sent["/odom"][-1]))


def _runner(room, planner, *, modules=(), time_limit=30.0, goal=(8.0, 5.0, 0.0)):
    jackal = load_robot("jackal")
    episode = make_episode(room, [(jackal, (2.0, 5.0, 0.0), goal)], time_limit=time_limit)
    cfg = load_config(None, ["output.video=false"])
    stack = build_stack(cfg.navigation, jackal, episode, local_planner=planner)
    nav = NavigationController(stack, TaskRuntime.single_goal(episode, modules=modules), jackal)
    runner = EpisodeRunner(Native2DBackend(), 0.1, [nav], nav)
    runner.reset(episode, build_driver({"type": "pysocial"}, None), seed=0)
    return runner


def _planner(**params) -> Ros2Planner:
    return Ros2Planner(RosPlannerParams(**params))


def test_lockstep_episode_with_a_pursuit_node_reaches_the_goal(room):
    planner = attach_loopback(_planner(), reply=PlannerNodeReply())
    runner = _runner(room, planner)
    assert runner.run() is Outcome.SUCCESS
    sent = planner.link.transport.sent
    ticks = runner.ticks
    # one odom per frame: the first at reset, then one per step (the last repeats no step)
    assert len(sent["/odom"]) == ticks + 1
    assert [m["header"]["stamp"] for m in sent["/odom"][:3]] == [
        {"sec": 0, "nanosec": 0}, {"sec": 0, "nanosec": 100_000_000},
        {"sec": 0, "nanosec": 200_000_000}]
    assert "/cmd_vel" not in sent  # the node's topic: the link subscribes it, never publishes
    assert len(sent["/goal_pose"]) == 1  # sent when it changes, not every step
    assert len(sent["/map"]) == len(sent["/tf_static"]) == 1
    assert len(sent["/clock"]) == ticks + 1
    assert runner.state.robots.poses[0][0] > 7.5


def test_each_command_answers_the_latest_frame(room):
    """Lock-step: the robot's command at step k is the node's answer to frame k."""
    answers: list[np.ndarray] = []

    def node(sent):
        k = len(sent.get("/odom", []))
        cmd = np.array([0.1 * (k % 5), 0.0, 0.0])
        answers.append(cmd)
        return cmd

    planner = attach_loopback(_planner(), reply=node)
    runner = _runner(room, planner, time_limit=2.0)
    runner.run()
    robots = runner.state.robots
    assert robots.commands[0][0] == pytest.approx(answers[-1][0])
    assert len(answers) == runner.ticks  # one poll per tick: the answer came at once


def test_a_silent_node_ends_the_episode_as_error_and_the_next_runs(room):
    planner = attach_loopback(_planner(timeout=0.05, startup_timeout=0.05),
                              reply=lambda sent: None)
    runner = _runner(room, planner)
    assert runner.run() is Outcome.ERROR
    assert runner.error.startswith("NodeTimeout: no /cmd_vel command within 0.05 s")
    planner.link.transport.reply = PlannerNodeReply()  # the node comes back: the next episode runs
    runner2 = _runner(room, planner)
    assert runner2.run() is Outcome.SUCCESS


def test_unsubscribed_topics_are_not_built_and_a_late_subscriber_gets_the_frame(room):
    planner = attach_loopback(_planner(), reply=PlannerNodeReply(), subscribed={"/odom", "/plan"})
    runner = _runner(room, planner, time_limit=1.0)
    runner.run()
    sent = planner.link.transport.sent
    assert "/people/markers" not in sent and "/scan" not in sent
    assert len(sent["/map"]) == 1  # latched: sent for late subscribers anyway


def test_goals_from_ros_reach_the_interactive_module(room):
    ui = InteractiveModule()
    planner = attach_loopback(_planner(), reply=PlannerNodeReply())
    runner = _runner(room, planner, modules=[ui], time_limit=60.0)
    runner.tick()
    planner.link.on_goal(Pose2D(3.0, 8.0, 0.0))
    planner.link.on_goal(Pose2D(*runner.controller.goal.as_array()))  # its own goal echoed
    assert runner.run() is Outcome.SUCCESS
    assert [e[1] for e in runner.events].count("new_goal") == 1
    assert np.allclose(runner.state.robots.poses[0][:2], [3.0, 8.0], atol=0.35)


def test_a_benchmark_ignores_goals_and_resets_from_ros(room):
    planner = attach_loopback(_planner(), reply=PlannerNodeReply())
    runner = _runner(room, planner)
    runner.tick()
    planner.link.on_goal(Pose2D(3.0, 8.0, 0.0))
    planner.link.on_reset()
    assert runner.run() is Outcome.SUCCESS
    assert any(kind == "ros_ignored" for _, kind, _ in runner.events)


def test_reset_ends_the_episode_through_the_interactive_module(room):
    ui = InteractiveModule()
    planner = attach_loopback(_planner(), reply=PlannerNodeReply())
    runner = _runner(room, planner, modules=[ui])
    runner.tick()
    assert planner.link.on_reset()[0]
    assert runner.run() is Outcome.ABORTED


def test_realtime_takes_the_latest_command_and_stops_on_a_stale_one():
    from arena.testing.ros import loopback_link

    link = loopback_link(LinkOptions(mode="realtime", command_timeout=1e-9),
                         reply=lambda sent: None)
    assert np.array_equal(link.command(), np.zeros(3))  # nothing yet: stop
    link.on_command(np.array([0.5, 0.0, 0.1]))
    assert np.array_equal(link.command(), np.zeros(3))  # older than the timeout: stop
    link2 = loopback_link(LinkOptions(mode="realtime", command_timeout=60.0),
                          reply=lambda sent: None)
    link2.on_command(np.array([0.5, 0.0, 0.1]))
    assert np.array_equal(link2.command(), [0.5, 0.0, 0.1])


def test_commands_are_clipped_to_the_robot(room):
    planner = attach_loopback(_planner(), reply=lambda sent: np.array([9.0, 3.0, 9.0]))
    runner = _runner(room, planner, time_limit=3.0)
    runner.run()
    lim = load_robot("jackal").limits()
    cmds = runner.state.robots.commands[0]
    assert cmds[0] <= lim.vx_max + 1e-9 and cmds[1] == 0.0


def test_outside_a_runner_the_planner_says_what_it_needs():
    from arena.nav.local_planners.base import LocalObservation

    obs = LocalObservation(pose=np.zeros(3), twist=np.zeros(3), goal=np.array([3.0, 0.0, 0.0]),
                           path=np.array([[0.0, 0.0], [3.0, 0.0]]),
                           limits=load_robot("jackal").limits(), robot_radius=0.3, dt=0.1)
    with pytest.raises(ConfigError, match="needs an episode runner"):
        _planner().compute(obs)


@pytest.mark.parametrize(("spec", "message"), [
    ({"namespace": "robot 1"}, "not a ROS namespace"),
    ({"mode": "fast"}, "mode"),
    ({"timeout": 0}, "timeout"),
    ({"launch": []}, "launch"),
    ({"tmeout": 3}, "tmeout"),
])
def test_bad_parameters_are_one_line_errors(spec, message):
    with pytest.raises(ConfigError, match=message) as err:
        LOCAL_PLANNERS.build({"type": "ros2", **spec}, path="navigation.local_planner")
    assert "\n" not in str(err.value)


def test_namespaces():
    assert check_namespace("") == ""
    assert check_namespace("/arena_12/") == "/arena_12"
    with pytest.raises(ConfigError):
        check_namespace("no_slash")
    assert RosPlannerParams(namespace="auto").link_options().namespace.startswith("/arena_")


def test_transport_records_like_a_node():
    from arena.testing.ros import loopback_link

    link = loopback_link()
    assert isinstance(link.transport, LoopbackTransport)
    assert link.transport.subscribers("/odom") == 0  # not advertised yet


def test_an_answer_that_arrives_during_the_send_counts_for_that_frame(room):
    planner = attach_loopback(_planner(timeout=0.2, startup_timeout=0.2), reply=PlannerNodeReply(),
                              eager=True)
    runner = _runner(room, planner)
    assert runner.run() is Outcome.SUCCESS, runner.error


def test_a_node_that_missed_its_first_frames_gets_the_frame_again(room):
    """A silent node (its first answer lost) gets the latest frame again after a second."""
    late = PlannerNodeReply()

    def node(sent):  # answers from the second odom on, as if the first never arrived
        return late(sent) if len(sent.get("/odom", [])) >= 2 else None

    planner = attach_loopback(_planner(startup_timeout=5.0), reply=node)
    runner = _runner(room, planner)
    assert runner.run() is Outcome.SUCCESS
    odoms = planner.link.transport.sent["/odom"]
    assert odoms[0]["header"]["stamp"] == odoms[1]["header"]["stamp"]  # the repeat


def test_remapped_topics_and_launch_arguments():
    planner = attach_loopback(_planner(remap={"/scan": "/front/scan"}, namespace="/r1"))
    opts = planner.link.options
    assert opts.name("/scan") == "/front/scan" and opts.name("/odom") == "/r1/odom"
    argv = Ros2Planner(RosPlannerParams(namespace="/r1", launch=["python", "-m", "x"])) \
        ._launch_argv(RosPlannerParams(namespace="/r1").link_options())
    assert argv[0] == sys.executable
    assert argv[3:] == ["--ros-args", "-r", "__ns:=/r1", "-r", "/clock:=/r1/clock",
                        "-r", "/tf:=/r1/tf", "-r", "/tf_static:=/r1/tf_static"]
    with pytest.raises(ConfigError, match="not an absolute ROS name") as err:
        LOCAL_PLANNERS.build({"type": "ros2", "remap": {"/scan": "front scan"}},
                             path="navigation.local_planner")
    assert "\n" not in str(err.value)


def test_a_stamped_command_older_than_the_frame_does_not_answer_it():
    """TwistStamped: a reply stamped before the latest frame's time answers an earlier one."""
    from arena.testing.ros import loopback_link
    from tests.ros.scenes import sample_frame, sample_scene

    link = loopback_link(LinkOptions(timeout=0.05, startup_timeout=0.05),
                         reply=lambda sent: None)
    link.scene(sample_scene(robots=1))
    link.frame(sample_frame(5, robots=1))  # t = 0.5 s
    link.on_command(np.array([0.3, 0.0, 0.0]), stamp_ns=400_000_000)  # 0.4 s: an older frame's
    with pytest.raises(NodeTimeout):
        link.command()
    link.on_command(np.array([0.2, 0.0, 0.0]), stamp_ns=500_000_000)  # the frame's own time
    assert link.command()[0] == 0.2
    fresh = loopback_link(LinkOptions(timeout=0.05), reply=lambda sent: None)
    fresh.scene(sample_scene(robots=1))
    fresh.frame(sample_frame(6, robots=1))
    fresh.on_command(np.array([0.1, 0.0, 0.0]), stamp_ns=0)  # an unset stamp: unstamped,
    assert fresh.command()[0] == 0.1  # the one answer to the one odom sent


def test_a_late_answer_to_the_last_frame_of_an_episode_does_not_shift_the_next():
    """The answer to an episode's last odom (no tick takes it) arrives in the next episode:
    each later command must still answer its own frame, not the one before."""
    from arena.testing.ros import loopback_link
    from tests.ros.scenes import sample_frame, sample_scene

    answered = 0  # the node answers each odom once, in order, one answer per poll: vx = x

    def node(sent):
        nonlocal answered
        odoms = sent.get("/odom", [])
        if answered >= len(odoms):
            return None
        answered += 1
        return np.array([odoms[answered - 1]["pose"]["pose"]["position"]["x"], 0.0, 0.0])

    link = loopback_link(LinkOptions(timeout=0.2, startup_timeout=0.2), reply=node)
    link.scene(sample_scene(robots=1))
    for step in range(3):  # episode 1: frames 0..2; frame 2's answer is not taken
        link.frame(sample_frame(step, robots=1))
        if step < 2:
            assert link.command()[0] == 1.0 + step  # sample frames: x = 1 + step
    link.scene(sample_scene(robots=1))  # episode 2
    link.frame(sample_frame(10, robots=1))
    link.transport.poll(0.0)  # the late answer to episode 1's last frame arrives first
    for step in range(3):
        if step:
            link.frame(sample_frame(10 + step, robots=1))
        assert link.command()[0] == 11.0 + step


def test_ros1_launch_remaps_are_bare_words():
    from arena.ros.planner import Ros1Planner

    assert Ros1Planner.remap_args([("__ns", "/a"), ("/clock", "/a/clock")]) == [
        "__ns:=/a", "/clock:=/a/clock"]


def test_the_example_node_reads_both_ros_versions_stamps():
    """ROS 2 stamps have sec / nanosec, ROS 1's secs / nsecs: the node answers either."""
    from arena.ros.messages import path as path_fields
    from arena.ros.messages import pose as pose_fields

    core = PlannerNode(parse_args("test", []))
    core.on_plan(as_message(path_fields(0, np.array([[0.0, 0.0], [3.0, 0.0]]))))
    core.on_goal(as_message({"pose": pose_fields(3.0, 0.0, 0.0)}))
    twist = {"twist": {"linear": {"x": 0.0, "y": 0.0, "z": 0.0},
                       "angular": {"x": 0.0, "y": 0.0, "z": 0.0}}}
    for stamp in ({"sec": 1, "nanosec": 0}, {"secs": 1, "nsecs": 0}):
        odom = as_message({"header": {"stamp": stamp}, "pose": {"pose": pose_fields(0, 0, 0)},
                           "twist": twist})
        cmd = core.command(odom)
        assert cmd[0] > 0 and cmd[1] == 0.0  # drives toward the goal ahead


def test_a_node_that_subscribes_late_is_answered_in_step(room):
    """No odom subscriber for the first second (the full resend comes with nothing to answer),
    then a node answering each odom once: lock-step still pairs each answer with its frame."""
    answered = 0
    calls = 0

    def node(sent):
        nonlocal answered, calls
        calls += 1
        if calls <= 15:  # 1.5 s without a subscription, past the link's full resend (1 s)
            time.sleep(0.1)
        elif transport.subscribed is not None:
            transport.subscribed = None  # the node subscribes now
        odoms = sent.get("/odom", [])
        if answered >= len(odoms):
            return None
        answered += 1
        return np.array([0.2, 0.0, 0.0])

    planner = attach_loopback(_planner(startup_timeout=10.0), reply=node, subscribed=set())
    transport = planner.link.transport
    runner = _runner(room, planner, time_limit=1.0)
    assert runner.run() is Outcome.TIMEOUT, runner.error  # drove to the time limit, no error
    assert runner.ticks == 10
