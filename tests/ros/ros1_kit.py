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

import contextlib
import json
import os
import signal
import subprocess
import sys
from functools import cache
from pathlib import Path
from typing import Any

import pytest

from tests.ros.sandbox import REPO, netns_problem, unavailable

SCENARIO = "tests.ros.ros1_scenario"
#: The master's port inside the namespace (a fresh namespace has every port free).
MASTER_PORT = 11311


def unshare_cmd() -> list[str]:
    """New network and PID namespaces (and a user one mapped to root when not root)."""
    own = ["unshare", "-n", "-p", "--kill-child"]
    return own if os.geteuid() == 0 else [own[0], "-r", *own[1:]]


@cache
def _problem() -> str | None:
    """Why the ROS 1 tests cannot run here, or ``None``."""
    probe = subprocess.run(
        [sys.executable, "-c", "from arena.ros.ros1_env import import_rospy; import_rospy()"],
        capture_output=True, text=True, timeout=60, check=False, cwd=REPO)
    if probe.returncode != 0:
        lines = probe.stderr.strip().splitlines()
        return f"needs Debian's ROS 1: {lines[-1] if lines else probe.returncode}"
    if subprocess.run(["sh", "-c", "command -v rosmaster"], capture_output=True,
                      check=False).returncode != 0:
        return "needs rosmaster on PATH (Debian's ros-base)"
    return netns_problem()


def require_ros1() -> None:
    """Skip (or fail in CI) unless ROS 1, rosmaster and ``unshare -n`` work here."""
    problem = _problem()
    if problem is not None:
        unavailable(problem, "ARENA_REQUIRE_ROS1", "tools/install_ros1.sh")


def run_isolated(case: str, tmp: Path, *args: str, timeout: float = 60.0) -> dict[str, Any]:
    """Run scenario ``case`` in loopback-only network and PID namespaces; its JSON result.

    ``timeout`` bounds the whole run; the scenario's master and nodes never outlive it.
    """
    env = dict(os.environ, ROS_MASTER_URI=f"http://127.0.0.1:{MASTER_PORT}",
               ROS_IP="127.0.0.1", ROS_HOME=str(tmp / "ros"), ROS_LOG_DIR=str(tmp / "ros" / "log"),
               PYTHONUNBUFFERED="1")
    env.pop("ROS_HOSTNAME", None)
    cmd = [*unshare_cmd(), "sh", "-c", 'ip link set lo up && exec "$@"', "sh",
           sys.executable, "-m", SCENARIO, case, *args]  # from the repository (tests.ros)
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=env, cwd=REPO, start_new_session=True)
    try:
        out, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)  # unshare dies; --kill-child ends the namespace
        out, err = proc.communicate()
        pytest.fail(f"ROS 1 scenario {case} ran over {timeout:g} s:\n{err[-3000:]}")
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)
    lines = out.strip().splitlines()
    if proc.returncode != 0 or not lines:
        pytest.fail(f"ROS 1 scenario {case} failed ({proc.returncode}):\n{err[-3000:]}")
    result: dict[str, Any] = json.loads(lines[-1])
    return result
