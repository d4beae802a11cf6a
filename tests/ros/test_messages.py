"""The ROS topic table and message values of a hand-made two-robot scene: namespaces, frame
prefixes, tf tree, lidar rates, people points; and their bags through rosbags."""

from __future__ import annotations

import numpy as np
import pytest

from arena.ros.messages import PEOPLE_DTYPE, RosMessages, sim_ns
from arena.ros.topics import MSG_TYPES, ros1_type, topic_table
from tests.ros.scenes import sample_frame as _frame
from tests.ros.scenes import sample_scene as _scene


def test_one_robot_has_nav2_names_and_no_prefix():
    names = {t.name: t.msgtype for t in topic_table(_scene(1), clock=True)}
    assert names == {
        "/clock": "rosgraph_msgs/msg/Clock", "/tf": "tf2_msgs/msg/TFMessage",
        "/tf_static": "tf2_msgs/msg/TFMessage", "/map": "nav_msgs/msg/OccupancyGrid",
        "/people/markers": "visualization_msgs/msg/MarkerArray",
        "/people/states": "sensor_msgs/msg/PointCloud2", "/odom": "nav_msgs/msg/Odometry",
        "/scan": "sensor_msgs/msg/LaserScan", "/rear/scan": "sensor_msgs/msg/LaserScan",
        "/plan": "nav_msgs/msg/Path",
        "/local_plan": "nav_msgs/msg/Path", "/goal_pose": "geometry_msgs/msg/PoseStamped",
        "/cmd_vel": "geometry_msgs/msg/Twist"}
    assert ros1_type(MSG_TYPES["scan"]) == "sensor_msgs/LaserScan"


def test_robots_get_namespaces_frames_and_one_scan_topic_per_lidar():
    scene = _scene()
    table = topic_table(scene, clock=False)
    names = [t.name for t in table]
    assert "/clock" not in names
    assert {"/robot_0/odom", "/robot_0/scan", "/robot_0/rear/scan", "/robot_0/plan",
            "/robot_0/cmd_vel", "/robot_1/odom", "/robot_1/scan", "/robot_1/cmd_vel"} <= set(names)
    assert "/robot_1/plan" not in names and "/odom" not in names  # the stack drives robot 0
    conv = RosMessages(clock=False)
    static = dict((t.name, m) for t, _, m in conv.scene(scene))["/tf_static"]["transforms"]
    pairs = {(tr["header"]["frame_id"], tr["child_frame_id"]) for tr in static}
    assert pairs == {("map", "robot_0/odom"), ("map", "robot_1/odom"),
                     ("robot_0/base_link", "robot_0/laser"), ("robot_0/base_link", "robot_0/rear"),
                     ("robot_1/base_link", "robot_1/laser")}
    rear = next(tr for tr in static if tr["child_frame_id"] == "robot_0/rear")["transform"]
    assert rear["translation"]["x"] == -0.3 and rear["rotation"]["z"] == pytest.approx(1.0)
    msgs = {t.name: m for t, _, m in conv.frame(_frame(0))}
    tf = {tr["child_frame_id"]: tr for tr in msgs["/tf"]["transforms"]}
    assert tf["robot_1/base_link"]["header"]["frame_id"] == "robot_1/odom"
    assert tf["robot_1/base_link"]["transform"]["translation"]["x"] == -3.0
    assert msgs["/robot_1/odom"]["child_frame_id"] == "robot_1/base_link"
    assert msgs["/robot_0/rear/scan"]["header"]["frame_id"] == "robot_0/rear"
    np.testing.assert_array_equal(msgs["/robot_1/scan"]["ranges"], np.full(5, 7.0))


def test_scans_follow_each_lidar_rate_and_repeated_steps_send_nothing():
    scene, conv = _scene(), RosMessages()
    conv.scene(scene)
    sent = []
    for step in range(5):
        msgs = conv.frame(_frame(step))
        sent.append({t.name for t, _, _ in msgs})
        assert [ns for _, ns, _ in msgs] == [sim_ns(0.1 * step)] * len(msgs)
    # the 10 Hz laser every 0.1 s step, the 5 Hz rear lidar every other step
    assert ["/robot_0/scan" in s for s in sent] == [True] * 5
    assert ["/robot_0/rear/scan" in s for s in sent] == [True, False, True, False, True]
    assert conv.frame(_frame(4)) == []  # the episode's last frame repeats its last step
    assert "/clock" in sent[0]


