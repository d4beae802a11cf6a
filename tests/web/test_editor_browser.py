"""The scenario editor in a real browser: a scenario drawn by clicking the canvas is validated
live, saved into the store's workspace, read back by Arena's loader, and opened again."""

from __future__ import annotations

import os
import time
from pathlib import Path

from arena.tasks.scenario import load_scenario
from arena.web.server import free_port, serve_subprocess
from tests.web.browser_kit import browser_page, chromium_path

SHOTS = Path(os.environ.get("ARENA_SCREENSHOTS", "")) if os.environ.get(
    "ARENA_SCREENSHOTS") else None
# small_office: an office around (-10, 3.5) and a free corridor along y = 0
START, GOAL = (-10.0, 3.5), (-7.0, 3.5)
PERSON, WAYPOINTS = (-6.0, 0.0), ((0.0, 0.0), (4.0, 0.0))


def _shot(page, name: str) -> None:
    if SHOTS is not None:
        SHOTS.mkdir(parents=True, exist_ok=True)
        page.screenshot(path=str(SHOTS / f"{name}.png"))


def _wait(predicate, timeout: float = 60.0, what: str = "condition"):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.05)
    raise AssertionError(f"timed out waiting for {what}")


def _settled(page) -> bool:
    """The editor shows the validation of its current state."""
    return page.evaluate("window.arenaEditor && window.arenaEditor.validated > 0 && "
                         "!window.arenaEditor.checking")


def _click(page, x: float, y: float) -> None:
    px, py = page.evaluate(f"window.arenaEditor.pageOf({x}, {y})")
    page.mouse.click(px, py)


def test_draw_validate_save_and_open_a_scenario(tmp_path):
    chromium_path()
    root = tmp_path / "runs"
    root.mkdir()
    web = serve_subprocess(root, port=free_port(8900 + os.getpid() % 500),
                           log=tmp_path / "web.log")
    try:
        with browser_page() as page:
            page.goto(f"{web.url}/editor")
            _wait(lambda: _settled(page), what="the editor's first validation")
            page.select_option("#editor-world", "small_office")
            page.select_option("#editor-world-scenario", "")
            page.click("#editor-load-world")
            _wait(lambda: page.inner_text("#editor-map-label") == "world small_office"
                  and _settled(page), what="small_office")
            assert "no robot" in page.inner_text("#editor-problems")

            page.click("#editor-tool-start")
            _click(page, *START)
            page.click("#editor-tool-goal")
            _click(page, *GOAL)
            page.click("#editor-tool-pedestrian")
            _click(page, *PERSON)
            # placing a person switches to the waypoint tool for it
            _wait(lambda: page.evaluate("window.arenaEditor.tool") == "waypoint",
                  what="the waypoint tool")
            for wp in WAYPOINTS:
                _click(page, *wp)
            _wait(lambda: _settled(page), what="the validation of the drawing")
            assert page.inner_text("#editor-status").startswith("OK"), page.inner_text(
                "#editor-problems")
            assert page.inner_text("#editor-problems") == ""
            _shot(page, "editor")

            page.fill("#editor-name", "editor_demo")
            page.click("#editor-save")
            _wait(lambda: "saved" in page.inner_text("#editor-save-result")
                  or "not saved" in page.inner_text("#editor-save-result"), what="saving")
            assert page.inner_text("#editor-save-result").startswith("saved"), page.inner_text(
                "#editor-save-result")
            file = root / "_scenarios" / "editor_demo.json"
            assert file.is_file()
            scenario = load_scenario(file)
            assert scenario.map == "small_office"
            (start, goal), = [(r.start, r.goal) for r in scenario.robots]
            assert abs(start[0] - START[0]) < 0.1 and abs(start[1] - START[1]) < 0.1
            assert abs(goal[0] - GOAL[0]) < 0.1 and abs(goal[1] - GOAL[1]) < 0.1
            person, = scenario.obstacles.dynamic
            assert len(person.waypoints) == 2
            assert abs(person.waypoints[1][0] - WAYPOINTS[1][0]) < 0.1

            page.goto(f"{web.url}/editor?load=editor_demo")
            _wait(lambda: _settled(page) and page.evaluate(
                "window.arenaEditor.scenario.obstacles.dynamic.length") == 1,
                what="the saved scenario, opened again")
            assert page.input_value("#editor-name") == "editor_demo"
            assert page.inner_text("#editor-status").startswith("OK")
            _shot(page, "editor_opened")
    finally:
        web.stop()
