"""Network-isolated runs for the ROS bridge tests (ROS 1 and ROS 2 share it).

A scenario module runs in a new network namespace that has only loopback (``unshare -n``,
``ip link set lo up``) and a PID namespace of its own: its nodes talk over 127.0.0.1, nothing
they send leaves the namespace, and every process it starts ends with it. A timeout bounds the
whole run. The scenario prints its result as JSON on its last line.
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
from typing import Any, NoReturn

import pytest

REPO = Path(__file__).resolve().parents[2]


def unavailable(message: str, require_var: str, install: str) -> NoReturn:
    """Skip, or fail where CI requires the piece (``<require_var>=1``)."""
    if os.environ.get(require_var) == "1":
        pytest.fail(f"{message} ({require_var}=1: CI installs it with {install})",
                    pytrace=False)
    pytest.skip(message)


def unshare_cmd() -> list[str]:
    """New network and PID namespaces (a user namespace mapped to root when not root).

    In the PID namespace, everything a scenario starts (a ROS master, launched nodes in their
    own sessions) ends with it (``--kill-child``).
    """
    own = ["unshare", "-n", "-p", "--fork", "--kill-child"]
    return own if os.geteuid() == 0 else [own[0], "-r", *own[1:]]


@cache
def netns_problem() -> str | None:
    """Why loopback-only network and PID namespaces cannot be made here, or ``None``."""
    for tool in ("unshare", "ip"):
        if subprocess.run(["sh", "-c", f"command -v {tool}"], capture_output=True,
                          check=False).returncode != 0:
            return f"needs {tool} on PATH"
    netns = subprocess.run([*unshare_cmd(), "sh", "-c", "ip link set lo up"],
                           capture_output=True, text=True, timeout=30, check=False)
    if netns.returncode != 0:
        return f"needs network namespaces (unshare -n -p): {netns.stderr.strip()}"
    return None


def client_problem(statement: str, what: str) -> str | None:
    """Why ``statement`` (importing a ROS client library) fails in a fresh interpreter."""
    probe = subprocess.run([sys.executable, "-c", statement], capture_output=True, text=True,
                           timeout=60, check=False, cwd=REPO)
    if probe.returncode != 0:
        lines = probe.stderr.strip().splitlines()
        return f"needs {what}: {lines[-1] if lines else probe.returncode}"
    return None


def run_isolated(module: str, case: str, *args: str,
                 env: dict[str, str | None] | None = None,
                 timeout: float = 60.0) -> dict[str, Any]:
    """Run ``python -m module case args...`` in the namespaces; its JSON result (last line).

    ``env`` adds variables to this process's (``None`` removes one).
    """
    full_env = dict(os.environ, PYTHONUNBUFFERED="1")
    for key, value in (env or {}).items():
        if value is None:
            full_env.pop(key, None)
        else:
            full_env[key] = value
    cmd = [*unshare_cmd(), "sh", "-c", 'ip link set lo up && exec "$@"', "sh",
           sys.executable, "-m", module, case, *args]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=full_env, cwd=REPO, start_new_session=True)
    try:
        out, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)  # unshare dies; --kill-child ends the namespace
        out, err = proc.communicate()
        pytest.fail(f"{module} {case} ran over {timeout:g} s:\n{err[-3000:]}")
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)  # whatever it left behind
    lines = out.strip().splitlines()
    if proc.returncode != 0 or not lines:
        pytest.fail(f"{module} {case} failed ({proc.returncode}):\n{err[-3000:]}")
    result: dict[str, Any] = json.loads(lines[-1])
    return result
