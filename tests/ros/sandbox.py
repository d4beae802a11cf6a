"""Network-isolated runs for the ROS bridge tests (ROS 1 and ROS 2 share it).

A scenario script runs in a new network namespace that has only loopback (``unshare -n``,
``ip link set lo up``): its nodes talk over 127.0.0.1 and nothing they send leaves the
namespace. Everything it starts is in one process group, killed at the end whatever happens;
a timeout bounds the whole run. The scenario prints its result as JSON on its last line.
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
    """``unshare -n`` as root; a user namespace mapped to root (``-rn``) otherwise."""
    return ["unshare", "-n"] if os.geteuid() == 0 else ["unshare", "-rn"]


@cache
def netns_problem() -> str | None:
    """Why a loopback-only network namespace cannot be made here, or ``None``."""
    for tool in ("unshare", "ip"):
        if subprocess.run(["sh", "-c", f"command -v {tool}"], capture_output=True,
                          check=False).returncode != 0:
            return f"needs {tool} on PATH"
    netns = subprocess.run([*unshare_cmd(), "sh", "-c", "ip link set lo up"],
                           capture_output=True, text=True, timeout=30, check=False)
    if netns.returncode != 0:
        return f"needs network namespaces (unshare -n): {netns.stderr.strip()}"
    return None


def run_isolated(script: Path, case: str, *args: str, env: dict[str, str] | None = None,
                 timeout: float = 60.0) -> dict[str, Any]:
    """Run ``script case args...`` in a loopback-only network namespace; its JSON result."""
    full_env = dict(os.environ, PYTHONUNBUFFERED="1", **(env or {}))
    cmd = [*unshare_cmd(), "sh", "-c", 'ip link set lo up && exec "$@"', "sh",
           sys.executable, str(script), case, *args]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=full_env, cwd=REPO, start_new_session=True)
    try:
        out, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, err = proc.communicate()
        pytest.fail(f"{script.name} {case} ran over {timeout:g} s:\n{err[-3000:]}")
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)  # whatever it left behind
    lines = out.strip().splitlines()
    if proc.returncode != 0 or not lines:
        pytest.fail(f"{script.name} {case} failed ({proc.returncode}):\n{err[-3000:]}")
    result: dict[str, Any] = json.loads(lines[-1])
    return result
