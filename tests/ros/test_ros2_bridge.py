"""The ROS 2 bridge over rclpy: topics and values, a lock-step episode driven by the example
node, a silent node, missing packages. Each scenario runs in its own loopback-only network
namespace (tests/ros/sandbox.py) with localhost-only discovery.
"""

from __future__ import annotations

import subprocess
import sys
from functools import cache

import pytest

from tests.ros.sandbox import REPO, client_problem, netns_problem, run_isolated, unavailable

SCENARIO = "tests.ros.ros2_scenario"
ENV: dict[str, str | None] = {"ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
                              "ROS_DOMAIN_ID": "0"}


@cache
def _problem() -> str | None:
    problem = client_problem("from arena.ros.ros2_env import import_rclpy; import_rclpy()",
                             "ROS 2 from PyPI (the ros2 extra, arena ros2 setup)")
    return problem or netns_problem()


@pytest.fixture
def ros2() -> None:
    """Skip (or fail in CI, ``ARENA_REQUIRE_ROS2=1``) unless rclpy and ``unshare -n`` work."""
    problem = _problem()
    if problem is not None:
        unavailable(problem, "ARENA_REQUIRE_ROS2", "make test (the ros2 extra, arena ros2 setup)")


def test_topics_values_and_what_comes_back(ros2, tmp_path):
    r = run_isolated(SCENARIO, "topics", str(tmp_path), env=ENV)
    assert r["scan"] == r["expected_scan"] and r["scan_frame"] == "laser"
    assert r["tf"] == [["odom", "base_link", r["pose"][0]]]
    assert r["odom_stamp"] == 0
    assert r["map"] == r["map_expected"]  # latched: reached a subscriber that came later
    assert r["cmd"] == [[0.4, 0.0, -0.2]]
    assert r["goal"][0] == pytest.approx(r["goal_expected"])  # the user's, not the echo
    assert r["reset"] == 1


def test_lockstep_run_with_the_example_node_reaches_its_goals(ros2, tmp_path):
    r = run_isolated(SCENARIO, "episode", str(tmp_path), env=ENV, timeout=180)
    assert r["rc"] == 0, r["stderr"]
    assert r["outcomes"] == ["success", "success"]


def test_bench_scores_a_ros_contestant_on_two_workers(ros2, tmp_path):
    """Each worker launches its own node in its own namespace (namespace: auto)."""
    r = run_isolated(SCENARIO, "bench", str(tmp_path), env=ENV, timeout=300)
    assert r["rc"] == 0, r["stderr"]
    assert r["contestants"] == ["ros_pursuit"]
    assert r["outcomes"] == ["success"] * 4


def test_a_silent_node_costs_each_episode_not_the_run(ros2, tmp_path):
    r = run_isolated(SCENARIO, "silent", str(tmp_path), env=ENV, timeout=120)
    assert r["rc"] == 0, r["stderr"]
    assert r["outcomes"] == ["error", "error"]
    assert r["errors"][0].startswith("NodeTimeout: no /cmd_vel command within 1 s")


def test_missing_rclpy_is_one_line_naming_the_extra(tmp_path):
    fake = tmp_path / "rclpy"
    fake.mkdir()
    (fake / "__init__.py").write_text("raise ImportError('no rclpy here')\n")
    done = subprocess.run(
        [sys.executable, "-m", "arena.cli", "ros2", "run", "episodes=1"],
        capture_output=True, text=True, timeout=120, check=False, cwd=REPO,
        env={**__import__("os").environ, "PYTHONPATH": str(tmp_path)})
    assert done.returncode != 0
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    assert "pip install 'arena[ros2]'" in lines[0]


def _fake_imports(monkeypatch, *, missing: str = "", genpy: bool = False) -> None:
    """``import_module`` as if ROS 2 were installed (``missing`` absent; ``genpy``: the message
    packages are ROS 1's)."""
    import importlib
    import types

    from arena.ros import ros2_env

    real = importlib.import_module

    class Rosidl:  # what a ROS 2 message class has
        @staticmethod
        def get_fields_and_field_types() -> dict:
            return {}

    class Genpy:  # what a ROS 1 message class has
        _slot_types: tuple = ()

    def fake(name, *args):
        if missing and name.startswith(missing):
            raise ImportError(name)
        if name == "rclpy" or name.endswith((".msg", ".srv")):
            module = types.ModuleType(name)
            module.Message = Genpy if genpy else Rosidl
            return module
        return real(name, *args)

    monkeypatch.setattr(ros2_env.importlib, "import_module", fake)


def test_missing_tf2_msgs_names_the_setup_command(monkeypatch):
    from arena.core.errors import ConfigError
    from arena.ros import ros2_env

    _fake_imports(monkeypatch, missing="tf2_msgs")
    with pytest.raises(ConfigError, match="arena ros2 setup"):
        ros2_env.import_rclpy()


def test_ros1_messages_in_the_process_are_one_line(monkeypatch):
    from arena.core.errors import ConfigError
    from arena.ros import ros2_env

    _fake_imports(monkeypatch, genpy=True)
    with pytest.raises(ConfigError, match="run ROS 1 and ROS 2 in separate processes"):
        ros2_env.import_rclpy()
