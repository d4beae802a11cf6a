"""Playwright driving the system's Chromium (Debian's ``chromium``; no browser download).

Without Chromium the browser tests skip on a user's machine and fail in CI
(``ARENA_REQUIRE_CHROMIUM=1``, set by ``.ci/run`` after ``tools/install_chromium.sh``).
"""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
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


def _placed(page: Any, key: str, point: tuple[float, float]) -> bool:
    """Robot 0's ``start`` / ``goal`` in the editor is within 5 cm of ``point``."""
    at = page.evaluate(f"(window.arenaEditor.scenario.robots[0] || {{}}).{key} || null")
    return at is not None and abs(at[0] - point[0]) < 0.05 and abs(at[1] - point[1]) < 0.05


def editor_click(page: Any, x: float, y: float) -> None:
    """Click the editor's canvas at the world point ``(x, y)`` (m)."""
    px, py = page.evaluate(f"window.arenaEditor.pageOf({x}, {y})")
    page.mouse.click(px, py)


def kill_jobs(root: Path) -> None:
    """SIGKILL the process groups of the processes whose command line names ``root``.

    That is every job a test started under ``root`` (wrappers and commands name their folder;
    a benchmark's workers share its group), orphans of a killed wrapper too; never a pid read
    from a job file, which the tests also fill with other processes' pids.
    """
    own = os.getpgid(0)
    groups = set()
    for proc in Path("/proc").glob("[0-9]*"):
        with contextlib.suppress(OSError):
            if str(root).encode() in (proc / "cmdline").read_bytes():
                groups.add(os.getpgid(int(proc.name)))
    for pgid in groups - {own, 0, 1}:
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.killpg(pgid, signal.SIGKILL)


def draw_scenario(page: Any, url: str, start: tuple[float, float], goal: tuple[float, float],
                  person: tuple[float, float], waypoints: Any) -> None:
    """In the editor at ``url``: load small_office, place the robot's start and goal and one
    person with its waypoints (world points, m) by clicking, and wait for the validation."""
    page.goto(f"{url}/editor")
    wait_until(lambda: editor_settled(page), what="the editor's first validation")
    page.select_option("#editor-world", "small_office")
    page.select_option("#editor-world-scenario", "")
    page.click("#editor-load-world")
    wait_until(lambda: page.inner_text("#editor-map-label") == "world small_office"
               and editor_settled(page) and page.evaluate("!!window.arenaEditor.map"),
               what="small_office")
    for tool, point in (("start", start), ("goal", goal)):
        # a click while the editor still swaps the map is lost: click again until it is placed
        for _ in range(5):
            page.click(f"#editor-tool-{tool}")
            editor_click(page, *point)
            with contextlib.suppress(AssertionError):
                wait_until(lambda tool=tool, point=point: _placed(page, tool, point),
                           timeout=5.0, what=f"the robot's {tool} at {point}")
                break
        assert _placed(page, tool, point), f"the robot's {tool} was not placed at {point}"
    page.click("#editor-tool-pedestrian")
    editor_click(page, *person)
    # placing a person switches to the waypoint tool for it
    wait_until(lambda: page.evaluate("window.arenaEditor.tool") == "waypoint",
               what="the waypoint tool")
    for wp in waypoints:
        editor_click(page, *wp)
    wait_until(lambda: editor_settled(page), what="the validation of the drawing")
