"""The guard and the sandbox of the ROS 1 bridge tests (on top of :mod:`tests.ros.sandbox`).

:func:`require_ros1` skips a test on a machine without Debian's ROS 1 (``bash
tools/install_ros1.sh``) or without network namespaces; CI installs ROS 1 and sets
``ARENA_REQUIRE_ROS1=1``, so there a missing piece fails the run instead of skipping it.

:func:`run_isolated` runs one case of :mod:`tests.ros.ros1_scenario` in a loopback-only
network namespace, as the sandbox does, and in a PID namespace of its own too: there the
scenario is process 1, and when it exits or is killed the kernel ends every process it left,
a node the ``ros1`` planner launched in a session of its own (out of reach of a process-group
kill) included. rospy is never imported into the pytest process itself (it would put Debian's
ROS 1 message packages in front of the ROS 2 ones other tests import).
"""

from __future__ import annotations

import subprocess
from functools import cache
from pathlib import Path
from typing import Any

from tests.ros import sandbox
from tests.ros.sandbox import client_problem, netns_problem, unavailable

SCENARIO = "tests.ros.ros1_scenario"
#: The master's port inside the namespace (a fresh namespace has every port free).
MASTER_PORT = 11311


@cache
def _problem() -> str | None:
    """Why the ROS 1 tests cannot run here, or ``None``."""
    problem = client_problem("from arena.ros.ros1_env import import_rospy; import_rospy()",
                             "Debian's ROS 1")
    if problem is None and subprocess.run(["sh", "-c", "command -v rosmaster"],
                                          capture_output=True, check=False).returncode != 0:
        problem = "needs rosmaster on PATH (Debian's ros-base)"
    return problem or netns_problem()


def require_ros1() -> None:
    """Skip (or fail in CI) unless ROS 1, rosmaster and ``unshare -n`` work here."""
    problem = _problem()
    if problem is not None:
        unavailable(problem, "ARENA_REQUIRE_ROS1", "tools/install_ros1.sh")


def run_isolated(case: str, tmp: Path, *args: str, timeout: float = 60.0) -> dict[str, Any]:
    """Run scenario ``case`` in loopback-only network and PID namespaces; its JSON result.

    ``timeout`` bounds the whole run; the scenario's master and nodes never outlive it.
    """
    env: dict[str, str | None] = {
        "ROS_MASTER_URI": f"http://127.0.0.1:{MASTER_PORT}", "ROS_IP": "127.0.0.1",
        "ROS_HOME": str(tmp / "ros"), "ROS_LOG_DIR": str(tmp / "ros" / "log"),
        "ROS_HOSTNAME": None}
    return sandbox.run_isolated(SCENARIO, case, *args, env=env, timeout=timeout)
