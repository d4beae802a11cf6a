"""Fixtures of the web app's browser tests."""

from __future__ import annotations

import os

import pytest

from arena.web.server import free_port, serve_subprocess
from tests.web.browser_kit import chromium_path, kill_jobs


@pytest.fixture
def web_app(tmp_path):
    """``arena web`` on an empty store ``tmp_path/runs``: ``(server, root)``; stopped, with
    every job it started, afterwards (its log: ``tmp_path/web.log``)."""
    chromium_path()
    root = tmp_path / "runs"
    root.mkdir()
    web = serve_subprocess(root, port=free_port(8400 + os.getpid() % 1000),
                           log=tmp_path / "web.log")
    try:
        yield web, root
    finally:
        web.stop()
        kill_jobs(root)
