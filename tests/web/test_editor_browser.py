"""The scenario editor in a real browser: a scenario drawn by clicking the canvas is validated
live, saved into the store's workspace, read back by Arena's loader, and opened again."""

from __future__ import annotations

import os

from arena.tasks.scenario import load_scenario
from arena.web.server import free_port, serve_subprocess
from tests.web.browser_kit import (
    browser_page,
    chromium_path,
    editor_click,
    editor_settled,
    screenshot,
    wait_until,
)

# small_office: an office around (-10, 3.5) and a free corridor along y = 0
START, GOAL = (-10.0, 3.5), (-7.0, 3.5)
PERSON, WAYPOINTS = (-6.0, 0.0), ((0.0, 0.0), (4.0, 0.0))






def test_draw_validate_save_and_open_a_scenario(tmp_path):
    chromium_path()
    root = tmp_path / "runs"
    root.mkdir()
    web = serve_subprocess(root, port=free_port(8900 + os.getpid() % 500),
                           log=tmp_path / "web.log")
    try:
        with browser_page() as page:
            page.goto(f"{web.url}/editor")
            wait_until(lambda: editor_settled(page), what="the editor's first validation")
            page.select_option("#editor-world", "small_office")
            page.select_option("#editor-world-scenario", "")
            page.click("#editor-load-world")
            wait_until(lambda: page.inner_text("#editor-map-label") == "world small_office"
                  and editor_settled(page), what="small_office")
            assert "no robot" in page.inner_text("#editor-problems")

            page.click("#editor-tool-start")
            editor_click(page, *START)
            page.click("#editor-tool-goal")
            editor_click(page, *GOAL)
            page.click("#editor-tool-pedestrian")
            editor_click(page, *PERSON)
            # placing a person switches to the waypoint tool for it
            wait_until(lambda: page.evaluate("window.arenaEditor.tool") == "waypoint",
                  what="the waypoint tool")
            for wp in WAYPOINTS:
                editor_click(page, *wp)
            wait_until(lambda: editor_settled(page), what="the validation of the drawing")
            assert page.inner_text("#editor-status").startswith("OK"), page.inner_text(
                "#editor-problems")
            assert page.inner_text("#editor-problems") == ""
            screenshot(page, "editor")

            page.fill("#editor-name", "editor_demo")
            page.click("#editor-save")
            wait_until(lambda: "saved" in page.inner_text("#editor-save-result")
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
            wait_until(lambda: editor_settled(page) and page.evaluate(
                "window.arenaEditor.scenario.obstacles.dynamic.length") == 1,
                what="the saved scenario, opened again")
            assert page.input_value("#editor-name") == "editor_demo"
            assert page.inner_text("#editor-status").startswith("OK")
            screenshot(page, "editor_opened")
    finally:
        web.stop()
