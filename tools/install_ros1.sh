#!/usr/bin/env bash
# Install Debian's ROS 1 (roscore, rospy and the message packages) for `arena ros1 run` and the
# ROS 1 bridge tests (arena/ros/ros1.py, tests/ros/test_ros1_bridge.py).
#
# Usage: sudo tools/install_ros1.sh        (or as root in a container)
#
# Debian 12 (bookworm) packages ROS 1 (Noetic-era sources) in its main archive: ros-base brings
# roscore/rosmaster, python3-rospy the client library, python3-*-msgs the message types Arena
# publishes (arena/ros/topics.py). They install into /usr/lib/python3/dist-packages, which
# arena.ros.ros1 adds to a virtual environment's path itself (after the venv's own packages).
#
# Idempotent: does nothing when roscore is on PATH and every Python module imports.
set -euo pipefail

PACKAGES=(ros-base python3-rospy python3-tf2-msgs python3-nav-msgs python3-sensor-msgs
          python3-geometry-msgs python3-visualization-msgs python3-rosgraph-msgs
          python3-std-msgs python3-std-srvs)
MODULES="rospy, tf2_msgs.msg, nav_msgs.msg, sensor_msgs.msg, geometry_msgs.msg, \
visualization_msgs.msg, rosgraph_msgs.msg, std_msgs.msg, std_srvs.srv"

have_ros1() {
    command -v roscore >/dev/null 2>&1 && /usr/bin/python3 -c "import $MODULES" 2>/dev/null
}

if have_ros1; then
    echo "install_ros1: ROS 1 already installed: $(command -v roscore)"
    exit 0
fi

# shellcheck source=tools/apt_lib.sh
source "$(dirname "$0")/apt_lib.sh"
apt_prepare install_ros1 "install ROS 1 (${PACKAGES[*]}) with your package manager"
apt_get update
apt_get install -y --no-install-recommends "${PACKAGES[@]}"

if have_ros1; then
    echo "install_ros1: installed $(command -v roscore)"
    exit 0
fi
echo "install_ros1: the install finished but roscore or a rospy message module is missing" >&2
exit 1
