"""The scenario editor in a real browser: a scenario drawn by clicking the canvas is validated
live, saved into the store's workspace, read back by Arena's loader, and opened again."""

from __future__ import annotations

from arena.tasks.scenario import load_scenario
from tests.web.browser_kit import (
    browser_page,
    draw_scenario,
    editor_settled,
    screenshot,
    wait_until,
)

# small_office: an office around (-10, 3.5) and a free corridor along y = 0
START, GOAL = (-10.0, 3.5), (-7.0, 3.5)
PERSON, WAYPOINTS = (-6.0, 0.0), ((0.0, 0.0), (4.0, 0.0))


def test_draw_validate_save_and_open_a_scenario(web_app):
    web, root = web_app
    with browser_page() as page:
        draw_scenario(page, web.url, START, GOAL, PERSON, WAYPOINTS)
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
