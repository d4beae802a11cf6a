"""The ROS 1 bridge (rospy): messages to and from a rospy node through a lock-step link, in a
network namespace with only loopback; and the one-line errors without ROS 1 or a master.

The ROS traffic runs in child processes (:mod:`tests.ros.ros1_kit`); this process never imports
rospy.
"""

from __future__ import annotations

import importlib.abc
import socket
import sys
import types

import numpy as np
import pytest

from arena.core.errors import ConfigError
from arena.ros import ros1_env
from tests.ros.ros1_kit import require_ros1, run_isolated


class _NoRospy(importlib.abc.MetaPathFinder):
    """Hides an installed rospy (a sourced ROS 1 on the test machine)."""

    def find_spec(self, fullname, path, target=None):
        if fullname == "rospy":
            raise ModuleNotFoundError("No module named 'rospy'", name="rospy")
        return None


def test_missing_ros1_is_one_line_naming_the_debian_packages(monkeypatch, tmp_path):
    monkeypatch.setattr(ros1_env, "DEBIAN_DIST", tmp_path)
    monkeypatch.setattr(sys, "meta_path", [_NoRospy(), *sys.meta_path])
    with pytest.raises(ConfigError) as e:
        ros1_env.import_rospy()
    message = str(e.value)
    assert "\n" not in message
    assert "python3-rospy" in message and "tools/install_ros1.sh" in message


def test_ros2_messages_already_loaded_are_one_line_not_a_mix(monkeypatch, tmp_path):
    for path in ("rospy/__init__.py", "geometry_msgs/msg/__init__.py"):
        (tmp_path / path).parent.mkdir(parents=True)
        (tmp_path / path).write_text("")
    ros2 = types.ModuleType("geometry_msgs")
    ros2.__file__ = "/venv/site-packages/geometry_msgs/__init__.py"
    monkeypatch.setitem(sys.modules, "geometry_msgs", ros2)
    monkeypatch.setattr(ros1_env, "DEBIAN_DIST", tmp_path)
    monkeypatch.setattr(sys, "meta_path", [_NoRospy(), *sys.meta_path])
    path = list(sys.path)
    with pytest.raises(ConfigError, match="cannot load Debian's geometry_msgs: this process "
                                          "already imported another package of that name"):
        ros1_env.import_rospy()
    assert sys.path == path  # nothing changed on the way to the error


def test_no_master_is_one_line_naming_the_uri():
    with socket.socket() as s:  # a port nobody listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    uri = f"http://127.0.0.1:{port}"
    with pytest.raises(ConfigError, match=f"no ROS master answers at ROS_MASTER_URI={uri}"):
        ros1_env.check_master(uri, timeout=1.0)
    with pytest.raises(ConfigError, match="ROS_MASTER_URI: 'localhost:11311' is not a URI"):
        ros1_env.check_master("localhost:11311")


def test_only_message_packages_are_taken_from_debian(tmp_path):
    for pkg, sub in (("geometry_msgs", "msg"), ("std_srvs", "srv"), ("numpy", "core"),
                     ("rospy", "impl")):
        (tmp_path / pkg / sub).mkdir(parents=True)
        (tmp_path / pkg / sub / "__init__.py").write_text("")
    assert ros1_env.debian_message_packages(tmp_path) == {"geometry_msgs", "std_srvs"}
    assert ros1_env.debian_message_packages(tmp_path / "absent") == frozenset()


@pytest.fixture(scope="module")
def roundtrip(tmp_path_factory):
    require_ros1()
    return run_isolated("roundtrip", tmp_path_factory.mktemp("ros1"))


