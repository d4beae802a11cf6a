"""The one guard of the tests that need the optional mujoco extra (``arena[3d]``).

Without the extra (or without a GL library for rendering tests) such tests are skipped on a
user's machine. CI installs both (``.ci/run`` sets ``ARENA_REQUIRE_GL=1``): there a missing
piece fails the run instead, so a 3-D test can never pass by being skipped.
"""

from __future__ import annotations

import os
from typing import Any, NoReturn

import pytest

from arena.core.errors import ConfigError
from arena.sim.mujoco.mjcf import import_mujoco


def unavailable(message: str, *, module: bool = False) -> NoReturn:
    """Skip (module-wide with ``module``), or fail where CI requires the 3-D extra."""
    if os.environ.get("ARENA_REQUIRE_GL") == "1":
        pytest.fail(f"{message} (ARENA_REQUIRE_GL=1: CI installs it)", pytrace=False)
    pytest.skip(message, allow_module_level=module)


def require_mujoco(*, module: bool = True) -> Any:
    """The ``mujoco`` module (imported the way arena chooses its headless GL), else see above.

    ``module``: called at module level (skips the whole file), else inside one test.
    """
    try:
        return import_mujoco()
    except ConfigError as e:
        unavailable(f"needs the mujoco extra (pip install 'arena[3d]'): {e}", module=module)
