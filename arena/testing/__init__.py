"""Conformance checkers for plugin authors: run them on your plugin in your own tests.

Each ``check_*`` raises ``AssertionError`` with a message naming the broken rule:

* :func:`check_local_planner` (a local planner: commands inside the limits, deterministic ...);
* :func:`check_crowd_model`, :func:`check_task_mode`, :func:`check_map_source`,
  :func:`check_backend`.

See ``docs/plugins.md`` for complete plugin examples that pass them.
"""

from arena.testing.conformance import (
    check_backend,
    check_crowd_model,
    check_map_source,
    check_task_mode,
)
from arena.testing.local_planner import check_local_planner

__all__ = [
    "check_backend",
    "check_crowd_model",
    "check_local_planner",
    "check_map_source",
    "check_task_mode",
]
