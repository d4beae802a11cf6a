"""The whole web app in a real browser, as a user goes through it: draw a scenario in the
editor and save it, start a run of it with a live view on the jobs page, watch it live, open
its results when it is done, and replay its episode. ``ARENA_SCREENSHOTS=DIR`` keeps a
screenshot of each step."""

from __future__ import annotations

import json

from tests.web.browser_kit import browser_page, draw_scenario, screenshot, wait_until

# small_office: an office around (-10, 3.5) and a free corridor along y = 0 (-12 .. 12 m)
START, GOAL = (-10.0, 3.5), (8.0, 0.0)  # about 20 m: time to watch it
PERSON, WAYPOINTS = (-6.0, 0.0), ((0.0, 0.0), (4.0, 0.0))


def test_create_save_run_watch_results_replay(web_app):
    web, root = web_app
    with browser_page() as page:
        # 1. the editor: a robot start and goal and a person with two waypoints
        draw_scenario(page, web.url, START, GOAL, PERSON, WAYPOINTS)
        assert page.inner_text("#editor-status").startswith("OK"), page.inner_text(
            "#editor-problems")
        page.fill("#editor-name", "flow")
        page.click("#editor-save")
        wait_until(lambda: "saved" in page.inner_text("#editor-save-result"), what="saving")
        assert page.inner_text("#editor-save-result").startswith("saved")
        screenshot(page, "flow_1_editor")

        # 2. the jobs page: run the saved scenario once, with a live view
        page.goto(f"{web.url}/jobs")
        page.locator("input#jobs-name").fill("flow_run")
        page.locator("#jobs-saved-scenario").click()
        page.get_by_role("option", name="flow", exact=True).click()
        page.locator("input#jobs-episodes").fill("1")
        page.locator("#jobs-live").click()
        screenshot(page, "flow_2_jobs")
        page.locator("#jobs-start").click()
        page.locator('[id="jobs-live-flow_run"]').wait_for(timeout=120_000)
        assert page.locator("#jobs-error").inner_text().strip() == ""
        job = json.loads((root / "flow_run" / "job.json").read_text())
        assert "--scenario" in job["argv"] and "--no-web" in job["argv"]

        # 3. the live view of the running episode
        page.locator('[id="jobs-live-flow_run"]').click()
        page.wait_for_url(f"{web.url}/live/flow_run")
        wait_until(lambda: page.evaluate("window.arenaView ? window.arenaView.drawn : 0") > 5,
                   timeout=120, what="live frames")
        frame = page.evaluate("window.arenaLive.lastFrame")
        assert len(frame["people"]["id"]) == 1  # the person drawn in the editor
        assert abs(frame["goal"][0] - GOAL[0]) < 0.1 and abs(frame["goal"][1] - GOAL[1]) < 0.1
        screenshot(page, "flow_3_live")

        # 4. its results once the job is done
        page.goto(f"{web.url}/jobs")
        page.wait_for_function(
            "document.getElementById('jobs-state-flow_run')?.textContent.trim() === 'done'",
            timeout=240_000)
        page.locator('[id="jobs-results-flow_run"]').click()
        page.wait_for_url(f"{web.url}/runs/flow_run")
        page.wait_for_function("document.querySelectorAll('.nicegui-echart canvas').length >= 3"
                               " && document.getElementById('results-episodes') !== null")
        assert "flow_run" in page.inner_text("#results-headline")
        screenshot(page, "flow_4_results", full_page=True)

        # 5. the replay of its episode, half-way
        page.get_by_text("replay").first.click()
        frames = wait_until(lambda: page.evaluate(
            "window.arenaReplay ? window.arenaReplay.frames.length : window.arenaReplayError"
            " ? -1 : 0"), timeout=120, what="the replay")
        assert frames > 1, page.inner_text("body")
        steps = json.loads((root / "flow_run" / "episode_000" / "episode.json").read_text())[
            "steps"]
        assert frames == steps + 1
        page.fill("#arena-slider", str(steps // 2))
        page.dispatch_event("#arena-slider", "input")
        assert page.evaluate("window.arenaView.frame.step") == steps // 2
        screenshot(page, "flow_5_replay")