def test_laser_map_and_people_values():
    scene, conv = _scene(1), RosMessages()
    latched = {t.name: m for t, _, m in conv.scene(scene)}
    grid = latched["/map"]
    assert grid["info"]["width"] == 6 and grid["info"]["height"] == 4
    assert grid["info"]["origin"]["position"]["x"] == -1.0
    np.testing.assert_array_equal(grid["data"][:6], 100)  # row 0: the row at the origin
    msgs = {t.name: m for t, _, m in conv.frame(_frame(2, robots=1))}
    scan = msgs["/scan"]
    assert scan["angle_max"] == pytest.approx(1.0) and scan["angle_increment"] == 0.5
    assert scan["ranges"].dtype == np.float32 and scan["scan_time"] == pytest.approx(0.1)
    pts = np.frombuffer(msgs["/people/states"]["data"].tobytes(), dtype=PEOPLE_DTYPE)
    np.testing.assert_array_equal(pts["vy"], [0.0, -1.25])
    np.testing.assert_array_equal(pts["id"], [4, 9])
    np.testing.assert_array_equal(pts["state"], [0, 1])
    offsets = {f["name"]: (f["offset"], f["datatype"]) for f in msgs["/people/states"]["fields"]}
    assert offsets["vx"] == (12, 7) and offsets["id"] == (28, 5)
    markers = msgs["/people/markers"]["markers"]
    assert [m.get("ns") for m in markers] == ["people", "people", "people/heading", "people",
                                              "people/heading"]
    assert markers[3]["id"] == 9 and markers[3]["scale"]["x"] == 0.5
    assert msgs["/cmd_vel"] == {"linear": {"x": 0.25, "y": 0.25, "z": 0.0},
                                "angular": {"x": 0.0, "y": 0.0, "z": 0.25}}
    path = msgs["/plan"]["poses"]
    assert path[0]["pose"]["orientation"]["z"] == pytest.approx(np.sin(np.pi / 8))


@pytest.mark.parametrize("flavour", ["ros1", "ros2"])
def test_two_robot_bag_reads_back(tmp_path, flavour):
    pytest.importorskip("rosbags")
    from rosbags.rosbag1 import Reader as Reader1
    from rosbags.rosbag2 import Reader as Reader2

    from arena.ros.bag import BagWriter, RosbagSink, typestore

    path = tmp_path / ("b.bag" if flavour == "ros1" else "b")
    bag = BagWriter(path, flavour)
    sink = RosbagSink(bag, clock=True)
    sink.scene(_scene())
    for step in range(3):
        sink.frame(_frame(step))
    bag.close()
    store = typestore(flavour)
    with (Reader1(path) if flavour == "ros1" else Reader2(path)) as reader:
        counts = {c.topic: c.msgcount for c in reader.connections}
        decode = store.deserialize_ros1 if flavour == "ros1" else store.deserialize_cdr
        rear = [decode(raw, c.msgtype) for c, _, raw in reader.messages()
                if c.topic == "/robot_0/rear/scan"]
        if flavour == "ros1":  # what rosbag play checks against the installed messages
            md5 = {c.topic: c.digest for c in reader.connections}
            assert md5["/tf"] == "94810edda583a504dfda3829e70d7eec"
            assert md5["/robot_0/odom"] == "cd5e73d190d741a2f92e81eda573aca7"
    assert counts["/robot_0/rear/scan"] == 2 and counts["/robot_1/scan"] == 3
    assert counts["/clock"] == 3 and counts["/tf_static"] == 1
    assert bag.messages == sum(counts.values())
    np.testing.assert_array_equal(rear[1].ranges, np.full(3, 3.0, dtype=np.float32))
    assert rear[1].header.frame_id == "robot_0/rear"


def test_unknown_fields_are_rejected():
    pytest.importorskip("rosbags")
    from arena.ros.bag import build_message, typestore

    store = typestore("ros2")
    with pytest.raises(KeyError, match="no field 'lenear'"):
        build_message(store, "geometry_msgs/msg/Twist", {"lenear": {"x": 1.0}})
    msg = build_message(typestore("ros1"), "std_msgs/msg/Header", {"frame_id": "map"})
    assert msg.seq == 0 and msg.frame_id == "map"  # ROS 1-only fields take their zero value
