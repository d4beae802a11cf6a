"""Playwright driving the system's Chromium (Debian's ``chromium``; no browser download).

Without Chromium the browser tests skip on a user's machine and fail in CI
(``ARENA_REQUIRE_CHROMIUM=1``, set by ``.ci/run`` after ``tools/install_chromium.sh``).
"""

from __future__ import annotations

import os
import shutil
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
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


def wait_until(predicate: Any, timeout: float = 60.0, what: str = "condition") -> Any:
    """Poll ``predicate`` every 50 ms until it returns something true; that value.

    Raises:
        AssertionError: not within ``timeout`` s (a bound, not a speed goal: generous for a
            loaded two-core machine).
    """
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.05)
    raise AssertionError(f"timed out waiting for {what}")


def screenshot(page: Any, name: str, *, full_page: bool = False) -> None:
    """Save the page as ``$ARENA_SCREENSHOTS/<name>.png`` when that variable names a folder."""
    folder = os.environ.get("ARENA_SCREENSHOTS")
    if folder:
        Path(folder).mkdir(parents=True, exist_ok=True)
        page.screenshot(path=str(Path(folder) / f"{name}.png"), full_page=full_page)


def editor_settled(page: Any) -> bool:
    """The scenario editor shows the validation of its current state."""
    return bool(page.evaluate("window.arenaEditor && window.arenaEditor.validated > 0 && "
                              "!window.arenaEditor.checking"))


def editor_click(page: Any, x: float, y: float) -> None:
    """Click the editor's canvas at the world point ``(x, y)`` (m)."""
    px, py = page.evaluate(f"window.arenaEditor.pageOf({x}, {y})")
    page.mouse.click(px, py)
