"""Conformance checkers for plugin authors: run them on your plugin in your own tests.

Each ``check_*`` raises ``AssertionError`` with a message naming the broken rule.
"""

from arena.testing.conformance import (
    check_backend,
    check_crowd_model,
    check_map_source,
    check_task_mode,
)

__all__ = ["check_backend", "check_crowd_model", "check_map_source", "check_task_mode"]