def test_scan_tf_odom_and_clock_reach_a_rospy_node(roundtrip):
    peer = roundtrip["peer"]
    scan = peer["scan"]  # the latest: frame 2's
    np.testing.assert_allclose(scan["ranges"], 3.0 + 0.1 * np.arange(5), rtol=1e-6)
    assert scan["frame_id"] == "laser" and scan["stamp"] == pytest.approx(0.2)
    assert scan["angle_min"] == pytest.approx(-1.0) and scan["angle_increment"] == 0.5
    assert scan["range_max"] == 8.0
    # the tf chain map -> odom -> base_link -> laser (and the rear lidar's frame)
    assert peer["tf_static"] == [["base_link", "laser", pytest.approx(0.2)],
                                 ["base_link", "rear", pytest.approx(-0.3)], ["map", "odom", 0.0]]
    assert peer["tf"] == ["odom", "base_link", 2.5, 2.0, pytest.approx(0.5)]
    assert peer["odom"] == ["odom", "base_link", 2.5, 0.25, pytest.approx(0.2)]
    assert peer["clock"] == pytest.approx(0.2)
    assert peer["plan"] == [[0.0, 0.0], [1.0, 1.0], [2.0, 1.0]]


def test_people_arrive_as_named_points_and_markers(roundtrip):
    people = roundtrip["peer"]["people"]
    assert people["names"][:3] == ["x", "y", "z"] and "state" in people["names"]
    assert people["xy"] == [[1.0, 2.0], [3.0, -1.5]]
    markers = roundtrip["peer"]["markers"]
    assert markers[0] == ["people", 0, 0, 3]  # delete-all first
    assert ["people", 9, 3, 0] in markers  # person 9's cylinder


def test_a_late_subscriber_gets_the_latched_map_and_goal(roundtrip):
    grid = roundtrip["peer"]["map"]
    assert (grid["width"], grid["height"], grid["resolution"]) == (6, 4, 0.5)
    assert grid["origin"] == [-1.0, 2.0]
    data = np.array(grid["data"]).reshape(4, 6)
    assert (data[0] == 100).all() and data[3, 5] == -1 and (data[1:3] == 0).all()
    goals = roundtrip["peer"]["goals"]
    assert ["/arena", 5.0, 5.0] in goals  # Arena's goal, latched
    assert ["/test_probe", 3.0, -1.0] in goals  # the node's own is latched too


def test_twists_goal_and_reset_reach_the_link_in_lock_step(roundtrip):
    # the probe answers each frame with vx = the odometry's x and wz = its stamp: the link
    # returned each frame's own answer
    assert roundtrip["commands"] == [[1.5, 0.0, pytest.approx(0.1)], [2.5, 0.0, pytest.approx(0.2)]]
    assert roundtrip["peer"]["answered"] == [pytest.approx(0.1), pytest.approx(0.2)]
    [goal] = roundtrip["goals"]  # the node's goal; Arena's own echo is not one
    assert goal == [3.0, -1.0, pytest.approx(0.5)]
    assert roundtrip["resets"] == 1
    assert roundtrip["peer"]["reset"][0] is True



def test_a_closed_link_leaves_the_graph_and_the_node_serves_the_next(roundtrip):
    ros = [e for e in roundtrip["graph_closed"] if "logger" not in e and "rosout" not in e]
    assert ros == []  # no publisher, subscriber or service left behind
    reopened = roundtrip["graph_reopened"]  # the same node /arena, the new link's namespace
    assert {"pub /second/map", "pub /second/scan", "sub /second/cmd_vel",
            "srv /second/arena/reset"} <= set(reopened)
    # two links of one namespace share the reset service: the latest open one answers
    assert roundtrip["served"] == [1, 0, 1]
    assert not [e for e in roundtrip["graph_last"] if "second" in e]


def test_arena_ros1_run_in_lock_step_reaches_the_goals_with_a_rospy_node(tmp_path):
    require_ros1()
    result = run_isolated("episode", tmp_path, str(tmp_path / "run"), "2", timeout=90)
    rows = result["rows"]
    assert [r["outcome"] for r in rows] == ["success", "success"], rows
    for r in rows:
        assert int(r["collisions"]) == 0 and float(r["final_goal_distance"]) < 0.25
        assert int(r["steps"]) > 30  # driven by the node: 6 m goals at <= 0.6 m/s
