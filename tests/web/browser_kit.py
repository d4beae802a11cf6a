"""Playwright driving the system's Chromium (Debian's ``chromium``; no browser download).

Without Chromium the browser tests skip on a user's machine and fail in CI
(``ARENA_REQUIRE_CHROMIUM=1``, set by ``.ci/run`` after ``tools/install_chromium.sh``).
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import pytest


def chromium_path() -> str:
    """The Chromium executable; skips (or fails in CI) without one."""
    for name in ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable"):
        path = shutil.which(name)
        if path:
            return path
    message = "no Chromium on PATH (bash tools/install_chromium.sh)"
    if os.environ.get("ARENA_REQUIRE_CHROMIUM"):
        pytest.fail(message)
    pytest.skip(message)


@contextmanager
def browser_page(width: int = 1280, height: int = 900) -> Iterator[Any]:
    """A fresh page in headless Chromium, closed afterwards."""
    from playwright.sync_api import sync_playwright

    exe = chromium_path()
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=exe, args=["--no-sandbox"])
        try:
            page = browser.new_page(viewport={"width": width, "height": height})
            page.set_default_timeout(90_000)
            yield page
        finally:
            browser.close()
